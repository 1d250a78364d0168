#pragma once
/// @file
/// A hypothetical world for one request (motion, placement, grasp): objects of the planner's
/// world moved or absent, applied to a copy of the world and undone when the request ends.

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/world/world.h"

namespace tamp::motion_planner {

/// A hypothetical world for one request: this object moved to `pose`, or absent.
struct ObjectOverride {
  std::string object_id;  ///< an object of the planner's world (planner view)
  bool removed{false};    ///< treat as absent
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};  ///< world_T_object when not removed
};

/// Objects the planner's world does not have, added for one request before its overrides are
/// applied (the overrides may then move them): what the caller knows and perception has not
/// seen, e.g. the oracle policy's hidden objects. Each id new to the planner's world.
using AddedObjects = std::vector<world::Object>;

}  // namespace tamp::motion_planner
