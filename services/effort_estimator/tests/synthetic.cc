#include "synthetic.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "tamp/effort_estimator/models.h"

namespace tamp::effort_estimator::synthetic {
namespace {

double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}
int uniformInt(std::mt19937_64& rng, int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }

ActionDescription baseAction(std::mt19937_64& rng, const ActionDistribution& dist) {
  ActionDescription a;
  a.kind = ActionKind::kMoveBase;
  a.path.joint_names = {"base_x", "base_y", "base_theta"};
  double x = uniform(rng, -5, 5), y = uniform(rng, -5, 5), th = uniform(rng, -3, 3);
  a.path.waypoints.push_back({x, y, th});
  const int legs = uniformInt(rng, 1, 6);
  double heading = th;
  for (int i = 0; i < legs; ++i) {
    const double max_turn = dist.short_moves_only ? 0.3 : std::numbers::pi;
    heading += uniform(rng, -max_turn, max_turn);
    const bool long_leg = !dist.short_moves_only && uniform(rng, 0, 1) < 0.6;
    const double length = long_leg ? uniform(rng, 0.5, 5.0) : uniform(rng, 0.03, 0.15);
    // Some legs are densely sampled (as a planner's interpolated output is).
    const int pieces = uniform(rng, 0, 1) < 0.3 ? uniformInt(rng, 2, 5) : 1;
    for (int p = 0; p < pieces; ++p) {
      x += std::cos(heading) * length / pieces;
      y += std::sin(heading) * length / pieces;
      a.path.waypoints.push_back({x, y, heading});
    }
  }
  const double final_turn = dist.short_moves_only ? 0.3 : std::numbers::pi;
  a.path.waypoints.back()[2] = heading + uniform(rng, -final_turn, final_turn);
  if (uniform(rng, 0, 1) < 0.3) a.object_mass_kg = uniform(rng, 0.1, 2.0);
  return a;
}

ActionDescription armAction(std::mt19937_64& rng, const ActionDistribution& dist) {
  ActionDescription a;
  a.kind = ActionKind::kMoveArm;
  for (int j = 1; j <= 6; ++j) a.path.joint_names.push_back("arm_joint_" + std::to_string(j));
  std::vector<double> q(6);
  for (double& v : q) v = uniform(rng, -1.5, 1.5);
  a.path.waypoints.push_back(q);
  const int segments = uniformInt(rng, 1, 5);
  for (int s = 0; s < segments; ++s) {
    const double range = dist.short_moves_only ? 0.05 : (uniform(rng, 0, 1) < 0.5 ? 0.15 : 2.0);
    for (double& v : q) v += uniform(rng, -range, range);
    a.path.waypoints.push_back(q);
  }
  if (uniform(rng, 0, 1) < 0.5) a.object_mass_kg = uniform(rng, 0.1, 3.0);
  return a;
}

ActionDescription manipulationAction(ActionKind kind, std::mt19937_64& rng, const ActionDistribution& dist) {
  ActionDescription a;
  a.kind = kind;
  const double hi = dist.short_moves_only ? 0.02 : 0.30;
  a.approach_m = uniform(rng, 0.01, hi);
  a.retreat_m = uniform(rng, 0.01, hi);
  a.object_mass_kg = uniform(rng, 0.0, 3.0);
  return a;
}

/// The "real robot" of the mismatch mode (see ExecutionNoise::mismatch).
double mismatchedDuration(const ActionDescription& a, std::span<const double> p) {
  const double nominal = *predictDuration(a, p);
  switch (a.kind) {
    case ActionKind::kMoveBase:
      return nominal + 0.08 * static_cast<double>(a.path.waypoints.size());
    case ActionKind::kMoveArm: {
      static constexpr double kSpeed[] = {1.0, 1.0, 0.8, 0.8, 1.3, 1.3};
      static constexpr double kAccel[] = {1.0, 0.9, 0.8, 0.7, 1.3, 1.5};
      const double slow = 1.0 + p[4] * a.object_mass_kg;
      double t = p[3];
      for (std::size_t i = 1; i < a.path.waypoints.size(); ++i) {
        double seg = 0.0;
        for (std::size_t j = 0; j < a.path.joint_names.size(); ++j) {
          const double d = std::abs(a.path.waypoints[i][j] - a.path.waypoints[i - 1][j]);
          seg = std::max(seg, trapezoidTime(d, kSpeed[j % 6] * p[0] / slow, kAccel[j % 6] * p[1] / slow));
        }
        t += seg + p[2];
      }
      return t;
    }
    case ActionKind::kPick:
    case ActionKind::kPlace:
      return nominal + 0.1 * a.object_mass_kg * a.object_mass_kg;
  }
  return nominal;
}

}  // namespace

