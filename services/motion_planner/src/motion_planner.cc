// MotionPlanner: request validation, the lazy and full pipelines (see motion_planner.h).
#include "tamp/core/format.h"
#include "tamp/motion_planner/motion_planner.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iterator>
#include <limits>
#include <mutex>

#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/goals/GoalSampleableRegion.h>
#include <ompl/base/goals/GoalState.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
#include <ompl/geometric/planners/kpiece/KPIECE1.h>
#include <ompl/geometric/planners/kpiece/LBKPIECE1.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include "planner_impl.h"
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

/// Base goal with a position tolerance and a free yaw (rotation-symmetric robots).
class AnyYawGoal : public ob::GoalSampleableRegion {
 public:
  AnyYawGoal(const ob::SpaceInformationPtr& si, const detail::GroupSpace& gs, const ob::State* templ,
             double x, double y, double tol)
      : ob::GoalSampleableRegion(si), gs_(gs), templ_(si->cloneState(templ)), x_(x), y_(y) {
    setThreshold(tol);
  }
  ~AnyYawGoal() override { si_->freeState(templ_); }
  double distanceGoal(const ob::State* s) const override {
    const Pose2D p = gs_.basePose(s);
    double d = std::hypot(p.x - x_, p.y - y_);
    if (gs_.movesArm()) {  // whole body: the arm must match too
      const auto v = gs_.values(s), t = gs_.values(templ_);
      for (std::size_t i = 3; i < v.size(); ++i) d += std::abs(v[i] - t[i]);
    }
    return d;
  }
  void sampleGoal(ob::State* s) const override {
    si_->copyState(s, templ_);
    auto v = gs_.values(s);
    v[2] = rng_.uniformReal(-M_PI, M_PI);
    gs_.setValues(v, s);
  }
  unsigned int maxSampleCount() const override { return 1000000u; }

 private:
  const detail::GroupSpace& gs_;
  ob::State* templ_;
  double x_, y_;
  mutable ompl::RNG rng_;
};

ob::PlannerPtr makePlanner(PlannerKind kind, const ob::SpaceInformationPtr& si, double range) {
  switch (kind) {
    case PlannerKind::kLbkpiece: {
      auto p = std::make_shared<og::LBKPIECE1>(si);
      if (range > 0) p->setRange(range);
      return p;
    }
    case PlannerKind::kKpiece: {
      auto p = std::make_shared<og::KPIECE1>(si);
      if (range > 0) p->setRange(range);
      return p;
    }
    case PlannerKind::kRrtConnect: {
      auto p = std::make_shared<og::RRTConnect>(si);
      if (range > 0) p->setRange(range);
      return p;
    }
  }
  return nullptr;
}

