#pragma once
// Planar extents of objects and of the robot's base, for the graph manager's geometric
// shortcuts (what a replanning invalidates, where the robot stands beside an object). Internal to
// the graph manager library.
#include <algorithm>

#include <Eigen/Geometry>

#include "tamp/robot/robot_model.h"
#include "tamp/world/world.h"

namespace tamp::graph_manager::detail {

/// The object's footprint radius about its centre (m).
inline double footprintRadius(const world::Object& o) {
  double r = 0.0;
  for (const auto& v : o.shape.footprint(12)) r = std::max(r, v.norm());
  return r;
}

/// How far the object's footprint reaches from its centre along the world direction `dir`
/// (unit, in the floor plane): its support function (m).
inline double objectExtentAlong(const world::Object& o, const Eigen::Vector2d& dir) {
  const Eigen::Matrix3d R = o.pose.linear();
  double h = 0.0;
  for (const auto& v : o.shape.footprint(12)) {
    const Eigen::Vector3d w = R * Eigen::Vector3d(v.x(), v.y(), 0.0);
    h = std::max(h, w.head<2>().dot(dir));
  }
  return h;
}

/// How far the base's footprint reaches ahead of base_link (its largest x, m).
inline double baseFront(const robot::RobotModel& robot) {
  double x = 0.0;
  for (const auto& v : robot.baseFootprint()) x = std::max(x, v.x());
  return x;
}

}  // namespace tamp::graph_manager::detail
