#include "tamp/sim/dynamics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "tamp/core/format.h"

namespace tamp::sim {
namespace {

constexpr double kMinJointMove = 1e-6;  // arm runs whose joints all move less are dropped

bool finitePositive(double v) { return std::isfinite(v) && v > 0.0; }

/// Time of the acceleration phase to peak speed vp (and its peak acceleration).
void accelPhase(double vp, double a, double j, double& tj, double& tc) {
  const double ap = std::min(a, std::sqrt(vp * j));
  tj = ap / j;
  tc = std::max(0.0, vp / ap - tj);
}

/// Distance of an accelerate-then-decelerate move peaking at vp.
double rampDistance(double vp, double a, double j) {
  double tj = 0.0, tc = 0.0;
  accelPhase(vp, a, j, tj, tc);
  return vp * (2.0 * tj + tc);  // two symmetric phases, mean speed vp / 2 each
}

}  // namespace

MotionProfile MotionProfile::restToRest(double length, double v, double a, double j) {
  if (!(std::isfinite(length) && length >= 0.0) || !finitePositive(v) || !finitePositive(a) ||
      !finitePositive(j)) {
    throw std::invalid_argument(
        "MotionProfile: length must be >= 0 and limits finite and > 0 (length " +
        formatNumber(length, 4) + ", v " + formatNumber(v, 4) + ", a " + formatNumber(a, 4) +
        ", j " + formatNumber(j, 4) + ")");
  }
  MotionProfile p;
  p.length_ = length;
  if (length == 0.0) return p;
  double vp = v;
  double cruise = 0.0;
  if (rampDistance(v, a, j) <= length) {
    cruise = (length - rampDistance(v, a, j)) / v;
  } else {
    double lo = 0.0, hi = v;
    for (int i = 0; i < 100; ++i) {
      const double mid = 0.5 * (lo + hi);
      (rampDistance(mid, a, j) < length ? lo : hi) = mid;
    }
    vp = 0.5 * (lo + hi);
  }
  double tj = 0.0, tc = 0.0;
  accelPhase(vp, a, j, tj, tc);
  const double plan[7][2] = {{j, tj},  {0.0, tc}, {-j, tj}, {0.0, cruise},
                             {-j, tj}, {0.0, tc}, {j, tj}};
  double t = 0.0, s = 0.0, vel = 0.0, acc = 0.0;
  for (const auto& [jerk, dt] : plan) {
    if (dt <= 0.0) continue;
    p.segments_.push_back(Segment{t, dt, jerk, s, vel, acc});
    s += vel * dt + 0.5 * acc * dt * dt + jerk * dt * dt * dt / 6.0;
    vel += acc * dt + 0.5 * jerk * dt * dt;
    acc += jerk * dt;
    t += dt;
  }
  p.duration_ = t;
  return p;
}

double MotionProfile::positionAt(double t) const {
  if (t <= 0.0 || segments_.empty()) return 0.0;
  if (t >= duration_) return length_;
  auto it = std::upper_bound(segments_.begin(), segments_.end(), t,
                             [](double x, const Segment& g) { return x < g.t0; });
  const Segment& g = *(it - 1);
  const double dt = t - g.t0;
  const double s = g.s0 + g.v0 * dt + 0.5 * g.a0 * dt * dt + g.jerk * dt * dt * dt / 6.0;
  return std::clamp(s, 0.0, length_);
}

double MotionProfile::timeAt(double s) const {
  if (s <= 0.0 || segments_.empty()) return 0.0;
  if (s >= length_) return duration_;
  double lo = 0.0, hi = duration_;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (positionAt(mid) < s ? lo : hi) = mid;
  }
  return hi;
}

namespace {

void checkPositive(std::vector<std::string>& bad, const std::string& field, double v) {
  if (!finitePositive(v))
    bad.push_back(field + ": must be finite and > 0, got " + formatNumber(v, 4));
}
void checkNonNegative(std::vector<std::string>& bad, const std::string& field, double v) {
  if (!(std::isfinite(v) && v >= 0.0))
    bad.push_back(field + ": must be finite and >= 0, got " + formatNumber(v, 4));
}

}  // namespace

