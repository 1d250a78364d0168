#pragma once
/// @file
/// The robot's own body in a depth frame. A camera on the robot sees its arm, its gripper and the
/// object it holds; without this filter they become obstacles in the world model (a "new box"
/// in front of the camera, occupied voxels where the arm is). `RobotBody` is the robot at the
/// instant of a frame: its links' collision shapes (the URDF `<collision>` geometry, as
/// `robot::RobotModel::collisionGeometry()` has it) posed by forward kinematics of the reported
/// state, plus the tool link's pose, to which the held object is attached. `removeBodyPoints()`
/// drops the returns that fall inside those shapes, or inside the held object's shape, grown by a
/// padding (the state's latency, joint-encoder and calibration error, the sensor's range noise).
///
/// Frames: the body is in the world frame; the frame's points stay in the sensor frame (each
/// shape is brought into the sensor frame once, not each point into the world). Removed points
/// become NaN triplets, so an organised frame keeps its layout and the range image of the
/// visibility test (`visibility.h`) sees no return there: what the arm hides is neither "seen
/// empty" nor "present".

#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/point_cloud.h"
#include "tamp/robot/robot_model.h"
#include "tamp/world/shape.h"
#include "tamp/world/world.h"

namespace tamp::perception {

/// One solid of the robot (or the held object) in the world.
struct BodyPart {
  std::string owner;  ///< link name (or the held object's id)
  world::Shape shape;
  Eigen::Isometry3d world_T_shape{Eigen::Isometry3d::Identity()};
};

/// The robot at the instant of a frame.
struct RobotBody {
  std::vector<BodyPart> parts;  ///< every link's collision shapes, world frame
  std::string held_object_id;   ///< the object in the gripper (robot state), empty: none
  Eigen::Isometry3d world_T_tool{Eigen::Isometry3d::Identity()};  ///< the tool link (held object)
  std::int64_t stamp_ns{0};  ///< of the robot state it was computed from
  std::string base_link;     ///< owner of the parts that drive on the floor (objects cannot be inside them)
  /// The tool where the robot's state first reported the gripper empty after holding
  /// `released_object_id` (the latest such change up to this instant), if known: where a dropped
  /// object left the gripper. A frame's own instant may be long after (states come every 50 ms,
  /// frames every 0.5 s), and the last frame that saw it held longer before.
  std::optional<Eigen::Isometry3d> world_T_tool_at_release;
  std::string released_object_id;
};

/// What the robot reported at one instant: its state and the object in its gripper.
struct StampedRobotState {
  std::int64_t stamp_ns{0};
  robot::RobotState state;
  std::string held_object_id;
};

/// The robot's state at `stamp_ns` from `samples` (oldest first). Between two samples it is
/// interpolated: base position and joints linearly, the base yaw the short way round, the held
/// object that of the nearer sample. A frame's returns are filtered with the body where it was
/// at the frame's instant, not at the nearest report (which, a state period away on a moving
/// base, leaves a strip of the robot in the frame: a "new box" beside it). Outside the samples'
/// span, the nearest sample when it is within `max_age_s` of `stamp_ns`; nullopt otherwise
/// (or when `samples` is empty). Arm vectors of different sizes are not interpolated (the
/// nearer sample is used).
std::optional<StampedRobotState> robotStateAt(const std::deque<StampedRobotState>& samples, std::int64_t stamp_ns,
                                              double max_age_s);

/// The body of `robot` in `state` (link poses by `RobotModel::linkPoses`, shapes from
/// `collisionGeometry()`; the tool link is `options().tool_link`).
/// @throws std::invalid_argument when `state.arm` does not fit the robot.
RobotBody robotBodyAt(const robot::RobotModel& robot, const robot::RobotState& state,
                      std::string held_object_id = {}, std::int64_t stamp_ns = 0);

/// Sets to NaN every point of `frame` (sensor frame) inside a part of `body`, or inside `held`
/// (the held object's shape at its world pose; nullptr: none), grown by `padding` (m, >= 0).
/// Returns the number of points removed. Cost: one pass over the points with a bounding-box test
/// per part in the sensor frame (~1 ms for 300k points and the project's 15 link shapes).
/// @throws std::invalid_argument for a negative or non-finite padding.
std::size_t removeBodyPoints(PointCloudFrame& frame, const RobotBody& body,
                             const world::Object* held, double padding);

}  // namespace tamp::perception
