#pragma once
/// @file
/// Placement sampling for the graph manager's `findEffectStates` (the paper's states where a
/// blocking object is out of the way): stable, collision-free poses of an object in a support
/// region, clear of the volume a path sweeps, with a base pose from which the robot reaches them.
///
/// A placement is *stable* when the object stands upright (its shape's z axis vertical) on the
/// region's surface (pose z = region height + half the object's height) with its whole footprint
/// inside the region's polygon, `support_margin` from its edges. It is *collision-free* when the
/// object there touches no other object (static or movable, the object itself excluded). It is
/// *clear of the swept volume* when its footprint keeps `keep_clear_radius` from every pose of
/// `keep_clear_path` (the base poses of the path the object blocked; the radius is normally the
/// robot's circumradius) and does not touch the robot at any of `keep_clear_states`. It is
/// *reachable* when a base pose `base_distance_min..max` from it, facing it, is collision-free
/// (with the object at the new pose) and the arm reaches a top grasp of it there with a
/// collision-free IK solution; for a planar robot (no arm) a free base pose within `planar_reach`.
///
/// *Placing a held object from where the robot stands* (`base` and `held_object_T_tool` given):
/// no base pose is sampled; a placement is reachable when the arm reaches the tool pose
/// `object_pose * held_object_T_tool` and the pre-place pose `approach` above it from `base`,
/// both with collision-free IK (the other objects and the robot itself). The reply then carries
/// both configurations, so the graph manager never proposes a pre-place the arm cannot take.
/// `object_overrides` plan the request in a hypothetical world (as for motion requests).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/geometry.h"
#include "tamp/motion_planner/object_override.h"
#include "tamp/robot/robot_model.h"

namespace tamp::motion_planner {

struct PlacementRequest {
  std::string object_id;                    ///< a movable object of the world
  std::string region_id;                    ///< a region of the world
  std::vector<Pose2D> keep_clear_path;      ///< base poses to keep clear of (may be empty)
  double keep_clear_radius{0.0};            ///< m, >= 0
  std::vector<robot::RobotState> keep_clear_states;  ///< robot states to keep clear of (may be empty)
  std::uint32_t max_placements{8};          ///< >= 1
  std::uint64_t seed{0};                    ///< 0: the planner's seed (results are reproducible either way)
  std::optional<Pose2D> base;               ///< place from this base pose (none: sample base poses)
  /// With `base`: the object is held with this grasp (tool frame in the object frame).
  std::optional<Eigen::Isometry3d> held_object_T_tool;
  double approach{0.0};                     ///< m >= 0, height of the pre-place pose above the place pose
  std::vector<ObjectOverride> object_overrides;  ///< each id at most once
  AddedObjects added_objects;                    ///< applied before the overrides
};

struct Placement {
  Eigen::Isometry3d object_pose{Eigen::Isometry3d::Identity()};  ///< world frame
  Pose2D base_pose;                   ///< a base pose from which the robot reaches it
  std::vector<double> arm_configuration;  ///< arm joints at the top grasp (empty for planar robots)
  std::vector<double> pre_arm_configuration;  ///< with a held grasp: arm joints at the pre-place pose
  double clearance{0.0};              ///< m, distance of the placed object to the nearest other object
  double transfer_distance{0.0};      ///< m, from the object's current position (xy)
};

}  // namespace tamp::motion_planner
