// MotionPlanner: request validation, the request's world, and plan() running the phases of
// Planning (planning.h: planning.cc, planning_search.cc); see motion_planner.h.
#include "tamp/core/format.h"
#include "tamp/motion_planner/motion_planner.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iterator>
#include <limits>
#include <mutex>

#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include "planning.h"
#include "tamp/core/log.h"

namespace tamp::motion_planner {

namespace ob = ompl::base;
namespace og = ompl::geometric;

// ---- names --------------------------------------------------------------------------------------

std::string_view toString(PlanningGroup group) {
  switch (group) {
    case PlanningGroup::kBase: return "base";
    case PlanningGroup::kArm: return "arm";
    case PlanningGroup::kWholeBody: return "whole_body";
  }
  return "?";
}

std::string_view toString(MotionMode mode) { return mode == MotionMode::kLazy ? "lazy" : "full"; }

std::string_view toString(MotionStatus status) {
  switch (status) {
    case MotionStatus::kSolved: return "solved";
    case MotionStatus::kNoPath: return "no_path";
    case MotionStatus::kStartInCollision: return "start_in_collision";
    case MotionStatus::kGoalInCollision: return "goal_in_collision";
    case MotionStatus::kTimeout: return "timeout";
    case MotionStatus::kInvalidRequest: return "invalid_request";
  }
  return "?";
}

MotionGoal MotionGoal::configurationGoal(std::vector<double> q) {
  MotionGoal g;
  g.kind = Kind::kConfiguration;
  g.configuration = std::move(q);
  return g;
}

MotionGoal MotionGoal::basePoseGoal(const Pose2D& pose, bool any_yaw) {
  MotionGoal g;
  g.kind = Kind::kBasePose;
  g.base = pose;
  g.any_base_yaw = any_yaw;
  return g;
}

MotionGoal MotionGoal::endEffectorGoal(const Eigen::Isometry3d& world_T_tool) {
  MotionGoal g;
  g.kind = Kind::kEndEffectorPose;
  g.end_effector = world_T_tool;
  return g;
}

bool seedRandomness(std::uint32_t seed) {
  static std::once_flag once;
  bool done = false;
  std::call_once(once, [&] {
    ompl::RNG::setSeed(seed == 0 ? 1 : seed);
    done = true;
  });
  return done;
}

namespace {

bool finite(const Pose2D& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta); }

/// Why `p` is not a rigid transform (a non-finite value, a rotation that is not orthonormal).
std::optional<std::string> invalidPose(const Eigen::Isometry3d& p) {
  if (!p.matrix().allFinite()) return std::string("not finite");
  const Eigen::Matrix3d R = p.linear();
  if (((R * R.transpose()) - Eigen::Matrix3d::Identity()).norm() > 1e-6) return std::string("rotation is not orthonormal");
  return std::nullopt;
}

}  // namespace

// ---- Impl ---------------------------------------------------------------------------------------

MotionPlanner::Impl::Impl(MotionPlannerParams p, detail::RobotBinding r)
    : params(std::move(p)), robot(std::move(r)) {
  scene.setRobot(robot.geometry());
  effort = [c = params.cost](const world::Object& o) { return defaultObjectEffort(o, c); };
}

Result<MotionPlanner::Impl::AttachGuard> MotionPlanner::Impl::attach(const std::string& object_id,
                                                                   const robot::RobotState& start,
                                                                   const std::string& field, const HeldGrasp* grasp,
                                                                   std::string* link_out,
                                                                   Eigen::Isometry3d* link_T_object_out) {
  const world::Object* obj = world.findObject(object_id);
  if (!obj) return Error(ErrorCode::kInvalidArgument, field + ": no object '" + object_id + "' in the world");
  if (obj->kind != world::ObjectKind::kMovable) {
    return Error(ErrorCode::kInvalidArgument, field + ": object '" + object_id + "' is static and cannot be held");
  }
  std::string link = robot.holdLink();
  Eigen::Isometry3d link_T_object;
  const auto& held = world.held();
  if (grasp) {
    if (!grasp->link.empty()) link = grasp->link;
    link_T_object = grasp->link_T_object;
  } else if (held && held->object_id == object_id && held->link == robot.holdLink()) {
    link_T_object = held->link_T_object;
  } else {
    const auto world_T_link = linkPose(start, link);
    if (!world_T_link) return Error(ErrorCode::kInvalidArgument, field + ": the robot has no link '" + link + "'");
    link_T_object = world_T_link->inverse() * obj->pose;
  }
  if (link_out) *link_out = link;
  if (link_T_object_out) *link_T_object_out = link_T_object;
  if (Status s = scene.attach(object_id, link, link_T_object); !s) {
    return Error(ErrorCode::kInvalidArgument, field + ": " + s.error().message);
  }
  return AttachGuard(&scene, object_id);
}

