#pragma once
/// @file
/// Parameters of the simulator: the robot's TRUE execution-time parameters (what the effort
/// estimator has to discover), execution noise, pacing, the resolution of the swept collision
/// check, the physical tolerances of grasping and placing, and the depth sensor. Loaded from YAML
/// (config/services/sim.yaml; every key optional, unknown keys refused):
///
///   scenario: ""                 # scenario file the node loads (relative: to this file)
///   realtime_factor: 1.0         # simulated seconds per wall-clock second; 0 = as fast as possible
///   state_period_s: 0.05         # simulated time between robot-state samples
///   cloud_period_s: 0.5          # simulated time between point clouds; 0 = only after actions
///   duration_noise: 0.03         # stddev of log(duration) of an action (log-normal, median 1)
///   seed: 1                      # execution-noise seed (the sensor has its own)
///   max_step_m: 0.01             # swept check: largest displacement of any robot point between checks
///   start_tolerance: {position_m: 0.05, angle_rad: 0.05}   # command start vs robot state
///   grasp: {position_tolerance_m: 0.03, tcp_tolerance_m: 0.02, max_payload_kg: 5.0}
///   place: {position_tolerance_m: 0.03, angle_tolerance_rad: 0.1, max_drop_m: 0.05,
///           max_tilt_rad: 0.1}
///   time_parameters:             # per action kind, parameter names of effort_model/models.h
///     move_base: {max_linear_speed: 0.4, ...}
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

namespace tamp::sim {

/// The simulated robot's true time parameters: for each action kind, values in physical units in
/// the order of `effort_model::modelSpec(kind).parameters`. The simulator times every action
/// with `effort_model::predictDuration(features, values)` (plus noise); the planner never
/// sees these values.
struct TimeParameters {
  std::array<std::vector<double>, 4> values;  ///< indexed by `static_cast<int>(ActionKind)`

  /// A robot that is deliberately *not* the estimator's prior: 20 % slower drives, faster turns,
  /// longer settling and gripper times, heavier payload effect. Tests and examples use it; a
  /// scenario gives its own.
  static TimeParameters simulatedRobot();
  const std::vector<double>& of(ActionKind kind) const;
  std::vector<double>& of(ActionKind kind);
  /// Value of a named parameter; throws std::invalid_argument for an unknown name.
  double get(ActionKind kind, const std::string& name) const;
  void set(ActionKind kind, const std::string& name, double value);
  /// Ok, or kInvalidArgument naming "time_parameters.<kind>.<name>": sizes match the model
  /// specs, values finite, within the specs' [lower, upper] bounds.
  Status validate() const;
};

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

struct SimParams {
  std::string scenario;            ///< scenario file (node only); resolved against the YAML file
  double realtime_factor{1.0};     ///< >= 0; 0 = as fast as possible
  double state_period_s{0.05};     ///< > 0
  double cloud_period_s{0.5};      ///< >= 0; 0 = clouds only after actions (and on demand)
  double duration_noise{0.03};     ///< in [0, 1]: stddev of log(duration); 0 = exact model time
  std::uint64_t seed{1};
  double max_step_m{0.01};         ///< in (0, 0.5]
  StartTolerance start_tolerance;
  GraspParams grasp;
  PlaceParams place;
  TimeParameters time_parameters{TimeParameters::simulatedRobot()};
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
