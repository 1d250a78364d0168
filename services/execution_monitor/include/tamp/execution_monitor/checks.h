#pragma once
/// @file
/// The checks of one command, each a pure function of the command, the robot's state and the
/// world model (no DDS, no clock): the command's own well-formedness, the start of its
/// trajectory against the robot, the held object, a pick's object against the world model, and a
/// swept collision check of the (remaining) path against the world model's objects.
///
/// Failures are values: `std::nullopt` when the check passes, else a `CheckFailure` whose
/// `reason` starts with what failed ("start: ...", "held object: ...", "path: ...").

#include <optional>
#include <string>
#include <vector>

#include "tamp/collision/scene.h"
#include "tamp/core/error.h"
#include "tamp/execution_monitor/params.h"
#include "tamp/execution_monitor/types.h"
#include "tamp/robot/robot_model.h"
#include "tamp/world/world.h"

namespace tamp::execution_monitor {

/// Why a check failed.
struct CheckFailure {
  std::string reason;     ///< names what failed, e.g. "start: trajectory.points[0] base_x ..."
  std::string object_id;  ///< the object concerned (on the path, held, picked), or ""
};

/// Well-formedness of a command against the robot: non-empty command_id; a known kind; trajectory
/// non-empty, consistent sizes, finite values, strictly increasing times; joint names known and
/// fitting the kind (move_base: exactly base_x, base_y, base_theta; arm kinds: arm joints and
/// optionally the gripper joint, no base joint, no duplicates); arm joints within their limits;
/// pick / place: object_id set; place:
/// object_target set; expected_duration_s and expected_stddev_s finite and >= 0.
/// @return kInvalidArgument whose `where.field` and message name the field
///   ("trajectory.points[2].positions[1]: not finite", "trajectory.joint_names[0]: unknown joint
///   'base_q'").
Status validateCommand(const ExecutionCommand& command, const robot::RobotModel& robot);

/// The robot state at the trajectory's first point: `current` with the trajectory's joints set.
/// Precondition: `validateCommand` passed (unknown joints throw std::invalid_argument).
robot::RobotState stateAt(const ExecutionCommand& command, std::size_t point,
                          const robot::RobotState& current, const robot::RobotModel& robot);

/// The trajectory's first point against the robot's current state: every joint of the
/// trajectory within `tolerance` (base heading and revolute joints compared as wrapped angles).
std::optional<CheckFailure> checkStart(const ExecutionCommand& command,
                                       const robot::RobotState& current,
                                       const robot::RobotModel& robot,
                                       const StartTolerance& tolerance);

/// The held object the action relies on: place needs the gripper to hold `object_id`, pick an
/// empty hand; move_base / move_arm need nothing.
std::optional<CheckFailure> checkHeld(const ExecutionCommand& command,
                                      const std::string& held_object_id);

/// A pick's object in the world model: it exists, is movable, and (when `object_target` is given)
/// lies within `tolerance_m` of it.
std::optional<CheckFailure> checkPickTarget(const ExecutionCommand& command,
                                            const world::World& world, double tolerance_m);

/// The command's path as a sequence of full robot states (one per trajectory point) with a
/// normalised path parameter: `s[i]` in [0, 1] is the fraction of the path length (a weighted
/// joint-space length: metres of base translation, radians of base turn times 0.5 m, radians of
/// arm joints times 0.5 m) at point i.
struct SweptPath {
  std::vector<robot::RobotState> states;
  std::vector<double> s;
  double length{0.0};  ///< the weighted length (m)

  /// The state at path fraction `f` (clamped into [0, 1]; linear between points).
  robot::RobotState at(double f) const;
  /// The fraction of the point of the path nearest to `state`, searched from fraction `from` on
  /// (progress is monotone: a path that comes back to a place is not rewound).
  double project(const robot::RobotState& state, double from = 0.0) const;
};

/// The path of `command` from `current` (joints the trajectory does not name keep their value in
/// `current`). Precondition: `validateCommand` passed.
SweptPath makePath(const ExecutionCommand& command, const robot::RobotState& current,
                   const robot::RobotModel& robot);

/// Swept collision checks of paths against a world model (a `collision::Scene` mirror kept in
/// sync incrementally). The robot's geometry is the URDF's (`RobotModel::collisionGeometry()`);
/// the held object is not attached (it is an allowed contact, see `allowedContacts`), so its own
/// sweep is not checked. Not thread-safe: one checker per thread.
class PathChecker {
 public:
  /// Throws std::invalid_argument when `params` are invalid.
  PathChecker(const robot::RobotModel& robot, PathCheckParams params);

  /// Brings the scene to `world` (only the diff since the last call is applied).
  void setWorld(const world::World& world);

  /// Objects touching the robot at `state` (sorted).
  std::vector<std::string> contactsAt(const robot::RobotState& state);
  /// Objects touching the robot at `state` or within `PathCheckParams::start_contact_m` of it
  /// (sorted): those an action starting at `state` may leave (see `start_contact_m`).
  std::vector<std::string> startContactsAt(const robot::RobotState& state);

  struct Hit {
    std::string object_id;
    double fraction{0.0};  ///< path fraction of the first state in contact
  };
  /// The first object the robot touches along `path` from fraction `from` to the end, sampling
  /// at the resolution of `PathCheckParams`; objects in `ignore` are never reported.
  std::optional<Hit> firstContact(const SweptPath& path, double from,
                                  const std::vector<std::string>& ignore);

  /// The objects `object` would rest on at `pose`: those touching it lowered by 5 mm whose top
  /// is not above its bottom (+ 5 mm), `object` itself excluded (sorted). A pick's or place's
  /// support (the table) is an allowed contact of the action.
  std::vector<std::string> supportsOf(const world::Object& object,
                                      const Eigen::Isometry3d& pose) const;

 private:
  const robot::RobotModel* robot_;
  PathCheckParams params_;
  collision::Scene scene_;
  bool has_world_{false};
  std::vector<Eigen::Isometry3d> poses_;
};

/// The contacts that are part of the task: the picked / placed object and the held object (the
/// monitor adds the object's support, see PathChecker::supportsOf).
std::vector<std::string> allowedContacts(const ExecutionCommand& command,
                                         const std::string& held_object_id);

}  // namespace tamp::execution_monitor
