#pragma once
/// @file
/// The motion layer of the conditional TAMP system: lazy paths that report the movable objects in
/// the way, collision-free paths, placements and grasps.
///
/// # Design
///
/// The paper (`spec/conditional-tamp-effort-based.tex`, Sections 3-4) computes, for every edge of
/// the reachability graph, a path with a *lazy* KPIECE against the static world; each movable
/// object that path sweeps through becomes a sub-task of the graph manager ("move o away" or "go
/// around o"). KPIECE (I. A. Sucan and L. E. Kavraki, "Kinodynamic motion planning by
/// interior-exterior cell exploration", WAFR 2008 / Springer 2009) grows a tree guided by a grid
/// on a low-dimensional projection of the state space, preferring exterior cells and little
/// explored ones; its lazy bi-directional variant (OMPL's LBKPIECE1) grows two trees without
/// checking motions and validates the edges of a connecting path only when it is a candidate,
/// removing invalid edges and going on -- the laziness the paper relies on.
///
/// **Lazy mode** (`MotionMode::kLazy`):
///  1. *Lazy KPIECE* (LBKPIECE1 by default) against static geometry only: states and the
///     candidate path's edges are checked against static objects, never against movables.
///  2. *Worth executing*: the raw lazy path crosses whatever movables happen to lie on it (on the
///     NAMO benchmark a median of 3-4, up to 19). The path is improved for the cost
///       J = length / speed + sum over crossed objects o of effort(o)      (seconds)
///     where effort(o) prices moving o (pick + place + transfer, the effort estimator's models;
///     see CostParams). A roadmap of the static free space -- the lazy path's states plus
///     uniform samples, k-nearest-neighbour edges -- is searched with A* under a lower bound of
///     J (length plus the objects touched at the edge's end that were not touched at its start);
///     the edges of each candidate are then evaluated (static validity and the movables touched
///     along them, checked densely), and the search repeats until the best candidate is fully
///     evaluated (LazySP: Dellin & Srinivasa, ICAPS 2016; lazy edge evaluation as in Bohlin &
///     Kavraki's Lazy PRM, ICRA 2000). Effort-aware shortcutting follows: a shortcut is taken
///     when the static check passes and J decreases, so it never adds an object whose effort
///     exceeds the length it saves.
///     *Roadmap cache*: the graph manager asks many motions against one static world while the
///     movables change, so the roadmap is kept in the planner per planning group and static
///     world (static objects, held object and where it is held, the joints the group does not
///     move; see detail::StaticWorldKey) -- movables are costs, not part of it -- and grows across
///     requests: starts and goals become nodes, edges keep their static validity once evaluated.
///     A new roadmap draws `roadmap_samples` uniform and `roadmap_bridge_samples` bridge-test
///     samples and is seeded with lazy KPIECE's path. Later, for the base group, the cached
///     roadmap is searched first; lazy KPIECE runs only when the roadmap cannot connect
///     start and goal within `roadmap_max_evaluations` edge evaluations, and its path (whose
///     edges are valid) is then added to the roadmap with `roadmap_growth_samples` more samples
///     and searched again, so the result never costs more than the lazy KPIECE path. Other
///     groups run lazy KPIECE first and seed the cached roadmap with its path. A changed static
///     world or held object selects another roadmap (LRU, `roadmap_cache_entries`). `prepare()`
///     builds a roadmap ahead of requests (samples and every edge's static validity), so the
///     first request after a static-world change finds it complete (the DDS node calls it after
///     world updates). For the base group the movables touched at nodes and along valid edges
///     are also kept across requests and dropped only near movables that changed. Budgets are
///     counts, so a request's result depends on the seeds and the requests before it, not on
///     the machine's load (a wall-clock safety cap and the request's deadline apply on top).
///  3. *Blocking report*: the final path is checked densely against movables; per object its id,
///     where contact starts and ends (waypoint index and path fraction), the swept states and
///     base poses while in contact, its mass and effort.
///
/// **Full mode** (`MotionMode::kFull`): KPIECE (LBKPIECE1 by default) against everything known,
/// then shortcutting, or a clear `no path`. For the base (and the whole body with a known base
/// goal) a conservative grid over the base's inscribed disc proves `no path` when start and goal
/// lie in different components (ProofParams), interleaved with the planner; otherwise the
/// deadline ends the search with kTimeout.
///
/// Both modes end with a trapezoidal time parameterization (trajectory_timing.h).
///
/// **Groups**: the base (SE(2): base_x, base_y, base_theta) with the arm fixed at the start
/// configuration; the arm (its joints, base fixed); the whole body (SE(2) x arm joints). A held
/// object moves rigidly with the tool link (the base link of a planar robot) and collides like a
/// robot part. Goals: a configuration over the group's joints, a base pose (base and whole
/// body; optionally any yaw), or an end-effector pose reached through IK (arm: from the start
/// base; whole body: from base poses sampled around the target).
///
/// **Scene**: one `collision::Scene` per planner mirrors the world (`setWorld` applies only the
/// diff, so updates between calls are cheap); FCL is reached only through tamp::collision and
/// OMPL only in this library's .cc files. A planner is not thread-safe (scene and roadmap cache
/// are mutated by every call): one per thread, or calls serialised (the DDS node keeps a small
/// pool of planners, each used by one request at a time).
///
/// **Determinism**: call `seedRandomness()` once before the first planner exists (OMPL's global
/// seed); the library's own samplers are seeded from `MotionPlannerParams::seed`.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/collision/scene.h"
#include "tamp/core/error.h"
#include "tamp/core/geometry.h"
#include "tamp/core/termination.h"
#include "tamp/core/trajectory.h"
#include "tamp/motion_planner/grasps.h"
#include "tamp/motion_planner/params.h"
#include "tamp/motion_planner/placement.h"
#include "tamp/robot/robot_model.h"
#include "tamp/world/world.h"

