// One MotionPlanner::plan() call (internal): the request's world, the Planning phases, and what
// they share. motion_planner.cc validates the request, puts its world in place and runs the
// phases; planning.cc sets up the spaces, leaves the start and sets the goal; planning_search.cc
// searches (roadmap, direct motion, sampler with the `no path` proof) and refines the path.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <ompl/base/Planner.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/geometric/PathGeometric.h>

#include "planner_impl.h"
#include "tamp/core/termination.h"

namespace tamp::motion_planner {

namespace ob = ompl::base;
namespace og = ompl::geometric;

/// The robot's parts grown sideways by `d` (m).
collision::RobotGeometry grownGeometry(collision::RobotGeometry geometry, double d);

/// The cache key of the static free space of `group` (see detail::StaticWorldKey).
detail::StaticWorldKey staticWorldKey(const MotionPlanner::Impl& impl, PlanningGroup group,
                                      const robot::RobotState& start, const std::string& held,
                                      const std::string& held_link, const Eigen::Isometry3d& link_T_held,
                                      const std::vector<std::string>& ignored);

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
  void escapeStaticsShallowly();
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

}  // namespace tamp::motion_planner
