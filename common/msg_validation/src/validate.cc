#include "tamp/msg_validation/validate.h"

#include <cmath>
#include <limits>
#include <vector>

#include "tamp/core/log.h"

namespace tamp::msgv {
namespace {

/// Walks one message and keeps the first problem. Field paths are built only on failure, from
/// the parts pushed on the way (`Scope`), so a valid message costs no string work.
class Check {
 public:
  Check(const char* type, const Limits& limits) : limits_(limits) { parts_.push_back(type); }

  bool ok() const { return !error_; }
  Status status() const { return error_ ? Status(*error_) : Status::Ok(); }
  const Limits& limits() const { return limits_; }

  /// A nested field for the lifetime of the scope: `Scope s(c, "header");`.
  class Scope {
   public:
    Scope(Check& c, std::string part) : c_(c) { c_.parts_.push_back(std::move(part)); }
    Scope(Check& c, const char* name, std::size_t index) : c_(c) {
      c_.parts_.push_back(std::string(name) + "[" + std::to_string(index) + "]");
    }
    ~Scope() { c_.parts_.pop_back(); }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    Check& c_;
  };

  void fail(const std::string& field, const std::string& what) {
    if (error_) return;
    std::string path;
    for (const auto& p : parts_) {
      if (!p.empty()) path += (path.empty() ? "" : ".") + p;
    }
    if (!field.empty()) path += (field[0] == '[' ? "" : ".") + field;
    error_ = Error(ErrorCode::kInvalidArgument, path + ": " + what, SourceLocation{"", 0, 0, path});
  }

  // ---- numbers
  static std::string describe(double v) {
    if (std::isnan(v)) return "NaN";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return std::to_string(v);
  }
  bool finite(const char* field, double v) {
    if (std::isfinite(v)) return true;
    fail(field, describe(v));
    return false;
  }
  bool nonNegative(const char* field, double v) {
    if (!finite(field, v)) return false;
    if (v >= 0) return true;
    fail(field, "must be >= 0, got " + describe(v));
    return false;
  }
  bool inRange(const char* field, double v, double lo, double hi) {
    if (!finite(field, v)) return false;
    if (v >= lo && v <= hi) return true;
    fail(field, "must be in [" + describe(lo) + ", " + describe(hi) + "], got " + describe(v));
    return false;
  }
  /// Every value finite; the failing index is named ("values[3]: NaN").
  template <typename Seq>
  bool allFinite(const char* field, const Seq& values) {
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (!std::isfinite(static_cast<double>(values[i]))) {
        fail(std::string(field) + "[" + std::to_string(i) + "]", describe(static_cast<double>(values[i])));
        return false;
      }
    }
    return true;
  }

  // ---- enums (CDR carries any 32-bit value)
  template <typename E>
  bool enumIn(const char* field, E v, E last) {
    const auto raw = static_cast<std::uint64_t>(static_cast<std::uint32_t>(v));
    if (raw <= static_cast<std::uint64_t>(static_cast<std::uint32_t>(last))) return true;
    fail(field, "unknown value " + std::to_string(raw) + " (0.." +
                    std::to_string(static_cast<std::uint32_t>(last)) + ")");
    return false;
  }

  // ---- strings
  bool id(const char* field, const std::string& s, bool required) {
    if (s.empty()) {
      if (required) fail(field, "empty (an id is required)");
      return !required;
    }
    if (s.size() > limits_.max_id_length) {
      fail(field, "id of " + std::to_string(s.size()) + " bytes (limit " +
                      std::to_string(limits_.max_id_length) + ")");
      return false;
    }
    for (char ch : s) {
      if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) {
        fail(field, "control character in an id");
        return false;
      }
    }
    return true;
  }
  bool text(const char* field, const std::string& s) {
    if (s.size() <= limits_.max_text_length) return true;
    fail(field, "text of " + std::to_string(s.size()) + " bytes (limit " +
                    std::to_string(limits_.max_text_length) + ")");
    return false;
  }
  /// Ids in a list: each non-empty and bounded; the list within max_items.
  bool ids(const char* field, const std::vector<std::string>& v, std::size_t max) {
    if (!size(field, v, max)) return false;
    for (std::size_t i = 0; i < v.size(); ++i) {
      Scope s(*this, field, i);
      if (!id("", v[i], true)) return false;
    }
    return true;
  }

  // ---- sequences
  template <typename Seq>
  bool size(const char* field, const Seq& v, std::size_t max) {
    if (v.size() <= max) return true;
    fail(field, std::to_string(v.size()) + " elements (limit " + std::to_string(max) + ")");
    return false;
  }

