#pragma once
/// @file
/// Grasp generation for boxes and cylinders with the parallel-jaw gripper (two fingers closing
/// along the tool frame's y axis; the tool z axis is the approach direction, out of the palm; see
/// config/robots/mobile_manipulator.urdf).
///
/// Candidates, in the object's frame (shapes are centred; z up for an upright object):
/// - **top**: the tool approaches along -z from above, its fingers closing across a horizontal
///   axis whose width fits the gripper (box: its x or y extent, both yaw flips; cylinder: the
///   diameter, `cylinder_yaw_samples` yaws), the tool centre point at the object's centre height
///   or lower by at most half the finger length so that the fingers hold the top part;
/// - **side**: the tool approaches horizontally (box: along +-x or +-y; cylinder: from
///   `cylinder_yaw_samples` directions) at `side_height_fraction` of the object's height, the
///   fingers closing across the horizontal width that fits.
/// Each candidate gets a pre-grasp pose `approach_distance` back along the approach axis and a
/// retreat pose `retreat_distance` above the grasp (world +z). A grasp is kept when inverse
/// kinematics reaches the pre-grasp, grasp and retreat poses from one base pose, each solution
/// collision-free (the object itself ignored at the grasp and retreat; the gripper open at the
/// pre-grasp and grasp) and within joint limits. Without a given base pose, base poses facing
/// the object at `base_distance_min..max` are tried. Spheres and prisms are refused
/// (kUnsupported); objects wider than the gripper's opening in every direction give no grasps.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/geometry.h"
#include "tamp/motion_planner/object_override.h"

namespace tamp::motion_planner {

enum class GraspType { kTop, kSide };
std::string_view toString(GraspType type);  ///< "top", "side"

struct GraspRequest {
  std::string object_id;            ///< a graspable object of the world
  std::optional<Pose2D> base_pose;  ///< the robot's base pose, or none: sample base poses
  std::vector<double> start_arm;    ///< IK seed (arm joints); empty: the arm's zero configuration
  std::uint32_t max_grasps{8};      ///< >= 1
  std::vector<ObjectOverride> object_overrides;  ///< plan in this hypothetical world; each id at most once
  AddedObjects added_objects;                    ///< applied before the overrides; may name `object_id`
};

struct Grasp {
  GraspType type{GraspType::kTop};
  Eigen::Isometry3d gripper_in_object{Eigen::Isometry3d::Identity()};  ///< tool frame in the object frame
  Eigen::Isometry3d world_T_tool{Eigen::Isometry3d::Identity()};       ///< at the grasp
  Pose2D base_pose;
  std::vector<double> pregrasp_configuration;  ///< arm joints at the pre-grasp pose
  std::vector<double> grasp_configuration;     ///< arm joints at the grasp pose
  std::vector<double> retreat_configuration;   ///< arm joints at the retreat pose
  double opening{0.0};                         ///< gripper joint value (m per finger) before closing
  double width{0.0};                           ///< m, object width between the fingers
};

}  // namespace tamp::motion_planner
