#pragma once
/// @file
/// Parameters of the execution monitor, loaded from YAML (config/services/execution_monitor.yaml;
/// every key optional, unknown keys refused):
///
///   robot_description: ""        # robot description YAML ("" = the scenario's, else the default)
///   world_id: world              # the world model instance mirrored (tamp/world/*)
///   start_tolerance: {position_m: 0.05, angle_rad: 0.05}  # trajectory start vs robot state
///   path_check: {step_m: 0.02, step_rad: 0.02, tolerance_m: 0.005, start_contact_m: 0.01}  # see PathCheckParams
///   object_tolerance_m: 0.15     # pick: world-model object vs commanded object_target
///   moved_tolerance_m: 0.05      # while running: a known object counts as new when it moved more
///   timeout: {stddevs: 3.0, margin_s: 5.0, stall_s: 5.0, max_factor: 3.0}  # overrun: see TimeoutParams
///   input_wait_s: 2.0            # before a start: wait this long for a robot state / world
///   version result_wait_s: 10.0          # after a cancel: wait this long for the robot's result
///   state_wait_s: 2.0            # after a result: wait this long for a robot state written later
///   status_period_s: 0.2         # EXEC_RUNNING progress updates
///   forward_unmatched_records: true  # forward robot records of commands the monitor did not send
///
/// Units: metres, radians, seconds.

#include <filesystem>
#include <string>

#include "tamp/core/error.h"

namespace tamp::execution_monitor {

/// How far the trajectory's first point may be from the robot's current state.
struct StartTolerance {
  double position_m{0.05};  ///< > 0: base position and prismatic joints (m)
  double angle_rad{0.05};   ///< > 0: base heading and revolute joints (rad)
};

/// Resolution of the swept collision check of a trajectory: between two checked states no
/// base point moves more than `step_m` by translation and no angle (base heading, arm joint)
/// changes by more than `step_rad`.
struct PathCheckParams {
  double step_m{0.02};    ///< in (0, 1] m
  double step_rad{0.02};  ///< in (0, 1] rad
  /// m, in [0, 0.05]: the robot's shapes are checked this much smaller (each side). The monitor
  /// catches what the plan did not know (a new obstacle, a moved object), not the planner's own
  /// millimetres: its checks sample the same motion differently, and a location a few cm from a
  /// table otherwise fails a path the planner proved free by 2 mm at the final turn.
  double tolerance_m{0.005};
  /// m, in [0, 0.05]: at the start of an action, objects this near the (shrunk) robot count as
  /// touching it, and the path may leave them. The planner's robot is not shrunk and it starts
  /// from where the plan put things (an object it has just put down, at its planned placement):
  /// what the planner found touching and left by its start escape is within `tolerance_m` of the
  /// shrunk robot, plus the few mm between the planned placement and what perception sees.
  double start_contact_m{0.01};
};

/// An action overruns when its elapsed time exceeds
/// expected_duration_s + stddevs * expected_stddev_s + margin_s.
/// An action is stopped as overrun once it is past expected + stddevs * stddev + margin_s AND
/// either has made no progress along its path for `stall_s` or is past `max_factor` times that
/// limit. A robot that is slower than predicted but moving (a loaded turn in place the default
/// time model prices at a fifth of its duration) is let finish: cancelling it half-way and
/// sending it again only makes it slower. The graph manager's own overrun event (its
/// `overrun_sigma`) is unaffected.
struct TimeoutParams {
  double stddevs{3.0};     ///< >= 0
  double margin_s{5.0};    ///< > 0 (s)
  double stall_s{5.0};     ///< > 0 (s): no progress for this long past the limit is an overrun
  double max_factor{3.0};  ///< >= 1: past this many times the limit, overrun even while moving
};

struct MonitorParams {
  std::string robot_description;  ///< robot description YAML; "" = the scenario's or the default
  std::string world_id{"world"};  ///< world model instance (WorldMirror)
  StartTolerance start_tolerance;
  PathCheckParams path_check;
  double object_tolerance_m{0.15};  ///< > 0: pick target vs the world model's object position (m), as the graph manager's moved_object_tolerance_m
  /// > 0: while an action runs, only objects perceived since its start, or moved by more than
  /// this since then (m), are checked against the remaining path (perception noise on known
  /// objects does not stop the robot; they were checked at the start).
  double moved_tolerance_m{0.05};
  TimeoutParams timeout;
  double input_wait_s{2.0};     ///< >= 0: wait for a robot state / the command's world version (s)
  double result_wait_s{10.0};   ///< > 0: wait for the robot's result after a cancel (s)
  double state_wait_s{2.0};     ///< > 0: wait for a robot state written after the result (s)
  double status_period_s{0.2};  ///< > 0: EXEC_RUNNING updates (s)
  bool forward_unmatched_records{true};

  /// Ok, or one kInvalidArgument error naming every bad field.
  Status validate() const;
};

/// Loads parameters from a YAML file; errors name file, line, column and field; unknown keys are
/// refused; a relative `robot_description` is resolved against the file's directory.
Result<MonitorParams> loadMonitorParams(const std::filesystem::path& file);
/// Same from text; `name` is used as the file name in messages.
Result<MonitorParams> parseMonitorParams(const std::string& yaml_text, const std::string& name);

}  // namespace tamp::execution_monitor
