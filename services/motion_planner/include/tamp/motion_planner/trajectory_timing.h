#pragma once
/// @file
/// Trapezoidal time parameterization of a joint path: the trajectory the simulator executes.
///
/// The robot stops at every waypoint (the planner's waypoints are the corners of a shortcut
/// path, so a stop there is what a controller without blending does). Between two waypoints all
/// joints move synchronously along the straight segment with one normalized trapezoidal
/// (or triangular) velocity profile s(t) in [0, 1]: q(t) = q_a + s(t) (q_b - q_a), so the robot
/// follows exactly the segment the planner checked for collisions. The profile's peak speed and
/// acceleration are the largest that keep every joint within its limits:
///   V = min_j v_j / |D_j|,  A = min_j a_j / |D_j|,   T = trap(1; V, A)
/// where trap(d; v, a) = d/v + v/a if d >= v^2/a, else 2 sqrt(d/a).
/// The base is a holonomic SE(2) joint set (base_x, base_y, base_theta): the translation counts
/// as one joint of displacement |(dx, dy)| with the base's linear limits, the yaw as one joint
/// with the angular limits; yaw values are unwrapped along the path (consecutive differences in
/// [-pi, pi)) so that linear interpolation of the trajectory turns the short way.
///
/// Output: points every `sample_period` plus the waypoints and the ends of the acceleration and
/// deceleration phases, with positions and velocities; `Trajectory::sample()` between points is
/// linear, exact at the points.

#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/trajectory.h"

namespace tamp::motion_planner {

/// Velocity and acceleration limit of one joint (or of the base translation).
struct JointLimit {
  double max_velocity{1.0};      ///< > 0 (rad/s or m/s)
  double max_acceleration{1.0};  ///< > 0 (rad/s^2 or m/s^2)
};

/// Limits by joint name. Base joints: `base_x`/`base_y` share `base_linear` (applied to the
/// translation's length), `base_theta` uses `base_angular`; any other joint needs an entry in
/// `joints` (same order as `joint_names`).
struct TimingLimits {
  JointLimit base_linear{0.5, 0.5};
  JointLimit base_angular{1.0, 1.5};
  std::vector<std::string> joint_names;  ///< non-base joints
  std::vector<JointLimit> joints;        ///< one per joint_names entry
  double sample_period{0.05};            ///< s, > 0
};

/// Minimum duration (s) of a stop-to-stop move of length `d` >= 0 with speed `v` > 0 and
/// acceleration `a` > 0.
double trapezoidDuration(double d, double v, double a);

/// Times `path`. kInvalidArgument (naming the joint or waypoint) when a joint has no limit, a
/// limit is not positive, the path is empty or has non-finite values. A one-waypoint path gives
/// a one-point trajectory at t = 0.
Result<Trajectory> timeParameterize(const JointPath& path, const TimingLimits& limits);

}  // namespace tamp::motion_planner
