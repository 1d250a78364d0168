#include "motion_convert.h"

#include <cmath>

#include "tamp/dds/convert.h"
#include "tamp/dds/world_sync.h"

namespace tamp::motion_planner {
namespace {

Error bad(const std::string& field, const std::string& what) {
  return Error(ErrorCode::kInvalidArgument, field + ": " + what);
}

bool allFinite(const std::vector<double>& v) {
  for (double x : v) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

Result<std::vector<ObjectOverride>> overridesFromMsg(const std::vector<msg::ObjectOverride>& in) {
  std::vector<ObjectOverride> out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const msg::ObjectOverride& o = in[i];
    const std::string field = "object_overrides[" + std::to_string(i) + "]";
    if (o.object_id().empty()) return bad(field + ".object_id", "empty");
    ObjectOverride ov;
    ov.object_id = o.object_id();
    ov.removed = o.removed();
    if (!o.removed()) {
      auto p = dds::fromMsg(o.pose(), field + ".pose");
      if (!p) return p.error();
      ov.pose = *p;
    }
    out.push_back(std::move(ov));
  }
  return out;
}

Result<AddedObjects> addedFromMsg(const std::vector<msg::WorldObject>& in) {
  AddedObjects out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    auto o = dds::fromMsg(in[i]);
    if (!o) return bad("added_objects[" + std::to_string(i) + "]", o.error().message);
    o->hidden = false;  // in this request's world, the caller knows it
    out.push_back(std::move(*o));
  }
  return out;
}

/// `m`'s object overrides and added objects, into `r`: the world every question to the motion
/// planner is asked in.
template <typename Msg, typename Request>
Status worldEditsFromMsg(const Msg& m, Request& r) {
  auto overrides = overridesFromMsg(m.object_overrides());
  if (!overrides) return overrides.error();
  r.object_overrides = std::move(*overrides);
  auto added = addedFromMsg(m.added_objects());
  if (!added) return added.error();
  r.added_objects = std::move(*added);
  return Status::Ok();
}

}  // namespace

msg::MotionStatus toMsg(MotionStatus s) {
  switch (s) {
    case MotionStatus::kSolved: return msg::MOTION_SOLVED;
    case MotionStatus::kNoPath: return msg::MOTION_NO_PATH;
    case MotionStatus::kStartInCollision: return msg::MOTION_START_IN_COLLISION;
    case MotionStatus::kGoalInCollision: return msg::MOTION_GOAL_IN_COLLISION;
    case MotionStatus::kTimeout: return msg::MOTION_TIMEOUT;
    case MotionStatus::kInvalidRequest: return msg::MOTION_INVALID_REQUEST;
  }
  return msg::MOTION_INVALID_REQUEST;
}