Status DynamicsParams::validate() const {
  std::vector<std::string> bad;
  const std::string b = "dynamics.base.";
  checkPositive(bad, b + "linear_speed", base.linear_speed);
  checkPositive(bad, b + "linear_accel", base.linear_accel);
  checkPositive(bad, b + "linear_jerk", base.linear_jerk);
  checkPositive(bad, b + "angular_speed", base.angular_speed);
  checkPositive(bad, b + "angular_accel", base.angular_accel);
  checkPositive(bad, b + "angular_jerk", base.angular_jerk);
  checkNonNegative(bad, b + "settle_s", base.settle_s);
  checkNonNegative(bad, b + "latency_s", base.latency_s);
  const std::string a = "dynamics.arm.";
  if (!(arm.speed_fraction > 0.0 && arm.speed_fraction <= 1.0)) {
    bad.push_back(a + "speed_fraction: must be in (0, 1], got " +
                  formatNumber(arm.speed_fraction, 4));
  }
  checkPositive(bad, a + "max_speed", arm.max_speed);
  checkPositive(bad, a + "accel", arm.accel);
  checkPositive(bad, a + "jerk", arm.jerk);
  if (!(arm.corner_threshold_rad > 0.0 && arm.corner_threshold_rad < M_PI)) {
    bad.push_back(a + "corner_threshold_rad: must be in (0, pi), got " +
                  formatNumber(arm.corner_threshold_rad, 4));
  }
  checkNonNegative(bad, a + "settle_s", arm.settle_s);
  checkNonNegative(bad, a + "latency_s", arm.latency_s);
  const std::string h = "dynamics.hand.";
  checkPositive(bad, h + "approach_speed", hand.approach_speed);
  checkPositive(bad, h + "approach_accel", hand.approach_accel);
  checkPositive(bad, h + "approach_jerk", hand.approach_jerk);
  checkNonNegative(bad, h + "close_s", hand.close_s);
  checkNonNegative(bad, h + "open_s", hand.open_s);
  checkNonNegative(bad, "dynamics.load.per_kg", load.per_kg);
  if (!(stall.probability >= 0.0 && stall.probability <= 1.0)) {
    bad.push_back("dynamics.stall.probability: must be in [0, 1], got " +
                  formatNumber(stall.probability, 4));
  }
  checkNonNegative(bad, "dynamics.stall.min_s", stall.min_s);
  if (!(std::isfinite(stall.max_s) && stall.max_s >= stall.min_s)) {
    bad.push_back("dynamics.stall.max_s: must be finite and >= min_s, got " +
                  formatNumber(stall.max_s, 4));
  }
  if (bad.empty()) return Status::Ok();
  std::string msg;
  for (const auto& m : bad) msg += (msg.empty() ? "" : "; ") + m;
  const std::string field = bad.front().substr(0, bad.front().find(':'));
  return Error(ErrorCode::kInvalidArgument, msg, SourceLocation{"", 0, 0, field});
}

double loadFactor(const DynamicsParams& d, double mass_kg) {
  return 1.0 + d.load.per_kg * std::max(0.0, mass_kg);
}

Limits scaled(const Limits& l, double f) { return Limits{l.speed / f, l.accel / f, l.jerk}; }

std::vector<ArmRun> armRuns(const std::vector<std::vector<double>>& waypoints,
                            const std::vector<std::string>& joint_names,
                            const std::unordered_map<std::string, double>& joint_speed,
                            const ArmDynamics& arm, double load_factor) {
  const std::size_t n = joint_names.size();
  std::vector<double> w(n, 1.0);  // each joint's speed limit
  for (std::size_t j = 0; j < n; ++j) {
    const auto it = joint_speed.find(joint_names[j]);
    const double urdf = it != joint_speed.end() && it->second > 0.0 ? it->second : 1.0;
    w[j] = std::min(arm.max_speed, arm.speed_fraction * urdf);
  }
  std::vector<ArmRun> runs;
  if (waypoints.empty()) return runs;
  const double cos_tol = std::cos(arm.corner_threshold_rad);
  ArmRun run;
  std::vector<double> rate(n, 0.0);   // per joint: the largest |dq_j / du| over the run
  std::vector<double> moved(n, 0.0);  // per joint: total |dq_j| over the run
  std::vector<double> last_dir, dir(n), delta(n);
  auto start = [&](std::size_t i) {
    run = ArmRun{};
    run.points = {i};
    run.u = {0.0};
    std::fill(rate.begin(), rate.end(), 0.0);
    std::fill(moved.begin(), moved.end(), 0.0);
    last_dir.clear();
  };
  auto flush = [&]() {
    if (*std::max_element(moved.begin(), moved.end()) >= kMinJointMove && run.length() > 0.0) {
      constexpr double inf = std::numeric_limits<double>::infinity();
      run.limits = Limits{1.0 / load_factor, inf, inf};
      for (std::size_t j = 0; j < n; ++j) {
        if (rate[j] <= 0.0) continue;
        run.limits.accel = std::min(run.limits.accel, arm.accel / (load_factor * rate[j]));
        run.limits.jerk = std::min(run.limits.jerk, arm.jerk / rate[j]);
      }
      runs.push_back(std::move(run));
    }
  };
  start(0);
  for (std::size_t i = 1; i < waypoints.size(); ++i) {
    double largest = 0.0, norm2 = 0.0, du = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      delta[j] = waypoints[i][j] - waypoints[i - 1][j];
      largest = std::max(largest, std::abs(delta[j]));
      norm2 += delta[j] * delta[j];
      du = std::max(du, std::abs(delta[j]) / w[j]);
    }
    if (largest >= kMinJointMove) {
      // A corner above the threshold ends the run at waypoint i - 1 (direction in joint space).
      const double norm = std::sqrt(norm2);
      double dot = 0.0;
      for (std::size_t j = 0; j < n; ++j) {
        dir[j] = delta[j] / norm;
        if (!last_dir.empty()) dot += last_dir[j] * dir[j];
      }
      if (!last_dir.empty() && dot < cos_tol) {
        flush();
        start(i - 1);
      }
      last_dir = dir;
    }
    // Every waypoint stays on the run's path, even one that barely moves (a tiny segment does not
    // change the direction the next one is compared with).
    run.points.push_back(i);
    run.u.push_back(run.u.back() + du);
    for (std::size_t j = 0; j < n; ++j) {
      moved[j] += std::abs(delta[j]);
      if (du > 0.0) rate[j] = std::max(rate[j], std::abs(delta[j]) / du);
    }
  }
  flush();
  return runs;
}

