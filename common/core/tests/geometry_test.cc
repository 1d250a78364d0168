#include "tamp/core/geometry.h"

#include <random>

#include <gtest/gtest.h>

namespace tamp {
namespace {

TEST(WrapAngleTest, HalfOpenInterval) {
  EXPECT_DOUBLE_EQ(wrapAngle(M_PI), -M_PI);
  EXPECT_DOUBLE_EQ(wrapAngle(-M_PI), -M_PI);
  EXPECT_NEAR(wrapAngle(3 * M_PI / 2), -M_PI / 2, 1e-12);
  EXPECT_NEAR(wrapAngle(-5 * M_PI / 2), -M_PI / 2, 1e-12);
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> d(-100, 100);
  for (int i = 0; i < 1000; ++i) {
    double a = d(rng), w = wrapAngle(a);
    EXPECT_GE(w, -M_PI);
    EXPECT_LT(w, M_PI);
    EXPECT_NEAR(std::remainder(a - w, 2 * M_PI), 0.0, 1e-9);
  }
}

TEST(Pose2DTest, IsometryRoundTrip) {
  Pose2D p{1.5, -2.0, 0.7};
  Pose2D q = Pose2D::fromIsometry(p.toIsometry(0.3));
  EXPECT_NEAR(q.x, p.x, 1e-12);
  EXPECT_NEAR(q.y, p.y, 1e-12);
  EXPECT_NEAR(q.theta, p.theta, 1e-12);
}

TEST(Pose2DTest, ComposeMatchesIsometryProduct) {
  Pose2D a{1, 2, M_PI / 2}, b{1, 0, M_PI / 2};
  Pose2D c = a.compose(b);
  EXPECT_NEAR(c.x, 1, 1e-12);
  EXPECT_NEAR(c.y, 3, 1e-12);
  EXPECT_NEAR(c.theta, -M_PI, 1e-12);
  Pose2D d = Pose2D::fromIsometry(a.toIsometry() * b.toIsometry());
  EXPECT_NEAR(d.x, c.x, 1e-12);
  EXPECT_NEAR(d.y, c.y, 1e-12);
}

TEST(AabbTest, ExtendOverlapContain) {
  Aabb a;
  EXPECT_TRUE(a.empty());
  a.extend(Eigen::Vector3d(0, 0, 0));
  a.extend(Eigen::Vector3d(1, 1, 1));
  Aabb b;
  b.extend(Eigen::Vector3d(0.5, 0.5, 0.5));
  b.extend(Eigen::Vector3d(2, 2, 2));
  Aabb c;
  c.extend(Eigen::Vector3d(3, 3, 3));
  EXPECT_TRUE(a.overlaps(b));
  EXPECT_FALSE(a.overlaps(c));
  EXPECT_FALSE(a.overlaps(Aabb{}));
  EXPECT_TRUE(a.contains(Eigen::Vector3d(0.2, 0.9, 1.0)));
  EXPECT_FALSE(a.contains(Eigen::Vector3d(1.1, 0, 0)));
}

}  // namespace
}  // namespace tamp