Result<MotionRequest> fromMsg(const msg::MotionRequest& m, const MotionPlanner& planner) {
  MotionRequest r;
  switch (m.group()) {
    case msg::GROUP_BASE: r.group = PlanningGroup::kBase; break;
    case msg::GROUP_ARM: r.group = PlanningGroup::kArm; break;
    case msg::GROUP_WHOLE_BODY: r.group = PlanningGroup::kWholeBody; break;
    default: return bad("group", "unknown value " + std::to_string(static_cast<unsigned>(m.group())));
  }
  switch (m.mode()) {
    case msg::MOTION_LAZY: r.mode = MotionMode::kLazy; break;
    case msg::MOTION_FULL: r.mode = MotionMode::kFull; break;
    default: return bad("mode", "unknown value " + std::to_string(static_cast<unsigned>(m.mode())));
  }
  auto base = dds::fromMsg(m.start_base(), "start_base");
  if (!base) return base.error();
  const auto& names = m.start_joint_names();
  const auto& values = m.start_joint_positions();
  if (names.size() != values.size()) {
    return bad("start_joint_positions", std::to_string(values.size()) + " values for " +
                                            std::to_string(names.size()) + " start_joint_names");
  }
  if (!allFinite(values)) return bad("start_joint_positions", "not finite");
  if (const robot::RobotModel* model = planner.robotModel()) {
    robot::RobotState defaults = model->defaultState(*base);
    auto st = model->fromJointValues(names, values, defaults);
    if (!st) return bad("start_joint_names", st.error().message);
    r.start = *st;
    r.start.base = *base;
  } else {
    if (!names.empty()) return bad("start_joint_names[0]", "unknown joint '" + names[0] + "' (planar robot: no joints)");
    r.start.base = *base;
  }
  switch (m.goal_type()) {
    case msg::GOAL_CONFIGURATION:
      if (!allFinite(m.goal_configuration())) return bad("goal_configuration", "not finite");
      r.goal = MotionGoal::configurationGoal(m.goal_configuration());
      break;
    case msg::GOAL_BASE_POSE: {
      auto g = dds::fromMsg(m.goal_base(), "goal_base");
      if (!g) return g.error();
      r.goal = MotionGoal::basePoseGoal(*g);
      break;
    }
    case msg::GOAL_END_EFFECTOR_POSE: {
      auto g = dds::fromMsg(m.goal_end_effector(), "goal_end_effector");
      if (!g) return g.error();
      r.goal = MotionGoal::endEffectorGoal(*g);
      break;
    }
    default: return bad("goal_type", "unknown value " + std::to_string(static_cast<unsigned>(m.goal_type())));
  }
  r.held_object = m.held_object_id();
  if (m.held_grasp_given()) {
    if (r.held_object.empty()) return bad("held_grasp_given", "true without held_object_id");
    auto t = dds::fromMsg(m.held_link_T_object(), "held_link_T_object");
    if (!t) return t.error();
    r.held_grasp = HeldGrasp{m.held_link(), *t};
  }
  r.held_padding_m = m.held_padding_m();
  r.ignored_objects.assign(m.ignored_objects().begin(), m.ignored_objects().end());
  if (Status s = worldEditsFromMsg(m, r); !s.ok()) return s.error();
  const double w = m.movable_cost_weight();
  if (!std::isfinite(w) || w < 0) return bad("movable_cost_weight", "must be finite and >= 0");
  r.object_cost_scale = w;
  r.fixed_objects.assign(m.fixed_objects().begin(), m.fixed_objects().end());
  r.straight_only = m.straight_only();
  return r;
}

msg::MotionReply toMsg(const MotionResult& r) {
  msg::MotionReply m;
  m.status(toMsg(r.status));
  m.reason(r.reason);
  m.colliding_object(r.colliding_object);
  if (!r.path.empty()) m.path(dds::toMsg(r.path));
  if (!r.trajectory.empty()) m.trajectory(dds::toMsg(r.trajectory));
  for (const auto& b : r.blocking) {
    msg::BlockingObject o;
    o.object_id(b.object_id);
    o.enter_fraction(b.enter_fraction);
    o.exit_fraction(b.exit_fraction);
    o.enter_waypoint(static_cast<uint32_t>(b.enter_waypoint));
    o.exit_waypoint(static_cast<uint32_t>(b.exit_waypoint));
    for (const auto& p : b.swept_base) o.swept_base().push_back(dds::toMsg(p));
    o.mass(b.mass);
    o.effort_s(b.effort_s);
    m.blocking().push_back(std::move(o));
  }
  m.path_length(r.path_length);
  m.planning_time_s(r.planning_time_s);
  m.cost_s(r.cost_s);
  return m;
}