ob::PlannerTerminationCondition ptcOf(const Termination& t) {
  return ob::PlannerTerminationCondition([t] { return t(); });
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

namespace {

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

/// Puts the planner's scene and world back when a request planned in a hypothetical world ends.
class WorldRestore {
 public:
  WorldRestore() = default;
  WorldRestore(MotionPlanner::Impl& impl, world::World hypothetical) : impl_(&impl), saved_(impl.world) {
    impl.world = std::move(hypothetical);
    impl.scene.syncWorld(impl.world);
  }
  WorldRestore(WorldRestore&& o) noexcept : impl_(o.impl_), saved_(std::move(o.saved_)) { o.impl_ = nullptr; }
  WorldRestore& operator=(WorldRestore&& o) noexcept {
    if (this != &o) {
      restore();
      impl_ = o.impl_;
      saved_ = std::move(o.saved_);
      o.impl_ = nullptr;
    }
    return *this;
  }
  WorldRestore(const WorldRestore&) = delete;
  WorldRestore& operator=(const WorldRestore&) = delete;
  ~WorldRestore() { restore(); }
  bool active() const { return impl_ != nullptr; }
  /// Another hypothetical world (active only); the saved one stays what is restored.
  void replaceWorld(world::World hypothetical) {
    impl_->world = std::move(hypothetical);
    impl_->scene.syncWorld(impl_->world);
  }

 private:
  void restore() {
    if (!impl_) return;
    impl_->world = std::move(saved_);
    impl_->scene.syncWorld(impl_->world);
    impl_ = nullptr;
  }
  MotionPlanner::Impl* impl_{nullptr};
  world::World saved_;
};

}  // namespace

namespace {

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

}  // namespace

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

/// Frees a state of `space` (a start, an escape): OMPL states belong to their space.
struct StateFree {
  const ob::StateSpace* space;
  void operator()(ob::State* s) const { space->freeState(s); }
};
using StatePtr = std::unique_ptr<ob::State, StateFree>;

/// Frees the goal states when the request ends.
struct GoalFree {
  std::vector<ob::State*>& v;
  const ob::StateSpacePtr& sp;
  ~GoalFree() {
    for (auto* s : v) sp->freeState(s);
  }
};

/// Set when a phase of plan() ends the request: plan() returns it.
using Outcome = std::optional<MotionResult>;

/// What plan() returns, filled in by its phases, and the clock of its planning time.
struct PlanOutput {
  Stopwatch clock;
  MotionResult res;
  /// `res` with its outcome and the planning time so far.
  MotionResult finish(MotionStatus st, std::string reason, std::string object = {}) {
    res.status = st;
    res.reason = std::move(reason);
    res.colliding_object = std::move(object);
    res.planning_time_s = clock.seconds();
    return res;
  }
};

/// The request's world in place of the planner's while the request is planned.
struct RequestWorld {
  // The planner's world with the overrides applied, restored on every return (declared before the
  // attachment so that the held object is detached first).
  WorldRestore restore;
  std::optional<world::Shape> held_shape;  // the held object's modelled shape, when grown
  Aabb bounds;                             // of the base
  std::string held;                        // the object that moves with the robot, or none
  MotionPlanner::Impl::AttachGuard guard;
  std::string held_link;
  Eigen::Isometry3d link_T_held = Eigen::Isometry3d::Identity();
};

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

/// One plan() call in the request's world: its state space, checkers and start state (set up on
/// construction), then its phases in the order plan() calls them. A phase that ends the request
/// returns its result. Members are declared in the order they are made, so that they are
/// destroyed in reverse (the planner before the goal states, the checkers before the space).
struct Planning {
  Planning(MotionPlanner::Impl& planner_impl, const MotionRequest& request, const Termination& term,
           const RequestWorld& rw, PlanOutput& output);

  /// The start: free, or left by a short straight motion (`escaped`); not in self-collision.
  Outcome leaveStart();
  /// The problem definition: the start and the goal, checked (a goal state, or IK solutions).
  Outcome setGoal();
  /// Lazy mode: the cached roadmap of the static free space, searched first when it is known.
  void searchRoadmapFirst();
  /// A new roadmap of a world that extends a cached one by obstacles (fixed objects) made from it.
  void deriveRoadmap();
  /// A path: the roadmap's, the direct motion or the sampling planner's.
  Outcome search();
  /// The path found by search() (its length reported).
  og::PathGeometric rawPath();
  /// Lazy mode: `raw` improved on the roadmap and by effort shortcuts; the objects it crosses.
  og::PathGeometric improveLazyPath(const og::PathGeometric& raw);
  /// Full mode: `path` simplified and (arm) repaired where the arm sweeps through an object.
  Outcome refineFullPath(og::PathGeometric& path);
  /// The result for `path`: joint path and trajectory.
  MotionResult finishSolved(const og::PathGeometric& path);

  // The steps of the phases, in the order of their definitions below.
  Outcome finish(MotionStatus st, std::string reason, std::string object = {}) {
    return out.finish(st, std::move(reason), std::move(object));
  }
  detail::Oracle requestOracle();
  std::vector<double> sweepRadii() const;
  ob::SpaceInformationPtr makeSi(detail::Oracle& checker, bool full, bool swept = false) const;
  ob::SpaceInformationPtr sweptSi(detail::Oracle& checker) const;
  void setUpClearance();
  void setUpStartFloor();
  bool collides(const ob::State* s);
  collision::Scene& plainScene();
  std::string selfHit(const ob::State* s);
  collision::Scene shrunkScene(const std::vector<std::string>& ids);
  bool escapeBy(const ob::SpaceInformationPtr& checker);
  void escapeTouchedMovables(const std::vector<int>& touching);
  bool escapeNoDeeper(const std::vector<int>& touching);
  bool escapeThrough(const std::vector<int>& touching);
  std::vector<std::string> touchedFixedOnly();
  void escapeFixed(const std::vector<std::string>& touched);
  std::vector<std::string> touchedStaticsShallowly();
  void escapeStatics(const std::vector<std::string>& touched);
  void escapeHeldMargin();
  bool checkGoal(ob::State* s, std::string& who);
  Outcome setStateGoal();
  Outcome setEndEffectorGoal();
  std::vector<Pose2D> goalBases() const;
  collision::Filter requestFilter() const;
  void ensureSampled();
  void densify(og::PathGeometric& path, int s, const std::vector<int>& goals, const std::vector<int>& objects);
  void tryDirect(bool keep_clearance);
  Outcome straightOnly();
  bool directKeepsClear(const ob::State* from, const ob::State* to);
  std::optional<detail::DisconnectionProof::Carried> carriedByBase() const;
  Outcome sample(const Stopwatch& phase, bool solved);
  og::PathGeometric improveByRoadmap(const og::PathGeometric& raw, const detail::PathCost& raw_cost);
  void simplify(og::PathGeometric& path);
  Outcome repairSwept(og::PathGeometric& path);
  void prependEscapeAndAlign(og::PathGeometric& path);

  MotionPlanner::Impl& impl;
  const MotionPlannerParams& P;
  const MotionRequest& req;
  const Termination& termination;
  PlanOutput& out;
  MotionResult& res;
  // The request's world (see RequestWorld).
  const std::optional<world::Shape>& held_shape;
  const Aabb& bounds;
  const std::string& held;
  const std::string& held_link;
  const Eigen::Isometry3d& link_T_held;

  const bool lazy;
  detail::GroupSpace gs;
  const ob::StateSpacePtr& space;
  const std::vector<std::string> ignored;
  detail::Oracle oracle;
  // How far a point of the arm (or the object it holds) moves per radian of each joint.
  const std::vector<double> sweep_radii;
  const ob::SpaceInformationPtr si;
  // Full-mode base paths: a clearance round objects where there is room for it (not for a push,
  // whose object rides on the base and drives into contact).
  std::unique_ptr<collision::Scene> padded_scene;
  std::unique_ptr<detail::Oracle> padded_oracle;
  std::unique_ptr<collision::Scene> direct_scene;  // the robot grown by direct_clearance
  std::unique_ptr<detail::Oracle> direct_oracle;
  ob::SpaceInformationPtr direct_si;
  std::shared_ptr<detail::ClearanceValidityChecker> clearance;
  StatePtr start;
  // The request's scene with the held object as modelled (no margin), built when first needed:
  // its contacts with the robot itself, and a start that touches something only with the margin.
  std::unique_ptr<collision::Scene> plain;
  // A full-mode start that touches movables only leaves them by a short straight motion first.
  StatePtr escaped;

  // ---- goal ----
  std::shared_ptr<ob::ProblemDefinition> pdef;
  std::optional<Eigen::Vector2d> base_goal;  // for the proof
  std::vector<ob::State*> goal_states;
  GoalFree goal_free{goal_states, space};

  // ---- lazy: the cached roadmap of the static free space ----
  const double spu;
  const double res_check;
  detail::StaticRoadmap* roadmap = nullptr;
  std::unique_ptr<detail::StaticRoadmap> uncached;  // roadmap_cache_entries == 0
  std::optional<og::PathGeometric> from_roadmap;

  // ---- search (+ infeasibility proof, interleaved) ----
  ob::PlannerPtr planner;
  // Full mode: the direct motion to a goal state, when it is free, needs no sampling.
  std::optional<og::PathGeometric> direct;
};

// ---- set-up: state space, validity and clearance checkers, start state ----

Planning::Planning(MotionPlanner::Impl& planner_impl, const MotionRequest& request, const Termination& term,
                   const RequestWorld& rw, PlanOutput& output)
    : impl(planner_impl),
      P(planner_impl.params),
      req(request),
      termination(term),
      out(output),
      res(output.res),
      held_shape(rw.held_shape),
      bounds(rw.bounds),
      held(rw.held),
      held_link(rw.held_link),
      link_T_held(rw.link_T_held),
      lazy(request.mode == MotionMode::kLazy),
      gs(impl.robot, req.group, req.start, bounds, P.sampling),
      space(gs.space()),
      ignored(req.ignored_objects),
      oracle(requestOracle()),
      sweep_radii(sweepRadii()),
      si(makeSi(oracle, !lazy)),
      start(nullptr, StateFree{space.get()}),
      escaped(nullptr, StateFree{space.get()}),
      spu(gs.secondsPerUnit(P.cost)),
      res_check(P.sampling.validity_resolution) {
  const bool pushes = !held.empty() && held_link == impl.robot.geometry().links.front();
  const bool keeps_room = P.sampling.base_clearance > 0.0 || P.sampling.base_start_margin > 0.0;
  if (!lazy && req.group == PlanningGroup::kBase && keeps_room && !pushes) setUpClearance();
  start.reset(space->allocState());
  {
    std::vector<double> v;
    if (gs.hasBase()) v = {req.start.base.x, req.start.base.y, wrapAngle(req.start.base.theta)};
    if (gs.movesArm()) v.insert(v.end(), req.start.arm.begin(), req.start.arm.end());
    gs.setValues(v, start.get());
  }
  if (clearance) setUpStartFloor();
  if (held_shape) oracle.setSelfScene(&plainScene());
}

/// The request's checker: the movables but the held and the ignored ones, with their effort.
detail::Oracle Planning::requestOracle() {
  std::vector<detail::MovableInfo> movables;
  for (const auto& o : impl.world.objects()) {
    if (o.kind != world::ObjectKind::kMovable || o.id == held) continue;
    if (std::find(ignored.begin(), ignored.end(), o.id) != ignored.end()) continue;
    detail::MovableInfo mi;
    mi.id = o.id;
    mi.mass = o.mass;
    mi.effort_s = impl.effort(o);
    mi.cost_s = mi.effort_s * req.object_cost_scale;
    mi.aabb = o.aabb();
    mi.object = impl.world.objectPtr(o.id);
    movables.push_back(std::move(mi));
  }
  const double reach =
      req.group == PlanningGroup::kBase ? impl.reachRadius(req.start, held, held_link, link_T_held) : 0.0;
  detail::Oracle o(impl.scene, gs, ignored, std::move(movables), reach);
  if (req.group == PlanningGroup::kBase)
    o.setClearance(impl.clearanceGrid(), impl.reachCover(req.start, held, held_link, link_T_held));
  return o;
}

std::vector<double> Planning::sweepRadii() const {
  std::vector<double> sweep = impl.robot.armJointRadii();
  if (!held.empty() && impl.robot.armReachTo(held_link) >= 0.0) {
    // The held object rides on `held_link`, below every arm joint: its reach from each joint is
    // at most that joint's radius plus the object's extent beyond the link.
    const Aabb box = impl.world.object(held).shape.aabb(Eigen::Isometry3d::Identity());
    const double extent = link_T_held.translation().norm() + 0.5 * (box.max - box.min).norm() + req.held_padding_m;
    for (double& r : sweep) r += extent;
  }
  return sweep;
}

ob::SpaceInformationPtr Planning::makeSi(detail::Oracle& checker, bool full, bool swept) const {
  auto info = std::make_shared<ob::SpaceInformation>(space);
  info->setStateValidityChecker(std::make_shared<detail::OracleValidityChecker>(info, checker, full));
  info->setStateValidityCheckingResolution(
      std::min(1.0, P.sampling.validity_resolution / std::max(1e-9, space->getMaximumExtent())));
  if (swept) {
    info->setMotionValidator(
        std::make_shared<detail::SweptArmMotionValidator>(info, gs, sweep_radii, P.sampling.arm_swept_step));
  } else if (detail::isStopAndTurn(*space)) {
    info->setMotionValidator(std::make_shared<detail::CornerMotionValidator>(info));
  }
  info->setup();
  return info;
}

/// Full checks, and an arm's motions checked as the robot sweeps them (`arm_swept_step`), as the
/// rest of its path is: a straight way out checked at `validity_resolution` moves a fingertip
/// centimetres between two checks, across an object a few cm wide.
ob::SpaceInformationPtr Planning::sweptSi(detail::Oracle& checker) const {
  const bool swept = req.group == PlanningGroup::kArm && P.sampling.arm_swept_step > 0.0 && !sweep_radii.empty();
  return makeSi(checker, true, swept);
}

void Planning::setUpClearance() {
  // Grown boxes, cylinders and spheres contain the originals (a grown prism need not); the
  // grown scene has no unknown space.
  const auto& parts = impl.robot.geometry().parts;
  const bool contains = !impl.scene.hasUnknownSpace() && std::all_of(parts.begin(), parts.end(), [](const auto& part) {
    return part.shape.kind != world::ShapeKind::kPrism;
  });
  if (P.sampling.base_clearance > 0.0) {
    padded_scene = std::make_unique<collision::Scene>(impl.world);
    padded_scene->setRobot(grownGeometry(impl.robot.geometry(), P.sampling.base_clearance));
    if (!held.empty()) (void)padded_scene->attach(held, held_link, link_T_held);
    // Those shapes grown by d reach at most d*sqrt(2) farther in xy (a box's corner).
    const double reach = oracle.reachRadius() + (contains ? std::sqrt(2.0) * P.sampling.base_clearance : 0.0);
    padded_oracle = std::make_unique<detail::Oracle>(*padded_scene, gs, ignored, oracle.movables(), reach);
    if (contains && oracle.reachRadius() > 0.0) {
      std::vector<Eigen::Vector3d> cover = impl.reachCover(req.start, held, held_link, link_T_held);
      for (auto& c : cover) c.z() += std::sqrt(2.0) * P.sampling.base_clearance;
      padded_oracle->setClearance(impl.clearanceGrid(), std::move(cover));
    }
  }
  std::vector<Eigen::Vector2d> ends{{req.start.base.x, req.start.base.y}};
  if (req.goal.kind == MotionGoal::Kind::kBasePose) ends.emplace_back(req.goal.base.x, req.goal.base.y);
  if (req.goal.kind == MotionGoal::Kind::kConfiguration && req.goal.configuration.size() >= 2)
    ends.emplace_back(req.goal.configuration[0], req.goal.configuration[1]);
  clearance = std::make_shared<detail::ClearanceValidityChecker>(si, oracle, padded_oracle.get(), gs, std::move(ends),
                                                                 P.sampling.base_clearance_near_ends, contains);
  si->setStateValidityChecker(clearance);
}

/// A start nearer than `base_start_margin` to a movable (and not touching it: that start is left
/// by `leaveStart`) keeps its distance near the start: no nearer than the start, nor than a goal
/// state that stands nearer still, less 1 mm for the distance query's own error.
void Planning::setUpStartFloor() {
  if (!(P.sampling.base_start_margin > 0.0)) return;
  double floor = oracle.movableDistance(start.get());
  if (!(floor > 0.0) || floor >= P.sampling.base_start_margin) return;
  std::vector<double> goal;
  if (req.goal.kind == MotionGoal::Kind::kBasePose)
    goal = {req.goal.base.x, req.goal.base.y, wrapAngle(req.goal.base.theta)};
  if (req.goal.kind == MotionGoal::Kind::kConfiguration) goal = req.goal.configuration;
  if (goal.size() == space->getDimension()) {
    StatePtr g(space->allocState(), StateFree{space.get()});
    gs.setValues(goal, g.get());
    floor = std::min(floor, oracle.movableDistance(g.get()));
  }
  constexpr double kDistanceError = 0.001;
  if (floor - kDistanceError > 0.0) {
    clearance->setStartFloor(floor - kDistanceError);
    log::get("motion_planner")->debug("the start stands {:.4f} m from a movable: no nearer within {} m of it", floor,
                                      P.sampling.base_clearance_near_ends);
  }
  gs.placeRobot(start.get(), impl.scene);
}

bool Planning::collides(const ob::State* s) { return lazy ? !oracle.staticFree(s) : !oracle.allFree(s); }

collision::Scene& Planning::plainScene() {
  if (!plain) {
    world::World w = impl.world;
    world::Object o = w.object(held);
    o.shape = *held_shape;
    (void)w.updateObject(o);
    plain = std::make_unique<collision::Scene>(w);
    plain->setRobot(impl.robot.geometry());
    (void)plain->attach(held, held_link, link_T_held);
  }
  return *plain;
}

// Contacts of the robot with itself at `s` (placed in the scene by the caller).
std::string Planning::selfHit(const ob::State* s) {
  if (impl.scene.attachedObjects().empty() && !gs.movesArm()) return {};
  collision::Scene* sc = &impl.scene;
  if (held_shape) {
    sc = &plainScene();
    gs.placeRobot(s, *sc);
  }
  const auto self = sc->selfCollisions();
  return self.empty() ? std::string() : "self:" + self.front().first + "/" + self.front().second;
}

// ---- the start ----

Outcome Planning::leaveStart() {
  if (collides(start.get())) {
    const std::string who = oracle.collidingObject(start.get(), !lazy);
    std::vector<int> touching;
    if (!lazy && oracle.staticFree(start.get())) oracle.touched(start.get(), touching);
    if (!touching.empty() && P.sampling.start_escape_distance > 0.0) escapeTouchedMovables(touching);
    // Touching only with the held object's margin: leave by a short straight motion checked
    // without it (the robot was stopped before the contact it is now given room for).
    if (!escaped && held_shape && P.sampling.start_escape_distance > 0.0) escapeHeldMargin();
    if (!escaped && lazy && P.sampling.start_escape_distance > 0.0) {
      const std::vector<std::string> fixed = touchedFixedOnly();
      if (!fixed.empty()) escapeFixed(fixed);
    }
    if (!escaped && P.sampling.start_escape_distance > 0.0 && P.sampling.start_escape_depth > 0.0) {
      const std::vector<std::string> statics = touchedStaticsShallowly();
      if (!statics.empty()) escapeStatics(statics);
    }
    if (!escaped) {
      return finish(MotionStatus::kStartInCollision, "the start state touches '" + who + "'" +
                                                         (touching.empty() ? "" : " (no way out of the contact found)"),
                    who);
    }
  }
  gs.placeRobot(start.get(), impl.scene);
  if (std::string s = selfHit(start.get()); !s.empty()) {
    return finish(MotionStatus::kStartInCollision, "the start state is in self-collision (" + s + ")", s);
  }
  return std::nullopt;
}

/// Out of the contact with the `touching` movables (indices into the oracle's), checked against
/// everything else; `escaped` stays empty when there is no way out. A way out that goes no deeper
/// into what it touches is taken first: a straight motion that slides a finger across an object
/// just put down pushes it, and the robot is stopped before it. A start deeper in an object than
/// `start_escape_depth` has no such way; it leaves through the objects it touches.
void Planning::escapeTouchedMovables(const std::vector<int>& touching) {
  const bool no_deeper = P.sampling.start_escape_depth > 0.0 && escapeNoDeeper(touching);
  if (!no_deeper)
    log::get("motion_planner")->debug("no way out of the start's contact going no deeper than {} m: through it",
                                      P.sampling.start_escape_depth);
  const bool left = no_deeper || escapeThrough(touching);
  if (left)
    for (int i : touching) res.start_contacts.push_back(oracle.movables()[static_cast<std::size_t>(i)].id);
}

/// Lazy mode: the objects this request fixes (movables the caller cannot move, static for this
/// request) that the start touches, when it touches nothing else static; empty otherwise.
std::vector<std::string> Planning::touchedFixedOnly() {
  std::vector<std::string> touched;
  gs.placeRobot(start.get(), impl.scene);
  for (const auto& id : req.fixed_objects)
    if (impl.scene.robotInCollision(collision::Filter::objects({id}))) touched.push_back(id);
  if (!touched.empty()) {
    std::vector<std::string> ignore = ignored;
    ignore.insert(ignore.end(), touched.begin(), touched.end());
    if (impl.scene.robotInCollision(collision::Filter{collision::kStaticObjects | collision::kUnknownSpace, {}, ignore}))
      touched.clear();
  }
  return touched;
}

/// Lazy mode: out of the contact with objects this request fixes (a perceived object that the
/// caller can neither carry nor push, estimated reaching where the robot stands), as a full-mode
/// start leaves movables: going no deeper into them first, else through them, to a state that
/// touches nothing static (they included).
void Planning::escapeFixed(const std::vector<std::string>& touched) {
  bool found = false;
  if (P.sampling.start_escape_depth > 0.0) {
    collision::Scene smaller = shrunkScene(touched);
    detail::Oracle escape_oracle(smaller, gs, ignored, oracle.movables(), oracle.reachRadius());
    if (held_shape) escape_oracle.setSelfScene(&plainScene());
    found = escapeBy(makeSi(escape_oracle, false));
  }
  if (!found) {
    std::vector<std::string> ignore = ignored;
    ignore.insert(ignore.end(), touched.begin(), touched.end());
    detail::Oracle escape_oracle(impl.scene, gs, ignore, oracle.movables(), oracle.reachRadius());
    if (held_shape) escape_oracle.setSelfScene(&plainScene());
    found = escapeBy(makeSi(escape_oracle, false));
  }
  if (found) res.start_contacts.insert(res.start_contacts.end(), touched.begin(), touched.end());
}

/// The static objects (and, lazy, the ones the request fixes) that the start touches, when it is
/// free of them `start_escape_depth` smaller and touches nothing else; empty otherwise. A robot
/// stopped at a wall by its own safety (or localised a few millimetres off) stands there: the
/// planner's model of the robot and the world is not the world.
std::vector<std::string> Planning::touchedStaticsShallowly() {
  std::vector<std::string> touched;
  gs.placeRobot(start.get(), impl.scene);
  for (const auto& o : impl.world.objects()) {  // (lazy: the fixed objects are static for the request)
    if (o.kind != world::ObjectKind::kStatic) continue;
    if (std::find(ignored.begin(), ignored.end(), o.id) != ignored.end()) continue;
    if (impl.scene.robotInCollision(collision::Filter::objects({o.id}))) touched.push_back(o.id);
  }
  if (touched.empty()) return touched;
  collision::Scene smaller = shrunkScene(touched);
  detail::Oracle shallow(smaller, gs, ignored, oracle.movables(), oracle.reachRadius());
  if (!(lazy ? shallow.staticFree(start.get()) : shallow.allFree(start.get()))) touched.clear();
  gs.placeRobot(start.get(), impl.scene);
  return touched;
}

/// Out of a shallow contact with static objects `touched`: a short straight motion going no
/// deeper into them (checked against them `start_escape_depth` smaller), to a free state. Never
/// through them, as a movable may be left.
void Planning::escapeStatics(const std::vector<std::string>& touched) {
  collision::Scene smaller = shrunkScene(touched);
  detail::Oracle escape_oracle(smaller, gs, ignored, oracle.movables(), oracle.reachRadius());
  if (held_shape) escape_oracle.setSelfScene(&plainScene());
  if (escapeBy(makeSi(escape_oracle, !lazy))) {
    res.start_contacts.insert(res.start_contacts.end(), touched.begin(), touched.end());
  }
}

/// A copy of the request's scene with the objects `ids` `start_escape_depth` smaller.
collision::Scene Planning::shrunkScene(const std::vector<std::string>& ids) {
  world::World w = impl.scene.world();
  for (const auto& id : ids) {
    world::Object o = w.object(id);
    o.shape = world::shrunk(o.shape, P.sampling.start_escape_depth);
    (void)w.updateObject(std::move(o));
  }
  collision::Scene smaller(impl.scene);
  smaller.syncWorld(w);
  return smaller;
}

/// A short way out of the start, each state checked by `checker` (whose oracle sees the held
/// object's self-collisions without its margin); sets `escaped`, or clears it when there is none.
/// The robot is placed back at the start in the request's scene.
bool Planning::escapeBy(const ob::SpaceInformationPtr& checker) {
  escaped.reset(space->allocState());
  const bool found = detail::escapeStart(si, checker, start.get(), P.sampling.start_escape_distance,
                                         P.sampling.start_escape_attempts, escaped.get());
  if (!found) escaped.reset();
  gs.placeRobot(start.get(), impl.scene);
  return found;
}

/// The way out checked against everything, the touched objects `start_escape_depth` smaller.
bool Planning::escapeNoDeeper(const std::vector<int>& touching) {
  std::vector<std::string> ids;
  for (int i : touching) ids.push_back(oracle.movables()[static_cast<std::size_t>(i)].id);
  collision::Scene smaller = shrunkScene(ids);
  detail::Oracle escape_oracle(smaller, gs, ignored, oracle.movables(), oracle.reachRadius());
  if (held_shape) escape_oracle.setSelfScene(&plainScene());
  return escapeBy(sweptSi(escape_oracle));
}

/// The way out checked against everything but the touched objects.
bool Planning::escapeThrough(const std::vector<int>& touching) {
  std::vector<std::string> ignore = ignored;
  std::vector<detail::MovableInfo> others;
  for (std::size_t i = 0; i < oracle.movables().size(); ++i) {
    const auto& m = oracle.movables()[i];
    if (std::binary_search(touching.begin(), touching.end(), static_cast<int>(i))) {
      ignore.push_back(m.id);
    } else {
      others.push_back(m);
    }
  }
  detail::Oracle escape_oracle(impl.scene, gs, ignore, std::move(others), oracle.reachRadius());
  if (held_shape) escape_oracle.setSelfScene(&plainScene());
  return escapeBy(makeSi(escape_oracle, true));
}

/// Out of a contact that only the held object's margin makes; `escaped` stays empty when the
/// start touches something without the margin too, or there is no way out.
void Planning::escapeHeldMargin() {
  detail::Oracle plain_oracle(plainScene(), gs, ignored, oracle.movables(), oracle.reachRadius());
  if (lazy ? plain_oracle.staticFree(start.get()) : plain_oracle.allFree(start.get())) (void)escapeBy(makeSi(plain_oracle, !lazy));
  gs.placeRobot(start.get(), impl.scene);
}

// ---- goal ----

Outcome Planning::setGoal() {
  Stopwatch goal_clock;
  pdef = std::make_shared<ob::ProblemDefinition>(si);
  pdef->addStartState(escaped ? escaped.get() : start.get());
  const auto& G = req.goal;
  if (auto done = G.kind == MotionGoal::Kind::kConfiguration || G.kind == MotionGoal::Kind::kBasePose
                      ? setStateGoal()
                      : setEndEffectorGoal()) {
    return done;
  }
  res.stats.goal_ms = goal_clock.millis();
  return std::nullopt;
}

/// Whether `s` is free (as the mode checks it) and not in self-collision; else who it touches.
bool Planning::checkGoal(ob::State* s, std::string& who) {
  if (collides(s)) {
    who = oracle.collidingObject(s, !lazy);
    return false;
  }
  gs.placeRobot(s, impl.scene);
  who = gs.movesArm() ? selfHit(s) : std::string();
  return who.empty();
}

/// A configuration or base pose goal (with any yaw: the first of 16 that is free).
Outcome Planning::setStateGoal() {
  const auto& G = req.goal;
  std::vector<double> v;
  if (G.kind == MotionGoal::Kind::kConfiguration) {
    v = G.configuration;
  } else {
    v = {G.base.x, G.base.y, wrapAngle(G.base.theta)};
    if (gs.movesArm()) v.insert(v.end(), req.start.arm.begin(), req.start.arm.end());
  }
  ob::State* gsState = space->allocState();
  goal_states.push_back(gsState);
  gs.setValues(v, gsState);
  if (gs.hasBase()) base_goal = Eigen::Vector2d(v[0], v[1]);
  std::string who;
  const bool any_yaw = G.kind == MotionGoal::Kind::kBasePose && G.any_base_yaw;
  bool free = checkGoal(gsState, who);
  if (!free && any_yaw) {  // another yaw may fit
    auto vv = v;
    for (int k = 1; k < 16 && !free; ++k) {
      vv[2] = wrapAngle(v[2] + k * M_PI / 8);
      gs.setValues(vv, gsState);
      std::string w2;
      free = checkGoal(gsState, w2);
    }
  }
  if (!free) return finish(MotionStatus::kGoalInCollision, "the goal state touches '" + who + "'", who);
  if (any_yaw) {
    pdef->setGoal(std::make_shared<AnyYawGoal>(si, gs, gsState, v[0], v[1], P.sampling.goal_position_tolerance));
  } else {
    pdef->setGoalState(gsState, gs.hasBase() ? P.sampling.goal_position_tolerance
                                             : P.sampling.goal_orientation_tolerance);
  }
  return std::nullopt;
}

/// An end-effector pose goal through IK: up to three free solutions from the goalBases().
Outcome Planning::setEndEffectorGoal() {
  const auto& G = req.goal;
  const auto* m = impl.robot.model();
  collision::Filter filter = requestFilter();
  const std::vector<Pose2D> bases = goalBases();
  std::string reject;
  int found = 0;
  for (std::size_t bi = 0; bi < bases.size() && found < 3; ++bi) {
    if (termination()) return finish(MotionStatus::kTimeout, "the deadline passed while solving IK for the goal");
    auto q = solveIk(impl, bases[bi], G.end_effector, req.start.arm, filter, req.start.gripper,
                     P.seed + static_cast<std::uint32_t>(bi), 16, termination);
    if (!q) continue;
    std::vector<double> v;
    if (gs.hasBase()) v = {bases[bi].x, bases[bi].y, bases[bi].theta};
    // (Not insert(): GCC 12 at -O3 reports a false -Warray-bounds for it here.)
    std::copy(q->begin(), q->end(), std::back_inserter(v));
    ob::State* s = space->allocState();
    goal_states.push_back(s);
    gs.setValues(v, s);
    if (!checkGoal(s, reject)) {
      space->freeState(s);
      goal_states.pop_back();
      continue;
    }
    ++found;
  }
  if (found == 0) {
    // Distinguish "unreachable" from "reachable only in collision".
    auto q = m->inverseKinematics(req.start.base.toIsometry().inverse() * G.end_effector, req.start.arm);
    if (req.group == PlanningGroup::kArm && q.ok()) {
      ob::State* s = space->allocState();
      goal_states.push_back(s);
      gs.setValues(q.q, s);
      std::string who = oracle.collidingObject(s, !lazy);
      if (!who.empty()) {
        return finish(MotionStatus::kGoalInCollision, "every IK solution of the goal touches an object, e.g. '" + who + "'",
                      who);
      }
    }
    return finish(MotionStatus::kNoPath, "goal.end_effector: no collision-free IK solution (" +
                                             std::to_string(bases.size()) + " base pose(s) tried)");
  }
  auto goals = std::make_shared<ob::GoalStates>(si);
  for (auto* s : goal_states) goals->addState(s);
  goals->setThreshold(P.sampling.goal_orientation_tolerance);
  pdef->setGoal(goals);
  return std::nullopt;
}

/// Where the base may stand for an end-effector goal: the start's (arm group), else rings round
/// the goal within the bounds.
std::vector<Pose2D> Planning::goalBases() const {
  std::vector<Pose2D> bases;
  if (req.group == PlanningGroup::kArm) {
    bases.push_back(req.start.base);
  } else {
    const Eigen::Vector3d t = req.goal.end_effector.translation();
    const auto& gp = P.grasp;
    for (int ring = 0; ring < 3; ++ring) {
      const double d = gp.base_distance_min + (gp.base_distance_max - gp.base_distance_min) * ring / 2.0;
      for (int k = 0; k < gp.base_poses; ++k) {
        // Start from the direction of the robot, alternate around it.
        const double a0 = std::atan2(req.start.base.y - t.y(), req.start.base.x - t.x());
        const double a = a0 + ((k % 2) ? 1 : -1) * ((k + 1) / 2) * (2 * M_PI / gp.base_poses);
        Pose2D b{t.x() + d * std::cos(a), t.y() + d * std::sin(a), wrapAngle(a + M_PI)};
        if (b.x < bounds.min.x() || b.x > bounds.max.x() || b.y < bounds.min.y() || b.y > bounds.max.y()) continue;
        bases.push_back(b);
      }
    }
  }
  return bases;
}

/// What the mode checks: static objects and unknown space (lazy) or everything (full), but the
/// ignored objects.
collision::Filter Planning::requestFilter() const {
  return lazy ? collision::Filter{collision::kStaticObjects | collision::kUnknownSpace, {}, ignored}
              : collision::Filter{collision::kAllGroups, {}, ignored};
}

// ---- lazy: the cached roadmap of the static free space ----

void Planning::searchRoadmapFirst() {
  if (!lazy || !P.lazy.optimize) return;
  Stopwatch rw;
  roadmap = impl.roadmapFor(staticWorldKey(impl, req.group, req.start, held, held_link, link_T_held, ignored), space,
                            res.stats.roadmap_reused, uncached);
  if (!res.stats.roadmap_reused && req.group == PlanningGroup::kBase && oracle.rigid()) deriveRoadmap();
  // A roadmap new in this request knows no edge yet: lazy KPIECE goes first and seeds it.
  if (req.group == PlanningGroup::kBase && P.lazy.roadmap_first && res.stats.roadmap_reused && !goal_states.empty()) {
    ensureSampled();
    res.stats.roadmap_pruned = roadmap->pruneRequestNodes(static_cast<std::size_t>(P.lazy.roadmap_max_request_nodes));
    const std::uint64_t request = ++impl.requests;
    const int s = roadmap->addRequestState(escaped ? escaped.get() : start.get(), request);
    std::vector<int> goals;
    for (const auto* g : goal_states) goals.push_back(roadmap->addRequestState(g, request));
    std::vector<int> crossed;
    from_roadmap = roadmap->search(oracle, si, s, goals, P.lazy, res_check, spu, termination, res.stats,
                                   P.lazy.roadmap_max_new_invalid, &crossed);
    if (from_roadmap) densify(*from_roadmap, s, goals, crossed);
  }
  res.stats.optimize_ms += rw.millis();
}

// The fixed objects of a request (obstacles for its lazy path) make a static world of their own,
// whose roadmap would be new: lazy KPIECE then ran in it, 1-3.3 s per request in
// namo_moghaddam_07. The cached roadmap of the world without them already knows that space but
// for the boxes the fixed objects occupy: it is copied, and only what is near them is checked.
void Planning::deriveRoadmap() {
  std::vector<std::shared_ptr<const world::Object>> added;
  for (const auto& cached : impl.roadmaps) {
    if (cached.get() == roadmap || cached->uniformSamples() == 0 || cached->samplingInterrupted()) continue;
    if (!roadmap->key().extends(cached->key(), added)) continue;
    std::vector<Aabb> boxes;
    for (const auto& o : added) boxes.push_back(o->aabb());
    const std::size_t dropped = roadmap->deriveFrom(*cached, oracle, boxes);
    res.stats.roadmap_reused = true;
    res.stats.roadmap_derived = true;
    log::get("motion_planner")
        ->debug("roadmap derived from a cached one ({} nodes, {} edges; {} nodes dropped) for {} more obstacle(s)",
                roadmap->nodeCount(), roadmap->edgeCount(), dropped, added.size());
    return;
  }
}

// A new roadmap draws its samples when it is first searched (arm requests whose lazy path
// crosses nothing never need it). Bridge-test samples for the base group only (narrow
// passages of the floor plan; in joint space they would cost many attempts, unmeasured).
void Planning::ensureSampled() {
  if (roadmap->uniformSamples() == 0 && P.lazy.roadmap_samples > 0) {
    roadmap->addSamples(oracle, gs, P.lazy.roadmap_samples, termination,
                        req.group == PlanningGroup::kBase ? P.lazy.roadmap_bridge_samples : 0,
                        P.lazy.roadmap_bridge_distance);
  }
}

// When the roadmap's best path crosses movables: samples around them, and the roadmap searched
// again (the result can only get cheaper: the old path is still in the roadmap).
// `objects`: those `path` crosses, as the search reported them.
void Planning::densify(og::PathGeometric& path, int s, const std::vector<int>& goals,
                       const std::vector<int>& objects) {
  if (objects.empty() || P.lazy.object_ring_samples <= 0 || req.group != PlanningGroup::kBase ||
      roadmap->nodeCount() >= static_cast<std::size_t>(P.lazy.roadmap_max_nodes)) {
    return;
  }
  if (roadmap->addObjectRingSamples(oracle, gs, objects, P.lazy.object_ring_samples, termination) == 0) return;
  auto again = roadmap->search(oracle, si, s, goals, P.lazy, res_check, spu, termination, res.stats);
  auto cost = [&](const og::PathGeometric& p) {
    return detail::evaluatePath(oracle, p, res_check, 0.0).cost(oracle, spu).cost;
  };
  if (again && cost(*again) < cost(path)) path = *again;
}

// ---- search (+ infeasibility proof, interleaved) ----

Outcome Planning::search() {
  if (req.straight_only) return straightOnly();
  Stopwatch phase;
  const PlannerKind kind = req.group != PlanningGroup::kBase ? P.sampling.arm_planner
                           : lazy                            ? P.sampling.lazy_planner
                                                             : P.sampling.full_planner;
  planner = makePlanner(kind, si, P.sampling.range);
  planner->setProblemDefinition(pdef);
  planner->setup();
  if (P.sampling.direct_first) tryDirect(true);
  const bool solved = from_roadmap.has_value() || direct.has_value();
  res.stats.lazy_planner_used = !solved;
  return sample(phase, solved);
}

/// Full mode: the direct motion to a goal state when it is free (and keeps the base clearance,
/// when `keep_clearance`).
void Planning::tryDirect(bool keep_clearance) {
  if (lazy || termination()) return;
  const ob::State* from = escaped ? escaped.get() : start.get();
  for (const ob::State* g : goal_states) {
    if (!si->checkMotion(from, g) || (keep_clearance && !directKeepsClear(from, g))) continue;
    direct.emplace(si, from, g);
    res.stats.direct = true;
    res.stats.clearance_relaxed = !keep_clearance;
    break;
  }
}

/// MotionRequest::straight_only: the direct motion (one that keeps the base clearance first, else
/// any free one), or `no path` at once; nothing is sampled.
Outcome Planning::straightOnly() {
  Stopwatch phase;
  tryDirect(true);
  if (!direct) tryDirect(false);
  res.stats.sampling_ms = phase.millis();
  if (direct) return std::nullopt;
  const ob::State* from = escaped ? escaped.get() : start.get();
  // What it touches: just past the last free state along it.
  std::pair<ob::State*, double> last_valid{space->allocState(), 0.0};
  ob::State* past = space->allocState();
  std::string who;
  if (!goal_states.empty()) {
    (void)si->checkMotion(from, goal_states.front(), last_valid);
    for (const double f : {0.002, 0.01, 0.05, 0.2, 1.0}) {
      space->interpolate(last_valid.first, goal_states.front(), f, past);
      if (!(who = oracle.collidingObject(past, true)).empty()) break;
    }
  }
  space->freeState(past);
  space->freeState(last_valid.first);
  return finish(MotionStatus::kNoPath,
                "straight_only: the straight motion to the goal is not free" +
                    (who.empty() ? std::string() : " (it touches '" + who + "' near " +
                                                       formatNumber(std::round(last_valid.second * 100.0)) + " % of it)"),
                who);
}

/// An arm's direct motion is taken only when the robot grown by `direct_clearance` sweeps it
/// free: a straight joint-space motion runs as close to what it passes as the check allows, and
/// objects are where perception saw them to within centimetres (right after a place, the fingers
/// swept past the object just put down and the robot was stopped before it). Sampled paths are
/// shortcut too, but from a tree grown through free space.
bool Planning::directKeepsClear(const ob::State* from, const ob::State* to) {
  if (!gs.movesArm() || !(P.sampling.direct_clearance > 0.0)) return true;
  if (!direct_si) {
    direct_scene = std::make_unique<collision::Scene>(impl.world);
    direct_scene->setRobot(grownGeometry(impl.robot.geometry(), P.sampling.direct_clearance));
    if (!held.empty()) (void)direct_scene->attach(held, held_link, link_T_held);
    direct_oracle = std::make_unique<detail::Oracle>(*direct_scene, gs, ignored, oracle.movables(), oracle.reachRadius());
    // Contacts of the robot with itself as modelled: grown, its links touch one another.
    direct_oracle->setSelfScene(held_shape ? &plainScene() : &impl.scene);
    direct_si = sweptSi(*direct_oracle);
  }
  const bool clear = direct_si->checkMotion(from, to);
  gs.placeRobot(start.get(), impl.scene);
  return clear;
}

/// Unless `solved`: the sampling planner in doubling time slices until it finds a path, the
/// proof shows there is none, or the time is up; the base clearance is dropped when no path kept
/// it in time. The proof (full mode: a first turn before sampling) gets a turn after each slice,
/// of ProofParams::time_share times the slice, and goes on from where its last turn stopped,
/// refining its grid each time one is too coarse to decide. Sampling time is reported either way.
/// The held object where it rides on the base for this request (the arm still), modelled
/// without its margin; nothing when nothing is held or the arm moves.
std::optional<detail::DisconnectionProof::Carried> Planning::carriedByBase() const {
  if (held.empty() || gs.movesArm()) return std::nullopt;
  const world::Object* o = impl.scene.world().findObject(held);
  const auto world_T_link = impl.linkPose(req.start, held_link);
  if (o == nullptr || !world_T_link) return std::nullopt;
  return detail::DisconnectionProof::Carried{held_shape ? *held_shape : o->shape,
                                             req.start.base.toIsometry().inverse() * *world_T_link * link_T_held};
}

Outcome Planning::sample(const Stopwatch& phase, bool solved) {
  // Proof levels: (xy cell, yaw cells); the disc on finer and finer cells, then the oriented base.
  std::vector<std::pair<double, int>> proof_cells;
  if (P.proof.enabled && gs.hasBase() && base_goal) {
    for (double c = P.proof.cell_size; c >= P.proof.min_cell_size - 1e-12; c *= 0.5) proof_cells.emplace_back(c, 1);
    if (P.proof.yaw_cells > 1) {
      proof_cells.emplace_back(P.proof.oriented_cell_size, P.proof.yaw_cells);
      for (int k = 1; k <= P.proof.oriented_refinements; ++k) {
        proof_cells.emplace_back(P.proof.oriented_cell_size / (1 << k), P.proof.yaw_cells << k);
      }
    }
  }
  const collision::Filter proof_filter = requestFilter();
  const std::shared_ptr<const collision::ClearanceGrid> statics = proof_cells.empty() ? nullptr : impl.clearanceGrid();
  std::size_t level = 0;
  std::unique_ptr<detail::DisconnectionProof> proof;
  // From where the sampler starts: a start touching movables is left first (the proof's cells
  // beside a touching start could all touch them too).
  const Pose2D proof_start = proof_cells.empty() ? req.start.base : gs.basePose(escaped ? escaped.get() : start.get());
  const auto carried = proof_cells.empty() ? std::nullopt : carriedByBase();
  auto traceProof = [&](const detail::DisconnectionProof& p, detail::ProofOutcome outcome) {
    static constexpr const char* kNames[] = {"disconnected", "connected", "skipped", "undecided"};
    std::string& t = res.stats.proof_trace;
    if (!t.empty()) t += ", ";
    t += formatNumber(p.cell()) + " m" + (p.yawCells() > 1 ? " x " + std::to_string(p.yawCells()) : std::string()) +
         ": " + kNames[static_cast<int>(outcome)] + " (" + std::to_string(p.tested()) + ")";
  };
  // One turn of the proof: true when it proved that there is no path.
  auto proofTurn = [&](double seconds) {
    Stopwatch pw;
    const Termination turn = termination.tightened(Deadline::in(seconds));
    bool proven = false;
    while (level < proof_cells.size() && !proven && !turn()) {
      if (!proof) {
        proof = std::make_unique<detail::DisconnectionProof>(
            impl.scene, proof_filter, statics.get(), impl.robot, bounds, proof_start, *base_goal,
            P.sampling.goal_position_tolerance, proof_cells[level].first, proof_cells[level].second,
            proof_cells[level].second > 1 ? P.proof.oriented_max_cells : P.proof.max_cells, carried);
      }
      const detail::ProofOutcome outcome = proof->advance(turn);
      if (outcome == detail::ProofOutcome::kStopped) break;
      proven = outcome == detail::ProofOutcome::kDisconnected;
      res.stats.proof_cells += proof->tested();
      res.stats.proof_grid_answers += proof->gridAnswers();
      traceProof(*proof, outcome);
      if (!proven) {
        // A finer (x, y, yaw) grid tests about eight times the cells: only where that fits.
        const bool refinement_next = level + 1 < proof_cells.size() && proof->yawCells() > 1;
        const bool small = outcome == detail::ProofOutcome::kConnected &&
                           8 * proof->tested() <= static_cast<std::size_t>(P.proof.oriented_max_cells);
        proof.reset();
        level = refinement_next && !small ? proof_cells.size() : level + 1;
      }
    }
    res.stats.proof_ms += pw.millis();
    return proven;
  };
  auto noPath = [&] {
    res.stats.sampling_ms = phase.millis() - res.stats.proof_ms;
    res.stats.validity_checks = oracle.checks();
    res.stats.grid_answers = oracle.gridAnswers();
    return finish(MotionStatus::kNoPath, std::string("no path: start and goal are in different components of the ") +
                                             (lazy ? "static " : "") + "free space of the base (proven on a " +
                                             formatNumber(proof->cell()) + " m grid" +
                                             (proof->yawCells() > 1 ? " with " + std::to_string(proof->yawCells()) +
                                                                          " yaw cells"
                                                                    : std::string()) +
                                             ")");
  };
  // A first turn before sampling: a goal walled off (by statics, or objects the request fixes)
  // is answered in milliseconds, before the first slice (lazy: 0.25 s) of a search that cannot
  // succeed. Requests the roadmap or the direct motion answered never get here.
  double slice = lazy ? 0.25 : 0.02;
  if (!solved && proofTurn(P.proof.first_turn_s)) return noPath();
  while (!solved) {
    if (termination()) break;
    // No path kept the clearance in time: on without it (every state and motion of the tree so
    // far passed the stronger check, so the tree stays valid).
    if (clearance && !clearance->relaxed() && phase.seconds() - res.stats.proof_ms / 1000.0 >= P.sampling.base_clearance_time_s) {
      clearance->relax();
      res.stats.clearance_relaxed = true;
    }
    const Termination slice_term = termination.tightened(Deadline::in(
        clearance && !clearance->relaxed() ? std::min(slice, P.sampling.base_clearance_time_s) : slice));
    planner->solve(ptcOf(slice_term));
    ++res.stats.sampling_slices;
    solved = pdef->hasExactSolution();
    if (!solved && proofTurn(slice * P.proof.time_share)) return noPath();
    slice *= 2;
  }
  res.stats.sampling_ms = phase.millis() - res.stats.proof_ms;
  if (proof) traceProof(*proof, detail::ProofOutcome::kStopped);
  if (!solved) {
    res.stats.validity_checks = oracle.checks();
    res.stats.grid_answers = oracle.gridAnswers();
    const bool stop = termination.reason() == StopReason::kStopRequested;
    return finish(MotionStatus::kTimeout,
                  std::string(stop ? "stop requested" : "the deadline passed") + " before a " + (lazy ? "lazy " : "") +
                      "path was found" +
                      (proof_cells.empty() ? std::string(" (no infeasibility proof for this group)")
                                           : " (infeasibility not proven: " + res.stats.proof_trace + ")"));
  }
  return std::nullopt;
}

og::PathGeometric Planning::rawPath() {
  og::PathGeometric raw = from_roadmap ? *from_roadmap
                          : direct     ? *direct
                                       : *pdef->getSolutionPath()->as<og::PathGeometric>();
  res.stats.raw_path_length = detail::reportedLength(gs, raw);
  return raw;
}

// ---- lazy: roadmap improvement, effort shortcut, blocking report ----

og::PathGeometric Planning::improveLazyPath(const og::PathGeometric& raw) {
  Stopwatch phase;
  detail::EvaluatedPath raw_eval = detail::evaluatePath(oracle, raw, res_check, 0.0);
  const detail::PathCost raw_cost = raw_eval.cost(oracle, spu);
  res.stats.raw_cost_s = raw_cost.cost;
  for (int o : raw_cost.objects) res.stats.raw_blocking.push_back(oracle.movables()[static_cast<std::size_t>(o)].id);
  const og::PathGeometric best = improveByRoadmap(raw, raw_cost);
  res.stats.optimize_ms += phase.millis();
  phase.reset();
  detail::EvaluatedPath ep = detail::evaluatePath(oracle, best, res_check, P.lazy.path_node_spacing * 0.5);
  std::mt19937 rng(P.seed);
  detail::effortShortcut(oracle, ep, P.lazy.shortcut_attempts, res_check, spu, rng, termination);
  res.cost_s = ep.cost(oracle, spu).cost;
  og::PathGeometric final_path = ep.path;
  prependEscapeAndAlign(final_path);
  res.stats.shortcut_ms = phase.millis();
  phase.reset();
  res.blocking = detail::blockingReport(oracle, final_path, P.lazy.contact_resolution, P.lazy.swept_spacing);
  res.stats.analysis_ms = phase.millis();
  return final_path;
}

/// `raw`, or the roadmap's path between its ends when that is cheaper (base group, or a request
/// that gives the objects `raw` crosses a cost).
og::PathGeometric Planning::improveByRoadmap(const og::PathGeometric& raw, const detail::PathCost& raw_cost) {
  og::PathGeometric best = raw;
  const bool improve = req.group == PlanningGroup::kBase || (req.object_cost_scale > 0 && !raw_cost.objects.empty());
  if (roadmap && !from_roadmap && improve) {
    // Lazy KPIECE's path (statically valid) joins the roadmap, which also grows where it is.
    ensureSampled();
    const auto [s, g] = roadmap->addPath(raw, P.lazy.path_node_spacing);
    if (roadmap->nodeCount() < static_cast<std::size_t>(P.lazy.roadmap_max_nodes)) {
      roadmap->addSamples(oracle, gs, P.lazy.roadmap_growth_samples, termination);
    }
    std::vector<int> crossed;
    auto rm = roadmap->search(oracle, si, s, {g}, P.lazy, res_check, spu, termination, res.stats, 0, &crossed);
    if (rm) densify(*rm, s, {g}, crossed);
    if (rm) {
      detail::EvaluatedPath rm_eval = detail::evaluatePath(oracle, *rm, res_check, 0.0);
      if (rm_eval.cost(oracle, spu).cost < raw_cost.cost) best = *rm;
    }
  }
  return best;
}

// ---- full: simplification, swept-arm repair ----

Outcome Planning::refineFullPath(og::PathGeometric& path) {
  Stopwatch phase;
  simplify(path);
  if (auto done = repairSwept(path)) return done;
  prependEscapeAndAlign(path);
  res.stats.shortcut_ms = phase.millis();
  return std::nullopt;
}

void Planning::simplify(og::PathGeometric& path) {
  og::PathSimplifier simplifier(si);
  const Termination simp = termination.tightened(Deadline::in(0.05));
  for (int round = 0; round < 4 && !direct && !simp(); ++round) {
    bool better = simplifier.shortcutPath(path, 0, 0, 0.33, 0.005);
    better |= simplifier.reduceVertices(path);
    if (!better) break;
  }
  simplifier.collapseCloseVertices(path);
}

// The path as the robot sweeps it: segments that touch something between two states checked
// at validity_resolution are planned again at the swept resolution.
Outcome Planning::repairSwept(og::PathGeometric& path) {
  if (!(req.group == PlanningGroup::kArm && P.sampling.arm_swept_step > 0.0 && !sweep_radii.empty())) {
    return std::nullopt;
  }
  auto fine_si = std::make_shared<ob::SpaceInformation>(space);
  fine_si->setStateValidityChecker(si->getStateValidityChecker());
  fine_si->setStateValidityCheckingResolution(si->getStateValidityCheckingResolution());
  fine_si->setMotionValidator(
      std::make_shared<detail::SweptArmMotionValidator>(fine_si, gs, sweep_radii, P.sampling.arm_swept_step));
  fine_si->setup();
  const PlannerKind arm_kind = P.sampling.arm_planner;
  res.stats.swept_repairs = detail::repairSegments(
      fine_si, path, [&](const ob::SpaceInformationPtr& s) { return makePlanner(arm_kind, s, P.sampling.range); },
      termination);
  if (res.stats.swept_repairs < 0) {
    return finish(MotionStatus::kTimeout,
                  "a segment of the path touches an object between two checked states and could not be planned "
                  "again at the swept resolution (arm_swept_step " + formatNumber(P.sampling.arm_swept_step) +
                      " m) in time");
  }
  return std::nullopt;
}

/// The escape from the start prepended; a stop-and-turn base's headings along its drives.
void Planning::prependEscapeAndAlign(og::PathGeometric& path) {
  if (escaped) path.prepend(start.get());
  if (req.group == PlanningGroup::kBase && P.sampling.base_turn_in_place) {
    detail::alignBaseHeadings(si, path);
    detail::explicitBaseTurns(si, path);
  }
}

// ---- finish ----

MotionResult Planning::finishSolved(const og::PathGeometric& path) {
  res.stats.validity_checks = oracle.checks();
  res.stats.grid_answers = oracle.gridAnswers();
  res.path = detail::toJointPath(gs, path);
  res.path_length = detail::reportedLength(gs, path);
  auto traj = timeParameterize(res.path, impl.timingLimits());
  if (!traj) return out.finish(MotionStatus::kInvalidRequest, "time parameterization: " + traj.error().message);
  res.trajectory = std::move(*traj);
  return out.finish(MotionStatus::kSolved, {});
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