namespace tamp::motion_planner {

enum class PlanningGroup { kBase, kArm, kWholeBody };
enum class MotionMode { kLazy, kFull };

/// What the caller can act on.
enum class MotionStatus {
  kSolved,            ///< a path (lazy: static-free, see `blocking`; full: collision-free)
  kNoPath,            ///< no path exists (proven), or the goal has no IK solution; see `reason`
  kStartInCollision,  ///< the start touches `colliding_object` (full: any object; lazy: static)
  kGoalInCollision,   ///< the goal touches `colliding_object`
  kTimeout,           ///< the deadline passed (or a stop was requested) before a path was found
  kInvalidRequest,    ///< the request is malformed; `reason` names the field
};
std::string_view toString(PlanningGroup group);  ///< "base", "arm", "whole_body"
std::string_view toString(MotionMode mode);      ///< "lazy", "full"
std::string_view toString(MotionStatus status);  ///< "solved", "no_path", ...

struct MotionGoal {
  enum class Kind { kConfiguration, kBasePose, kEndEffectorPose };
  Kind kind{Kind::kConfiguration};
  std::vector<double> configuration;  ///< kConfiguration: one value per `groupJointNames(group)`
  Pose2D base;                        ///< kBasePose
  bool any_base_yaw{false};           ///< kBasePose: the yaw is free (rotation-symmetric robots)
  Eigen::Isometry3d end_effector{Eigen::Isometry3d::Identity()};  ///< kEndEffectorPose: world_T_tool

