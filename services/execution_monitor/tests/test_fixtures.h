#pragma once
// Shared fixtures of the execution monitor's unit tests: the project's robot, the NAMO corridor's
// planner world and start state, straight base trajectories and a crate to drop on a path.
#include <gtest/gtest.h>

#include "tamp/core/paths.h"
#include "tamp/execution_monitor/types.h"
#include "tamp/robot/robot_model.h"
#include "tamp/world/scenario.h"

namespace tamp::execution_monitor::testing {

inline const robot::RobotModel& robotModel() {
  static const robot::RobotModel kRobot = [] {
    auto r = robot::RobotModel::loadDefault();
    if (!r) throw std::runtime_error(r.error().toString());
    return std::move(r).value();
  }();
  return kRobot;
}

inline const world::Scenario& corridor() {
  static const world::Scenario kScenario = [] {
    auto s = world::loadScenario(configDir() / "scenarios" / "namo_corridor.yaml");
    if (!s) throw std::runtime_error(s.error().toString());
    return std::move(s).value();
  }();
  return kScenario;
}

/// A straight move_base through `poses` (x, y, theta), 1 s apart.
inline ExecutionCommand moveBase(const std::string& id, const std::vector<Pose2D>& poses) {
  ExecutionCommand c;
  c.command_id = id;
  c.mission_id = "m1";
  c.kind = ActionKind::kMoveBase;
  c.trajectory.joint_names = {"base_x", "base_y", "base_theta"};
  for (std::size_t i = 0; i < poses.size(); ++i) {
    c.trajectory.points.push_back(
        {static_cast<double>(i), {poses[i].x, poses[i].y, poses[i].theta}, {}});
  }
  c.expected_duration_s = 4.0;
  c.expected_stddev_s = 0.5;
  return c;
}

/// A 0.4 m crate standing on the floor at (x, y).
inline world::Object crate(const std::string& id, double x, double y) {
  world::Object o;
  o.id = id;
  o.label = "crate";
  o.kind = world::ObjectKind::kStatic;
  o.shape = world::Shape::box(0.4, 0.4, 0.4);
  o.pose = Eigen::Isometry3d::Identity();
  o.pose.translation() = Eigen::Vector3d(x, y, 0.2);
  return o;
}

inline world::World withCrate(world::World w, const std::string& id, double x, double y) {
  if (Status s = w.addObject(crate(id, x, y)); !s) throw std::runtime_error(s.error().toString());
  return w;
}

}  // namespace tamp::execution_monitor::testing
