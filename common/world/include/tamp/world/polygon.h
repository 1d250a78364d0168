#pragma once
/// @file
/// Planar polygon utilities used by the world model (prism footprints, regions), the NAMO loader
/// and the collision library (convex decomposition of non-convex prisms).
///
/// A polygon is a closed ring of vertices in a plane (metres), without repeating the first vertex
/// at the end. "Simple" means the boundary does not cross itself; "weakly simple" polygons whose
/// boundary touches itself along a zero-width slit (as the NAMO wall outlines do) are accepted by
/// `triangulate()` and `convexDecomposition()`.

#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>

namespace tamp::world {

using Point2 = Eigen::Vector2d;
using Polygon2 = std::vector<Point2>;

/// Signed area (m^2): positive for counter-clockwise vertex order.
double signedArea(const Polygon2& poly);
/// Area centroid; for a degenerate (zero-area) polygon, the mean of the vertices.
/// Precondition: `poly` is not empty (throws std::invalid_argument).
Point2 areaCentroid(const Polygon2& poly);
/// True when every turn has the same sign (collinear vertices allowed) and the polygon has at
/// least 3 vertices and a non-zero area.
bool isConvex(const Polygon2& poly);
/// Even-odd point-in-polygon test. Points exactly on the boundary may go either way.
bool containsPoint(const Polygon2& poly, const Point2& p);
/// Distance from `p` to the segment a-b (a point when a == b).
double segmentDistance(const Point2& p, const Point2& a, const Point2& b);
/// Distance from `p` to the polygon: 0 inside (even-odd, as containsPoint), else to its nearest edge.
double polygonDistance(const Polygon2& poly, const Point2& p);
/// Largest distance from `centre` to a vertex.
double circumradius(const Polygon2& poly, const Point2& centre);

/// The points of a convex counter-clockwise polygon at least `by` (m, >= 0) from its boundary:
/// the polygon inset by `by` (each edge moved inwards, edges that vanish dropped). Nothing when
/// less than a polygon of non-zero area is left.
std::optional<Polygon2> insetConvex(const Polygon2& convex, double by);

/// A copy without consecutive duplicate vertices (closer than `eps`) and without vertices on a
/// straight line between their neighbours, oriented counter-clockwise. The result may have fewer
/// than 3 vertices when the input is degenerate.
Polygon2 cleanPolygon(const Polygon2& poly, double eps = 1e-9);

/// Ear-clipping triangulation of a counter-clockwise (weakly) simple polygon. Returns triangles as
/// counter-clockwise vertex index triples into `poly`; n-2 triangles for n vertices. Never fails:
/// on a self-intersecting input it still terminates and returns a best-effort cover.
std::vector<std::array<int, 3>> triangulate(const Polygon2& poly);

/// Splits a counter-clockwise (weakly) simple polygon into convex polygons (counter-clockwise)
/// whose union is the polygon: ear-clipping triangulation followed by Hertel-Mehlhorn merging
/// (at most 4x the minimal number of pieces). A convex input is returned as one piece.
std::vector<Polygon2> convexDecomposition(const Polygon2& poly);

}  // namespace tamp::world
