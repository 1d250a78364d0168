#include "tamp/world/polygon.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace tamp::world {
namespace {

Polygon2 square(double x0, double y0, double s) {
  return {{x0, y0}, {x0 + s, y0}, {x0 + s, y0 + s}, {x0, y0 + s}};
}
Polygon2 lShape() { return {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}; }

double triangleArea(const Polygon2& p, const std::array<int, 3>& t) {
  const Point2 a = p[static_cast<size_t>(t[0])], b = p[static_cast<size_t>(t[1])],
               c = p[static_cast<size_t>(t[2])];
  return 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
}

// A random star-shaped (hence simple) polygon around the origin, counter-clockwise.
Polygon2 randomStar(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> r(0.3, 2.0);
  Polygon2 p;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    const double rr = r(rng);
    p.emplace_back(rr * std::cos(a), rr * std::sin(a));
  }
  return p;
}

TEST(PolygonTest, SignedAreaAndOrientation) {
  EXPECT_DOUBLE_EQ(signedArea(square(0, 0, 2)), 4.0);
  Polygon2 cw = square(0, 0, 2);
  std::reverse(cw.begin(), cw.end());
  EXPECT_DOUBLE_EQ(signedArea(cw), -4.0);
  EXPECT_DOUBLE_EQ(signedArea(lShape()), 3.0);
  EXPECT_DOUBLE_EQ(signedArea(Polygon2{{0, 0}, {1, 1}}), 0.0);
}

TEST(PolygonTest, DistancesToASegmentAndToAPolygon) {
  EXPECT_DOUBLE_EQ(segmentDistance({0.0, 1.0}, {-1.0, 0.0}, {1.0, 0.0}), 1.0);
  EXPECT_DOUBLE_EQ(segmentDistance({4.0, 4.0}, {-1.0, 0.0}, {1.0, 0.0}), 5.0);  // to the end (1, 0)
  EXPECT_DOUBLE_EQ(segmentDistance({3.0, 4.0}, {0.0, 0.0}, {0.0, 0.0}), 5.0);   // a point
  const Polygon2 unit{{0.0, 0.0}, {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}};
  EXPECT_DOUBLE_EQ(polygonDistance(unit, {0.5, 0.5}), 0.0);
  EXPECT_DOUBLE_EQ(polygonDistance(unit, {0.5, 3.0}), 2.0);
  EXPECT_DOUBLE_EQ(polygonDistance(unit, {4.0, 5.0}), 5.0);  // to the corner (1, 1)
}

TEST(PolygonTest, AreaCentroidOfLShapeByHand) {
  // Rectangles [0,2]x[0,1] (area 2, centroid (1, .5)) and [0,1]x[1,2] (area 1, centroid (.5, 1.5)).
  const Point2 c = areaCentroid(lShape());
  EXPECT_NEAR(c.x(), 2.5 / 3.0, 1e-12);
  EXPECT_NEAR(c.y(), 2.5 / 3.0, 1e-12);
  // Far from the origin: no loss of precision from the shift.
  Polygon2 far = square(1e6, -1e6, 1.0);
  EXPECT_NEAR(areaCentroid(far).x(), 1e6 + 0.5, 1e-6);
  EXPECT_THROW(areaCentroid(Polygon2{}), std::invalid_argument);
}

TEST(PolygonTest, Convexity) {
  EXPECT_TRUE(isConvex(square(0, 0, 1)));
  EXPECT_FALSE(isConvex(lShape()));
  EXPECT_TRUE(isConvex(Polygon2{{0, 0}, {1, 0}, {2, 0}, {2, 2}, {0, 2}}));  // collinear vertex
  // Pentagram: every turn has the same sign but it winds twice.
  Polygon2 star;
  for (int i = 0; i < 5; ++i)
    star.emplace_back(std::cos(4 * M_PI * i / 5), std::sin(4 * M_PI * i / 5));
  EXPECT_FALSE(isConvex(star));
  EXPECT_FALSE(isConvex(Polygon2{{0, 0}, {1, 0}}));
}

TEST(PolygonTest, InsetOfAConvexPolygon) {
  // A 2 x 1 rectangle inset by 0.25: 1.5 x 0.5, same centre; by 0.5 or more: nothing left.
  const Polygon2 rect{{0, 0}, {2, 0}, {2, 1}, {0, 1}};
  const auto in = insetConvex(rect, 0.25);
  ASSERT_TRUE(in.has_value());
  EXPECT_NEAR(signedArea(*in), 1.5 * 0.5, 1e-12);
  for (const auto& p : *in) {
    EXPECT_GE(p.x(), 0.25 - 1e-12);
    EXPECT_LE(p.x(), 1.75 + 1e-12);
    EXPECT_GE(p.y(), 0.25 - 1e-12);
    EXPECT_LE(p.y(), 0.75 + 1e-12);
  }
  EXPECT_FALSE(insetConvex(rect, 0.5).has_value());
  EXPECT_FALSE(insetConvex(rect, 0.6).has_value());
  // A triangle with a short edge: the edge vanishes, what is left is still every point at least
  // `by` from the boundary (checked at random points).
  const Polygon2 tri{{0, 0}, {4, 0}, {0.1, 1.0}};
  const double by = 0.2;
  const auto t = insetConvex(tri, by);
  ASSERT_TRUE(t.has_value());
  EXPECT_TRUE(isConvex(*t));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ux(-0.5, 4.5), uy(-0.5, 1.5);
  int inside = 0;
  for (int k = 0; k < 20000; ++k) {
    const Point2 p(ux(rng), uy(rng));
    if (!containsPoint(tri, p)) continue;
    double to_boundary = 1e9;
    for (size_t i = 0; i < tri.size(); ++i) to_boundary = std::min(to_boundary, segmentDistance(p, tri[i], tri[(i + 1) % 3]));
    if (std::abs(to_boundary - by) < 1e-6) continue;
    EXPECT_EQ(containsPoint(*t, p), to_boundary > by) << p.transpose();
    inside += containsPoint(*t, p);
  }
  EXPECT_GT(inside, 0);
}

