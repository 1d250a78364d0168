#include "tamp/core/trajectory.h"

#include <gtest/gtest.h>

namespace tamp {
namespace {

Trajectory line() {
  Trajectory t;
  t.joint_names = {"base_x", "base_y", "base_theta"};
  t.points = {{0.0, {0, 0, 0}, {}}, {2.0, {2, 0, 0}, {}}, {3.0, {2, 1, 0}, {}}};
  return t;
}

TEST(ActionKindTest, NamesRoundTrip) {
  for (ActionKind k : kAllActionKinds) EXPECT_EQ(actionKindFromString(toString(k)), k);
  EXPECT_FALSE(actionKindFromString("fly").has_value());
}

TEST(TrajectoryTest, SampleInterpolatesAndClamps) {
  Trajectory t = line();
  EXPECT_DOUBLE_EQ(t.duration(), 3.0);
  EXPECT_EQ(t.sample(-1.0), (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(t.sample(1.0), (std::vector<double>{1, 0, 0}));
  EXPECT_EQ(t.sample(2.5), (std::vector<double>{2, 0.5, 0}));
  EXPECT_EQ(t.sample(10.0), (std::vector<double>{2, 1, 0}));
  EXPECT_EQ(t.indexOf("base_y"), 1);
  EXPECT_EQ(t.indexOf("elbow"), -1);
  EXPECT_EQ(t.path().waypoints.size(), 3u);
}

TEST(TrajectoryTest, ValidateRejectsBadShapes) {
  Trajectory t = line();
  EXPECT_NO_THROW(t.validate());
  t.points[1].positions.pop_back();
  EXPECT_THROW(t.validate(), std::invalid_argument);
  t = line();
  t.points[2].time_from_start = 1.0;
  EXPECT_THROW(t.validate(), std::invalid_argument);
  JointPath p{{"a", "b"}, {{1, 2}, {3}}};
  EXPECT_THROW(p.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace tamp
