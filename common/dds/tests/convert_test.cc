#include "tamp/dds/convert.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace tamp::dds {
namespace {

using ::testing::HasSubstr;

TEST(ConvertTest, StatusCodesRoundTrip) {
  for (ErrorCode c : {ErrorCode::kInvalidArgument, ErrorCode::kParseError, ErrorCode::kUnsupported,
                      ErrorCode::kNotFound, ErrorCode::kIo, ErrorCode::kTimeout, ErrorCode::kCancelled,
                      ErrorCode::kUnavailable, ErrorCode::kInfeasible, ErrorCode::kInternal, ErrorCode::kNotReady}) {
    EXPECT_EQ(fromMsg(toMsg(c)), c);
  }
}

TEST(ConvertTest, PosesRoundTrip) {
  Pose2D p{1, -2, 0.5};
  EXPECT_EQ(*fromMsg(toMsg(p)), p);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translate(Eigen::Vector3d(1, 2, 3));
  T.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 0).normalized()));
  auto back = fromMsg(toMsg(T));
  ASSERT_TRUE(back.ok());
  EXPECT_TRUE(back->isApprox(T, 1e-12));
}

TEST(ConvertTest, RejectsBadPoses) {
  msg::Pose3D m;  // zero quaternion
  auto r = fromMsg(m, "goal_end_effector");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().where.field, "goal_end_effector.orientation");
  msg::Pose2D p;
  p.x(std::nan(""));
  EXPECT_FALSE(fromMsg(p).ok());
}

TEST(ConvertTest, JointPathRoundTripAndShapeErrors) {
  JointPath p{{"base_x", "base_y", "base_theta"}, {{0, 0, 0}, {1, 0, 0.5}}};
  auto back = fromMsg(toMsg(p));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->waypoints, p.waypoints);
  msg::JointPath bad = toMsg(p);
  bad.values().push_back(1.0);
  auto r = fromMsg(bad, "path");
  ASSERT_FALSE(r.ok());
  EXPECT_THAT(r.error().toString(), HasSubstr("7 values are not a multiple of 3 joints"));
}

TEST(ConvertTest, TrajectoryRoundTripAndTimeErrors) {
  Trajectory t;
  t.joint_names = {"a", "b"};
  t.points = {{0.0, {0, 1}, {0, 0}}, {1.5, {1, 2}, {0, 0}}};
  auto back = fromMsg(toMsg(t));
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->points.size(), 2u);
  EXPECT_DOUBLE_EQ(back->duration(), 1.5);
  msg::JointTrajectory m = toMsg(t);
  m.times({1.0, 0.5});
  EXPECT_FALSE(fromMsg(m).ok());
  m = toMsg(t);
  m.positions().pop_back();
  EXPECT_FALSE(fromMsg(m).ok());
}

}  // namespace
}  // namespace tamp::dds
