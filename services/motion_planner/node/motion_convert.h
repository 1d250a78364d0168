#pragma once
/// @file
/// IDL (`idl/motion.idl`) <-> motion planner types. Every `fromMsg` validates what it reads and
/// names the offending IDL field in its error ("goal_base: pose has a non-finite value",
/// "start_joint_names[2]: unknown joint 'elbow'").

#include "tamp/core/error.h"
#include "tamp/motion_planner/motion_planner.h"
#include "tamp/msg/effort.h"
#include "tamp/msg/motion.h"

namespace tamp::motion_planner {

/// A motion request for `planner`'s robot. The start's joints not named keep the robot's
/// default state (arm at "stow" or zero, gripper closed). `movable_cost_weight` is the object
/// cost scale as it is (0: movables free). `object_overrides` and the held grasp are converted
/// (non-finite poses named here); unknown ids are the planner's to report.
Result<MotionRequest> fromMsg(const msg::MotionRequest& m, const MotionPlanner& planner);
/// The reply body (the header is filled by the RPC server; `world_version` by the node).
msg::MotionReply toMsg(const MotionResult& r);

/// The pick, place and move_base (and move_arm) parameter values of an effort model snapshot;
/// errors name the field (`models[i].values: 3 values for 4 parameter_names`).
Result<std::vector<TimeModelValues>> fromMsg(const msg::EffortModelSnapshot& m);

msg::MotionStatus toMsg(MotionStatus s);

Result<PlacementRequest> fromMsg(const msg::PlacementRequest& m);
msg::PlacementReply toMsg(const std::vector<Placement>& placements);

Result<GraspRequest> fromMsg(const msg::GraspRequest& m);
msg::GraspReply toMsg(const std::vector<Grasp>& grasps);

}  // namespace tamp::motion_planner
