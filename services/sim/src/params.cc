#include "tamp/core/format.h"
#include "tamp/sim/params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "tamp/config/schema.h"
#include "tamp/core/paths.h"
#include "tamp/effort_model/models.h"

namespace tamp::sim {
namespace {

int kindIndex(ActionKind kind) {
  const auto it = std::find(kAllActionKinds.begin(), kAllActionKinds.end(), kind);
  if (it == kAllActionKinds.end()) {
    throw std::invalid_argument("sim: unknown action kind " + std::to_string(static_cast<int>(kind)));
  }
  return static_cast<int>(it - kAllActionKinds.begin());
}

using config::Ends;
using config::inRange;
using config::nonNegative;
using config::positive;

const config::Schema<SimParams>& schema() {
  using P = SimParams;
  static const config::Schema<P> kSchema = [] {
    config::Schema<P> s;
    s.root()
        .field("scenario", &P::scenario)
        .field("realtime_factor", &P::realtime_factor, nonNegative("(0 = as fast as possible)"))
        .field("state_period_s", &P::state_period_s, inRange(0, 10, Ends::kOpenClosed, "s"))
        .field("cloud_period_s", &P::cloud_period_s, nonNegative("s"))
        .field("duration_noise", &P::duration_noise,
               inRange(0, 1, Ends::kClosed, "(stddev of log duration)"))
        .convert<int>("seed", &P::seed,
                      [](int v, std::uint64_t& out) -> std::optional<std::string> {
                        if (v < 0) return "must be >= 0, got " + std::to_string(v);
                        out = static_cast<std::uint64_t>(v);
                        return std::nullopt;
                      })
        .field("max_step_m", &P::max_step_m, inRange(0, 0.5, Ends::kOpenClosed, "m"));
    s.section("start_tolerance", &P::start_tolerance)
        .field("position_m", &StartTolerance::position_m, positive())
        .field("angle_rad", &StartTolerance::angle_rad, positive());
    s.section("grasp", &P::grasp)
        .field("position_tolerance_m", &GraspParams::position_tolerance_m, positive())
        .field("tcp_tolerance_m", &GraspParams::tcp_tolerance_m, nonNegative())
        .field("max_payload_kg", &GraspParams::max_payload_kg, positive());
    s.section("place", &P::place)
        .field("position_tolerance_m", &PlaceParams::position_tolerance_m, positive())
        .field("angle_tolerance_rad", &PlaceParams::angle_tolerance_rad, positive())
        .field("max_drop_m", &PlaceParams::max_drop_m, nonNegative())
        .field("max_tilt_rad", &PlaceParams::max_tilt_rad,
               config::that<double>(
                   [](double v) { return std::isfinite(v) && v > 0 && v < std::numbers::pi / 2; },
                   "must be in (0, pi/2)"));
    return s;
  }();
  return kSchema;
}

}  // namespace

TimeParameters TimeParameters::simulatedRobot() {
  TimeParameters t;
  for (ActionKind k : kAllActionKinds) t.of(k) = effort_model::modelSpec(k).defaults();
  using K = ActionKind;
  t.set(K::kMoveBase, "max_linear_speed", 0.4);
  t.set(K::kMoveBase, "max_linear_accel", 0.3);
  t.set(K::kMoveBase, "max_angular_speed", 1.2);
  t.set(K::kMoveBase, "max_angular_accel", 1.0);
  t.set(K::kMoveBase, "settle_time", 0.35);
  t.set(K::kMoveBase, "overhead", 0.8);
  t.set(K::kMoveArm, "max_joint_speed", 0.8);
  t.set(K::kMoveArm, "max_joint_accel", 1.5);
  t.set(K::kMoveArm, "settle_time", 0.15);
  t.set(K::kMoveArm, "overhead", 0.5);
  t.set(K::kMoveArm, "payload_slowdown", 0.15);
  t.set(K::kPick, "approach_speed", 0.04);
  t.set(K::kPick, "gripper_time", 2.2);
  t.set(K::kPick, "payload_slowdown", 0.3);
  t.set(K::kPlace, "approach_speed", 0.04);
  t.set(K::kPlace, "gripper_time", 1.4);
  t.set(K::kPlace, "payload_slowdown", 0.3);
  return t;
}

const std::vector<double>& TimeParameters::of(ActionKind kind) const { return values[kindIndex(kind)]; }
std::vector<double>& TimeParameters::of(ActionKind kind) { return values[kindIndex(kind)]; }

double TimeParameters::get(ActionKind kind, const std::string& name) const {
  const int i = effort_model::modelSpec(kind).indexOf(name);
  if (i < 0 || i >= static_cast<int>(of(kind).size())) {
    throw std::invalid_argument("TimeParameters: no parameter '" + name + "' for " +
                                std::string(toString(kind)));
  }
  return of(kind)[i];
}

void TimeParameters::set(ActionKind kind, const std::string& name, double value) {
  const auto& spec = effort_model::modelSpec(kind);
  const int i = spec.indexOf(name);
  if (i < 0) {
    throw std::invalid_argument("TimeParameters: no parameter '" + name + "' for " +
                                std::string(toString(kind)));
  }
  auto& v = of(kind);
  if (v.size() != static_cast<std::size_t>(spec.size())) v = spec.defaults();
  v[i] = value;
}

Status TimeParameters::validate() const {
  std::vector<Error> errors;
  for (ActionKind k : kAllActionKinds) {
    const auto& spec = effort_model::modelSpec(k);
    const auto& v = of(k);
    const std::string base = "time_parameters." + std::string(toString(k));
    if (v.size() != static_cast<std::size_t>(spec.size())) {
      errors.emplace_back(ErrorCode::kInvalidArgument,
                          "expected " + std::to_string(spec.size()) + " values, got " + std::to_string(v.size()),
                          SourceLocation{"", 0, 0, base});
      continue;
    }
    for (int i = 0; i < spec.size(); ++i) {
      const auto& ps = spec.parameters[i];
      if (!(std::isfinite(v[i]) && v[i] >= ps.lower && v[i] <= ps.upper)) {
        errors.emplace_back(ErrorCode::kInvalidArgument,
                            "must be within [" + formatNumber(ps.lower) + ", " + formatNumber(ps.upper) + "] " + ps.unit +
                                ", got " + formatNumber(v[i]),
                            SourceLocation{"", 0, 0, base + "." + ps.name});
      }
    }
  }
  if (errors.empty()) return Status::Ok();
  Error e(ErrorCode::kInvalidArgument, joinErrors(errors), errors.front().where);
  return e;
}

Status SimParams::validate() const {
  std::vector<Error> errors = schema().errors(*this);
  if (Status s = time_parameters.validate(); !s) errors.push_back(s.error());
  if (Status s = sensor.validate(); !s) errors.push_back(s.error());
  if (errors.empty()) return Status::Ok();
  return Error(ErrorCode::kInvalidArgument, "invalid simulator parameters:\n" + joinErrors(errors),
               errors.front().where);
}

Result<SimParams> parseSimParams(const std::string& yaml_text, const std::string& name) {
  auto doc = config::parseYaml(yaml_text, name);
  if (!doc) return doc.error();
  SimParams p;
  config::FieldReader r(*doc);
  if (doc->root.IsNull()) return p;  // an empty file: every default
  if (!r.isMap()) {
    return Error(ErrorCode::kParseError, "expected a mapping of simulator parameters", SourceLocation{name});
  }
  schema().read(r, p);
  for (auto& [kind_name, kr] : r.entries("time_parameters", false)) {
    const auto kind = actionKindFromString(kind_name);
    if (!kind) {
      r.child("time_parameters").fail(kind_name, "unknown action kind '" + kind_name +
                                                     "' (expected one of: move_base, move_arm, pick, place)");
      continue;
    }
    const auto& spec = effort_model::modelSpec(*kind);
    for (int i = 0; i < spec.size(); ++i) {
      const auto& ps = spec.parameters[i];
      double v = p.time_parameters.of(*kind)[i];
      if (kr.optional(ps.name, v) &&
          kr.check(std::isfinite(v) && v >= ps.lower && v <= ps.upper, ps.name,
                   "must be within [" + formatNumber(ps.lower) + ", " + formatNumber(ps.upper) + "] " + ps.unit + ", got " + formatNumber(v))) {
        p.time_parameters.of(*kind)[i] = v;
      }
    }
    kr.refuseUnknownKeys();
  }
  {
    auto c = r.child("sensor", false);
    DepthSensorParams& s = p.sensor;
    c.optional("sensor_id", s.sensor_id);
    c.optional("frame", s.frame);
    c.optional("width", s.width);
    c.optional("height", s.height);
    c.optional("horizontal_fov_rad", s.horizontal_fov_rad);
    c.optional("min_range_m", s.min_range_m);
    c.optional("max_range_m", s.max_range_m);
    c.optional("noise_stddev_m", s.noise_stddev_m);
    c.optional("noise_quadratic", s.noise_quadratic);
    c.optional("dropout_probability", s.dropout_probability);
    c.optional("see_robot", s.see_robot);
    int sseed = static_cast<int>(s.seed);
    if (c.optional("seed", sseed) && c.check(sseed >= 0, "seed", "must be >= 0")) s.seed = static_cast<std::uint64_t>(sseed);
    if (c.isMap()) {
      c.refuseUnknownKeys();
      if (Status st = s.validate(); !st) {
        // One error per bad field, located in the file ("sensor.width: must be ..." -> key width).
        std::string msg = st.error().message;
        std::size_t pos = 0;
        while (pos < msg.size()) {
          std::size_t end = msg.find("; ", pos);
          if (end == std::string::npos) end = msg.size();
          const std::string part = msg.substr(pos, end - pos);
          const auto colon = part.find(": ");
          std::string key = part.substr(0, colon);
          if (key.rfind("sensor.", 0) == 0) key = key.substr(7);
          c.fail(key, colon == std::string::npos ? part : part.substr(colon + 2));
          pos = end + 2;
        }
      }
    }
  }
  r.refuseUnknownKeys();
  if (!r.ok()) return r.status().error();
  if (Status s = p.validate(); !s) return s.error();
  return p;
}

Result<SimParams> loadSimParams(const std::filesystem::path& file) {
  auto text = readTextFile(file);
  if (!text) return text.error();
  auto p = parseSimParams(*text, file.string());
  if (p && !p->scenario.empty()) p->scenario = resolveRelativeTo(file, p->scenario).string();
  return p;
}

}  // namespace tamp::sim
