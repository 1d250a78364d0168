#pragma once
/// @file
/// Is the place where an object should be seen, empty, or hidden? Answered from the frame alone,
/// without the sensor's intrinsics: the returns are binned by direction (tangent coordinates
/// x/z, y/z of the optical frame, i.e. a pinhole image of square bins) keeping the nearest range
/// per bin. For a point of the world the bin of its direction then tells:
/// - no return in that bin: unknown (outside the field of view, out of range, no echo);
/// - nearest return clearly beyond the point: the ray went **through** it (the point is free);
/// - nearest return clearly before it: **occluded** by something in front;
/// - otherwise the ray ends at the point.
/// An object is gone from its place only when enough of its volume is seen through; an object
/// behind another one is occluded, never gone.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/point_cloud.h"
#include "tamp/world/world.h"

namespace tamp::perception {

/// Counts over the sample points of an object's volume.
struct ObjectVisibility {
  int samples{0};   ///< sample points tested
  int testable{0};  ///< with a return in their direction
  int through{0};   ///< the nearest return is beyond the sample (+ margin): that space is free
  int occluded{0};  ///< the nearest return is before the sample and outside the object
  int present{0};   ///< the nearest return lies on/in the object (something is there)
  double throughFraction() const { return testable > 0 ? double(through) / testable : 0.0; }
  double presentFraction() const { return testable > 0 ? double(present) / testable : 0.0; }
};

class RangeImage {
 public:
  /// Bins every valid return of a (validated) frame. `bin` in tangent units (> 0, throws
  /// std::invalid_argument). Points behind the optical plane (z <= 0) are ignored.
  RangeImage(const PointCloudFrame& frame, double bin);

  /// Nearest range (m) of the returns in the direction of world point `p`; < 0 when none.
  double nearestRange(const Eigen::Vector3d& p) const;
  /// True when every bin the box `[lo, hi]` (world frame) projects onto has a return, all
  /// farther than the box's farthest corner + `margin`: every ray through the box passed it.
  /// False when a bin is empty or out of the image, or the box reaches behind the sensor.
  bool seenThrough(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double margin) const;
  /// Tests the volume of `object` (samples `n` per axis, ignoring a band of `bottom_band` m at
  /// its bottom where the supporting surface lies) with a range margin of `margin` m.
  ObjectVisibility checkObject(const world::Object& object, double margin, int n = 5,
                               double bottom_band = 0.03) const;

  const Eigen::Isometry3d& worldTSensor() const { return world_T_sensor_; }
  std::size_t binsWithReturns() const;

 private:
  long binOf(const Eigen::Vector3d& p_sensor) const;  // -1 outside
  Eigen::Isometry3d world_T_sensor_;
  Eigen::Isometry3d sensor_T_world_;
  double bin_;
  double u0_{0}, v0_{0};
  long cols_{0}, rows_{0};
  std::vector<float> nearest_;  // per bin, +inf when empty
};

}  // namespace tamp::perception