std::optional<Eigen::Isometry3d> MotionPlanner::Impl::linkPose(const robot::RobotState& s,
                                                               const std::string& link) const {
  const auto& links = robot.geometry().links;
  const auto it = std::find(links.begin(), links.end(), link);
  if (it == links.end()) return std::nullopt;
  std::vector<Eigen::Isometry3d> poses;
  robot.linkPoses(s, poses);
  return poses[static_cast<std::size_t>(it - links.begin())];
}

detail::StaticRoadmap* MotionPlanner::Impl::roadmapFor(detail::StaticWorldKey key, const ob::StateSpacePtr& space,
                                                      bool& reused, std::unique_ptr<detail::StaticRoadmap>& scratch) {
  for (auto it = roadmaps.begin(); it != roadmaps.end(); ++it) {
    if ((*it)->key() == key) {
      std::rotate(it, it + 1, roadmaps.end());
      reused = true;
      return roadmaps.back().get();
    }
  }
  reused = false;
  auto rm = std::make_unique<detail::StaticRoadmap>(space, std::move(key), params.seed, params.lazy.roadmap_neighbors);
  const auto entries = static_cast<std::size_t>(params.lazy.roadmap_cache_entries);
  if (entries == 0) {
    scratch = std::move(rm);
    return scratch.get();
  }
  while (roadmaps.size() >= entries) roadmaps.erase(roadmaps.begin());
  roadmaps.push_back(std::move(rm));
  return roadmaps.back().get();
}

std::shared_ptr<const collision::ClearanceGrid> MotionPlanner::Impl::clearanceGrid() {
  const double h = params.sampling.clearance_grid_resolution;
  if (!(h > 0.0)) return nullptr;
  std::vector<std::shared_ptr<const world::Object>> statics;
  for (const auto& o : world.objects())
    if (o.kind == world::ObjectKind::kStatic) statics.push_back(world.objectPtr(o.id));
  auto same = [](const std::shared_ptr<const world::Object>& a, const std::shared_ptr<const world::Object>& b) {
    return a == b || (a && b && *a == *b);
  };
  for (auto it = clearance_grids.begin(); it != clearance_grids.end(); ++it) {
    if (!std::equal(it->statics.begin(), it->statics.end(), statics.begin(), statics.end(), same)) continue;
    std::rotate(it, it + 1, clearance_grids.end());
    return clearance_grids.back().grid;
  }
  std::vector<world::Polygon2> footprints;
  for (const auto& o : statics) footprints.push_back(collision::floorFootprint(*o));
  Aabb bounds = baseBounds({});
  bounds.min.head<2>() -= Eigen::Vector2d::Constant(1.0);
  bounds.max.head<2>() += Eigen::Vector2d::Constant(1.0);
  constexpr std::size_t kKept = 4;
  if (clearance_grids.size() >= kKept) clearance_grids.erase(clearance_grids.begin());
  clearance_grids.push_back({std::move(statics), std::make_shared<const collision::ClearanceGrid>(footprints, bounds, h)});
  return clearance_grids.back().grid;
}

double MotionPlanner::Impl::reachRadius(const robot::RobotState& s, const std::string& held, const std::string& link,
                                        const Eigen::Isometry3d& link_T_held) const {
  std::vector<Eigen::Isometry3d> poses;
  robot.linkPoses(s, poses);
  double r = 0.0;
  const Eigen::Vector2d c(s.base.x, s.base.y);
  auto extend = [&](const Aabb& b) {
    for (double x : {b.min.x(), b.max.x()})
      for (double y : {b.min.y(), b.max.y()}) r = std::max(r, (Eigen::Vector2d(x, y) - c).norm());
  };
  for (const auto& p : robot.geometry().parts) extend(p.shape.aabb(poses[static_cast<std::size_t>(p.link)] * p.link_T_shape));
  if (!held.empty()) {
    if (const world::Object* o = world.findObject(held)) {
      // Its pose relative to the link is fixed: at the start it is where the grasp puts it.
      const auto world_T_link = linkPose(s, link);
      extend(world_T_link ? o->shape.aabb(*world_T_link * link_T_held) : o->aabb());
    }
  }
  return r + 1e-3;
}

