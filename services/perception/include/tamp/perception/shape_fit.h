#pragma once
/// @file
/// Geometry of detections: the footprint of a point cluster (convex hull, minimum-area rectangle,
/// circle fit), the box-or-cylinder decision, and the pose of a known shape fitted to a partial
/// view. Pure Eigen (no PCL): used by the pipeline and testable on hand-made points.
///
/// Frames and conventions: world frame z-up, metres, radians. Objects stand upright: an object's
/// pose is a translation and a yaw about z; a box's yaw is defined modulo pi (modulo pi/2 for a
/// square footprint) and a cylinder's yaw is 0 by convention.
///
/// A depth sensor sees one side of an object. The fitted pose of a known shape is therefore
/// anchored on the faces the sensor saw: along each footprint axis, when the observed extent is
/// shorter than the shape's, the shape is placed so that its near face (towards the sensor)
/// coincides with the observed near face. Heights come from the support surface (the floor or
/// table below), not from the lowest point seen, so occluded bottoms do not bias them.

#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/perception/params.h"
#include "tamp/world/shape.h"

namespace tamp::perception {

/// Convex hull (Andrew's monotone chain), counter-clockwise, without collinear points.
std::vector<Eigen::Vector2d> convexHull(std::vector<Eigen::Vector2d> points);

/// A rectangle in the plane: centre, yaw of its first axis in [0, pi/2), full extents.
struct Rect2 {
  Eigen::Vector2d centre{Eigen::Vector2d::Zero()};
  double yaw{0.0};
  Eigen::Vector2d extents{Eigen::Vector2d::Zero()};  ///< along yaw, along yaw + pi/2
};
/// Minimum-area enclosing rectangle of a convex hull (rotating calipers over hull edges).
/// A hull of fewer than 3 points gives the bounding segment or point.
Rect2 minAreaRect(const std::vector<Eigen::Vector2d>& hull);

struct Circle {
  Eigen::Vector2d centre{Eigen::Vector2d::Zero()};
  double radius{0.0};
  double rms{0.0};  ///< rms geometric residual | |p - c| - r |, m
  bool ok{false};   ///< false for fewer than 3 points or a degenerate (collinear) set
};
/// Least-squares circle: algebraic (Kasa) fit refined by Gauss-Newton on the geometric error.
Circle fitCircle(const std::vector<Eigen::Vector2d>& points);
/// Circle of known radius through the points (Gauss-Newton on the centre from `initial`).
Circle fitCircleFixedRadius(const std::vector<Eigen::Vector2d>& points, double radius,
                            const Eigen::Vector2d& initial);

/// One cluster described as an upright box or cylinder, from what the sensor saw of it.
struct Detection {
  std::vector<Eigen::Vector3d> points;  ///< world frame (voxel-filtered cluster)
  /// xy of the points near the footprint's convex-hull boundary (what the shape fits use).
  std::vector<Eigen::Vector2d> boundary;
  double support_z{0.0};                ///< height of the surface it rests on, m
  double top_z{0.0};                    ///< highest point, m
  double height{0.0};                   ///< top_z - support_z, m
  Rect2 rect;                           ///< minimum-area rectangle of the xy footprint
  Circle circle;                        ///< circle fit of the footprint boundary
  double rect_rms{0.0};                 ///< rms distance of boundary points to the rectangle, m
  world::ShapeKind kind{world::ShapeKind::kBox};  ///< decided: kBox or kCylinder
  world::Shape shape;                   ///< observed size (a partial view: a lower bound)
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};  ///< of `shape`
  /// Largest and smallest footprint extents seen (cylinder: both the diameter), m.
  double majorExtent() const;
  double minorExtent() const;
};

/// Describes a cluster resting on a surface at `support_z`: footprint, box-or-cylinder decision
/// (`params.cylinder_residual_ratio`), observed shape and pose. Precondition: >= 3 points
/// (throws std::invalid_argument).
Detection describeCluster(std::vector<Eigen::Vector3d> points, double support_z,
                          const ClusterParams& params);

