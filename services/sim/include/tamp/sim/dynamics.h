#pragma once
/// @file
/// The simulated robot's own execution dynamics (issue 12 part 3): how long the TRUE robot takes
/// to execute a commanded trajectory. Deliberately not the effort estimator's model family
/// (common/effort_model: trapezoidal stop-to-stop moves): here every move is a jerk-limited
/// rest-to-rest S-curve with its own speed, acceleration and jerk limits, the arm passes through
/// gentle bends of its path without stopping, a held mass slows every motion, the robot stalls
/// now and then (seeded random pauses), and the gripper has its own close/open times. The
/// estimator's models are therefore misspecified against it, as they would be against a real
/// robot. Pure functions, no DDS.
///
/// Only the *timing* is the simulator's own. The *geometry* is the commanded one: the robot is
/// position-controlled and passes through every commanded waypoint on the straight joint-space
/// segments between them, which is what the motion planner checked (a run through several
/// waypoints is one S-curve along the polyline, never a chord cutting its bends). The base path
/// is executed stop-and-turn as `effort_model::baseSteps` segments it (the base model shared with
/// the motion planner and the execution monitor).
///
/// Units: metres, radians, seconds, kilograms.

#include <cstddef>
#include <string>
#include <unordered_map>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/geometry.h"
#include "tamp/core/trajectory.h"
#include "tamp/effort_model/features.h"

namespace tamp::sim {

/// A rest-to-rest move of `length` >= 0 with speed, acceleration and jerk limits: the
/// time-optimal seven-segment S-curve (jerk +j, 0, -j, cruise, -j, 0, +j; segments of zero length
/// dropped when the limits are not reached).
class MotionProfile {
 public:
  MotionProfile() = default;
  /// @throws std::invalid_argument when a limit is not finite and > 0 or length is < 0.
  static MotionProfile restToRest(double length, double v, double a, double j);
  double length() const { return length_; }
  double duration() const { return duration_; }
  /// Distance covered after time t (clamped to [0, duration]).
  double positionAt(double t) const;
  /// The first time at which distance s is reached (clamped to [0, length]).
  double timeAt(double s) const;