  // ---- geometry
  bool pose2(const char* field, const msg::Pose2D& p) {
    Scope s(*this, field);
    return finite("x", p.x()) && finite("y", p.y()) && finite("theta", p.theta());
  }
  /// `used`: the receiver reads the rotation, so the quaternion must not be zero (it is
  /// normalised). Unused poses (default-constructed, all zero) need only be finite.
  bool pose3(const char* field, const msg::Pose3D& p, bool used) {
    Scope s(*this, field);
    const auto& t = p.position();
    const auto& q = p.orientation();
    if (!(finite("position.x", t.x()) && finite("position.y", t.y()) && finite("position.z", t.z()) &&
          finite("orientation.x", q.x()) && finite("orientation.y", q.y()) &&
          finite("orientation.z", q.z()) && finite("orientation.w", q.w()))) {
      return false;
    }
    const double n2 = q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w();
    if (used && !(n2 > 1e-12)) {
      fail("orientation", "zero quaternion");
      return false;
    }
    if (used && !std::isfinite(n2)) {
      fail("orientation", "quaternion norm overflows");
      return false;
    }
    return true;
  }
  bool points(const char* field, const std::vector<msg::Point2>& v) {
    if (!size(field, v, limits_.max_polygon_vertices)) return false;
    for (std::size_t i = 0; i < v.size(); ++i) {
      Scope s(*this, field, i);
      if (!finite("x", v[i].x()) || !finite("y", v[i].y())) return false;
    }
    return true;
  }
  bool poses2(const char* field, const std::vector<msg::Pose2D>& v) {
    if (!size(field, v, limits_.max_waypoints)) return false;
    for (std::size_t i = 0; i < v.size(); ++i) {
      Scope s(*this, field, i);
      if (!pose2("", v[i])) return false;
    }
    return true;
  }

  // ---- composite types of common.idl
  bool jointNames(const char* field, const std::vector<std::string>& names) {
    if (!size(field, names, limits_.max_joints)) return false;
    for (std::size_t i = 0; i < names.size(); ++i) {
      Scope s(*this, field, i);
      if (!id("", names[i], true)) return false;
    }
    return true;
  }
  bool jointPath(const char* field, const msg::JointPath& p) {
    Scope s(*this, field);
    if (!jointNames("joint_names", p.joint_names())) return false;
    const std::size_t n = p.joint_names().size();
    if (n == 0 && !p.values().empty()) {
      fail("values", std::to_string(p.values().size()) + " values without joint names");
      return false;
    }
    if (n != 0 && p.values().size() % n != 0) {
      fail("values", std::to_string(p.values().size()) + " values are not a multiple of " +
                         std::to_string(n) + " joints");
      return false;
    }
    if (n != 0 && p.values().size() / n > limits_.max_waypoints) {
      fail("values", std::to_string(p.values().size() / n) + " waypoints (limit " +
                         std::to_string(limits_.max_waypoints) + ")");
      return false;
    }
    return allFinite("values", p.values());
  }
  bool trajectory(const char* field, const msg::JointTrajectory& t) {
    Scope s(*this, field);
    if (!jointNames("joint_names", t.joint_names())) return false;
    if (!size("times", t.times(), limits_.max_waypoints)) return false;
    const std::size_t n = t.joint_names().size(), k = t.times().size();
    if (t.positions().size() != n * k) {
      fail("positions", "expected " + std::to_string(n * k) + " values (" + std::to_string(k) +
                            " points x " + std::to_string(n) + " joints), got " +
                            std::to_string(t.positions().size()));
      return false;
    }
    if (!t.velocities().empty() && t.velocities().size() != n * k) {
      fail("velocities", "expected 0 or " + std::to_string(n * k) + " values, got " +
                             std::to_string(t.velocities().size()));
      return false;
    }
    if (!allFinite("times", t.times())) return false;
    for (std::size_t i = 1; i < k; ++i) {
      if (t.times()[i] < t.times()[i - 1]) {
        fail("times[" + std::to_string(i) + "]", "decreasing (" + describe(t.times()[i]) + " after " +
                                                     describe(t.times()[i - 1]) + ")");
        return false;
      }
    }
    return allFinite("positions", t.positions()) && allFinite("velocities", t.velocities());
  }
  bool requestHeader(const msg::RequestHeader& h) {
    Scope s(*this, "header");
    // The RPC server needs both ids to answer; budget_s <= 0 means none, NaN/inf is garbage.
    return id("request_id", h.request_id(), true) && id("client_id", h.client_id(), true) &&
           finite("budget_s", h.budget_s());
  }
  bool replyHeader(const msg::ReplyHeader& h) {
    Scope s(*this, "header");
    return id("request_id", h.request_id(), false) && id("client_id", h.client_id(), false) &&
           enumIn("code", h.code(), msg::STATUS_INTERNAL) && text("message", h.message()) &&
           finite("service_time_s", h.service_time_s());
  }
  bool shape(const char* field, const msg::ShapeSpec& sh) {
    Scope s(*this, field);
    if (!enumIn("type", sh.type(), msg::SHAPE_PRISM)) return false;
    if (!size("dimensions", sh.dimensions(), 16) || !allFinite("dimensions", sh.dimensions())) return false;
    for (std::size_t i = 0; i < sh.dimensions().size(); ++i) {
      if (sh.dimensions()[i] < 0) {
        fail("dimensions[" + std::to_string(i) + "]", "negative (" + describe(sh.dimensions()[i]) + ")");
        return false;
      }
    }
    return points("polygon", sh.polygon()) && nonNegative("height", sh.height());
  }

