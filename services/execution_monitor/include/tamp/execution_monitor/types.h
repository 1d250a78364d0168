#pragma once
/// @file
/// The execution monitor's value types: the command it executes, what it observes of the robot,
/// and what it reports. They map field by field to the IDL messages of idl/execution.idl
/// (ExecuteCommand, RobotState, ActionResult, ExecuteStatus, FailureEvent), which only the node
/// sees.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/geometry.h"
#include "tamp/core/trajectory.h"
#include "tamp/robot/robot_model.h"

namespace tamp::execution_monitor {

/// One action of the plan to execute (the graph manager's ExecuteCommand).
struct ExecutionCommand {
  std::string command_id;  ///< non-empty; the monitor executes an id at most once
  std::string mission_id;
  std::string edge_id;
  std::string pddl_action;  ///< "(pick can table over_table)", for messages
  ActionKind kind{ActionKind::kMoveBase};
  /// move_base: over exactly base_x, base_y, base_theta (world frame, m / rad, theta unwrapped);
  /// move_arm / pick / place: over arm joints (and optionally the gripper joint). The first point
  /// must match the robot's state when the action starts.
  Trajectory trajectory;
  std::string object_id;  ///< pick / place: the object
  std::string region_id;
  /// place: where the object goes (required); pick: where it is believed to be (optional).
  std::optional<Eigen::Isometry3d> object_target;
  double expected_duration_s{0.0};  ///< the predicted duration (s, >= 0; 0 = unknown)
  double expected_stddev_s{0.0};    ///< its standard deviation (s, >= 0)
  std::uint64_t world_version{0};   ///< world model version the command was planned in
  bool cancel{false};               ///< true: cancel the command with this id
};

/// A sample of the robot's state stream.
struct RobotObservation {
  robot::RobotState state;
  std::string held_object_id;  ///< "" = gripper empty
  bool moving{false};
  /// When the robot wrote the sample (ns, the robot's clock; comparable with
  /// `RobotResult::stamp_ns` of the same robot).
  std::int64_t stamp_ns{0};
};

enum class RobotOutcome { kSucceeded, kBlocked, kFailed, kCancelled };

/// The robot's result of a trajectory command.
struct RobotResult {
  std::string command_id;
  RobotOutcome outcome{RobotOutcome::kFailed};
  double duration_s{0.0};  ///< measured duration (s)
  double progress{0.0};    ///< [0, 1]
  std::string blocking_object_id;
  std::string reason;
  std::int64_t stamp_ns{0};  ///< when the robot wrote it (ns, the robot's clock)
};

enum class ExecState { kAccepted, kRunning, kSucceeded, kFailed, kBlocked, kCancelled };
std::string_view toString(ExecState s);  ///< "accepted", "running", "succeeded", ...
/// kSucceeded, kFailed, kBlocked, kCancelled.
bool isFinal(ExecState s);

/// What the monitor reports about a command (ExecuteStatus).
struct StatusUpdate {
  std::string command_id;
  ExecState state{ExecState::kAccepted};
  double progress{0.0};             ///< [0, 1]: fraction of the trajectory's path done
  double elapsed_s{0.0};            ///< since the robot was commanded (monitor clock)
  std::string reason;               ///< empty on success; otherwise why, naming what failed
  std::string blocking_object_id;   ///< kBlocked (and path preconditions): the object in the way
  double measured_duration_s{0.0};  ///< final states: the robot's measured duration (0: not run)
  std::string held_object_id;       ///< final states: held afterwards ("" = empty)
  /// kBlocked: the robot itself stopped before contact with `blocking_object_id`, not the
  /// monitor on a predicted collision.
  bool stopped_at_contact{false};
};

enum class FailureType {
  kBlocked,
  kObjectDropped,
  kActionFailed,
  kNewObstacle,
  kTimeout,
  kPrecondition
};
std::string_view toString(FailureType t);  ///< "blocked", "object_dropped", ...

/// An unexpected event during execution (FailureEvent).
struct FailureReport {
  std::string command_id;
  FailureType type{FailureType::kActionFailed};
  std::string object_id;  ///< the object concerned (blocking, dropped, ...), or ""
  Pose2D robot_base;      ///< the robot's base when it was detected
  std::string description;
};

/// A request to the robot: execute a command or cancel it (TrajectoryCommand).
struct RobotRequest {
  enum class Type { kExecute, kCancel } type{Type::kExecute};
  ExecutionCommand command;  ///< kCancel: only command_id is meaningful
};

/// What the node must publish after an event, in order.
struct Outputs {
  std::vector<StatusUpdate> statuses;
  std::vector<FailureReport> failures;
  std::vector<RobotRequest> robot;

  bool empty() const { return statuses.empty() && failures.empty() && robot.empty(); }
  void append(Outputs other);
};

}  // namespace tamp::execution_monitor
