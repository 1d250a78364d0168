#pragma once
/// @file
/// Small geometric value types shared by every service. Frames: the world frame is z-up, metres,
/// radians; planar poses are (x, y, theta) in the world's xy-plane with theta counter-clockwise
/// from +x. 3-D poses are `Eigen::Isometry3d`.

#include <cmath>
#include <iosfwd>

#include <Eigen/Geometry>

namespace tamp {

/// Wraps an angle to [-pi, pi) (the interval OMPL's SO2 bounds accept).
double wrapAngle(double a);
/// Smallest signed difference a - b, in [-pi, pi).
inline double angleDiff(double a, double b) { return wrapAngle(a - b); }

struct Pose2D {
  double x{0.0};
  double y{0.0};
  double theta{0.0};  ///< rad, counter-clockwise from +x

  /// The pose as a 3-D transform at height z.
  Eigen::Isometry3d toIsometry(double z = 0.0) const;
  /// Projection of a 3-D pose onto the plane (yaw about z).
  static Pose2D fromIsometry(const Eigen::Isometry3d& T);
  /// Euclidean distance of the positions, metres.
  double distanceTo(const Pose2D& o) const { return std::hypot(x - o.x, y - o.y); }
  /// Composition: `*this` then `local` expressed in this frame.
  Pose2D compose(const Pose2D& local) const;
  friend bool operator==(const Pose2D&, const Pose2D&) = default;
};
std::ostream& operator<<(std::ostream& os, const Pose2D& p);

/// Axis-aligned box in 3-D, metres.
struct Aabb {
  Eigen::Vector3d min{Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity())};
  Eigen::Vector3d max{Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity())};
  bool empty() const { return (min.array() > max.array()).any(); }
  void extend(const Eigen::Vector3d& p) { min = min.cwiseMin(p); max = max.cwiseMax(p); }
  void extend(const Aabb& b) { if (!b.empty()) { extend(b.min); extend(b.max); } }
  bool overlaps(const Aabb& o) const {
    return !empty() && !o.empty() && (min.array() <= o.max.array()).all() &&
           (o.min.array() <= max.array()).all();
  }
  bool contains(const Eigen::Vector3d& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

}  // namespace tamp
