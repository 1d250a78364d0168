#pragma once
/// @file
/// Conversions between the core value types (common/core) and IDL messages. Services convert at
/// their boundary only; algorithm libraries never see `tamp::msg` types.
///
/// `fromMsg` functions validate what they read: a malformed message (e.g. a JointPath whose value
/// count is not a multiple of its joint count, a NaN pose) gives kInvalidArgument naming the field.

#include <string>

#include <Eigen/Geometry>

#include "tamp/core/error.h"
#include "tamp/core/geometry.h"
#include "tamp/core/point_cloud.h"
#include "tamp/core/trajectory.h"
#include "tamp/msg/common.h"
#include "tamp/msg/robot.h"

namespace tamp::dds {

msg::StatusCode toMsg(ErrorCode code);
ErrorCode fromMsg(msg::StatusCode code);

msg::ActionKind toMsg(ActionKind kind);
ActionKind fromMsg(msg::ActionKind kind);

msg::Pose2D toMsg(const Pose2D& p);
Result<Pose2D> fromMsg(const msg::Pose2D& m, const std::string& field = "pose");

msg::Pose3D toMsg(const Eigen::Isometry3d& T);
/// The quaternion is normalised; a zero or non-finite one is an error.
Result<Eigen::Isometry3d> fromMsg(const msg::Pose3D& m, const std::string& field = "pose");

msg::JointPath toMsg(const JointPath& p);
Result<JointPath> fromMsg(const msg::JointPath& m, const std::string& field = "path");

msg::JointTrajectory toMsg(const Trajectory& t);
Result<Trajectory> fromMsg(const msg::JointTrajectory& m, const std::string& field = "trajectory");

msg::PointCloudFrame toMsg(const PointCloudFrame& f, std::uint64_t seq = 0);
/// The frame's shape is checked, not its points: `points` a multiple of 3, width x height equal
/// to the point count when `width` is set (errors name `points`, `width`/`height`), and the
/// sensor pose (`sensor_pose.*`). Consumers add their own checks (perception: validateFrame).
Result<PointCloudFrame> fromMsg(const msg::PointCloudFrame& m);

/// Nanoseconds since the Unix epoch, now.
int64_t nowNs();

}  // namespace tamp::dds