  std::vector<std::string> parts_;

 private:
  const Limits& limits_;
  std::optional<Error> error_;
};

using Scope = Check::Scope;

bool isPickOrPlace(msg::ActionKind k) { return k == msg::ACTION_PICK || k == msg::ACTION_PLACE; }

/// A request's hypothetical world: objects moved or removed for it.
void objectOverrides(Check& c, const std::vector<msg::ObjectOverride>& v) {
  if (!c.size("object_overrides", v, c.limits().max_items)) return;
  for (std::size_t i = 0; i < v.size() && c.ok(); ++i) {
    Scope s(c, "object_overrides", i);
    c.id("object_id", v[i].object_id(), true);
    c.pose3("pose", v[i].pose(), !v[i].removed());
  }
}

/// Whole objects in a message (a request's added objects, the oracle's hidden ones).
void worldObjects(Check& c, const char* field, const std::vector<msg::WorldObject>& v) {
  if (!c.size(field, v, c.limits().max_items)) return;
  for (std::size_t i = 0; i < v.size() && c.ok(); ++i) {
    Scope s(c, field, i);
    c.id("id", v[i].id(), true);
    c.enumIn("kind", v[i].kind(), msg::OBJECT_HIDDEN);
    c.shape("shape", v[i].shape());
    c.pose3("pose", v[i].pose(), true);
    c.nonNegative("mass", v[i].mass());
  }
}

}  // namespace

// ---- requests ----------------------------------------------------------------------------------

Status validate(const msg::PlanRequest& m, const Limits& limits) {
  Check c("PlanRequest", limits);
  if (!c.requestHeader(m.header())) return c.status();
  if (!(c.text("domain_pddl", m.domain_pddl()) && c.text("domain_path", m.domain_path()) &&
        c.text("problem_pddl", m.problem_pddl()))) {
    return c.status();
  }
  if (m.domain_pddl().empty() && m.domain_path().empty()) c.fail("domain_pddl", "empty, and no domain_path");
  for (const auto* field : {"objects", "init", "goal"}) {
    const auto& v = std::string_view(field) == "objects" ? m.objects()
                    : std::string_view(field) == "init"  ? m.init()
                                                         : m.goal();
    if (!c.size(field, v, limits.max_items)) return c.status();
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (v[i].empty()) c.fail(std::string(field) + "[" + std::to_string(i) + "]", "empty string");
      if (v[i].size() > limits.max_id_length * 16)
        c.fail(std::string(field) + "[" + std::to_string(i) + "]", std::to_string(v[i].size()) + " bytes");
    }
  }
  if (m.problem_pddl().empty() && m.goal().empty()) c.fail("goal", "empty, and no problem_pddl");
  c.enumIn("search", m.search(), msg::SEARCH_ASTAR);
  c.finite("weight", m.weight());
  return c.status();
}