std::vector<Eigen::Vector3d> MotionPlanner::Impl::reachCover(const robot::RobotState& s, const std::string& held,
                                                             const std::string& link,
                                                             const Eigen::Isometry3d& link_T_held) const {
  std::vector<Eigen::Isometry3d> poses;
  robot.linkPoses(s, poses);
  const Eigen::Isometry3d base_T_world = s.base.toIsometry().inverse();
  Aabb box;
  for (const auto& p : robot.geometry().parts)
    box.extend(p.shape.aabb(base_T_world * poses[static_cast<std::size_t>(p.link)] * p.link_T_shape));
  if (!held.empty()) {
    if (const world::Object* o = world.findObject(held)) {
      const auto world_T_link = linkPose(s, link);
      if (world_T_link) {
        box.extend(o->shape.aabb(base_T_world * *world_T_link * link_T_held));
      } else {
        const Aabb w = o->aabb();
        for (double x : {w.min.x(), w.max.x()})
          for (double y : {w.min.y(), w.max.y()}) box.extend(base_T_world * Eigen::Vector3d(x, y, w.min.z()));
      }
    }
  }
  if (box.empty()) return {};
  const Eigen::Vector2d lo = box.min.head<2>(), size = (box.max - box.min).head<2>();
  const int axis = size.x() >= size.y() ? 0 : 1;
  const double along = size[axis], across = size[1 - axis];
  const int slabs = std::clamp(static_cast<int>(std::ceil(along / std::max(across, 1e-6))), 1, 4);
  const double step = along / slabs;
  std::vector<Eigen::Vector3d> cover;
  for (int i = 0; i < slabs; ++i) {
    Eigen::Vector2d c = lo + 0.5 * size;
    c[axis] = lo[axis] + (i + 0.5) * step;
    cover.emplace_back(c.x(), c.y(), 0.5 * std::hypot(step, across) + 1e-3);
  }
  return cover;
}

Aabb MotionPlanner::Impl::baseBounds(const std::vector<Eigen::Vector2d>& extra) const {
  Aabb b = world.bounds();
  for (const auto& p : extra) b.extend(Eigen::Vector3d(p.x(), p.y(), 0.0));
  if (b.empty()) b.extend(Eigen::Vector3d::Zero());
  // An explicit workspace (a scenario's, a NAMO map's extent) is where the robot may go: no
  // margin beyond it (with one, a base went round a wall outside the map). Bounds derived from
  // the objects get the margin.
  const double m = world.workspace() ? 0.0 : params.sampling.workspace_margin;
  b.min.x() -= m;
  b.min.y() -= m;
  b.max.x() += m;
  b.max.y() += m;
  // A degenerate extent (a single point) still needs a non-empty box for OMPL.
  if (b.max.x() - b.min.x() < 1e-3) b.max.x() = b.min.x() + 1e-3;
  if (b.max.y() - b.min.y() < 1e-3) b.max.y() = b.min.y() + 1e-3;
  return b;
}

TimingLimits MotionPlanner::Impl::timingLimits() const {
  TimingLimits l;
  const auto& t = params.timing;
  l.base_linear = {t.base_linear_speed, t.base_linear_accel};
  l.base_angular = {t.base_angular_speed, t.base_angular_accel};
  l.sample_period = t.sample_period;
  if (const auto* m = robot.model()) {
    for (std::size_t i = 0; i < m->armDof(); ++i) {
      l.joint_names.push_back(m->armJointNames()[i]);
      const double v = m->armLimits()[i].velocity > 0 ? m->armLimits()[i].velocity : 1.0;
      l.joints.push_back({v * t.arm_speed_scale, t.arm_accel});
    }
  }
  return l;
}

std::optional<std::vector<double>> solveIk(MotionPlanner::Impl& impl, const Pose2D& base,
                                           const Eigen::Isometry3d& world_T_tool, const std::vector<double>& seed,
                                           const collision::Filter& filter, double gripper, std::uint32_t seed_rng,
                                           int attempts, const Termination& termination) {
  const robot::RobotModel* m = impl.robot.model();
  if (!m) return std::nullopt;
  robot::RobotState st = m->defaultState(base);
  st.gripper = gripper;
  std::vector<Eigen::Isometry3d> poses;
  robot::IkOptions opt;
  opt.seed = seed_rng;
  opt.max_attempts = attempts;
  opt.position_tolerance = 1e-4;
  opt.orientation_tolerance = 1e-3;
  opt.accept = [&](const std::vector<double>& q) {
    st.arm = q;
    m->linkPoses(st, poses);
    impl.scene.setLinkPoses(poses);
    return !impl.scene.robotInCollision(filter) && impl.scene.selfCollisions().empty();
  };
  const Eigen::Isometry3d base_T_tool = base.toIsometry().inverse() * world_T_tool;
  std::vector<double> s = seed.size() == m->armDof() ? seed : m->defaultState().arm;
  auto r = m->inverseKinematics(base_T_tool, s, opt, termination);
  if (!r.ok()) return std::nullopt;
  return r.q;
}