  static MotionGoal configurationGoal(std::vector<double> q);
  static MotionGoal basePoseGoal(const Pose2D& pose, bool any_yaw = false);
  static MotionGoal endEffectorGoal(const Eigen::Isometry3d& world_T_tool);
};

/// Where a held object sits on the robot: rigidly attached to `link` at `link_T_object`.
struct HeldGrasp {
  std::string link;  ///< a link of the robot's collision geometry; empty: the hold (tool) link
  Eigen::Isometry3d link_T_object{Eigen::Isometry3d::Identity()};
};

struct MotionRequest {
  PlanningGroup group{PlanningGroup::kBase};
  MotionMode mode{MotionMode::kLazy};
  robot::RobotState start;  ///< the full robot state (planar robots: `arm` empty)
  MotionGoal goal;
  /// A movable object held by the gripper (planar robots: carried by the base), or empty. When
  /// the world's `held()` names it, its `link_T_object` is used; otherwise the object keeps its
  /// current pose relative to the link at the start state.
  std::string held_object;
  /// With `held_object`: the grasp to attach it with, overriding the world's held record and
  /// the object's pose (which then does not matter: the object moves with `link`).
  std::optional<HeldGrasp> held_grasp;
  /// With `held_object`: its footprint grown by this much (m) on every side for this request
  /// (not its height: it still rests on its support when put down; a sphere grows whole).
  /// Where the object sits in the hand is known only as well as the grasp went (perception's
  /// estimate of it, where the base and arm really stopped): a caller that saw the held object
  /// touch what the plan cleared asks for margin here. Finite, in [0, 0.25]; 0 = as modelled.
  double held_padding_m{0.0};
  std::vector<std::string> ignored_objects;  ///< treated as absent (e.g. the object to pick)
  /// The request is planned in the planner's world with these objects moved or removed (e.g.
  /// after a sampled placement of a blocking object); the world is restored afterwards. Each id
  /// at most once, not the held object when removed. Overriding movables keeps the cached
  /// roadmap of the static world (movables are costs, see "Roadmap cache"); overriding a static
  /// object selects (and may build) the roadmap of another static world.
  std::vector<ObjectOverride> object_overrides;
  /// Objects added to the planner's world for this request, before the overrides (a lazy path
  /// reports an added movable it crosses; a full path goes round it).
  AddedObjects added_objects;
  /// Lazy mode: multiplier on every object's effort in the path cost. 1 (default): the effort
  /// model as it is; 0: ignore objects (the shortest static-free path); larger values avoid
  /// objects at the price of longer detours. Must be finite and >= 0.
  double object_cost_scale{1.0};
  /// Lazy mode: movables the caller cannot move (over the payload, no push), obstacles like the
  /// static objects for this request: the lazy path goes round them, or there is none (`no
  /// path`). Selects (and may build) the roadmap of that static world, as overriding a static
  /// object does. Each must be a movable of the world; ignored in full mode (every object is
  /// an obstacle there).
  std::vector<std::string> fixed_objects;
  /// Full mode, base group: only the direct motion from the start to the goal counts (a push, a
  /// back-off): kSolved when it is free (the base clearance is not asked of it), kNoPath at
  /// once when it is not; nothing is sampled. Invalid in lazy mode or for an arm group.
  bool straight_only{false};
};

/// A movable object a lazy path sweeps through.
struct BlockingObject {
  std::string object_id;
  double enter_fraction{0.0};       ///< path parameter in [0, 1] (space metric) where contact starts
  double exit_fraction{0.0};        ///< and where the last contact ends
  std::size_t enter_waypoint{0};    ///< index of the waypoint that starts the segment of first contact
  std::size_t exit_waypoint{0};     ///< index of the waypoint that ends the segment of last contact
  std::vector<std::pair<double, double>> intervals;  ///< every contact interval (fractions)
  std::vector<Pose2D> swept_base;   ///< base poses while in contact (every `swept_spacing`)
  std::vector<std::vector<double>> swept_configurations;  ///< group configurations, same samples
  double mass{0.0};                 ///< kg
  double effort_s{0.0};             ///< effort of moving it (CostParams), before object_cost_scale
};

/// Diagnostics of one call (milliseconds, counts).
struct PlanningStats {
  double sampling_ms{0.0};      ///< lazy KPIECE (or the full-mode planner)
  int sampling_slices{0};       ///< time slices the sampling planner ran (0: answered without it)
  double optimize_ms{0.0};      ///< roadmap build/growth and search (lazy)
  double shortcut_ms{0.0};
  double analysis_ms{0.0};      ///< blocking report
  double proof_ms{0.0};         ///< the infeasibility grid (both modes)
  /// Cells the proof tested (its disc asked of FCL or the clearance grid), and of those the ones
  /// the static clearance grid cleared of statics (FCL asked of the movables only).
  std::uint64_t proof_cells{0};
  std::uint64_t proof_grid_answers{0};
  /// Per proof level reached: "<cell> m[ x <yaw cells>]: <outcome> (<cells>)", comma-separated.
  std::string proof_trace;
  double goal_ms{0.0};          ///< goal states: IK for an end-effector goal, validity of the goal
  std::uint64_t validity_checks{0};
  /// Of those, static checks the clearance grid answered without FCL (clearance_grid_resolution).
  std::uint64_t grid_answers{0};
  /// Full-mode arm paths: segments planned again because they touched something between two
  /// checked states at the swept resolution (SamplingParams::arm_swept_step).
  int swept_repairs{0};
  /// Full-mode base paths: no path kept SamplingParams::base_clearance in time, so the path
  /// found may pass closer to objects.
  bool clearance_relaxed{false};
  std::size_t roadmap_nodes{0};
  std::size_t roadmap_edges{0};
  std::size_t roadmap_pruned{0};  ///< request nodes removed from the roadmap before this search
  std::size_t edges_evaluated{0};
  int search_iterations{0};
  /// Lazy mode: the path source's path before optimization -- lazy KPIECE's raw path, or the
  /// cached roadmap's path when the roadmap answered the request (`lazy_planner_used` false).
  double raw_path_length{0.0};  ///< the planner's raw path (lazy: before optimization)
  std::vector<std::string> raw_blocking;  ///< movables the raw lazy path crosses
  double raw_cost_s{0.0};       ///< J of the raw lazy path
  bool optimize_completed{false};  ///< the roadmap search finished before its budget
  bool roadmap_reused{false};   ///< lazy: the cached roadmap of this static world was reused
  /// lazy: this static world's roadmap was new, made from a cached one of the same world with
  /// fewer obstacles (the request's fixed objects made static): roadmap_reused is set too.
  bool roadmap_derived{false};
  bool lazy_planner_used{false};  ///< lazy: lazy KPIECE ran (roadmap_first off, or the roadmap could not connect)
  bool direct{false};           ///< full mode: the direct motion to a goal state was free (no sampling)
};

struct MotionResult {
  MotionStatus status{MotionStatus::kInvalidRequest};
  std::string reason;            ///< why, when not solved (names the field or object)
  std::string colliding_object;  ///< for kStartInCollision / kGoalInCollision ("self:a/b" for self-collision)
  JointPath path;                ///< over `groupJointNames(group)`; yaw unwrapped
  Trajectory trajectory;         ///< trapezoidal time parameterization of `path`
  std::vector<BlockingObject> blocking;  ///< lazy mode: movables on the path, by first contact
  double path_length{0.0};       ///< base: xy length (m); arm: joint-space length (rad); whole body: space metric
  double cost_s{0.0};            ///< J of the returned path (lazy mode), seconds
  double planning_time_s{0.0};
  /// Full mode: the movables the start touched, which the path leaves first by a straight
  /// motion (SamplingParams::start_escape_distance); empty when the start touched nothing.
  std::vector<std::string> start_contacts;
  PlanningStats stats;
  bool ok() const { return status == MotionStatus::kSolved; }
};

/// What MotionPlanner::prepare() did.
struct PrepareStats {
  bool built{false};                ///< a new roadmap was created (false: the cached one was completed)
  std::size_t roadmap_nodes{0};
  std::size_t roadmap_edges{0};
  std::size_t edges_evaluated{0};   ///< edges whose static validity this call evaluated
  std::size_t edges_invalid{0};     ///< of those, statically invalid
  bool completed{false};            ///< every edge's static validity is known (false: `termination` fired)
  double time_ms{0.0};
};

/// Seeds OMPL's global random number generator. Call once, before any planner exists; later
/// calls are ignored (OMPL cannot re-seed deterministically). Returns false when ignored.
bool seedRandomness(std::uint32_t seed);

/// Prices moving an object out of the way, in seconds (see CostParams). Replaceable so that the
/// graph manager can use the effort estimator's refitted models.
using ObjectEffortFn = std::function<double(const world::Object&)>;

/// The default effort model: pick + place + transfer with the effort estimator's default time
/// models (tamp::effort_model::modelSpec defaults) and `params`.
double defaultObjectEffort(const world::Object& object, const CostParams& params);

/// The parameter values of one action kind's time model (e.g. the effort estimator's fit), by
/// name (physical units, tamp::effort_model::modelSpec names); names not given keep their
/// default.
struct TimeModelValues {
  ActionKind kind{ActionKind::kPick};
  std::vector<std::string> names;
  std::vector<double> values;  ///< one per name, finite and > 0
};

/// The effort model of defaultObjectEffort with the pick, place and move_base (transfer) time
/// models of `models` (kinds not given, and other kinds, keep the defaults). Errors
/// (kInvalidArgument): a name unknown to the kind's model, sizes that differ, a value that is
/// not finite and positive -- each naming `models[i]` and the parameter.
Result<ObjectEffortFn> fittedObjectEffort(const CostParams& params, const std::vector<TimeModelValues>& models);

class MotionPlanner {
 public:
  /// A mobile manipulator: every group. Throws std::invalid_argument when `params` is invalid.
  MotionPlanner(robot::RobotModel model, MotionPlannerParams params = {});
  /// A planar robot (NAMO disc or box): base group only; `geometry` must have links, with link 0
  /// the base. Throws std::invalid_argument when `params` or `geometry` is invalid.
  MotionPlanner(collision::RobotGeometry planar_geometry, MotionPlannerParams params = {});
  ~MotionPlanner();
  MotionPlanner(MotionPlanner&&) noexcept;
  MotionPlanner& operator=(MotionPlanner&&) noexcept;
  MotionPlanner(const MotionPlanner&) = delete;
  MotionPlanner& operator=(const MotionPlanner&) = delete;

