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
#include "tamp/core/trajectory.h"
#include "tamp/msg/common.h"

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

/// Nanoseconds since the Unix epoch, now.
int64_t nowNs();

}  // namespace tamp::dds