// ---- MotionPlanner ------------------------------------------------------------------------------

MotionPlanner::MotionPlanner(robot::RobotModel model, MotionPlannerParams params) {
  if (Status s = params.validate(); !s) throw std::invalid_argument(s.error().message);
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  impl_ = std::make_unique<Impl>(std::move(params), detail::RobotBinding(std::move(model)));
}

MotionPlanner::MotionPlanner(collision::RobotGeometry planar_geometry, MotionPlannerParams params) {
  if (Status s = params.validate(); !s) throw std::invalid_argument(s.error().message);
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  impl_ = std::make_unique<Impl>(std::move(params), detail::RobotBinding(std::move(planar_geometry)));
}

MotionPlanner::~MotionPlanner() = default;
MotionPlanner::MotionPlanner(MotionPlanner&&) noexcept = default;
MotionPlanner& MotionPlanner::operator=(MotionPlanner&&) noexcept = default;

void MotionPlanner::setWorld(const world::World& world) {
  impl_->world = world.plannerView();
  impl_->scene.syncWorld(impl_->world);
}

const world::World& MotionPlanner::world() const { return impl_->world; }

void MotionPlanner::setObjectEffort(ObjectEffortFn fn) {
  if (!fn) throw std::invalid_argument("setObjectEffort: empty function");
  impl_->effort = std::move(fn);
}

void MotionPlanner::clearRoadmapCache() { impl_->roadmaps.clear(); }
std::size_t MotionPlanner::roadmapCacheSize() const { return impl_->roadmaps.size(); }

const MotionPlannerParams& MotionPlanner::params() const { return impl_->params; }
bool MotionPlanner::hasArm() const { return impl_->robot.hasArm(); }
const robot::RobotModel* MotionPlanner::robotModel() const { return impl_->robot.model(); }
double MotionPlanner::footprintRadius() const { return impl_->robot.footprintRadius(); }

std::vector<std::string> MotionPlanner::groupJointNames(PlanningGroup group) const {
  std::vector<std::string> names;
  if (group != PlanningGroup::kArm) {
    for (auto n : kBaseJointNames) names.emplace_back(n);
  }
  if (group != PlanningGroup::kBase && impl_->robot.model()) {
    for (const auto& n : impl_->robot.model()->armJointNames()) names.push_back(n);
  }
  return names;
}

