#include "tamp/core/format.h"
#include "tamp/sim/params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "tamp/config/schema.h"
#include "tamp/core/paths.h"

namespace tamp::sim {
namespace {

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
        .field("checkpoint_period_s", &P::checkpoint_period_s, inRange(0, 10, Ends::kOpenClosed, "s"))
        .field("checkpoint_idle_period_s", &P::checkpoint_idle_period_s, inRange(0, 60, Ends::kOpenClosed, "s"))
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
    s.section("push", &P::push)
        .field("max_contact_gap_m", &PushParams::max_contact_gap_m, positive())
        .field("lateral_slip", &PushParams::lateral_slip, nonNegative())
        .field("yaw_slip_rad_per_m", &PushParams::yaw_slip_rad_per_m, nonNegative());
    return s;
  }();
  return kSchema;
}

const config::Schema<DynamicsParams>& dynamicsSchema() {
  using D = DynamicsParams;
  static const config::Schema<D> kSchema = [] {
    config::Schema<D> s;
    s.section("base", &D::base)
        .field("linear_speed", &BaseDynamics::linear_speed, positive())
        .field("linear_accel", &BaseDynamics::linear_accel, positive())
        .field("linear_jerk", &BaseDynamics::linear_jerk, positive())
        .field("angular_speed", &BaseDynamics::angular_speed, positive())
        .field("angular_accel", &BaseDynamics::angular_accel, positive())
        .field("angular_jerk", &BaseDynamics::angular_jerk, positive())
        .field("settle_s", &BaseDynamics::settle_s, nonNegative("s"))
        .field("latency_s", &BaseDynamics::latency_s, nonNegative("s"));
    s.section("arm", &D::arm)
        .field("speed_fraction", &ArmDynamics::speed_fraction, inRange(0, 1, Ends::kOpenClosed, "(of the URDF limit)"))
        .field("max_speed", &ArmDynamics::max_speed, positive())
        .field("accel", &ArmDynamics::accel, positive())
        .field("jerk", &ArmDynamics::jerk, positive())
        .field("corner_threshold_rad", &ArmDynamics::corner_threshold_rad,
               inRange(0, std::numbers::pi, Ends::kOpen, "rad"))
        .field("settle_s", &ArmDynamics::settle_s, nonNegative("s"))
        .field("latency_s", &ArmDynamics::latency_s, nonNegative("s"));
    s.section("hand", &D::hand)
        .field("approach_speed", &HandDynamics::approach_speed, positive())
        .field("approach_accel", &HandDynamics::approach_accel, positive())
        .field("approach_jerk", &HandDynamics::approach_jerk, positive())
        .field("close_s", &HandDynamics::close_s, nonNegative("s"))
        .field("open_s", &HandDynamics::open_s, nonNegative("s"));
    s.section("load", &D::load).field("per_kg", &LoadDynamics::per_kg, nonNegative("1/kg"));
    s.section("stall", &D::stall)
        .field("probability", &StallDynamics::probability, inRange(0, 1, Ends::kClosed))
        .field("min_s", &StallDynamics::min_s, nonNegative("s"))
        .field("max_s", &StallDynamics::max_s, nonNegative("s"));
    return s;
  }();
  return kSchema;
}

}  // namespace

Status SimParams::validate() const {
  std::vector<Error> errors = schema().errors(*this);
  if (Status s = dynamics.validate(); !s) errors.push_back(s.error());
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
  {
    auto d = r.child("dynamics", false);
    if (d.isMap()) {
      dynamicsSchema().read(d, p.dynamics);
      d.refuseUnknownKeys();
    } else if (r.has("dynamics")) {
      r.fail("dynamics", "expected a mapping (base, arm, hand, load, stall)");
    }
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
