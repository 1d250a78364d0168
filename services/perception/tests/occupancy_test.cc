#include "tamp/perception/occupancy.h"

#include <sstream>

#include <gtest/gtest.h>

#include "tamp/collision/scene.h"
#include "test_scenes.h"

namespace tamp::perception {
namespace {

std::vector<Eigen::Vector3f> column(double x, double y, double z0, double z1) {
  std::vector<Eigen::Vector3f> pts;
  for (double z = z0; z <= z1; z += 0.02) pts.emplace_back(x, y, z);
  return pts;
}

TEST(OccupancyTest, HitsNeedTwoFramesAndRaysClearThem) {
  OccupancyMap map{OccupancyParams()};
  const Eigen::Vector3d origin(0, 0, 1.0);
  const auto obstacle = column(2.0, 0.0, 0.1, 0.6);
  std::vector<Eigen::Vector3f> floor;
  for (double x = 0.5; x < 4.0; x += 0.05) {
    for (double y = -1.0; y < 1.0; y += 0.05) floor.emplace_back(x, y, 0.0);
  }
  std::vector<Eigen::Vector3f> scan = floor;
  scan.insert(scan.end(), obstacle.begin(), obstacle.end());
  map.integrate(origin, scan, obstacle);
  EXPECT_EQ(map.occupiedCount(), 0u) << "one noisy return is not an obstacle";
  map.integrate(origin, scan, obstacle);
  EXPECT_EQ(map.state({2.0, 0.0, 0.3}), CellState::kOccupied);
  EXPECT_EQ(map.state({1.0, 0.0, 0.5}), CellState::kFree);
  EXPECT_EQ(map.state({2.0, 3.0, 0.5}), CellState::kUnknown);
  EXPECT_GE(map.occupiedCount(), 8u);
  for (const auto& v : map.occupiedVoxels()) EXPECT_LT((v.head<2>() - Eigen::Vector2d(2.0, 0.0)).norm(), 0.1);

  // The obstacle is gone: rays to the floor behind it clear it.
  for (int k = 0; k < 4; ++k) map.integrate(origin, floor, {});
  EXPECT_NE(map.state({2.0, 0.0, 0.3}), CellState::kOccupied);
}

TEST(OccupancyTest, KnownObjectsClearTheirVoxelsAndTheBinaryLoadsInTheCollisionScene) {
  OccupancyMap map{OccupancyParams()};
  const auto obstacle = column(2.0, 0.0, 0.1, 0.6);
  const auto other = column(3.0, 1.0, 0.1, 0.4);
  std::vector<Eigen::Vector3f> both = obstacle;
  both.insert(both.end(), other.begin(), other.end());
  for (int k = 0; k < 2; ++k) map.integrate({0, 0, 1}, both, both);
  ASSERT_EQ(map.state({3.0, 1.0, 0.3}), CellState::kOccupied);

  collision::Scene scene{world::World()};
  ASSERT_TRUE(scene.setUnknownSpaceFromOctomapBinary(map.toBinary()).ok());
  const auto probe = world::Shape::box(0.06, 0.06, 0.06);
  EXPECT_TRUE(scene.shapeInCollision(probe, Eigen::Isometry3d(Eigen::Translation3d(3.0, 1.0, 0.3))));
  EXPECT_FALSE(scene.shapeInCollision(probe, Eigen::Isometry3d(Eigen::Translation3d(2.5, 0.5, 0.3))));

  // The column at (2, 0) turns out to be a known object: its voxels are no unknown space.
  const world::Object pole = testing::cylinder("pole", 0.03, 0.7, 2.0, 0.0);
  EXPECT_GT(map.clearObject(pole), 0u);
  EXPECT_NE(map.state({2.0, 0.0, 0.3}), CellState::kOccupied);
  EXPECT_EQ(map.state({3.0, 1.0, 0.3}), CellState::kOccupied);
  ASSERT_TRUE(scene.setUnknownSpaceFromOctomapBinary(map.toBinary()).ok());
  EXPECT_FALSE(scene.shapeInCollision(probe, Eigen::Isometry3d(Eigen::Translation3d(2.0, 0.0, 0.3))));
}

TEST(OccupancyTest, RejectsBadParameters) {
  OccupancyParams p;
  p.resolution = 0;
  EXPECT_THROW(OccupancyMap{p}, std::invalid_argument);
  p = OccupancyParams();
  p.prob_hit = 0.4;
  EXPECT_THROW(OccupancyMap{p}, std::invalid_argument);
}

}  // namespace
}  // namespace tamp::perception