namespace {

/// The largest margin a request may grow its held object by (m).
constexpr double kMaxHeldPadding_m = 0.25;

/// Validates the request against the robot and the world; the first problem, naming the field.
std::optional<std::string> validateRequest(const MotionRequest& r, const MotionPlanner::Impl& impl,
                                           const std::vector<std::string>& group_names) {
  const auto* m = impl.robot.model();
  if (r.group != PlanningGroup::kBase && !m) {
    return "group: '" + std::string(toString(r.group)) + "' needs a robot with an arm (this robot is planar)";
  }
  if (!finite(r.start.base)) return std::string("start.base: not finite");
  const std::size_t dof = impl.robot.armDof();
  if (r.start.arm.size() != dof) {
    return "start.arm: expected " + std::to_string(dof) + " values, got " + std::to_string(r.start.arm.size());
  }
  for (std::size_t i = 0; i < dof; ++i) {
    const double q = r.start.arm[i];
    const auto& l = m->armLimits()[i];
    if (!std::isfinite(q)) return "start.arm[" + std::to_string(i) + "]: not finite";
    if (q < l.lower - 1e-6 || q > l.upper + 1e-6) {
      return "start.arm[" + std::to_string(i) + "] (" + m->armJointNames()[i] + "): " + formatNumber(q) + " outside [" +
             formatNumber(l.lower) + ", " + formatNumber(l.upper) + "]";
    }
  }
  if (!std::isfinite(r.start.gripper)) return std::string("start.gripper: not finite");
  const auto& g = r.goal;
  switch (g.kind) {
    case MotionGoal::Kind::kConfiguration: {
      if (g.configuration.size() != group_names.size()) {
        return "goal.configuration: expected " + std::to_string(group_names.size()) + " values (" +
               std::string(toString(r.group)) + " joints), got " + std::to_string(g.configuration.size());
      }
      const std::size_t off = r.group == PlanningGroup::kArm ? 0 : 3;
      for (std::size_t i = 0; i < g.configuration.size(); ++i) {
        const double q = g.configuration[i];
        if (!std::isfinite(q)) return "goal.configuration[" + std::to_string(i) + "] (" + group_names[i] + "): not finite";
        if (i >= off) {
          const auto& l = m->armLimits()[i - off];
          if (q < l.lower - 1e-6 || q > l.upper + 1e-6) {
            return "goal.configuration[" + std::to_string(i) + "] (" + group_names[i] + "): " + formatNumber(q) +
                   " outside [" + formatNumber(l.lower) + ", " + formatNumber(l.upper) + "]";
          }
        }
      }
      break;
    }
    case MotionGoal::Kind::kBasePose:
      if (r.group == PlanningGroup::kArm) return std::string("goal: a base pose goal needs group base or whole_body");
      if (!finite(g.base)) return std::string("goal.base: not finite");
      break;
    case MotionGoal::Kind::kEndEffectorPose: {
      if (r.group == PlanningGroup::kBase) {
        return std::string("goal: an end-effector goal needs group arm or whole_body");
      }
      if (!g.end_effector.matrix().allFinite()) return std::string("goal.end_effector: not finite");
      const Eigen::Matrix3d R = g.end_effector.linear();
      if (((R * R.transpose()) - Eigen::Matrix3d::Identity()).norm() > 1e-6) {
        return std::string("goal.end_effector: rotation is not orthonormal");
      }
      break;
    }
  }
  if (!r.held_object.empty()) {
    const world::Object* o = impl.world.findObject(r.held_object);
    if (!o) return "held_object: no object '" + r.held_object + "' in the world";
    if (o->kind != world::ObjectKind::kMovable) return "held_object: object '" + r.held_object + "' is static";
  }
  for (std::size_t i = 0; i < r.ignored_objects.size(); ++i) {
    if (!impl.world.findObject(r.ignored_objects[i])) {
      return "ignored_objects[" + std::to_string(i) + "]: no object '" + r.ignored_objects[i] + "' in the world";
    }
  }
  if (r.straight_only && (r.mode != MotionMode::kFull || r.group != PlanningGroup::kBase)) {
    return std::string("straight_only: only for full-mode base requests");
  }
  for (std::size_t i = 0; i < r.fixed_objects.size(); ++i) {
    const world::Object* o = impl.world.findObject(r.fixed_objects[i]);
    if (!o) return "fixed_objects[" + std::to_string(i) + "]: no object '" + r.fixed_objects[i] + "' in the world";
    if (o->kind != world::ObjectKind::kMovable) {
      return "fixed_objects[" + std::to_string(i) + "]: object '" + r.fixed_objects[i] + "' is static already";
    }
  }
  if (!std::isfinite(r.held_padding_m) || r.held_padding_m < 0 || r.held_padding_m > kMaxHeldPadding_m) {
    return "held_padding_m: must be finite and in [0, " + formatNumber(kMaxHeldPadding_m) + "], got " +
           formatNumber(r.held_padding_m);
  }
  if (r.held_padding_m > 0 && r.held_object.empty() && !impl.world.held()) {
    return std::string("held_padding_m: given without a held object");
  }
  if (!std::isfinite(r.object_cost_scale) || r.object_cost_scale < 0) {
    return "object_cost_scale: must be finite and >= 0, got " + formatNumber(r.object_cost_scale);
  }
  if (r.held_grasp) {
    if (r.held_object.empty()) return std::string("held_grasp: given without held_object");
    const auto& links = impl.robot.geometry().links;
    if (!r.held_grasp->link.empty() && std::find(links.begin(), links.end(), r.held_grasp->link) == links.end()) {
      return "held_grasp.link: the robot has no link '" + r.held_grasp->link + "'";
    }
    if (auto why = invalidPose(r.held_grasp->link_T_object)) return "held_grasp.link_T_object: " + *why;
  }
  return std::nullopt;
}

}  // namespace

