#include "tamp/sim/ray_scene.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace tamp::sim {
namespace {

using world::Shape;

Eigen::Isometry3d at(double x, double y, double z, double yaw = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

TEST(IntersectShapeTest, BoxFrontFaceDistance) {
  // Box 1 x 2 x 0.5 centred at (3, 0, 1): the ray along +x from the origin's height hits x = 2.5.
  const auto t = intersectShape(Shape::box(1, 2, 0.5), at(3, 0, 1), {0, 0, 1}, {1, 0, 0}, 0, 10);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 2.5, 1e-12);
  // Non-unit direction: t is in units of |dir|.
  const auto t2 = intersectShape(Shape::box(1, 2, 0.5), at(3, 0, 1), {0, 0, 1}, {2, 0, 0}, 0, 10);
  ASSERT_TRUE(t2);
  EXPECT_NEAR(*t2, 1.25, 1e-12);
  // Rotated 45 deg about z: the near corner is at 3 - sqrt(0.5^2 + ...) -> hits the corner edge.
  const auto t3 =
      intersectShape(Shape::box(1, 1, 0.5), at(3, 0, 1, M_PI / 4), {0, 0, 1}, {1, 0, 0}, 0, 10);
  ASSERT_TRUE(t3);
  EXPECT_NEAR(*t3, 3 - std::sqrt(0.5), 1e-12);
  // Passing above it, behind the ray, beyond t_max, from inside: no hit.
  EXPECT_FALSE(intersectShape(Shape::box(1, 2, 0.5), at(3, 0, 1), {0, 0, 1.3}, {1, 0, 0}, 0, 10));
  EXPECT_FALSE(intersectShape(Shape::box(1, 2, 0.5), at(3, 0, 1), {0, 0, 1}, {-1, 0, 0}, 0, 10));
  EXPECT_FALSE(intersectShape(Shape::box(1, 2, 0.5), at(3, 0, 1), {0, 0, 1}, {1, 0, 0}, 0, 2.4));
  EXPECT_FALSE(intersectShape(Shape::box(1, 2, 0.5), at(3, 0, 1), {3, 0, 1}, {1, 0, 0}, 0, 10));
}

TEST(IntersectShapeTest, CylinderSideAndCap) {
  const Shape c = Shape::cylinder(0.5, 1.0);
  // Side: along +x at mid height -> x = 2 - 0.5.
  auto t = intersectShape(c, at(2, 0, 0.5), {0, 0, 0.5}, {1, 0, 0}, 0, 10);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.5, 1e-12);
  // Off-centre chord: y = 0.3 -> x = 2 - sqrt(0.25 - 0.09) = 1.6.
  t = intersectShape(c, at(2, 0, 0.5), {0, 0.3, 0.5}, {1, 0, 0}, 0, 10);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.6, 1e-12);
  // Cap: straight down from z = 3 onto the top at z = 1.
  t = intersectShape(c, at(2, 0, 0.5), {2.2, 0.1, 3}, {0, 0, -1}, 0, 10);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 2.0, 1e-12);
  // Down, outside the circle: miss. Horizontal above the top: miss.
  EXPECT_FALSE(intersectShape(c, at(2, 0, 0.5), {2.6, 0, 3}, {0, 0, -1}, 0, 10));
  EXPECT_FALSE(intersectShape(c, at(2, 0, 0.5), {0, 0, 1.1}, {1, 0, 0}, 0, 10));
}

TEST(IntersectShapeTest, Sphere) {
  auto t = intersectShape(Shape::sphere(0.25), at(0, 4, 1), {0, 0, 1}, {0, 1, 0}, 0, 10);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 3.75, 1e-12);
  EXPECT_FALSE(intersectShape(Shape::sphere(0.25), at(0, 4, 1), {0.3, 0, 1}, {0, 1, 0}, 0, 10));
}

