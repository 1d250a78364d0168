#include "tamp/perception/visibility.h"

#include <numbers>

#include <gtest/gtest.h>

#include "test_scenes.h"

namespace tamp::perception {
namespace {

TEST(VisibilityTest, PresentSeenThroughOccludedOrOutOfView) {
  world::World w("v");
  const world::Object target = testing::box("target", 0.3, 0.3, 0.3, 2.8, 0.0, 0.2);
  const auto cam = testing::mastCamera(0, 0, 0);
  const double margin = 0.05;

  world::World present = w;
  ASSERT_TRUE(present.addObject(target).ok());
  const RangeImage with(testing::render(present, cam, {}, 1), 0.01);
  const ObjectVisibility a = with.checkObject(target, margin);
  EXPECT_GT(a.testable, 20);
  EXPECT_GT(a.presentFraction(), 0.5);
  EXPECT_LT(a.throughFraction(), 0.1);

  const RangeImage without(testing::render(w, cam, {}, 2), 0.01);  // the place is empty
  const ObjectVisibility b = without.checkObject(target, margin);
  EXPECT_GT(b.testable, 20);
  EXPECT_GT(b.throughFraction(), 0.8);
  EXPECT_EQ(b.present, 0);

  world::World blocked = w;  // empty place, but a tall box in front
  ASSERT_TRUE(blocked.addObject(testing::box("blocker", 0.6, 0.8, 1.0, 2.0, 0.0, 0.0)).ok());
  const RangeImage behind(testing::render(blocked, cam, {}, 3), 0.01);
  const ObjectVisibility c = behind.checkObject(target, margin);
  EXPECT_LT(c.throughFraction(), 0.1);
  EXPECT_GT(c.occluded, c.testable / 2);

  const RangeImage away(testing::render(w, testing::mastCamera(0, 0, std::numbers::pi), {}, 4), 0.01);
  EXPECT_EQ(away.checkObject(target, margin).testable, 0);
  EXPECT_LT(away.nearestRange(target.pose.translation()), 0.0);
}

TEST(VisibilityTest, RejectsABadBin) {
  PointCloudFrame f;
  f.xyz = {0, 0, 1};
  f.width = 1;
  EXPECT_THROW(RangeImage(f, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace tamp::perception