Status validate(const msg::MotionRequest& m, const Limits& limits) {
  Check c("MotionRequest", limits);
  if (!c.requestHeader(m.header())) return c.status();
  c.enumIn("group", m.group(), msg::GROUP_WHOLE_BODY);
  c.enumIn("mode", m.mode(), msg::MOTION_FULL);
  c.enumIn("goal_type", m.goal_type(), msg::GOAL_END_EFFECTOR_POSE);
  c.pose2("start_base", m.start_base());
  if (c.jointNames("start_joint_names", m.start_joint_names()) &&
      m.start_joint_positions().size() != m.start_joint_names().size()) {
    c.fail("start_joint_positions", std::to_string(m.start_joint_positions().size()) + " values for " +
                                        std::to_string(m.start_joint_names().size()) + " start_joint_names");
  }
  c.allFinite("start_joint_positions", m.start_joint_positions());
  if (c.size("goal_configuration", m.goal_configuration(), limits.max_joints + 3))
    c.allFinite("goal_configuration", m.goal_configuration());
  c.pose2("goal_base", m.goal_base());
  c.pose3("goal_end_effector", m.goal_end_effector(), m.goal_type() == msg::GOAL_END_EFFECTOR_POSE);
  c.id("held_object_id", m.held_object_id(), false);
  if (m.held_grasp_given() && m.held_object_id().empty()) c.fail("held_grasp_given", "true without held_object_id");
  c.id("held_link", m.held_link(), false);  // empty: the robot's tool link
  c.pose3("held_link_T_object", m.held_link_T_object(), m.held_grasp_given());
  c.inRange("held_padding_m", m.held_padding_m(), 0.0, 0.25);
  c.ids("ignored_objects", m.ignored_objects(), limits.max_items);
  objectOverrides(c, m.object_overrides());
  worldObjects(c, "added_objects", m.added_objects());
  c.nonNegative("movable_cost_weight", m.movable_cost_weight());
  c.ids("fixed_objects", m.fixed_objects(), limits.max_items);
  return c.status();
}

Status validate(const msg::PlacementRequest& m, const Limits& limits) {
  Check c("PlacementRequest", limits);
  if (!c.requestHeader(m.header())) return c.status();
  c.id("object_id", m.object_id(), true);
  c.id("region_id", m.region_id(), true);
  c.poses2("keep_clear_path", m.keep_clear_path());
  c.nonNegative("keep_clear_radius", m.keep_clear_radius());
  if (m.max_placements() > limits.max_items)
    c.fail("max_placements", std::to_string(m.max_placements()) + " (limit " + std::to_string(limits.max_items) + ")");
  objectOverrides(c, m.object_overrides());
  worldObjects(c, "added_objects", m.added_objects());
  return c.status();
}

Status validate(const msg::GraspRequest& m, const Limits& limits) {
  Check c("GraspRequest", limits);
  if (!c.requestHeader(m.header())) return c.status();
  c.id("object_id", m.object_id(), true);
  c.pose2("base_pose", m.base_pose());
  if (m.max_grasps() > limits.max_items)
    c.fail("max_grasps", std::to_string(m.max_grasps()) + " (limit " + std::to_string(limits.max_items) + ")");
  objectOverrides(c, m.object_overrides());
  worldObjects(c, "added_objects", m.added_objects());
  return c.status();
}

Status validateEnvelope(const msg::EffortRequest& m, const Limits& limits) {
  Check c("EffortRequest", limits);
  if (!c.requestHeader(m.header())) return c.status();
  c.size("queries", m.queries(), limits.max_items);
  return c.status();
}

Status validateQuery(const msg::EffortQuery& q, std::size_t index, const Limits& limits) {
  Check c("EffortRequest", limits);
  Scope s(c, "queries", index);
  c.enumIn("kind", q.kind(), msg::ACTION_PLACE);
  c.jointPath("path", q.path());
  c.nonNegative("object_mass", q.object_mass());
  c.nonNegative("approach_m", q.approach_m());
  c.nonNegative("retreat_m", q.retreat_m());
  return c.status();
}

Status validate(const msg::EffortRequest& m, const Limits& limits) {
  if (Status s = validateEnvelope(m, limits); !s.ok()) return s;
  for (std::size_t i = 0; i < m.queries().size(); ++i) {
    if (Status s = validateQuery(m.queries()[i], i, limits); !s.ok()) return s;
  }
  return Status::Ok();
}

// ---- replies -----------------------------------------------------------------------------------

Status validate(const msg::PlanReply& m, const Limits& limits) {
  Check c("PlanReply", limits);
  if (!c.replyHeader(m.header())) return c.status();
  c.enumIn("status", m.status(), msg::PLAN_INVALID_INPUT);
  c.size("actions", m.actions(), limits.max_items);
  c.finite("cost", m.cost());
  c.finite("ground_time_s", m.ground_time_s());
  c.finite("search_time_s", m.search_time_s());
  if (c.size("states", m.states(), limits.max_items + 1)) {
    for (std::size_t i = 0; i < m.states().size() && c.ok(); ++i) {
      Scope s(c, "states", i);
      c.size("atoms", m.states()[i].atoms(), limits.max_items);
    }
  }
  return c.status();
}