/// A known shape fitted to a detection.
struct ShapeFit {
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};  ///< upright, on the detection's support
  double residual{0.0};  ///< rms distance of the footprint boundary points to the shape, m
  double excess{0.0};    ///< m, how far the detection's footprint exceeds the shape's
  double deficit{0.0};   ///< m, how much of the shape's footprint was not seen (sum over axes)
  double height_error{0.0};  ///< detection height - shape height, m
  /// Size-compatible: excess <= size_tolerance and |height_error| <= max(height_tolerance,
  /// 10 % of the shape's height).
  bool compatible{false};
};

/// Fits `shape` (box, cylinder; a sphere as a cylinder of its radius; a prism by its bounding
/// box) to a detection seen from `sensor` (world frame). `yaw_hint` (a track's yaw) resolves a
/// box's yaw among its symmetric equivalents (the result is the equivalent closest to it), and
/// which side of the box a face belongs to when the view cannot tell (both fit within
/// `size_tolerance`). NaN (the default, a first sighting): yaw 0 for the equivalents, the
/// detection's extents for the side.
/// Less of a box seen along an axis than its side: the box is anchored on the seen end nearer to
/// the sensor, taken for a face. With `origin_hint` (a track's pose origin, xy), that end is a
/// face only when `seen_free` says the space just beyond it is seen free (not out of the image,
/// not hidden); along an axis with no face seen (the sensor abreast of the seen part, or its near
/// end cut by the image's edge), every centre within the unseen length explains the points, and
/// the one nearest the track's is taken. Without a hint (a first sighting): the near end is a
/// face, and abreast the seen part's centre is taken. A crate driven past close, its near end
/// below the image, was anchored on that cut 0.9 m off, and taken for a new crate (namo_doorway).
/// A box seen end to end along an axis whose near end is a face towards the sensor, with
/// `known_size`: placed by that face's points (their median), the box's length behind it, not by
/// the trimmed extent, which range noise pulls towards the sensor (1-2 cm: a re-pick missed). A
/// shape still growing from views (`known_size` false) is not a length to measure from.
ShapeFit fitShape(const Detection& detection, const world::Shape& shape, const Eigen::Vector3d& sensor,
                  const TrackingParams& params, double yaw_hint = std::numeric_limits<double>::quiet_NaN(),
                  const std::optional<Eigen::Vector2d>& origin_hint = std::nullopt,
                  const std::function<bool(const Eigen::Vector3d&)>& seen_free = {}, bool known_size = true);

/// Yaw of an upright pose (rotation about world z), in [-pi, pi).
double yawOf(const Eigen::Isometry3d& pose);
/// An upright pose at (x, y, z) with yaw.
Eigen::Isometry3d uprightPose(double x, double y, double z, double yaw);
/// Symmetry of a shape's footprint about its z axis: pi for a rectangle, pi/2 for a square,
/// 0 (any yaw) for a cylinder or sphere, 2 pi for a prism.
double yawSymmetry(const world::Shape& shape, double square_tolerance = 0.01);
/// |a - b| modulo the shape's yaw symmetry, in [0, symmetry/2] (0 for rotation-invariant shapes).
double yawError(const world::Shape& shape, double a, double b);

/// True when world point `p` lies within `tolerance` (m, > 0) of the surface of `shape` placed at
/// `pose`: inside it grown by `tolerance`, not inside it shrunk by `tolerance`.
bool pointNearSurface(const world::Shape& shape, const Eigen::Isometry3d& pose, const Eigen::Vector3d& p,
                      double tolerance);

/// True when world point `p` is inside `shape` placed at `pose`, grown by `margin` (m).
bool pointInShape(const world::Shape& shape, const Eigen::Isometry3d& pose, const Eigen::Vector3d& p,
                  double margin);

/// Points filling a shape (a grid of `n` per axis over its bounding box, kept when inside),
/// in the world frame at `pose`; optionally only those at least `min_above_bottom` above its
/// bottom face.
std::vector<Eigen::Vector3d> volumeSamples(const world::Shape& shape, const Eigen::Isometry3d& pose,
                                           int n, double min_above_bottom = 0.0);

}  // namespace tamp::perception