TEST(PolygonTest, ContainsPoint) {
  EXPECT_TRUE(containsPoint(lShape(), {0.5, 1.5}));
  EXPECT_FALSE(containsPoint(lShape(), {1.5, 1.5}));
  EXPECT_FALSE(containsPoint(lShape(), {3, 0.5}));
}

TEST(PolygonTest, CleanRemovesDuplicatesCollinearAndOrientsCcw) {
  Polygon2 p{{0, 0}, {0, 0}, {0, 2}, {2, 2}, {2, 1}, {2, 0}, {1, 0}, {0, 0}};
  const Polygon2 c = cleanPolygon(p);
  ASSERT_EQ(c.size(), 4u);
  EXPECT_GT(signedArea(c), 0.0);
  EXPECT_DOUBLE_EQ(signedArea(c), 4.0);
}

TEST(PolygonTest, TriangulationCoversRandomStarPolygons) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 3 + trial % 40;
    const Polygon2 p = randomStar(rng, n);
    const auto tris = triangulate(p);
    ASSERT_EQ(static_cast<int>(tris.size()), n - 2) << "trial " << trial;
    double sum = 0;
    for (const auto& t : tris) {
      const double a = triangleArea(p, t);
      EXPECT_GE(a, -1e-12) << "clockwise triangle, trial " << trial;
      sum += a;
    }
    EXPECT_NEAR(sum, signedArea(p), 1e-9) << "trial " << trial;
  }
}

TEST(PolygonTest, TriangulationAcceptsClockwiseInput) {
  Polygon2 p = lShape();
  std::reverse(p.begin(), p.end());
  double sum = 0;
  for (const auto& t : triangulate(p)) sum += triangleArea(p, t);
  EXPECT_NEAR(sum, 3.0, 1e-12);
}

TEST(PolygonTest, ConvexDecompositionOfLShapeGivesTwoPieces) {
  const auto pieces = convexDecomposition(lShape());
  ASSERT_EQ(pieces.size(), 2u);
  double sum = 0;
  for (const auto& q : pieces) {
    EXPECT_TRUE(isConvex(q));
    sum += signedArea(q);
  }
  EXPECT_NEAR(sum, 3.0, 1e-12);
}

TEST(PolygonTest, ConvexDecompositionOfRandomPolygons) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 100; ++trial) {
    const Polygon2 p = randomStar(rng, 5 + trial % 30);
    const auto pieces = convexDecomposition(p);
    ASSERT_FALSE(pieces.empty());
    double sum = 0;
    for (const auto& q : pieces) {
      EXPECT_TRUE(isConvex(q)) << "trial " << trial;
      EXPECT_TRUE(containsPoint(p, areaCentroid(q))) << "trial " << trial;
      sum += signedArea(q);
    }
    EXPECT_NEAR(sum, signedArea(cleanPolygon(p)), 1e-9) << "trial " << trial;
    EXPECT_LE(pieces.size(), triangulate(p).size());
  }
}

TEST(PolygonTest, WeaklySimpleRingWithSlitDecomposesToTheRing) {
  // A 10x10 square with a 6x6 hole, joined by a zero-width slit (the NAMO wall outline style).
  const Polygon2 ring{{0, 0}, {10, 0}, {10, 10}, {0, 10}, {0, 5}, {2, 5},
                      {2, 8}, {8, 8},  {8, 2},   {2, 2},  {2, 5}, {0, 5}};
  EXPECT_NEAR(signedArea(ring), 64.0, 1e-12);
  const auto tris = triangulate(ring);
  double sum = 0;
  for (const auto& t : tris) sum += triangleArea(ring, t);
  EXPECT_NEAR(sum, 64.0, 1e-9);
  const auto pieces = convexDecomposition(ring);
  double psum = 0;
  for (const auto& q : pieces) {
    EXPECT_TRUE(isConvex(q));
    const Point2 c = areaCentroid(q);
    EXPECT_FALSE(c.x() > 2 && c.x() < 8 && c.y() > 2 && c.y() < 8) << "piece inside the hole";
    psum += signedArea(q);
  }
  EXPECT_NEAR(psum, 64.0, 1e-9);
}

TEST(PolygonTest, DegenerateInputsDoNotCrash) {
  EXPECT_TRUE(triangulate(Polygon2{}).empty());
  EXPECT_TRUE(convexDecomposition(Polygon2{{0, 0}, {1, 1}, {2, 2}}).empty());
  // Self-intersecting bow-tie: terminates with n-2 triangles.
  const Polygon2 bow{{0, 0}, {2, 2}, {2, 0}, {0, 2}};
  EXPECT_EQ(triangulate(bow).size(), 2u);
  (void)convexDecomposition(bow);
  const Polygon2 nan{{0, 0}, {std::nan(""), 1}, {1, 1}, {1, 0}};
  EXPECT_EQ(cleanPolygon(nan).size(), 3u);
}

}  // namespace
}  // namespace tamp::world
