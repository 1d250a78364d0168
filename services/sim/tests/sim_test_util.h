#pragma once
// Shared fixtures of the simulator tests: the project's robot, worlds, commands, run-to-end.
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <gtest/gtest.h>

#include "tamp/effort_model/features.h"
#include "tamp/effort_model/models.h"
#include "tamp/sim/setup.h"
#include "tamp/sim/simulator.h"

namespace tamp::sim::testing {

inline const robot::RobotModel& robotModel() {
  static const robot::RobotModel m = [] {
    auto r = robot::RobotModel::loadFile(std::filesystem::path(TAMP_SOURCE_DIR) /
                                         "config/robots/mobile_manipulator.urdf");
    if (!r) throw std::runtime_error(r.error().toString());
    return std::move(r).value();
  }();
  return m;
}

/// Arm straight up (zero), gripper closed, base at `base`.
inline robot::RobotState upright(const Pose2D& base = {}) {
  robot::RobotState s;
  s.base = base;
  s.arm.assign(robotModel().armDof(), 0.0);
  return s;
}

/// Noise-free, as fast as possible, no clouds.
inline SimParams exactParams() {
  SimParams p;
  p.duration_noise = 0.0;
  p.realtime_factor = 0.0;
  p.cloud_period_s = 0.0;
  p.dynamics.stall.probability = 0.0;
  return p;
}

inline Eigen::Isometry3d at(double x, double y, double z, double yaw = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

inline world::Object box(const std::string& id, double sx, double sy, double sz,
                         const Eigen::Isometry3d& pose, bool movable = false, bool hidden = false) {
  world::Object o;
  o.id = id;
  o.kind = movable ? world::ObjectKind::kMovable : world::ObjectKind::kStatic;
  o.shape = world::Shape::box(sx, sy, sz);
  o.pose = pose;
  o.mass = movable ? 2.0 : 0.0;
  o.hidden = hidden;
  return o;
}

/// A move_base command through (x, y, theta) waypoints, one second apart.
inline ActionCommand moveBase(const std::string& id, const std::vector<Pose2D>& poses) {
  ActionCommand c;
  c.command_id = id;
  c.kind = ActionKind::kMoveBase;
  c.trajectory.joint_names = {"base_x", "base_y", "base_theta"};
  double t = 0.0;
  for (const auto& p : poses) c.trajectory.points.push_back({t++, {p.x, p.y, p.theta}, {}});
  return c;
}

/// An arm command (move_arm / pick / place) through full arm configurations.
inline ActionCommand armCommand(const std::string& id, ActionKind kind,
                                const std::vector<std::vector<double>>& configs) {
  ActionCommand c;
  c.command_id = id;
  c.kind = kind;
  c.trajectory.joint_names = robotModel().armJointNames();
  double t = 0.0;
  for (const auto& q : configs) c.trajectory.points.push_back({t++, q, {}});
  return c;
}

/// Steps until the action in progress ends (at most `limit_s` of simulated time); collects all.
inline StepEvents runToEnd(Simulator& sim, double dt = 0.05, double limit_s = 600.0) {
  StepEvents all;
  const double t_end = sim.time() + limit_s;
  while (sim.busy() && sim.time() < t_end) {
    StepEvents e = sim.step(dt);
    all.world_changed |= e.world_changed;
    for (auto& r : e.results) all.results.push_back(std::move(r));
    for (auto& r : e.records) all.records.push_back(std::move(r));
    for (auto& f : e.faults) all.faults.push_back(std::move(f));
  }
  return all;
}

/// Per-joint speed scales of the robot's arm (URDF velocity / fastest), computed independently
/// of the simulator.
inline effort_model::FeatureOptions urdfScales() {
  effort_model::FeatureOptions o;
  const auto& lim = robotModel().armLimits();
  double fastest = 0;
  for (const auto& l : lim) fastest = std::max(fastest, l.velocity);
  for (std::size_t j = 0; j < lim.size(); ++j) {
    o.joint_scales[robotModel().armJointNames()[j]] = lim[j].velocity / fastest;
  }
  return o;
}

/// The time model with `params` for the action a record describes.
inline double modelTime(const effort_model::ExecutionRecord& r, std::span<const double> params) {
  auto f = effort_model::extractFeatures(r.action, urdfScales());
  if (!f) throw std::runtime_error(f.error().toString());
  return effort_model::predictDuration(*f, params);
}

/// The simulator's own true nominal duration (dynamics.h) of the action a record describes.
inline double trueTime(const effort_model::ExecutionRecord& r, const SimParams& p) {
  NominalQuery q;
  q.kind = r.action.kind;
  q.path = r.action.path;
  q.approach_m = r.action.approach_m;
  q.retreat_m = r.action.retreat_m;
  q.object_mass_kg = r.action.object_mass_kg;
  auto t = nominalDuration(p.dynamics, armSpeedLimits(robotModel()), q);
  if (!t) throw std::runtime_error(t.error().toString());
  return *t;
}
}  // namespace tamp::sim::testing