Status validate(const msg::MotionReply& m, const Limits& limits) {
  Check c("MotionReply", limits);
  if (!c.replyHeader(m.header())) return c.status();
  c.enumIn("status", m.status(), msg::MOTION_INVALID_REQUEST);
  c.jointPath("path", m.path());
  c.trajectory("trajectory", m.trajectory());
  if (c.size("blocking", m.blocking(), limits.max_items)) {
    for (std::size_t i = 0; i < m.blocking().size() && c.ok(); ++i) {
      const auto& b = m.blocking()[i];
      Scope s(c, "blocking", i);
      c.id("object_id", b.object_id(), true);
      c.inRange("enter_fraction", b.enter_fraction(), 0.0, 1.0);
      c.inRange("exit_fraction", b.exit_fraction(), 0.0, 1.0);
      c.poses2("swept_base", b.swept_base());
      c.nonNegative("mass", b.mass());
      c.nonNegative("effort_s", b.effort_s());
    }
  }
  c.nonNegative("path_length", m.path_length());
  c.finite("planning_time_s", m.planning_time_s());
  c.nonNegative("cost_s", m.cost_s());
  return c.status();
}

Status validate(const msg::PlacementReply& m, const Limits& limits) {
  Check c("PlacementReply", limits);
  if (!c.replyHeader(m.header())) return c.status();
  if (!c.size("placements", m.placements(), limits.max_items)) return c.status();
  for (std::size_t i = 0; i < m.placements().size() && c.ok(); ++i) {
    const auto& p = m.placements()[i];
    Scope s(c, "placements", i);
    c.pose3("object_pose", p.object_pose(), true);
    c.pose2("base_pose", p.base_pose());
    if (c.size("arm_configuration", p.arm_configuration(), limits.max_joints))
      c.allFinite("arm_configuration", p.arm_configuration());
    c.finite("clearance", p.clearance());
  }
  return c.status();
}

Status validate(const msg::GraspReply& m, const Limits& limits) {
  Check c("GraspReply", limits);
  if (!c.replyHeader(m.header())) return c.status();
  if (!c.size("grasps", m.grasps(), limits.max_items)) return c.status();
  for (std::size_t i = 0; i < m.grasps().size() && c.ok(); ++i) {
    const auto& g = m.grasps()[i];
    Scope s(c, "grasps", i);
    c.enumIn("type", g.type(), msg::GRASP_SIDE);
    c.pose3("gripper_in_object", g.gripper_in_object(), true);
    c.pose2("base_pose", g.base_pose());
    if (c.size("pregrasp_configuration", g.pregrasp_configuration(), limits.max_joints))
      c.allFinite("pregrasp_configuration", g.pregrasp_configuration());
    if (c.size("grasp_configuration", g.grasp_configuration(), limits.max_joints))
      c.allFinite("grasp_configuration", g.grasp_configuration());
    c.nonNegative("opening", g.opening());
  }
  return c.status();
}

Status validate(const msg::EffortReply& m, const Limits& limits) {
  Check c("EffortReply", limits);
  if (!c.replyHeader(m.header())) return c.status();
  if (!c.size("estimates", m.estimates(), limits.max_items)) return c.status();
  for (std::size_t i = 0; i < m.estimates().size() && c.ok(); ++i) {
    const auto& e = m.estimates()[i];
    Scope s(c, "estimates", i);
    c.enumIn("code", e.code(), msg::STATUS_INTERNAL);
    if (e.code() == msg::STATUS_OK) {
      c.nonNegative("mean_s", e.mean_s());
      c.nonNegative("stddev_s", e.stddev_s());
    }
  }
  return c.status();
}

Status validateEnvelope(const msg::OracleRequest& m, const Limits& limits) {
  Check c("OracleRequest", limits);
  if (!c.requestHeader(m.header())) return c.status();
  c.size("queries", m.queries(), limits.max_items);
  return c.status();
}

Status validate(const msg::OracleReply& m, const Limits& limits) {
  Check c("OracleReply", limits);
  if (!c.replyHeader(m.header())) return c.status();
  if (!c.size("durations", m.durations(), limits.max_items)) return c.status();
  for (std::size_t i = 0; i < m.durations().size() && c.ok(); ++i) {
    const auto& e = m.durations()[i];
    Scope s(c, "durations", i);
    c.enumIn("code", e.code(), msg::STATUS_INTERNAL);
    if (e.code() == msg::STATUS_OK) {
      c.nonNegative("mean_s", e.mean_s());
      c.nonNegative("stddev_s", e.stddev_s());
    }
  }
  worldObjects(c, "hidden_objects", m.hidden_objects());
  if (!c.ok()) return c.status();
  if (!c.size("faults", m.faults(), limits.max_items)) return c.status();
  for (std::size_t i = 0; i < m.faults().size() && c.ok(); ++i) {
    const auto& f = m.faults()[i];
    Scope s(c, "faults", i);
    c.id("fault_id", f.fault_id(), false);
    c.enumIn("type", f.type(), msg::FAULT_REMOVE_OBJECT);
    c.nonNegative("time_s", f.time_s());
    c.inRange("fraction", f.fraction(), 0.0, 1.0);
    c.enumIn("action", f.action(), msg::ACTION_PLACE);
    c.id("object_id", f.object_id(), false);
  }
  c.nonNegative("sim_time_s", m.sim_time_s());
  return c.status();
}

