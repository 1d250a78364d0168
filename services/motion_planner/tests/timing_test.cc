// Trapezoidal time parameterization: limits respected, waypoints reached, minimal durations.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tamp/motion_planner/trajectory_timing.h"

namespace tamp::motion_planner {
namespace {

TimingLimits limits() {
  TimingLimits l;
  l.base_linear = {0.5, 0.4};
  l.base_angular = {1.0, 1.5};
  l.joint_names = {"j1", "j2"};
  l.joints = {{1.2, 2.0}, {0.6, 0.8}};
  l.sample_period = 0.02;
  return l;
}

/// Checks velocity and acceleration limits by finite differences of the trajectory points.
void checkLimits(const Trajectory& t, const TimingLimits& l) {
  const int ix = t.indexOf("base_x"), iy = t.indexOf("base_y"), ith = t.indexOf("base_theta");
  auto limitOf = [&](std::size_t j) -> JointLimit {
    if (static_cast<int>(j) == ith) return l.base_angular;
    for (std::size_t k = 0; k < l.joint_names.size(); ++k)
      if (l.joint_names[k] == t.joint_names[j]) return l.joints[k];
    return l.base_linear;
  };
  const double tol = 1e-6;
  for (std::size_t i = 0; i < t.points.size(); ++i) {
    const auto& p = t.points[i];
    ASSERT_EQ(p.velocities.size(), t.joint_names.size());
    for (std::size_t j = 0; j < t.joint_names.size(); ++j) {
      if (static_cast<int>(j) == ix || static_cast<int>(j) == iy) continue;
      EXPECT_LE(std::abs(p.velocities[j]), limitOf(j).max_velocity + tol) << t.joint_names[j] << " at " << i;
    }
    if (ix >= 0 && iy >= 0) {
      EXPECT_LE(std::hypot(p.velocities[static_cast<std::size_t>(ix)], p.velocities[static_cast<std::size_t>(iy)]),
                l.base_linear.max_velocity + tol);
    }
    if (i == 0) continue;
    const auto& q = t.points[i - 1];
    const double dt = p.time_from_start - q.time_from_start;
    ASSERT_GT(dt, 0.0);
    for (std::size_t j = 0; j < t.joint_names.size(); ++j) {
      // Average velocity over the interval is bounded by the limit too.
      const double avg = (p.positions[j] - q.positions[j]) / dt;
      if (static_cast<int>(j) != ix && static_cast<int>(j) != iy) {
        EXPECT_LE(std::abs(avg), limitOf(j).max_velocity + tol);
        const double acc = (p.velocities[j] - q.velocities[j]) / dt;
        EXPECT_LE(std::abs(acc), limitOf(j).max_acceleration + 1e-4) << t.joint_names[j] << " at " << i;
      }
    }
    if (ix >= 0 && iy >= 0) {
      const double ax = (p.velocities[static_cast<std::size_t>(ix)] - q.velocities[static_cast<std::size_t>(ix)]) / dt;
      const double ay = (p.velocities[static_cast<std::size_t>(iy)] - q.velocities[static_cast<std::size_t>(iy)]) / dt;
      EXPECT_LE(std::hypot(ax, ay), l.base_linear.max_acceleration + 1e-4) << "base accel at " << i;
    }
  }
}

TEST(TimingTest, TrapezoidDurationClosedForm) {
  EXPECT_DOUBLE_EQ(trapezoidDuration(0.0, 1.0, 1.0), 0.0);
  EXPECT_NEAR(trapezoidDuration(4.0, 1.0, 1.0), 5.0, 1e-12);          // 4/1 + 1/1
  EXPECT_NEAR(trapezoidDuration(0.25, 1.0, 1.0), 1.0, 1e-12);         // 2 sqrt(0.25)
  EXPECT_NEAR(trapezoidDuration(1.0, 1.0, 1.0), 2.0, 1e-12);          // both branches agree
}

TEST(TimingTest, SingleJointMoveIsTimeOptimalAndStopsAtTheEnd) {
  JointPath p;
  p.joint_names = {"j1"};
  p.waypoints = {{0.0}, {2.0}};
  const auto t = timeParameterize(p, limits());
  ASSERT_TRUE(t.ok()) << t.error().toString();
  EXPECT_NEAR(t->duration(), trapezoidDuration(2.0, 1.2, 2.0), 1e-9);
  EXPECT_DOUBLE_EQ(t->points.back().positions[0], 2.0);
  EXPECT_DOUBLE_EQ(t->points.back().velocities[0], 0.0);
  checkLimits(*t, limits());
}

TEST(TimingTest, SynchronisedJointsFollowTheStraightSegment) {
  JointPath p;
  p.joint_names = {"j1", "j2"};
  p.waypoints = {{0.0, 0.0}, {1.0, 1.0}, {1.0, -0.5}, {-2.0, 0.3}};
  const auto t = timeParameterize(p, limits());
  ASSERT_TRUE(t.ok());
  checkLimits(*t, limits());
  // Each point lies on the segment between two consecutive waypoints (collinearity in joint space).
  std::size_t seg = 0;
  for (const auto& pt : t->points) {
    while (seg + 1 < p.waypoints.size()) {
      const auto& a = p.waypoints[seg];
      const auto& b = p.waypoints[seg + 1];
      const double cross = (pt.positions[0] - a[0]) * (b[1] - a[1]) - (pt.positions[1] - a[1]) * (b[0] - a[0]);
      const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
      if (std::abs(cross) / len < 1e-9) break;
      ++seg;
    }
    ASSERT_LT(seg + 1, p.waypoints.size()) << "a trajectory point is off the path";
  }
  // Every waypoint is a point of the trajectory, with zero velocity.
  for (const auto& w : p.waypoints) {
    bool found = false;
    for (const auto& pt : t->points) {
      if (std::abs(pt.positions[0] - w[0]) < 1e-12 && std::abs(pt.positions[1] - w[1]) < 1e-12) {
        found = true;
        EXPECT_NEAR(pt.velocities[0], 0.0, 1e-12);
        EXPECT_NEAR(pt.velocities[1], 0.0, 1e-12);
      }
    }
    EXPECT_TRUE(found);
  }
}

TEST(TimingTest, BaseTranslationAndYawRespectTheirLimitsOnRandomPaths) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    JointPath p;
    p.joint_names = {"base_x", "base_y", "base_theta", "j2"};
    for (int k = 0; k < 5; ++k) p.waypoints.push_back({u(rng), u(rng), u(rng), u(rng) / 3});
    const auto t = timeParameterize(p, limits());
    ASSERT_TRUE(t.ok());
    checkLimits(*t, limits());
    // Yaw is unwrapped: consecutive trajectory yaws never jump by more than pi.
    for (std::size_t i = 1; i < t->points.size(); ++i) {
      EXPECT_LT(std::abs(t->points[i].positions[2] - t->points[i - 1].positions[2]), M_PI);
    }
  }
}

TEST(TimingTest, BadInputIsAnErrorNamingTheProblem) {
  JointPath p;
  p.joint_names = {"unknown"};
  p.waypoints = {{0.0}, {1.0}};
  auto t = timeParameterize(p, limits());
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.error().message.find("unknown"), std::string::npos);
  p.joint_names = {"j1"};
  p.waypoints = {{0.0}, {NAN}};
  t = timeParameterize(p, limits());
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.error().message.find("waypoint 1"), std::string::npos);
  p.waypoints = {};
  EXPECT_FALSE(timeParameterize(p, limits()).ok());
  TimingLimits bad = limits();
  bad.joints[0].max_velocity = 0;
  p.waypoints = {{0.0}, {1.0}};
  t = timeParameterize(p, bad);
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.error().message.find("j1"), std::string::npos);
}

}  // namespace
}  // namespace tamp::motion_planner