namespace {

Error bad(const std::string& field, const std::string& message) {
  return Error(ErrorCode::kInvalidArgument, field + ": " + message,
               SourceLocation{"", 0, 0, field});
}

Status checkPath(const JointPath& p) {
  if (p.joint_names.empty()) return bad("path.joint_names", "no joints");
  for (std::size_t i = 0; i < p.waypoints.size(); ++i) {
    const std::string f = "path.waypoints[" + std::to_string(i) + "]";
    if (p.waypoints[i].size() != p.joint_names.size()) {
      return bad(f, "has " + std::to_string(p.waypoints[i].size()) + " values for " +
                        std::to_string(p.joint_names.size()) + " joints");
    }
    for (double v : p.waypoints[i]) {
      if (!std::isfinite(v)) return bad(f, "is not finite");
    }
  }
  return Status::Ok();
}

double baseDuration(const DynamicsParams& d, const JointPath& p, double f) {
  const int ix = p.indexOf("base_x"), iy = p.indexOf("base_y"), it = p.indexOf("base_theta");
  std::vector<Pose2D> poses;
  for (const auto& w : p.waypoints) poses.push_back(Pose2D{w[ix], w[iy], w[it]});
  double t = d.base.latency_s;
  for (const effort_model::BaseStep& r : effort_model::baseSteps(poses)) {
    const Limits l = scaled(
        r.kind == effort_model::BaseStep::Kind::kTurn ? d.base.angular() : d.base.linear(), f);
    t += MotionProfile::restToRest(r.amount, l.speed, l.accel, l.jerk).duration() + d.base.settle_s;
  }
  return t;
}

}  // namespace

Result<double> nominalDuration(const DynamicsParams& d,
                               const std::unordered_map<std::string, double>& joint_speed,
                               const NominalQuery& q) {
  if (Status s = d.validate(); !s) return s.error();
  if (!(std::isfinite(q.object_mass_kg) && q.object_mass_kg >= 0.0)) {
    return bad("object_mass_kg",
               "must be finite and >= 0, got " + formatNumber(q.object_mass_kg, 4));
  }
  const double f = loadFactor(d, q.object_mass_kg);
  switch (q.kind) {
    case ActionKind::kMoveBase: {
      if (Status s = checkPath(q.path); !s) return s.error();
      for (const char* j : {"base_x", "base_y", "base_theta"}) {
        if (q.path.indexOf(j) < 0)
          return bad("path.joint_names", std::string("move_base needs ") + j);
      }
      return baseDuration(d, q.path, f);
    }
    case ActionKind::kMoveArm: {
      if (Status s = checkPath(q.path); !s) return s.error();
      for (const auto& name : q.path.joint_names) {
        if (name.rfind("base_", 0) == 0)
          return bad("path.joint_names", "move_arm moves no base joint ('" + name + "')");
      }
      double t = d.arm.latency_s;
      for (const ArmRun& r : armRuns(q.path.waypoints, q.path.joint_names, joint_speed, d.arm, f)) {
        t += MotionProfile::restToRest(r.length(), r.limits.speed, r.limits.accel, r.limits.jerk)
                 .duration() +
             d.arm.settle_s;
      }
      return t;
    }
    case ActionKind::kPick:
    case ActionKind::kPlace: {
      for (auto [field, v] :
           {std::pair{"approach_m", q.approach_m}, std::pair{"retreat_m", q.retreat_m}}) {
        if (!(std::isfinite(v) && v >= 0.0))
          return bad(field, "must be finite and >= 0, got " + formatNumber(v, 4));
      }
      const bool pick = q.kind == ActionKind::kPick;
      // A pick carries the mass on its retreat, a place on its approach.
      const Limits in = scaled(d.hand.approach(), pick ? 1.0 : f);
      const Limits out = scaled(d.hand.approach(), pick ? f : 1.0);
      return MotionProfile::restToRest(q.approach_m, in.speed, in.accel, in.jerk).duration() +
             (pick ? d.hand.close_s : d.hand.open_s) +
             MotionProfile::restToRest(q.retreat_m, out.speed, out.accel, out.jerk).duration();
    }
  }
  return bad("kind", "unknown action kind");
}

}  // namespace tamp::sim
