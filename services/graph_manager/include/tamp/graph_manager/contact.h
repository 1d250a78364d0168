#pragma once
/// @file
/// Contact as evidence of where an object is.
///
/// The robot stops at the last collision-free sample before it would touch an object. So where it
/// stopped, its body is free of the object, and a little further along it was not: the object's
/// surface lies within the stop's resolution of the body. When the world model's estimate stands
/// farther off (a face perception never saw: a crate pushed into a room slides sideways, and the
/// camera, which looks ahead, does not see the side the robot then drives past), planning round
/// the estimate again drives into the object again (namo_doorway in CI, docs/reliability.md).
/// `touchingPose` is the least correction of the estimate that agrees with the stop: the object
/// moved in the plane until it touches the body. From an estimate farther off, along the line of
/// its nearest points to the body (the true object is no closer than touching, and no farther
/// off than the stop's resolution). From an estimate that overlaps the body (the robot strayed
/// from its path into a gap the estimate left it: Moghaddam 01, session 30, where the robot then
/// stood "in collision" in the model with no way out), by the shortest move that clears it: the
/// robot stood there, so the object does not.

#include <optional>

#include <Eigen/Geometry>

#include "tamp/robot/robot_model.h"
#include "tamp/world/world.h"

namespace tamp::graph_manager {

struct ContactCorrection {
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};  ///< the object touching the robot's body
  /// How far the estimate moved (m): > 0 towards the robot (it stood off), < 0 away from it (it
  /// overlapped the body).
  double shift_m{0.0};
};

/// The pose of `object` touching the robot's body (its links, not a held object) at `stop`, moved
/// in the plane from where the estimate has it. None when the estimate already touches the body
/// (within `touch_m`, > 0: nothing to learn), or when it would move more than `max_shift_m`, or
/// its nearest point is above or below the body rather than beside it: then the stop says
/// nothing about this estimate (another part touched, or the state is not the stop's).
std::optional<ContactCorrection> touchingPose(const world::Object& object, const robot::RobotModel& robot,
                                              const robot::RobotState& stop, double max_shift_m,
                                              double touch_m = 0.002);

}  // namespace tamp::graph_manager