// ---- streams and commands ----------------------------------------------------------------------

Status validate(const msg::MissionCommand& m, const Limits& limits) {
  Check c("MissionCommand", limits);
  c.id("mission_id", m.mission_id(), true);
  c.text("scenario_path", m.scenario_path());
  if (!m.abort() && m.scenario_path().empty()) c.fail("scenario_path", "empty (a mission needs a scenario)");
  if (c.size("goal", m.goal(), limits.max_items)) {
    for (std::size_t i = 0; i < m.goal().size(); ++i) {
      if (m.goal()[i].empty()) c.fail("goal[" + std::to_string(i) + "]", "empty string");
    }
  }
  c.enumIn("policy", m.policy(), msg::POLICY_ORACLE);
  if (m.max_replans() > 10000) c.fail("max_replans", std::to_string(m.max_replans()) + " (limit 10000)");
  return c.status();
}

Status validate(const msg::ExecuteCommand& m, const Limits& limits) {
  Check c("ExecuteCommand", limits);
  c.id("command_id", m.command_id(), true);
  if (m.cancel()) return c.status();  // a cancel needs only the id
  c.id("mission_id", m.mission_id(), false);
  c.id("edge_id", m.edge_id(), false);
  c.text("pddl_action", m.pddl_action());
  c.enumIn("kind", m.kind(), msg::ACTION_PLACE);
  c.trajectory("trajectory", m.trajectory());
  c.id("object_id", m.object_id(), isPickOrPlace(m.kind()));
  c.id("region_id", m.region_id(), false);
  c.pose3("object_target", m.object_target(), m.object_target_given());
  c.nonNegative("expected_duration_s", m.expected_duration_s());
  c.nonNegative("expected_stddev_s", m.expected_stddev_s());
  return c.status();
}

Status validate(const msg::ExecuteStatus& m, const Limits& limits) {
  Check c("ExecuteStatus", limits);
  c.id("command_id", m.command_id(), true);
  c.enumIn("state", m.state(), msg::EXEC_CANCELLED);
  c.finite("progress", m.progress());
  c.finite("elapsed_s", m.elapsed_s());
  c.text("reason", m.reason());
  c.id("blocking_object_id", m.blocking_object_id(), false);
  c.finite("measured_duration_s", m.measured_duration_s());
  c.id("held_object_id", m.held_object_id(), false);
  return c.status();
}

Status validate(const msg::TrajectoryCommand& m, const Limits& limits) {
  Check c("TrajectoryCommand", limits);
  c.id("command_id", m.command_id(), true);
  if (m.cancel()) return c.status();
  c.enumIn("kind", m.kind(), msg::ACTION_PLACE);
  c.trajectory("trajectory", m.trajectory());
  c.id("object_id", m.object_id(), isPickOrPlace(m.kind()));
  c.pose3("object_target", m.object_target(), false);
  return c.status();
}

Status validate(const msg::ActionResult& m, const Limits& limits) {
  Check c("ActionResult", limits);
  c.id("command_id", m.command_id(), true);
  c.enumIn("outcome", m.outcome(), msg::OUTCOME_CANCELLED);
  c.nonNegative("duration_s", m.duration_s());
  c.finite("progress", m.progress());
  c.id("blocking_object_id", m.blocking_object_id(), m.outcome() == msg::OUTCOME_BLOCKED);
  c.text("reason", m.reason());
  return c.status();
}

Status validate(const msg::FailureEvent& m, const Limits& limits) {
  Check c("FailureEvent", limits);
  c.id("command_id", m.command_id(), false);
  c.enumIn("type", m.type(), msg::FAILURE_PRECONDITION);
  c.id("object_id", m.object_id(), false);
  c.pose2("robot_base", m.robot_base());
  c.text("description", m.description());
  return c.status();
}