 private:
  struct Segment {
    double t0, dt, jerk, s0, v0, a0;
  };
  std::vector<Segment> segments_;
  double length_{0.0};
  double duration_{0.0};
};

/// Speed, acceleration and jerk limits of one motion.
struct Limits {
  double speed{1.0};
  double accel{1.0};
  double jerk{1.0};
};

struct BaseDynamics {
  double linear_speed{0.45};  ///< m/s
  double linear_accel{0.35};  ///< m/s^2
  double linear_jerk{0.8};    ///< m/s^3
  double angular_speed{1.1};  ///< rad/s
  double angular_accel{1.4};  ///< rad/s^2
  double angular_jerk{4.0};   ///< rad/s^3
  double settle_s{0.25};      ///< pause after each drive or turn
  double latency_s{0.6};      ///< command latency before the base moves
  Limits linear() const { return {linear_speed, linear_accel, linear_jerk}; }
  Limits angular() const { return {angular_speed, angular_accel, angular_jerk}; }
};

struct ArmDynamics {
  /// Each joint's speed limit is this fraction of its URDF velocity limit (in (0, 1]).
  double speed_fraction{0.55};
  double max_speed{2.0};  ///< cap of every joint's speed limit (rad/s or m/s)
  double accel{1.8};      ///< rad/s^2 (m/s^2 for prismatic joints), every joint
  double jerk{6.0};       ///< rad/s^3, every joint
  /// Where the joint-space direction of the path changes by more than this, the arm stops (one
  /// S-curve ends, the next starts); gentler bends are passed through at speed (rad, in (0, pi)).
  /// Only the timing depends on it: the path followed is the commanded polyline either way.
  double corner_threshold_rad{0.05};
  double settle_s{0.12};  ///< pause after each run (at each stop)
  double latency_s{0.4};
};

struct HandDynamics {
  double approach_speed{0.05};  ///< tool path of pick/place approach and retreat, m/s
  double approach_accel{0.1};   ///< m/s^2
  double approach_jerk{0.5};    ///< m/s^3
  double close_s{1.9};          ///< gripper closing (pick)
  double open_s{1.1};           ///< gripper opening (place)
  Limits approach() const { return {approach_speed, approach_accel, approach_jerk}; }
};

struct LoadDynamics {
  /// A held mass m divides speed and acceleration limits by 1 + per_kg * m (>= 0, 1/kg).
  double per_kg{0.12};
};

struct StallDynamics {
  double probability{0.08};  ///< per motion (drive, turn, arm run, approach), in [0, 1]
  double min_s{0.3};         ///< duration of a stall: uniform in [min_s, max_s]
  double max_s{1.5};
};

/// The true robot's dynamics (the "truth" the effort estimator must discover). Defaults differ
/// from the estimator's prior (config/services/effort_estimator.yaml) so that its first
/// predictions are off by tens of percent.
struct DynamicsParams {
  BaseDynamics base;
  ArmDynamics arm;
  HandDynamics hand;
  LoadDynamics load;
  StallDynamics stall;
  /// Ok, or one kInvalidArgument error naming every bad field ("dynamics.base.linear.speed").
  Status validate() const;
};

/// The base executes its path as `effort_model::baseSteps(poses)` segments it (stop-and-turn:
/// the geometry the motion planner and the execution monitor check); each turn and each drive is
/// one S-curve of the base's angular or linear limits.

/// A run of an arm path: consecutive segments whose joint-space direction changes by at most
/// `ArmDynamics::corner_threshold_rad` from one to the next, executed as one rest-to-rest S-curve
/// *along the polyline* through their waypoints (the arm passes every waypoint exactly).
/// The path parameter u is the time each segment takes at full speed: segment k adds
/// max_j |dq_kj| / w_j (w_j = min(max_speed, speed_fraction x URDF limit of joint j)), so that
/// du/dt <= 1 / load_factor keeps every joint within w_j / load_factor.
struct ArmRun {
  std::vector<std::size_t> points;  ///< waypoint indices in order, the run's start included
  std::vector<double> u;            ///< path parameter at each of `points` (u.front() = 0), s
  Limits limits;                    ///< of du/dt, d2u/dt2, d3u/dt3
  double length() const { return u.empty() ? 0.0 : u.back(); }
};
/// The runs of an arm path (waypoints over `joint_names`; `joint_speed`: the URDF velocity limit
/// by joint name, 1 for joints not listed), limits divided by `load_factor` (jerk excepted).
/// Runs whose joints all move less than 1e-6 are dropped.
std::vector<ArmRun> armRuns(const std::vector<std::vector<double>>& waypoints,
                            const std::vector<std::string>& joint_names,
                            const std::unordered_map<std::string, double>& joint_speed,
                            const ArmDynamics& arm, double load_factor);

/// 1 + per_kg * mass.
double loadFactor(const DynamicsParams& d, double mass_kg);
Limits scaled(const Limits& l, double load_factor);

/// What the oracle needs to know of an action (the same content as the effort estimator's
/// query: the path for motions, the tool-path distances for pick/place, the held mass).
struct NominalQuery {
  ActionKind kind{ActionKind::kMoveBase};
  JointPath path;          ///< move_base: base_x, base_y, base_theta; move_arm: arm joints
  double approach_m{0.0};  ///< pick/place
  double retreat_m{0.0};
  double object_mass_kg{0.0};
};

/// The true nominal duration of an action (no noise, no stall), deterministic: the oracle's
/// answer. kInvalidArgument naming the field for a malformed query (unknown or missing joints,
/// ragged or non-finite waypoints, negative distances or mass).
Result<double> nominalDuration(const DynamicsParams& d,
                               const std::unordered_map<std::string, double>& joint_speed,
                               const NominalQuery& q);

}  // namespace tamp::sim
