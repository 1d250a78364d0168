#pragma once
/// @file
/// Paths and trajectories in a named joint space, and the robot's action kinds. Shared by the
/// motion planner (produces them), the effort estimator (prices them), the simulator and the
/// execution monitor (execute them).
///
/// Joint naming convention: the planar base is the three virtual joints `base_x`, `base_y`
/// (metres, world frame) and `base_theta` (rad); arm and gripper joints use their URDF names.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tamp {

inline constexpr std::array<std::string_view, 3> kBaseJointNames{"base_x", "base_y", "base_theta"};

/// What the robot can do (the paper's Move_base, Move_arm, Pick, Place).
enum class ActionKind { kMoveBase, kMoveArm, kPick, kPlace };
inline constexpr std::array<ActionKind, 4> kAllActionKinds{ActionKind::kMoveBase, ActionKind::kMoveArm,
                                                           ActionKind::kPick, ActionKind::kPlace};

/// "move_base", "move_arm", "pick", "place".
std::string_view toString(ActionKind kind);
std::optional<ActionKind> actionKindFromString(std::string_view name);

/// An untimed geometric path: waypoints over `joint_names` (each waypoint has one value per name).
struct JointPath {
  std::vector<std::string> joint_names;
  std::vector<std::vector<double>> waypoints;

  bool empty() const { return waypoints.empty(); }
  /// Index of a joint name, or -1.
  int indexOf(std::string_view joint) const;
  /// Throws std::invalid_argument naming the first waypoint whose size differs from the names.
  void validate() const;
};

struct TrajectoryPoint {
  double time_from_start{0.0};     ///< seconds
  std::vector<double> positions;   ///< one per joint name
  std::vector<double> velocities;  ///< one per joint name, or empty
};

/// A timed trajectory (what the simulator or a robot controller executes).
struct Trajectory {
  std::vector<std::string> joint_names;
  std::vector<TrajectoryPoint> points;

  double duration() const { return points.empty() ? 0.0 : points.back().time_from_start; }
  bool empty() const { return points.empty(); }
  int indexOf(std::string_view joint) const;
  /// The untimed path through the same waypoints.
  JointPath path() const;
  /// Linear interpolation of positions at time t (clamped to [0, duration]). Angular joints are
  /// interpolated as plain numbers: callers keep consecutive angles unwrapped.
  std::vector<double> sample(double t) const;
  /// Throws std::invalid_argument on inconsistent sizes or non-monotonic times.
  void validate() const;
};

}  // namespace tamp
