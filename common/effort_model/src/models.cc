#include "tamp/effort_model/models.h"

#include <ceres/jet.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "tamp/effort_model/model_math.h"

namespace tamp::effort_model {
namespace {

// Defaults describe a small indoor mobile manipulator (base ~0.5 m/s, 6-7 dof arm ~1 rad/s).
// Bounds are physical plausibility limits, wide enough for any robot the system targets; the
// prior (log stddev) says how far from the default a value may plausibly be before any record.
const std::array<ModelSpec, 4>& specTable() {
  static const std::array<ModelSpec, 4> table{{
      {ActionKind::kMoveBase,
       {{"max_linear_speed", "m/s", 0.5, 0.01, 5.0, 0.5, "cruise speed of straight drives"},
        {"max_linear_accel", "m/s^2", 0.5, 0.01, 10.0, 0.5, "acceleration/deceleration of drives"},
        {"max_angular_speed", "rad/s", 1.0, 0.02, 10.0, 0.5, "cruise rate of turns in place"},
        {"max_angular_accel", "rad/s^2", 1.5, 0.02, 20.0, 0.5, "angular acceleration of turns"},
        {"settle_time", "s", 0.2, 0.001, 10.0, 1.0, "stop/settle time after each drive or turn"},
        {"overhead", "s", 0.5, 0.001, 60.0, 1.0, "fixed time per action (start-up, checks)"},
        {"payload_slowdown", "1/kg", 0.02, 1e-4, 5.0, 1.0,
         "drive and turn speeds and accelerations divided by 1 + payload_slowdown * mass (carried "
         "or pushed)"}}},
      {ActionKind::kMoveArm,
       {{"max_joint_speed", "rad/s", 1.0, 0.02, 10.0, 0.5, "joint cruise speed (all joints)"},
        {"max_joint_accel", "rad/s^2", 2.0, 0.02, 50.0, 0.5, "joint acceleration (all joints)"},
        {"settle_time", "s", 0.1, 0.001, 10.0, 1.0, "stop/settle time after each segment"},
        {"overhead", "s", 0.3, 0.001, 60.0, 1.0, "fixed time per action"},
        {"payload_slowdown", "1/kg", 0.1, 1e-4, 5.0, 1.0,
         "speed and acceleration are divided by 1 + payload_slowdown * mass"}}},
      {ActionKind::kPick,
       {{"approach_speed", "m/s", 0.05, 0.002, 1.0, 0.5, "gripper speed on approach/retreat"},
        {"approach_accel", "m/s^2", 0.2, 0.005, 10.0, 0.5, "gripper acceleration"},
        {"gripper_time", "s", 1.5, 0.01, 60.0, 1.0, "closing, grasp check and fixed overhead"},
        {"payload_slowdown", "1/kg", 0.2, 1e-4, 5.0, 1.0,
         "retreat speed and acceleration divided by 1 + payload_slowdown * mass"}}},
      {ActionKind::kPlace,
       {{"approach_speed", "m/s", 0.05, 0.002, 1.0, 0.5, "gripper speed on approach/retreat"},
        {"approach_accel", "m/s^2", 0.2, 0.005, 10.0, 0.5, "gripper acceleration"},
        {"gripper_time", "s", 1.0, 0.01, 60.0, 1.0, "opening, release check and fixed overhead"},
        {"payload_slowdown", "1/kg", 0.2, 1e-4, 5.0, 1.0,
         "approach speed and acceleration divided by 1 + payload_slowdown * mass"}}},
  }};
  return table;
}

void checkParams(const ActionFeatures& features, std::span<const double> params) {
  const ModelSpec& spec = modelSpec(features.kind);
  if (static_cast<int>(params.size()) != spec.size()) {
    throw std::invalid_argument("model of '" + std::string(toString(features.kind)) + "' takes " +
                                std::to_string(spec.size()) + " parameters, got " +
                                std::to_string(params.size()));
  }
  for (int i = 0; i < spec.size(); ++i) {
    if (!std::isfinite(params[i]) || params[i] <= 0.0) {
      throw std::invalid_argument("parameter '" + spec.parameters[i].name + "' of '" +
                                  std::string(toString(features.kind)) +
                                  "' must be positive and finite, got " + std::to_string(params[i]));
    }
  }
}

}  // namespace

int ModelSpec::indexOf(const std::string& name) const {
  for (int i = 0; i < size(); ++i) {
    if (parameters[i].name == name) return i;
  }
  return -1;
}

std::vector<std::string> ModelSpec::names() const {
  std::vector<std::string> out;
  for (const auto& p : parameters) out.push_back(p.name);
  return out;
}

std::vector<double> ModelSpec::defaults() const {
  std::vector<double> out;
  for (const auto& p : parameters) out.push_back(p.default_value);
  return out;
}

const ModelSpec& modelSpec(ActionKind kind) {
  for (const auto& spec : specTable()) {
    if (spec.kind == kind) return spec;
  }
  throw std::invalid_argument("unknown action kind " + std::to_string(static_cast<int>(kind)));
}

double trapezoidTime(double d, double v, double a) {
  require(std::isfinite(d) && d >= 0.0, "trapezoidTime: d must be finite and >= 0");
  require(v > 0.0 && a > 0.0, "trapezoidTime: v and a must be positive");
  return detail::trapezoid(d, v, a);
}

double predictDuration(const ActionFeatures& features, std::span<const double> params) {
  checkParams(features, params);
  return detail::duration<double>(features, params.data());
}

Result<double> predictDuration(const ActionDescription& action, std::span<const double> params,
                               const FeatureOptions& options) {
  auto features = extractFeatures(action, options);
  if (!features) return features.error();
  return predictDuration(*features, params);
}

double predictDurationWithLogGradient(const ActionFeatures& features, std::span<const double> params,
                                      std::span<double> gradient) {
  checkParams(features, params);
  require(gradient.size() >= params.size(), "predictDurationWithLogGradient: gradient too small");
  using Jet = ceres::Jet<double, kMaxModelParameters>;
  std::array<Jet, kMaxModelParameters> p;
  for (std::size_t i = 0; i < params.size(); ++i) {
    // d p / d log p = p
    p[i] = Jet(params[i], static_cast<int>(i));
    p[i].v[static_cast<int>(i)] = params[i];
  }
  const Jet t = detail::duration<Jet>(features, p.data());
  for (std::size_t i = 0; i < params.size(); ++i) gradient[i] = t.v[static_cast<int>(i)];
  return t.a;
}

}  // namespace tamp::effort_model