/// The planner's world with the request's object overrides applied; errors name the override.
Result<world::World> overriddenWorld(const world::World& base, const AddedObjects& added,
                                     const std::vector<ObjectOverride>& overrides, const std::string& held_object) {
  world::World w = base;
  for (std::size_t i = 0; i < added.size(); ++i) {
    const std::string field = "added_objects[" + std::to_string(i) + "]";
    if (base.findObject(added[i].id)) {
      return Error(ErrorCode::kInvalidArgument, field + ".id: '" + added[i].id + "' is already in the world");
    }
    if (auto why = invalidPose(added[i].pose)) return Error(ErrorCode::kInvalidArgument, field + ".pose: " + *why);
    if (Status s = w.addObject(added[i]); !s) return Error(ErrorCode::kInvalidArgument, field + ": " + s.error().message);
  }
  for (std::size_t i = 0; i < overrides.size(); ++i) {
    const ObjectOverride& o = overrides[i];
    const std::string field = "object_overrides[" + std::to_string(i) + "]";
    if (!w.findObject(o.object_id)) {
      return Error(ErrorCode::kInvalidArgument, field + ".object_id: no object '" + o.object_id + "' in the world");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (overrides[j].object_id == o.object_id) {
        return Error(ErrorCode::kInvalidArgument, field + ".object_id: '" + o.object_id +
                                                      "' is overridden twice (also object_overrides[" +
                                                      std::to_string(j) + "])");
      }
    }
    if (o.removed) {
      if (o.object_id == held_object) {
        return Error(ErrorCode::kInvalidArgument, field + ".removed: '" + o.object_id + "' is the held object");
      }
      if (Status s = w.removeObject(o.object_id); !s) {
        return Error(ErrorCode::kInvalidArgument, field + ": " + s.error().message);
      }
      continue;
    }
    if (auto why = invalidPose(o.pose)) return Error(ErrorCode::kInvalidArgument, field + ".pose: " + *why);
    if (Status s = w.setObjectPose(o.object_id, o.pose); !s) {
      return Error(ErrorCode::kInvalidArgument, field + ".pose: " + s.error().message);
    }
  }
  return w;
}

// (not file-local: planning.h declares grownGeometry)

world::Shape grownShape(const world::Shape& shape, double d);

/// The robot's parts grown sideways by `d` (m).
collision::RobotGeometry grownGeometry(collision::RobotGeometry geometry, double d) {
  for (auto& part : geometry.parts) part.shape = grownShape(part.shape, d);
  return geometry;
}

/// `shape` grown sideways by `d` (m): its footprint, not its height, so that a held object still
/// rests on its support when it is put down. A prism grows about its vertices' centroid, by a
/// factor that moves its nearest edge out by `d` (every other edge by at least as much).
world::Shape grownShape(const world::Shape& shape, double d) {
  world::Shape g = shape;
  switch (shape.kind) {
    case world::ShapeKind::kBox:
      g.size.x() += 2 * d;
      g.size.y() += 2 * d;
      break;
    case world::ShapeKind::kCylinder: g.radius += d; break;
    case world::ShapeKind::kSphere: g.radius += d; break;  // no footprint apart from its height
    case world::ShapeKind::kPrism: {
      const auto& v = shape.polygon;
      Eigen::Vector2d c = Eigen::Vector2d::Zero();
      for (const auto& p : v) c += p;
      c /= static_cast<double>(v.size());
      double nearest = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < v.size(); ++i) {
        const Eigen::Vector2d a = v[i], b = v[(i + 1) % v.size()];
        const Eigen::Vector2d ab = b - a;
        const double t = std::clamp((c - a).dot(ab) / std::max(1e-12, ab.squaredNorm()), 0.0, 1.0);
        nearest = std::min(nearest, (a + t * ab - c).norm());
      }
      const double k = 1.0 + d / std::max(1e-6, nearest);
      std::vector<Eigen::Vector2d> out;
      for (const auto& p : v) out.push_back(c + k * (p - c));
      g = world::Shape::prism(world::Polygon2(out.begin(), out.end()), shape.height);
      break;
    }
  }
  return g;
}



/// The cache key of the static free space of `group` (see detail::StaticWorldKey).
detail::StaticWorldKey staticWorldKey(const MotionPlanner::Impl& impl, PlanningGroup group,
                                      const robot::RobotState& start, const std::string& held,
                                      const std::string& held_link, const Eigen::Isometry3d& link_T_held,
                                      const std::vector<std::string>& ignored) {
  detail::StaticWorldKey key;
  key.group = group;
  for (const auto& o : impl.world.objects()) {
    if (o.kind != world::ObjectKind::kStatic) continue;
    if (std::find(ignored.begin(), ignored.end(), o.id) != ignored.end()) continue;
    key.statics.push_back(impl.world.objectPtr(o.id));
  }
  if (!held.empty()) {
    key.held = impl.world.objectPtr(held);
    key.held_link = held_link;
    key.link_T_held = link_T_held;
  }
  if (group == PlanningGroup::kBase) key.fixed = start.arm;
  if (group == PlanningGroup::kArm) key.fixed = {start.base.x, start.base.y, start.base.theta};
  if (impl.robot.hasArm()) key.fixed.push_back(start.gripper);
  return key;
}