Status validate(const msg::FaultInjection& m, const Limits& limits) {
  Check c("FaultInjection", limits);
  c.id("fault_id", m.fault_id(), false);
  c.enumIn("type", m.type(), msg::FAULT_REMOVE_OBJECT);
  const bool needs_object = m.type() == msg::FAULT_SPAWN_OBJECT || m.type() == msg::FAULT_REMOVE_OBJECT;
  c.id("object_id", m.object_id(), needs_object);
  c.shape("shape", m.shape());
  c.pose3("pose", m.pose(), m.type() == msg::FAULT_SPAWN_OBJECT);
  c.text("reason", m.reason());
  return c.status();
}

Status validate(const msg::ExecutionRecord& m, const Limits& limits) {
  Check c("ExecutionRecord", limits);
  c.id("record_id", m.record_id(), false);  // optional: de-duplication only when given
  c.enumIn("kind", m.kind(), msg::ACTION_PLACE);
  c.jointPath("path", m.path());
  c.nonNegative("object_mass", m.object_mass());
  c.nonNegative("duration_s", m.duration_s());
  c.id("source", m.source(), false);
  c.nonNegative("approach_m", m.approach_m());
  c.nonNegative("retreat_m", m.retreat_m());
  c.finite("predicted_s", m.predicted_s());
  c.finite("predicted_stddev_s", m.predicted_stddev_s());
  c.id("command_id", m.command_id(), false);
  c.id("mission_id", m.mission_id(), false);
  return c.status();
}

Status validate(const msg::RecordAck& m, const Limits& limits) {
  Check c("RecordAck", limits);
  c.id("record_id", m.record_id(), true);
  c.id("estimator", m.estimator(), false);
  return c.status();
}

Status validate(const msg::EffortModelSnapshot& m, const Limits& limits) {
  Check c("EffortModelSnapshot", limits);
  c.id("model_id", m.model_id(), true);
  if (!c.size("models", m.models(), 64)) return c.status();
  for (std::size_t i = 0; i < m.models().size() && c.ok(); ++i) {
    const auto& a = m.models()[i];
    Scope s(c, "models", i);
    c.enumIn("kind", a.kind(), msg::ACTION_PLACE);
    if (!c.ids("parameter_names", a.parameter_names(), 64)) break;
    const std::size_t n = a.parameter_names().size();
    if (a.values().size() != n) {
      c.fail("values", std::to_string(a.values().size()) + " values for " + std::to_string(n) + " parameter_names");
      break;
    }
    c.allFinite("values", a.values());
    if (!a.log_covariance().empty() && a.log_covariance().size() != n * n) {
      c.fail("log_covariance", "expected 0 or " + std::to_string(n * n) + " values (n x n), got " +
                                   std::to_string(a.log_covariance().size()));
      break;
    }
    c.allFinite("log_covariance", a.log_covariance());
    c.nonNegative("noise_log_stddev", a.noise_log_stddev());
  }
  return c.status();
}

Status validate(const msg::RobotState& m, const Limits& limits) {
  Check c("RobotState", limits);
  c.id("robot_id", m.robot_id(), false);
  c.pose2("base", m.base());
  if (!c.jointNames("joint_names", m.joint_names())) return c.status();
  const std::size_t n = m.joint_names().size();
  if (m.joint_positions().size() != n) {
    c.fail("joint_positions", std::to_string(m.joint_positions().size()) + " values for " + std::to_string(n) +
                                  " joint_names");
    return c.status();
  }
  if (!m.joint_velocities().empty() && m.joint_velocities().size() != n) {
    c.fail("joint_velocities", "expected 0 or " + std::to_string(n) + " values, got " +
                                   std::to_string(m.joint_velocities().size()));
    return c.status();
  }
  c.allFinite("joint_positions", m.joint_positions());
  c.allFinite("joint_velocities", m.joint_velocities());
  c.id("held_object_id", m.held_object_id(), false);
  return c.status();
}

Status validate(const msg::PointCloudFrame& m, const Limits& limits) {
  Check c("PointCloudFrame", limits);
  c.id("sensor_id", m.sensor_id(), true);
  c.pose3("sensor_pose", m.sensor_pose(), true);
  const std::size_t values = m.points().size();
  if (values % 3 != 0) {
    c.fail("points", std::to_string(values) + " values are not x, y, z triplets");
    return c.status();
  }
  if (values / 3 > limits.max_cloud_points) {
    c.fail("points", std::to_string(values / 3) + " points (limit " + std::to_string(limits.max_cloud_points) + ")");
    return c.status();
  }
  if (m.width() != 0 && static_cast<std::uint64_t>(m.width()) * m.height() != values / 3) {
    c.fail("width", "width x height = " + std::to_string(m.width()) + " x " + std::to_string(m.height()) +
                        " does not match " + std::to_string(values / 3) + " points");
    return c.status();
  }
  // NaN triplets mean "no return"; an infinite coordinate is garbage.
  for (std::size_t i = 0; i < values; ++i) {
    if (std::isinf(m.points()[i])) {
      c.fail("points[" + std::to_string(i) + "]", "inf");
      break;
    }
  }
  return c.status();
}

