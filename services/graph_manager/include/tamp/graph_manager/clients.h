#pragma once
/// @file
/// What the graph manager asks of the other services, as plain value types (no DDS, no other
/// service's headers): task plans `TP(v, s)`, lazy and full motions in hypothetical worlds,
/// placements (`findEffectStates`), grasps, effort estimates, and the execution of one edge.
///
/// The DDS node implements `ServiceClients` and `Executor` over request/reply and topics; tests
/// and embedded uses can implement them in-process over the same service libraries. Every call
/// takes a budget and returns its failure as a value.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/error.h"
#include "tamp/core/geometry.h"
#include "tamp/core/trajectory.h"
#include "tamp/graph_manager/oracle.h"
#include "tamp/robot/robot_model.h"

namespace tamp::graph_manager {

// ---- task planning -------------------------------------------------------------------------------

struct TaskQuery {
  std::string domain_pddl;              ///< the domain text
  std::vector<std::string> objects;     ///< "name - type"
  std::vector<std::string> init;        ///< ground atoms, static and dynamic
  std::vector<std::string> goal;        ///< ground literals (conjunction)
  double budget_s{5.0};
};

enum class TaskStatus { kSolved, kUnsolvable, kFailed, kTimeout, kInputError, kUnavailable };
std::string_view toString(TaskStatus s);

struct TaskPlan {
  TaskStatus status{TaskStatus::kFailed};
  std::vector<std::string> actions;               ///< "(move_base start goal)"
  std::vector<std::vector<std::string>> states;   ///< dynamic atoms: states[0] init, states[i+1] after actions[i]
  std::string message;
  double time_s{0.0};
};

// ---- motion ----------------------------------------------------------------------------------------

enum class Group { kBase, kArm };
enum class Mode { kLazy, kFull };

struct ObjectOverride {
  std::string object_id;
  bool removed{false};
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};
};

struct HeldGrasp {
  std::string object_id;  ///< empty: nothing held
  std::string link;
  Eigen::Isometry3d link_T_object{Eigen::Isometry3d::Identity()};
};

struct MotionQuery {
  Group group{Group::kBase};
  Mode mode{Mode::kLazy};
  robot::RobotState start;
  Pose2D goal_base;                   ///< kBase
  std::vector<double> goal_arm;       ///< kArm
  HeldGrasp held;
  std::vector<std::string> ignored;   ///< treated as absent
  std::vector<ObjectOverride> overrides;
  /// Objects the services' world model lacks, in the world of this question (applied before the
  /// overrides): the oracle's hidden objects perception has not found; set by the graph manager.
  std::vector<world::Object> added;
  double movable_cost_weight{0.0};    ///< lazy: 0 = the pure static-only lazy path
  /// Lazy: movables the robot cannot move (over the payload, no push): obstacles for this path.
  std::vector<std::string> fixed;
  /// Full base motions: only the straight motion from start to goal counts (pushes, back-offs).
  bool straight_only{false};
  double held_padding_m{0.0};         ///< the held object grown by this much (m); set by the graph manager
  /// The world model version the question is asked in (0: the server's latest). A server whose
  /// mirror lags waits for it within the budget, or answers kUnavailable; set by the graph manager.
  std::uint64_t world_version{0};
  double budget_s{5.0};
};

enum class MotionOutcome { kSolved, kNoPath, kStartInCollision, kGoalInCollision, kTimeout, kInvalid, kUnavailable };
std::string_view toString(MotionOutcome s);

struct Crossing {
  std::string object_id;
  double enter_fraction{0.0};
  double exit_fraction{0.0};
  std::vector<Pose2D> swept_base;
  double mass{0.0};
  double effort_s{0.0};
};

struct MotionAnswer {
  MotionOutcome status{MotionOutcome::kInvalid};
  std::string reason;
  JointPath path;
  Trajectory trajectory;
  std::vector<Crossing> blocking;   ///< lazy mode: movables the path crosses
  double path_length{0.0};
  double time_s{0.0};
  std::uint64_t world_version{0};
  bool ok() const { return status == MotionOutcome::kSolved; }
};

// ---- placements and grasps --------------------------------------------------------------------------

struct PlacementQuery {
  std::string object_id;
  std::string region_id;
  std::vector<Pose2D> keep_clear_path;
  double keep_clear_radius{0.0};
  unsigned max_placements{4};
  double budget_s{3.0};
  std::optional<Pose2D> base;                      ///< place from here (none: base poses are sampled)
  std::optional<Eigen::Isometry3d> object_T_tool;  ///< with base: the grasp the object is held with
  double approach_m{0.0};                          ///< pre-place height above the place pose
  std::vector<ObjectOverride> overrides;           ///< the branch's hypothetical world
  std::vector<world::Object> added;                ///< as MotionQuery::added
  std::uint64_t world_version{0};                  ///< answered in this world model version or later (0: any)
};