Result<PrepareStats> MotionPlanner::prepare(PlanningGroup group, const robot::RobotState& state,
                                            const std::string& held_object, const Termination& termination) {
  Impl& impl = *impl_;
  const auto& P = impl.params;
  Stopwatch clock;
  PrepareStats out;
  if (group != PlanningGroup::kBase && !impl.robot.hasArm()) {
    return Error(ErrorCode::kInvalidArgument, "group: '" + std::string(toString(group)) + "' needs an arm");
  }
  if (state.arm.size() != impl.robot.armDof()) {
    return Error(ErrorCode::kInvalidArgument, "state.arm: expected " + std::to_string(impl.robot.armDof()) +
                                                  " values, got " + std::to_string(state.arm.size()));
  }
  if (!std::isfinite(state.base.x) || !std::isfinite(state.base.y) || !std::isfinite(state.base.theta)) {
    return Error(ErrorCode::kInvalidArgument, "state.base: not finite");
  }
  if (!P.lazy.optimize || P.lazy.roadmap_cache_entries == 0) {  // no roadmap to keep
    out.completed = true;
    out.time_ms = clock.millis();
    return out;
  }
  const std::string held = !held_object.empty() ? held_object
                           : impl.world.held() ? impl.world.held()->object_id
                                               : std::string();
  Impl::AttachGuard guard;
  std::string held_link;
  Eigen::Isometry3d link_T_held = Eigen::Isometry3d::Identity();
  if (!held.empty()) {
    auto g = impl.attach(held, state, held_object.empty() ? "world.held" : "held_object", nullptr, &held_link,
                         &link_T_held);
    if (!g) return g.error();
    guard = std::move(*g);
  }
  const Aabb bounds = impl.baseBounds({{state.base.x, state.base.y}});
  detail::GroupSpace gs(impl.robot, group, state, bounds, P.sampling);
  const double reach = group == PlanningGroup::kBase ? impl.reachRadius(state, held, held_link, link_T_held) : 0.0;
  detail::Oracle oracle(impl.scene, gs, {}, {}, reach);  // static checks only
  std::unique_ptr<detail::StaticRoadmap> uncached;
  bool reused = false;
  detail::StaticRoadmap* roadmap =
      impl.roadmapFor(staticWorldKey(impl, group, state, held, held_link, link_T_held, {}), gs.space(), reused,
                      uncached);
  out.built = !reused;
  // A new roadmap's samples, or the rest of an interrupted preparation's.
  if ((roadmap->uniformSamples() == 0 || roadmap->samplingInterrupted()) && P.lazy.roadmap_samples > 0) {
    const int bridges = group == PlanningGroup::kBase ? P.lazy.roadmap_bridge_samples : 0;
    roadmap->addSamples(oracle, gs, std::max(0, P.lazy.roadmap_samples - static_cast<int>(roadmap->plainSamples())),
                        termination, std::max(0, bridges - static_cast<int>(roadmap->bridgeSamples())),
                        P.lazy.roadmap_bridge_distance);
  }
  bool edges_complete = false;
  const auto [evaluated, invalid] =
      roadmap->evaluateEdges(oracle, P.sampling.validity_resolution, termination, edges_complete);
  out.completed = edges_complete && !roadmap->samplingInterrupted();
  out.edges_evaluated = evaluated;
  out.edges_invalid = invalid;
  out.roadmap_nodes = roadmap->nodeCount();
  out.roadmap_edges = roadmap->edgeCount();
  out.time_ms = clock.millis();
  return out;
}