Status validate(const msg::WorldObject& m, const Limits& limits) {
  Check c("WorldObject", limits);
  c.id("id", m.id(), true);
  c.text("label", m.label());
  c.enumIn("kind", m.kind(), msg::OBJECT_HIDDEN);
  c.shape("shape", m.shape());
  c.pose3("pose", m.pose(), true);
  c.nonNegative("mass", m.mass());
  c.id("supported_by", m.supported_by(), false);
  c.inRange("confidence", m.confidence(), 0.0, 1.0);
  return c.status();
}

Status validate(const msg::WorldMeta& m, const Limits& limits) {
  Check c("WorldMeta", limits);
  c.id("world_id", m.world_id(), true);
  if (c.size("regions", m.regions(), limits.max_items)) {
    for (std::size_t i = 0; i < m.regions().size() && c.ok(); ++i) {
      const auto& r = m.regions()[i];
      Scope s(c, "regions", i);
      c.id("id", r.id(), true);
      c.text("label", r.label());
      if (c.points("polygon", r.polygon()) && r.polygon().size() < 3)
        c.fail("polygon", std::to_string(r.polygon().size()) + " vertices (at least 3)");
      c.finite("height", r.height());
    }
  }
  if (c.size("locations", m.locations(), limits.max_items)) {
    for (std::size_t i = 0; i < m.locations().size() && c.ok(); ++i) {
      Scope s(c, "locations", i);
      c.id("id", m.locations()[i].id(), true);
      c.pose2("pose", m.locations()[i].pose());
    }
  }
  if (!m.bounds().empty() && m.bounds().size() != 4) {
    c.fail("bounds", std::to_string(m.bounds().size()) + " values (expected 0 or 4: xmin, ymin, xmax, ymax)");
  }
  c.allFinite("bounds", m.bounds());
  if (c.ids("object_ids", m.object_ids(), limits.max_items) && m.object_versions().size() != m.object_ids().size()) {
    c.fail("object_versions", std::to_string(m.object_versions().size()) + " versions for " +
                                  std::to_string(m.object_ids().size()) + " object_ids");
  }
  return c.status();
}

Status validate(const msg::WorldEvent& m, const Limits& limits) {
  Check c("WorldEvent", limits);
  c.enumIn("type", m.type(), msg::WORLD_OBJECT_GONE);
  c.id("object_id", m.object_id(), true);
  c.enumIn("kind", m.kind(), msg::OBJECT_HIDDEN);
  c.pose3("pose", m.pose(), false);
  c.text("description", m.description());
  return c.status();
}

// ---- logging -----------------------------------------------------------------------------------

std::string kindOf(const Error& why) {
  const std::string& f = why.where.field;
  std::string out;
  out.reserve(f.size());
  for (std::size_t i = 0; i < f.size(); ++i) {
    out += f[i];
    if (f[i] == '[') {
      while (i + 1 < f.size() && f[i + 1] != ']') ++i;
    }
  }
  return out;
}

RejectLog::RejectLog(std::string component, std::chrono::steady_clock::duration period)
    : component_(std::move(component)), period_(period) {}

void RejectLog::reject(std::string_view topic, const Error& why) {
  const auto now = std::chrono::steady_clock::now();
  const std::string key = std::string(topic) + " " + kindOf(why);
  std::uint64_t more = 0;
  bool first = false;
  {
    std::lock_guard lock(mutex_);
    ++count_;
    Kind& k = kinds_[key];
    ++k.count;
    first = k.count == 1;
    if (!first && now - k.last_logged < period_) {
      ++k.unlogged;
      return;
    }
    more = k.unlogged;
    k.unlogged = 0;
    k.last_logged = now;
    ++lines_;
  }
  auto log = tamp::log::get(component_);
  if (first) {
    log->warn("rejected a message on {}: {} (later rejections of this kind are counted)", topic, why.message);
  } else {
    log->warn("rejected a message on {}: {} ({} more of this kind since the last report)", topic, why.message,
              more);
  }
}

std::uint64_t RejectLog::count() const {
  std::lock_guard lock(mutex_);
  return count_;
}

std::uint64_t RejectLog::linesLogged() const {
  std::lock_guard lock(mutex_);
  return lines_;
}

}  // namespace tamp::msgv