  /// Brings the scene to `world`'s planner view (hidden objects dropped): the first call builds
  /// it, later calls apply the diff.
  void setWorld(const world::World& world);
  const world::World& world() const;
  /// Replaces the object effort model (default: defaultObjectEffort with params().cost).
  void setObjectEffort(ObjectEffortFn fn);

  const MotionPlannerParams& params() const;
  bool hasArm() const;
  const robot::RobotModel* robotModel() const;  ///< nullptr for planar robots
  /// Joint names of a group's configurations and paths (base: base_x, base_y, base_theta).
  std::vector<std::string> groupJointNames(PlanningGroup group) const;
  /// Radius of the robot's footprint (base) around the base origin, m.
  double footprintRadius() const;

  /// Drops every cached roadmap (the next lazy request builds its roadmap from scratch).
  void clearRoadmapCache();
  /// Number of cached roadmaps.
  std::size_t roadmapCacheSize() const;
  /// Builds the cached roadmap of `group` for the current static world ahead of requests (e.g.
  /// right after a world update): its uniform and bridge-test samples and the static validity of
  /// every edge, so that a later lazy request whose fixed joints (`state`: base group: arm and
  /// gripper; arm group: base pose and gripper) and held object match (`held_object`, or the
  /// world's held object when empty) searches a complete roadmap instead of paying the build
  /// (and lazy KPIECE) itself. Cheap when the roadmap exists and is complete (only edges added
  /// by later requests are evaluated). `termination` may stop it early: what was done is kept.
  /// Errors: kInvalidArgument (a group the robot lacks, a wrong arm size, an unknown held object).
  Result<PrepareStats> prepare(PlanningGroup group, const robot::RobotState& state,
                               const std::string& held_object = {}, const Termination& termination = {});

  /// Plans one motion. Never throws for bad input: a malformed request gives kInvalidRequest
  /// naming the field. Checks `termination` throughout.
  MotionResult plan(const MotionRequest& request, const Termination& termination = {});

  /// Stable, collision-free, reachable placements (placement.h), best (shortest transfer) first.
  /// Errors: kNotFound (object, region), kInvalidArgument (a static object, a bad field),
  /// kTimeout when `termination` fired before any placement was found. Fewer than requested (or
  /// none) is not an error.
  Result<std::vector<Placement>> samplePlacements(const PlacementRequest& request,
                                                  const Termination& termination = {});

  /// Grasps of a box or cylinder (grasps.h), top grasps first. Errors: kNotFound (object),
  /// kInvalidArgument (bad field, not graspable), kUnsupported (shape, planar robot), kTimeout.
  Result<std::vector<Grasp>> generateGrasps(const GraspRequest& request,
                                            const Termination& termination = {});

  struct Impl;  ///< opaque: private to the library's .cc files

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace tamp::motion_planner