TEST(IntersectShapeTest, NonConvexPrismNotch) {
  // A U shape open towards -x: outer square [-1,1]^2 minus the notch x in [-1, 0.5], |y| < 0.5.
  world::Polygon2 u{{-1, -1}, {1, -1}, {1, 1}, {-1, 1}, {-1, 0.5}, {0.5, 0.5}, {0.5, -0.5},
                    {-1, -0.5}};
  const Shape p = Shape::prism(u, 1.0);
  ASSERT_TRUE(p.valid()) << *p.invalidReason();
  // Along +x through the notch (y = 0): enters at the notch bottom x = 0.5 (from x = -3: t = 3.5).
  auto t = intersectShape(p, at(0, 0, 0.5), {-3, 0, 0.5}, {1, 0, 0}, 0, 10);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 3.5, 1e-12);
  // Along +x at y = 0.8: enters the arm at x = -1 (t = 2).
  t = intersectShape(p, at(0, 0, 0.5), {-3, 0.8, 0.5}, {1, 0, 0}, 0, 10);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 2.0, 1e-12);
  // Down into the notch: no top cap there, reaches the floor of nothing -> miss.
  EXPECT_FALSE(intersectShape(p, at(0, 0, 0.5), {-0.5, 0, 3}, {0, 0, -1}, 0, 10));
  // Down onto an arm: top cap at z = 1.
  t = intersectShape(p, at(0, 0, 0.5), {-0.5, 0.8, 3}, {0, 0, -1}, 0, 10);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 2.0, 1e-12);
  // Along -y through the notch from above the arm's x range... leaving the upper arm, crossing
  // the notch, re-entering the lower arm: starts inside the upper arm (t_min = 0) -> the first
  // entry is the lower arm's face at y = -0.5 (t = 1.3 from y = 0.8).
  t = intersectShape(p, at(0, 0, 0.5), {-0.5, 0.8, 0.5}, {0, -1, 0}, 0, 10);
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 1.3, 1e-12);
}

TEST(RaySceneTest, FloorAndNearestObject) {
  RayScene s;
  s.add(Shape::box(0.2, 0.2, 0.2), at(2, 0, 0.1), 7);
  s.add(Shape::box(0.2, 0.2, 0.2), at(4, 0, 0.1), 8);
  s.build();
  RayHit h = s.cast({0, 0, 0.1}, {1, 0, 0}, 0, 100);
  EXPECT_EQ(h.tag, 7);
  EXPECT_NEAR(h.t, 1.9, 1e-12);
  // Downwards at 45 deg from z = 1: floor at t = 1 (unit-x direction scaled).
  h = s.cast({0, 5, 1}, {1, 0, -1}, 0, 100);
  EXPECT_EQ(h.tag, kFloorTag);
  EXPECT_NEAR(h.t, 1.0, 1e-12);
  s.setFloor(std::nullopt);
  h = s.cast({0, 5, 1}, {1, 0, -1}, 0, 100);
  EXPECT_FALSE(h.hit());
  // Adding without build() is misuse.
  s.add(Shape::sphere(1), at(0, 0, 0), 1);
  EXPECT_THROW((void)s.cast({0, 0, 0}, {1, 0, 0}, 0, 1), std::logic_error);
  EXPECT_THROW(s.add(Shape::sphere(-1), at(0, 0, 0), 1), std::invalid_argument);
}

// The hierarchy must give exactly the brute-force nearest entry over all shapes.
TEST(RaySceneTest, HierarchyMatchesBruteForce) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> pos(-10, 10), size(0.1, 1.5), yaw(-M_PI, M_PI);
  std::vector<std::pair<Shape, Eigen::Isometry3d>> shapes;
  RayScene s;
  s.setFloor(std::nullopt);
  for (int i = 0; i < 300; ++i) {
    Shape sh;
    switch (i % 4) {
      case 0: sh = Shape::box(size(rng), size(rng), size(rng)); break;
      case 1: sh = Shape::cylinder(size(rng) / 2, size(rng)); break;
      case 2: sh = Shape::sphere(size(rng) / 2); break;
      default:
        sh = Shape::prism({{0, 0}, {size(rng), 0}, {0.3, 0.3}, {size(rng), size(rng)}, {0, 1}},
                          size(rng));
    }
    ASSERT_TRUE(sh.valid()) << *sh.invalidReason();
    Eigen::Isometry3d T = at(pos(rng), pos(rng), pos(rng) / 5, yaw(rng));
    T.rotate(Eigen::AngleAxisd(yaw(rng) / 3, Eigen::Vector3d::UnitX()));
    shapes.emplace_back(sh, T);
    s.add(sh, T, i);
  }
  s.build();
  int hits = 0;
  for (int r = 0; r < 3000; ++r) {
    const Eigen::Vector3d o(pos(rng), pos(rng), pos(rng) / 5);
    const Eigen::Vector3d d = Eigen::Vector3d(pos(rng), pos(rng), pos(rng) / 10).normalized();
    double best = 30.0;
    int tag = kNoHitTag;
    for (int i = 0; i < static_cast<int>(shapes.size()); ++i) {
      if (auto t = intersectShape(shapes[i].first, shapes[i].second, o, d, 0, best); t) {
        best = *t;
        tag = i;
      }
    }
    const RayHit h = s.cast(o, d, 0, 30.0);
    ASSERT_EQ(h.tag, tag) << "ray " << r;
    if (tag != kNoHitTag) {
      ++hits;
      EXPECT_NEAR(h.t, best, 1e-12);
    }
  }
  EXPECT_GT(hits, 300);  // the scene is dense enough for the comparison to mean something
}

}  // namespace
}  // namespace tamp::sim