struct PlacementOption {
  Eigen::Isometry3d object_pose{Eigen::Isometry3d::Identity()};
  Pose2D base_pose;
  std::vector<double> arm;      ///< at the place pose (top grasp when not held)
  std::vector<double> pre_arm;  ///< with a held grasp: at the pre-place pose, collision-free
  double clearance{0.0};
};

struct GraspQuery {
  std::string object_id;
  std::optional<Pose2D> base;  ///< none: the service samples base poses
  unsigned max_grasps{4};
  double budget_s{3.0};
  std::vector<ObjectOverride> overrides;  ///< the branch's hypothetical world
  std::vector<world::Object> added;       ///< as MotionQuery::added
  std::uint64_t world_version{0};         ///< answered in this world model version or later (0: any)
};

struct GraspOption {
  Eigen::Isometry3d gripper_in_object{Eigen::Isometry3d::Identity()};
  Pose2D base_pose;
  std::vector<double> pregrasp;
  std::vector<double> grasp;
  bool top{true};
};

// ---- effort ------------------------------------------------------------------------------------------

struct EffortQuery {
  ActionKind kind{ActionKind::kMoveBase};
  JointPath path;           ///< move_base, move_arm
  double object_mass{0.0};  ///< kg
  double approach_m{0.0};   ///< pick/place
  double retreat_m{0.0};
};

struct EffortAnswer {
  bool ok{false};
  double mean_s{0.0};
  double stddev_s{0.0};
  std::string message;
};

/// The services the graph manager calls. Implementations must be safe to call from one thread at
/// a time; each call honours its budget and returns failures as values.
class ServiceClients {
 public:
  virtual ~ServiceClients() = default;
  virtual TaskPlan plan(const TaskQuery& q) = 0;
  virtual MotionAnswer motion(const MotionQuery& q) = 0;
  /// Independent motion queries at once, answered in their order. This one asks them one after
  /// the other; clients of a planner that serves requests concurrently (the motion node's pool)
  /// send them all before waiting, so the batch takes about as long as its slowest query.
  virtual std::vector<MotionAnswer> motions(const std::vector<MotionQuery>& qs);
  virtual Result<std::vector<PlacementOption>> placements(const PlacementQuery& q) = 0;
  virtual Result<std::vector<GraspOption>> grasps(const GraspQuery& q) = 0;
  virtual std::vector<EffortAnswer> effort(const std::vector<EffortQuery>& q) = 0;
  /// The effort estimator's model version (+1 per refit of any kind), or nullopt when these
  /// clients cannot tell (or the estimator does not answer). The graph manager compares it
  /// across an action to see the refit that the action's record caused.
  virtual std::optional<std::uint64_t> effortModelVersion() { return std::nullopt; }
  /// Policy `oracle` only: what the simulator knows (hidden objects, scripted faults, how many
  /// commands it accepted). An error when no oracle is served (a normal deployment).
  virtual Result<OracleKnowledge> oracle() {
    return Error(ErrorCode::kUnavailable, "no oracle: these clients do not reach the simulator's truth");
  }
};

// ---- execution ----------------------------------------------------------------------------------------

/// One chosen edge, ready for the robot.
struct EdgeCommand {
  std::string command_id;
  std::string edge_id;
  std::string action;   ///< ground PDDL action
  ActionKind kind{ActionKind::kMoveBase};
  Trajectory trajectory;
  std::string object_id;
  std::string region_id;
  std::optional<Eigen::Isometry3d> object_target;
  double expected_s{0.0};
  double expected_stddev_s{0.0};
  std::uint64_t world_version{0};
};

enum class ExecOutcome { kSucceeded, kFailed, kBlocked, kCancelled, kTimeout, kUnavailable };
std::string_view toString(ExecOutcome o);

struct ExecutionReport {
  ExecOutcome outcome{ExecOutcome::kFailed};
  double measured_s{0.0};
  std::string reason;
  std::string blocking_object_id;
  std::string held_object_id;
  /// kBlocked: the robot itself stopped before contact with `blocking_object_id` (evidence of
  /// where it is), not the monitor on a predicted collision.
  bool stopped_at_contact{false};
};

/// Executes one edge on the robot (through the execution monitor) and blocks until it ends.
class Executor {
 public:
  virtual ~Executor() = default;
  virtual ExecutionReport execute(const EdgeCommand& command, double budget_s) = 0;
  /// The outcome of a command sent earlier (by a graph manager that then crashed), without
  /// sending it again; blocks up to `budget_s`. kTimeout when none came (the command never
  /// reached the robot, or is still running); kUnavailable when this executor cannot tell.
  virtual ExecutionReport await(const std::string& command_id, double budget_s) {
    (void)budget_s;
    ExecutionReport r;
    r.outcome = ExecOutcome::kUnavailable;
    r.reason = "this executor cannot await '" + command_id + "'";
    return r;
  }
};

/// The robot and world as the graph manager last saw them.
struct Observation {
  robot::RobotState robot;
  std::string held_object_id;
  bool valid{false};
  bool moving{false};  ///< the robot reports itself in motion (a state taken while it still moved)
};

}  // namespace tamp::graph_manager