Result<std::vector<TimeModelValues>> fromMsg(const msg::EffortModelSnapshot& m) {
  std::vector<TimeModelValues> out;
  for (std::size_t i = 0; i < m.models().size(); ++i) {
    const msg::ActionTimeModel& a = m.models()[i];
    const std::string field = "models[" + std::to_string(i) + "]";
    if (a.values().size() != a.parameter_names().size()) {
      return bad(field + ".values", std::to_string(a.values().size()) + " values for " +
                                        std::to_string(a.parameter_names().size()) + " parameter_names");
    }
    TimeModelValues v;
    v.kind = dds::fromMsg(a.kind());
    v.names.assign(a.parameter_names().begin(), a.parameter_names().end());
    v.values.assign(a.values().begin(), a.values().end());
    out.push_back(std::move(v));
  }
  return out;
}

Result<PlacementRequest> fromMsg(const msg::PlacementRequest& m) {
  PlacementRequest r;
  if (m.object_id().empty()) return bad("object_id", "empty");
  if (m.region_id().empty()) return bad("region_id", "empty");
  r.object_id = m.object_id();
  r.region_id = m.region_id();
  for (std::size_t i = 0; i < m.keep_clear_path().size(); ++i) {
    auto p = dds::fromMsg(m.keep_clear_path()[i], "keep_clear_path[" + std::to_string(i) + "]");
    if (!p) return p.error();
    r.keep_clear_path.push_back(*p);
  }
  if (!std::isfinite(m.keep_clear_radius()) || m.keep_clear_radius() < 0) {
    return bad("keep_clear_radius", "must be finite and >= 0");
  }
  r.keep_clear_radius = m.keep_clear_radius();
  r.max_placements = m.max_placements() == 0 ? 8u : std::min<std::uint32_t>(m.max_placements(), 256u);
  if (m.base_given()) {
    auto b = dds::fromMsg(m.base_pose(), "base_pose");
    if (!b) return b.error();
    r.base = *b;
  }
  if (m.held_grasp_given()) {
    if (!m.base_given()) return bad("held_grasp_given", "true without base_given");
    auto t = dds::fromMsg(m.held_object_T_tool(), "held_object_T_tool");
    if (!t) return t.error();
    r.held_object_T_tool = *t;
  }
  if (!std::isfinite(m.approach()) || m.approach() < 0) return bad("approach", "must be finite and >= 0");
  r.approach = m.approach();
  if (Status s = worldEditsFromMsg(m, r); !s.ok()) return s.error();
  return r;
}

msg::PlacementReply toMsg(const std::vector<Placement>& placements) {
  msg::PlacementReply m;
  for (const auto& p : placements) {
    msg::Placement o;
    o.object_pose(dds::toMsg(p.object_pose));
    o.base_pose(dds::toMsg(p.base_pose));
    o.arm_configuration(p.arm_configuration);
    o.pre_arm_configuration(p.pre_arm_configuration);
    o.clearance(p.clearance);
    m.placements().push_back(std::move(o));
  }
  return m;
}

Result<GraspRequest> fromMsg(const msg::GraspRequest& m) {
  GraspRequest r;
  if (m.object_id().empty()) return bad("object_id", "empty");
  r.object_id = m.object_id();
  if (m.base_given()) {
    auto p = dds::fromMsg(m.base_pose(), "base_pose");
    if (!p) return p.error();
    r.base_pose = *p;
  }
  r.max_grasps = m.max_grasps() == 0 ? 8u : std::min<std::uint32_t>(m.max_grasps(), 64u);
  if (Status s = worldEditsFromMsg(m, r); !s.ok()) return s.error();
  return r;
}

msg::GraspReply toMsg(const std::vector<Grasp>& grasps) {
  msg::GraspReply m;
  for (const auto& g : grasps) {
    msg::Grasp o;
    o.type(g.type == GraspType::kTop ? msg::GRASP_TOP : msg::GRASP_SIDE);
    o.gripper_in_object(dds::toMsg(g.gripper_in_object));
    o.base_pose(dds::toMsg(g.base_pose));
    o.pregrasp_configuration(g.pregrasp_configuration);
    o.grasp_configuration(g.grasp_configuration);
    o.opening(g.opening);
    m.grasps().push_back(std::move(o));
  }
  return m;
}

}  // namespace tamp::motion_planner
