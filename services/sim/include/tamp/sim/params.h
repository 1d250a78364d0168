#pragma once
/// @file
/// Parameters of the simulator: the robot's TRUE execution dynamics (what the effort
/// estimator has to discover), execution noise, pacing, the resolution of the swept collision
/// check, the physical tolerances of grasping and placing, and the depth sensor. Loaded from YAML
/// (config/services/sim.yaml; every key optional, unknown keys refused):
///
///   scenario: ""                 # scenario file the node loads (relative: to this file)
///   realtime_factor: 1.0         # simulated seconds per wall-clock second; 0 = as fast as possible
///   state_period_s: 0.05         # simulated time between robot-state samples
///   cloud_period_s: 0.5          # simulated time between point clouds; 0 = only after actions
///   checkpoint_period_s: 0.2     # simulated time between checkpoints while an action runs (node)
///   checkpoint_idle_period_s: 1.0  # the same while idle (the clock goes on)
///   duration_noise: 0.03         # stddev of log(duration) of an action (log-normal, median 1)
///   seed: 1                      # execution-noise seed (the sensor has its own)
///   max_step_m: 0.01             # swept check: largest displacement of any robot point between checks
///   start_tolerance: {position_m: 0.05, angle_rad: 0.05}   # command start vs robot state
///   grasp: {position_tolerance_m: 0.03, tcp_tolerance_m: 0.02, max_payload_kg: 5.0}
///   place: {position_tolerance_m: 0.03, angle_tolerance_rad: 0.1, max_drop_m: 0.05,
///           max_tilt_rad: 0.1}
///   dynamics:                    # the true robot (DynamicsParams, dynamics.h)
///     base: {linear_speed: 0.45, linear_accel: 0.35, linear_jerk: 0.8, angular_speed: 1.1, ...}
///     arm: {speed_fraction: 0.55, max_speed: 2.0, accel: 1.8, jerk: 6.0, corner_threshold_rad: 0.05, ...}
///     hand: {approach_speed: 0.05, approach_accel: 0.1, approach_jerk: 0.5, close_s: 1.9, open_s: 1.1}
///     load: {per_kg: 0.12}
///     stall: {probability: 0.08, min_s: 0.3, max_s: 1.5}
///   sensor: {width: 320, height: 240, ...}                 # DepthSensorParams
///
/// Units: metres, radians, seconds, kilograms.

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/trajectory.h"
#include "tamp/sim/depth_sensor.h"
#include "tamp/sim/dynamics.h"

namespace tamp::sim {

struct StartTolerance {
  double position_m{0.05};  ///< base position and prismatic joints
  double angle_rad{0.05};   ///< base heading and revolute joints
};

/// Physical checks of a pick, at the waypoint where the gripper closes.
struct GraspParams {
  /// The object's true position may differ from the commanded one by at most this (m).
  double position_tolerance_m{0.03};
  /// The tool centre point must lie within the object's bounding box (object frame) grown by
  /// this (m).
  double tcp_tolerance_m{0.02};
  double max_payload_kg{5.0};  ///< heavier objects slip out
};

/// Physical checks of a place, at the waypoint where the gripper opens.
struct PlaceParams {
  double position_tolerance_m{0.03};  ///< released vs commanded position (m)
  double angle_tolerance_rad{0.1};    ///< released vs commanded orientation (rad)
  double max_drop_m{0.05};            ///< release height above the support (m); higher = dropped
  double max_tilt_rad{0.1};           ///< the object's z axis vs vertical; more = topples
};

/// A push: a move_base command naming an object. The base must touch it within
/// `max_contact_gap_m` straight ahead; the object then rides ahead of the base, and where it is
/// released it slips: sideways by a normal error of `lateral_slip` x the distance pushed (m/m)
/// and turns by one of `yaw_slip_rad_per_m` x that distance (the planner does not know either).
struct PushParams {
  double max_contact_gap_m{0.10};
  double lateral_slip{0.02};
  double yaw_slip_rad_per_m{0.02};
};

struct SimParams {
  std::string scenario;            ///< scenario file (node only); resolved against the YAML file
  double realtime_factor{1.0};     ///< >= 0; 0 = as fast as possible
  double state_period_s{0.05};     ///< > 0
  double cloud_period_s{0.5};      ///< >= 0; 0 = clouds only after actions (and on demand)
  /// In (0, 10]: simulated time between checkpoints of the physical state while an action runs
  /// (node only, with $TAMP_RUN_DIR; every action's start and end and every fault write one too).
  /// A restarted simulator resumes the robot where the last checkpoint had it.
  double checkpoint_period_s{0.2};
  /// In (0, 60]: the same while no action runs (the state does not change then, but the clock
  /// does: a resumed simulator's stamps go on from the last checkpoint's time, and a reader drops
  /// frames stamped before the killed process's last ones).
  double checkpoint_idle_period_s{1.0};
  double duration_noise{0.03};     ///< in [0, 1]: stddev of log(duration); 0 = exact model time
  std::uint64_t seed{1};
  double max_step_m{0.01};         ///< in (0, 0.5]
  StartTolerance start_tolerance;
  GraspParams grasp;
  PlaceParams place;
  PushParams push;
  DynamicsParams dynamics;         ///< the true robot's execution dynamics (dynamics.h)
  DepthSensorParams sensor;

  /// Ok, or one kInvalidArgument error listing every bad field (field paths as in the YAML).
  Status validate() const;
};

/// Loads parameters from YAML (see the file comment). Errors name file, line, column and field;
/// unknown keys are refused; a relative `scenario` is resolved against the file's directory.
Result<SimParams> loadSimParams(const std::filesystem::path& file);
/// Same from text; `name` is used as the file name in messages (relative scenario paths are
/// resolved against the current directory).
Result<SimParams> parseSimParams(const std::string& yaml_text, const std::string& name);

}  // namespace tamp::sim
