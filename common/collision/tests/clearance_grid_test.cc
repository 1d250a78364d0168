#include "tamp/collision/clearance_grid.h"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include <filesystem>

#include <gtest/gtest.h>

#include "tamp/collision/scene.h"
#include "tamp/world/namo.h"

namespace tamp::collision {
namespace {

Aabb box(double x0, double y0, double x1, double y1) {
  Aabb b;
  b.extend(Eigen::Vector3d(x0, y0, 0.0));
  b.extend(Eigen::Vector3d(x1, y1, 1.0));
  return b;
}

/// A rectangle of centre (x, y), half sides (a, b), turned by `yaw`.
world::Polygon2 rect(double x, double y, double a, double b, double yaw) {
  world::Polygon2 out;
  for (const auto& [u, v] : {std::pair{-a, -b}, {a, -b}, {a, b}, {-a, b}})
    out.emplace_back(x + u * std::cos(yaw) - v * std::sin(yaw), y + u * std::sin(yaw) + v * std::cos(yaw));
  return out;
}


// The contract the motion planner relies on: never more than the true distance, so "clearance
// above the robot's radius" is never said of a point where the robot could touch an obstacle.
// And not much less either (else the grid saves no collision checks): within 3 cell diagonals.
TEST(ClearanceGridTest, IsALowerBoundOfTheDistanceToEveryFootprintAndATightOne) {
  std::mt19937 rng(7);
  // Inside the grid (beyond it, a footprint clamped onto the border is much nearer than it is).
  std::uniform_real_distribution<double> u(1.2, 8.8), end(0.0, 10.0), size(0.01, 0.8), yaw(-M_PI, M_PI);
  for (int world = 0; world < 30; ++world) {
    std::vector<world::Polygon2> polys;
    const int n = 1 + world % 9;
    for (int i = 0; i < n; ++i) polys.push_back(rect(u(rng), u(rng), size(rng), size(rng), yaw(rng)));
    if (world % 3 == 0) polys.push_back({{end(rng), end(rng)}, {end(rng), end(rng)}});  // a bare segment
    const double h = world % 2 == 0 ? 0.05 : 0.13;
    const ClearanceGrid grid(polys, box(0.0, 0.0, 10.0, 10.0), h);
    std::uniform_real_distribution<double> in(0.0, 10.0 - 1e-9);
    for (int k = 0; k < 2000; ++k) {
      const Eigen::Vector2d p(in(rng), in(rng));
      double truth = std::numeric_limits<double>::infinity();
      for (const auto& poly : polys) truth = std::min(truth, poly.size() == 2 ? world::segmentDistance(p, poly[0], poly[1]) : world::polygonDistance(poly, p));
      const double c = grid.clearance(p.x(), p.y());
      ASSERT_LE(c, truth + 1e-9) << "world " << world << " at (" << p.transpose() << ")";
      ASSERT_GE(c, truth - 3 * std::sqrt(2.0) * grid.resolution()) << "world " << world << " at (" << p.transpose() << ")";
    }
  }
}

// A NAMO map's walls are one outline round the map, joined to the inner boundary by a slit: the
// room inside it is free, however large the outline's bounding box.
TEST(ClearanceGridTest, TheInsideOfAWallOutlineIsFree) {
  // A 10 x 6 ring of walls 0.2 thick, as one weakly simple polygon (outer ccw, slit, inner cw).
  const world::Polygon2 ring{{0, 0}, {10, 0}, {10, 6}, {0, 6}, {0, 0.1}, {0.2, 0.1}, {0.2, 5.8},
                             {9.8, 5.8}, {9.8, 0.2}, {0.2, 0.2}, {0.2, 0.1}, {0, 0.1}};
  const ClearanceGrid grid({ring}, box(-1.0, -1.0, 11.0, 7.0), 0.05);
  EXPECT_GT(grid.clearance(5.0, 3.0), 2.5);
  EXPECT_LE(grid.clearance(5.0, 3.0), 2.8);
  EXPECT_EQ(grid.clearance(0.1, 3.0), 0.0);
  EXPECT_EQ(grid.clearance(5.0, 0.1), 0.0);
  EXPECT_LE(grid.clearance(5.0, 6.5), 0.5);
}

// The motion planner's use of it, on real NAMO worlds and FCL: wherever the grid's clearance
// exceeds the robot's radius, FCL finds the robot free of every static object.
TEST(ClearanceGridTest, WhereItExceedsTheRobotsRadiusFclFindsNoStaticContact) {
  const std::filesystem::path dir = std::filesystem::path(TAMP_BENCHMARKS_DIR) / "namo";
  const std::vector<std::filesystem::path> files{
      dir / "moghaddam_planning_2016_benchmark" / "moghaddam_planning_2016_benchmark_05.svg",
      dir / "s-namo_cases" / "04_after_the_feast" / "04_after_the_feast.json",
      dir / "stilman_2005_thesis" / "04_chen_difficult_problem" / "04_chen_difficult_problem.json"};
  std::mt19937 rng(3);
  for (const auto& file : files) {
    if (!std::filesystem::exists(file)) continue;
    auto loaded = world::loadNamo(file);
    ASSERT_TRUE(loaded.ok()) << loaded.error().toString();
    const world::World& w = loaded->world;
    Scene scene(w);
    const double r = loaded->robot_radius;
    scene.setRobot(RobotGeometry::disc(r, 1.0));
    std::vector<world::Polygon2> footprints;
    for (const auto& o : w.objects())
      if (o.kind == world::ObjectKind::kStatic) footprints.push_back(floorFootprint(o));
    const Aabb bounds = w.bounds();
    const ClearanceGrid grid(footprints, bounds, 0.05);
    std::uniform_real_distribution<double> ux(bounds.min.x(), bounds.max.x()), uy(bounds.min.y(), bounds.max.y());
    int free_by_fcl = 0, free_by_grid = 0;
    for (int k = 0; k < 20000; ++k) {
      const Pose2D p{ux(rng), uy(rng), 0.0};
      scene.setBasePose(p);
      const bool fcl_free = !scene.robotInCollision(Filter::staticOnly());
      const bool grid_free = grid.clearance(p.x, p.y) > r;
      free_by_fcl += fcl_free;
      free_by_grid += grid_free;
      if (grid_free) {
        ASSERT_TRUE(fcl_free) << file << " at (" << p.x << ", " << p.y << ")";
      }
    }
    EXPECT_GT(free_by_grid, free_by_fcl / 2) << file << ": the grid finds " << free_by_grid << " of FCL's " << free_by_fcl << " free poses";
  }
}

TEST(ClearanceGridTest, AnObstacleBeyondTheGridStillBoundsItsBorder) {
  const ClearanceGrid grid({rect(12.5, 4.5, 0.5, 0.5, 0.0)}, box(0.0, 0.0, 10.0, 10.0), 0.1);
  // 2.05 m from the box: the clamped box stands at the border, 0.05 m away.
  EXPECT_LE(grid.clearance(9.95, 4.5), 2.05);
  EXPECT_LE(grid.clearance(9.95, 4.5), 0.1);
  EXPECT_GT(grid.clearance(2.0, 4.5), 7.5);
}

TEST(ClearanceGridTest, OutsideTheGridThereIsNoClearanceAndWithoutObstaclesNoLimit) {
  const ClearanceGrid empty({}, box(0.0, 0.0, 1.0, 1.0), 0.1);
  EXPECT_EQ(empty.clearance(0.5, 0.5), std::numeric_limits<double>::infinity());
  EXPECT_EQ(empty.clearance(1.5, 0.5), 0.0);
  EXPECT_EQ(empty.clearance(std::nan(""), 0.5), 0.0);
  const ClearanceGrid one({rect(0.5, 0.5, 0.1, 0.1, 0.3)}, box(0.0, 0.0, 1.0, 1.0), 0.1);
  EXPECT_EQ(one.clearance(0.5, 0.5), 0.0);
  EXPECT_EQ(one.clearance(-0.1, 0.5), 0.0);
}

TEST(ClearanceGridTest, TooManyCellsMakeThemCoarserAndBadArgumentsAreRefused) {
  const ClearanceGrid coarse({rect(0.5, 0.5, 0.5, 0.5, 0.0)}, box(0.0, 0.0, 100.0, 100.0), 0.01, 10'000);
  EXPECT_LE(static_cast<long>(coarse.cellsX()) * coarse.cellsY(), 10'500);
  EXPECT_NEAR(coarse.resolution(), 1.0, 0.05);
  EXPECT_THROW(ClearanceGrid({}, box(0.0, 0.0, 1.0, 1.0), 0.0), std::invalid_argument);
  EXPECT_THROW(ClearanceGrid({}, box(0.0, 0.0, 1.0, 1.0), std::nan("")), std::invalid_argument);
  EXPECT_THROW(ClearanceGrid({}, Aabb{}, 0.1), std::invalid_argument);
  EXPECT_THROW(ClearanceGrid({{{0.0, 0.0}, {std::nan(""), 1.0}, {1.0, 1.0}}}, box(0.0, 0.0, 1.0, 1.0), 0.1), std::invalid_argument);
}

TEST(ClearanceGridTest, AFootprintCoversTheObjectUprightOrTilted) {
  world::Object drum;
  drum.id = "drum";
  drum.shape = world::Shape::cylinder(0.3, 1.0);
  drum.pose = Eigen::Isometry3d(Eigen::Translation3d(2.0, 1.0, 0.5));
  const world::Polygon2 f = floorFootprint(drum);
  for (int k = 0; k < 360; ++k) {  // every point of the circle inside the polygon
    const double a = k * M_PI / 180.0;
    EXPECT_TRUE(world::containsPoint(f, {2.0 + 0.2999 * std::cos(a), 1.0 + 0.2999 * std::sin(a)}));
  }
  drum.pose.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();  // lying down
  const world::Polygon2 lying = floorFootprint(drum);
  EXPECT_TRUE(world::containsPoint(lying, {2.0, 1.45}));  // along its axis, now y
  EXPECT_TRUE(world::containsPoint(lying, {2.25, 1.0}));
}

}  // namespace
}  // namespace tamp::collision
