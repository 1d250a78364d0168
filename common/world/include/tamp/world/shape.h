#pragma once
/// @file
/// Primitive solid shapes of the world model and the robot's collision geometry.
///
/// Every shape is expressed in its own frame and **centred at the frame origin**:
/// - box: full extents `size` (x, y, z), faces parallel to the frame axes;
/// - cylinder: axis along +z, `radius`, full `height`, from z = -height/2 to +height/2;
/// - sphere: `radius`;
/// - prism: a planar polygon `polygon` (x, y; counter-clockwise; may be non-convex) extruded
///   along z from -height/2 to +height/2. NAMO obstacles and walls are prisms whose polygon is
///   given relative to its area centroid, so the object's pose is the centroid.
/// Units: metres. A plain value type (a mechanical mapping to the IDL `Shape`).

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/geometry.h"
#include "tamp/world/polygon.h"

namespace tamp::world {

enum class ShapeKind { kBox, kCylinder, kSphere, kPrism };

/// "box", "cylinder", "sphere", "prism".
std::string_view toString(ShapeKind kind);
std::optional<ShapeKind> shapeKindFromString(std::string_view name);

struct Shape {
  ShapeKind kind{ShapeKind::kBox};
  Eigen::Vector3d size{Eigen::Vector3d::Zero()};  ///< kBox: full extents x, y, z (m)
  double radius{0.0};                             ///< kCylinder, kSphere (m)
  double height{0.0};                             ///< kCylinder, kPrism: full extent along z (m)
  Polygon2 polygon;                               ///< kPrism: footprint, counter-clockwise (m)

  static Shape box(double sx, double sy, double sz);
  static Shape cylinder(double radius, double height);
  static Shape sphere(double radius);
  /// The polygon is cleaned (duplicates and collinear vertices removed) and made
  /// counter-clockwise; it is not re-centred.
  static Shape prism(Polygon2 polygon, double height);

  /// Empty when the shape is usable; otherwise why not ("box size must be positive, got ...").
  /// Dimensions must be finite and positive; a prism needs >= 3 vertices and a non-zero area.
  std::optional<std::string> invalidReason() const;
  bool valid() const { return !invalidReason().has_value(); }

  /// Bounding box in the shape's own frame.
  Aabb localAabb() const;
  /// Bounding box of the shape placed at `pose` (world frame).
  Aabb aabb(const Eigen::Isometry3d& pose) const;
  /// Footprint in the shape's frame (its projection on the xy-plane of that frame, for shapes
  /// standing upright): box rectangle, cylinder/sphere as a `segments`-gon, prism polygon.
  Polygon2 footprint(int segments = 24) const;
  /// Volume in m^3.
  double volume() const;
  /// Half the extent along z (distance from the centre to the bottom face of an upright shape).
  double halfHeight() const;

  friend bool operator==(const Shape& a, const Shape& b);
};

/// `shape` `by` metres smaller on each side (boxes, cylinders, spheres; never below 1 mm per
/// extent); prisms are returned as they are. `by` <= 0: unchanged.
Shape shrunk(Shape shape, double by);

/// Bitwise-equal poses (used by diffs); `tolerance` > 0 compares translation (m) and rotation
/// (max matrix element) within it.
bool samePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double tolerance = 0.0);

}  // namespace tamp::world