FeatureOptions urdfJointScales() {
  FeatureOptions o;
  const double scales[] = {1.0, 1.0, 0.8, 0.8, 1.3, 1.3};
  for (int j = 0; j < 6; ++j) o.joint_scales["arm_joint_" + std::to_string(j + 1)] = scales[j];
  return o;
}

ActionDescription randomAction(ActionKind kind, std::mt19937_64& rng, const ActionDistribution& dist) {
  switch (kind) {
    case ActionKind::kMoveBase: return baseAction(rng, dist);
    case ActionKind::kMoveArm: return armAction(rng, dist);
    case ActionKind::kPick:
    case ActionKind::kPlace: return manipulationAction(kind, rng, dist);
  }
  throw std::invalid_argument("randomAction: unknown kind");
}

std::vector<double> trueParameters(ActionKind kind) {
  std::vector<double> factors;
  switch (kind) {
    case ActionKind::kMoveBase: factors = {0.7, 1.4, 1.3, 0.75, 1.5, 1.6, 1.8}; break;
    case ActionKind::kMoveArm: factors = {1.3, 0.7, 1.6, 0.6, 2.0}; break;
    case ActionKind::kPick: factors = {1.4, 0.7, 1.3, 1.8}; break;
    case ActionKind::kPlace: factors = {0.75, 1.5, 0.7, 0.5}; break;
  }
  std::vector<double> p = modelSpec(kind).defaults();
  for (std::size_t i = 0; i < p.size(); ++i) p[i] *= factors[i];
  return p;
}

ExecutionRecord simulate(const ActionDescription& action, std::span<const double> params,
                         const ExecutionNoise& noise, std::mt19937_64& rng, double timestamp_s) {
  auto t = predictDuration(action, params);
  if (!t) throw std::invalid_argument("simulate: " + t.error().toString());
  const double base = noise.mismatch ? mismatchedDuration(action, params) : *t;
  double d = base * std::exp(noise.log_stddev * std::normal_distribution<double>(0.0, 1.0)(rng));
  if (noise.outlier_fraction > 0 && uniform(rng, 0, 1) < noise.outlier_fraction) {
    d *= uniform(rng, noise.outlier_min, noise.outlier_max);
  }
  ExecutionRecord r;
  r.action = action;
  r.duration_s = d;
  r.timestamp_s = timestamp_s;
  r.source = "synthetic";
  return r;
}

std::vector<ExecutionRecord> records(ActionKind kind, int n, std::mt19937_64& rng, const ExecutionNoise& noise,
                                     const ActionDistribution& dist) {
  const std::vector<double> truth = trueParameters(kind);
  std::vector<ExecutionRecord> out;
  for (int i = 0; i < n; ++i) out.push_back(simulate(randomAction(kind, rng, dist), truth, noise, rng, 1e9 + i));
  return out;
}

std::vector<FeatureRecord> featureRecords(ActionKind kind, int n, std::mt19937_64& rng, const ExecutionNoise& noise,
                                          const ActionDistribution& dist) {
  std::vector<FeatureRecord> out;
  for (const auto& r : records(kind, n, rng, noise, dist)) {
    auto f = toFeatureRecord(r);
    if (!f) throw std::invalid_argument("featureRecords: " + f.error().toString());
    out.push_back(std::move(*f));
  }
  return out;
}

}  // namespace tamp::effort_estimator::synthetic