namespace {

/// The held object with its margin (the world restored afterwards, as for overrides); the
/// problem, if any.
std::optional<std::string> padHeldObject(MotionPlanner::Impl& impl, const MotionRequest& req, RequestWorld& rw) {
  if (!(req.held_padding_m > 0)) return std::nullopt;
  world::World padded = impl.world;
  const std::string id = !req.held_object.empty() ? req.held_object : impl.world.held()->object_id;
  world::Object o = padded.object(id);
  rw.held_shape = o.shape;
  o.shape = grownShape(o.shape, req.held_padding_m);
  if (Status s = padded.updateObject(o); !s) return "held_padding_m: " + s.error().message;
  if (rw.restore.active()) {
    rw.restore.replaceWorld(std::move(padded));
  } else {
    rw.restore = WorldRestore(impl, std::move(padded));
  }
  return std::nullopt;
}

/// Lazy mode: the request's fixed objects made static for it (the world restored afterwards, as
/// for overrides): the lazy path goes round them, and the roadmap of that static world is used.
std::optional<std::string> fixObjects(MotionPlanner::Impl& impl, const MotionRequest& req, RequestWorld& rw) {
  if (req.mode != MotionMode::kLazy || req.fixed_objects.empty()) return std::nullopt;
  world::World fixed = impl.world;
  for (std::size_t i = 0; i < req.fixed_objects.size(); ++i) {
    world::Object o = fixed.object(req.fixed_objects[i]);
    o.kind = world::ObjectKind::kStatic;
    o.graspable = false;
    if (Status s = fixed.updateObject(o); !s) return "fixed_objects[" + std::to_string(i) + "]: " + s.error().message;
  }
  if (rw.restore.active()) {
    rw.restore.replaceWorld(std::move(fixed));
  } else {
    rw.restore = WorldRestore(impl, std::move(fixed));
  }
  return std::nullopt;
}

/// Base bounds: the world, the start and a base goal.
Aabb requestBounds(const MotionPlanner::Impl& impl, const MotionRequest& req) {
  std::vector<Eigen::Vector2d> extra{{req.start.base.x, req.start.base.y}};
  if (req.goal.kind == MotionGoal::Kind::kBasePose) extra.emplace_back(req.goal.base.x, req.goal.base.y);
  if (req.goal.kind == MotionGoal::Kind::kConfiguration && req.group != PlanningGroup::kArm) {
    extra.emplace_back(req.goal.configuration[0], req.goal.configuration[1]);
  }
  if (req.goal.kind == MotionGoal::Kind::kEndEffectorPose) {
    extra.emplace_back(req.goal.end_effector.translation().x(), req.goal.end_effector.translation().y());
  }
  return impl.baseBounds(extra);
}

/// Puts the request's world in place (overrides, the held object's margin), its base bounds and
/// the held object attached to the robot into `rw`; the first problem (an invalid request).
std::optional<std::string> enterRequestWorld(MotionPlanner::Impl& impl, const MotionRequest& req,
                                             RequestWorld& rw) {
  if (!req.object_overrides.empty() || !req.added_objects.empty()) {
    auto hypothetical = overriddenWorld(impl.world, req.added_objects, req.object_overrides, req.held_object);
    if (!hypothetical) return hypothetical.error().message;
    rw.restore = WorldRestore(impl, std::move(*hypothetical));
  }
  if (auto why = fixObjects(impl, req, rw)) return why;
  if (auto why = padHeldObject(impl, req, rw)) return why;
  rw.bounds = requestBounds(impl, req);
  // The held object moves with the robot for this request.
  rw.held = !req.held_object.empty() ? req.held_object
            : impl.world.held()      ? impl.world.held()->object_id
                                     : std::string();
  if (!rw.held.empty()) {
    auto g = impl.attach(rw.held, req.start, req.held_object.empty() ? "world.held" : "held_object",
                         req.held_grasp ? &*req.held_grasp : nullptr, &rw.held_link, &rw.link_T_held);
    if (!g) return g.error().message;
    rw.guard = std::move(*g);
  }
  return std::nullopt;
}

}  // namespace

MotionResult MotionPlanner::plan(const MotionRequest& req, const Termination& termination) {
  Impl& impl = *impl_;
  PlanOutput out;
  if (auto why = validateRequest(req, impl, groupJointNames(req.group))) {
    return out.finish(MotionStatus::kInvalidRequest, *why);
  }
  // The request's world, restored on every return: declared before the planning state, which
  // checks in it, so that it outlives it.
  RequestWorld request_world;
  if (auto why = enterRequestWorld(impl, req, request_world)) return out.finish(MotionStatus::kInvalidRequest, *why);
  Planning planning(impl, req, termination, request_world, out);
  if (auto done = planning.leaveStart()) return *done;
  if (auto done = planning.setGoal()) return *done;
  planning.searchRoadmapFirst();
  if (auto done = planning.search()) return *done;
  og::PathGeometric path = planning.rawPath();
  if (planning.lazy) {
    path = planning.improveLazyPath(path);
  } else if (auto done = planning.refineFullPath(path)) {
    return *done;
  }
  return planning.finishSolved(path);
}

}  // namespace tamp::motion_planner
