#pragma once
/// @file
/// Analytic ray casting against the world's primitive shapes, for the simulated depth sensor.
///
/// A `RayScene` holds solid shapes (box, cylinder, sphere, prism; see world/shape.h) placed in
/// the world, each with a caller-chosen integer tag, plus an optional floor plane. `build()`
/// makes a bounding-volume hierarchy over the shapes' world AABBs (median split, leaves of
/// <= 2 shapes); `cast()` walks it front to back and intersects the candidate shapes exactly in
/// their own frame: slabs for boxes, a quadratic plus caps for cylinders, a quadratic for
/// spheres, and for prisms the z slab plus the polygon's edges (non-convex polygons handled
/// exactly). No FCL: a 640x480 frame is ~300k rays (see bench/sensor_bench.cc).
///
/// Semantics: a hit is where the ray *enters* a solid (a front face) at a distance
/// t in [t_min, t_max] along the ray (t in units of |dir|). A ray starting inside a convex solid
/// does not hit that solid (a camera inside its own housing sees out of it).
///
/// Frames: world frame, z up, metres. Thread safety: `cast()` is const and may run concurrently;
/// `add()`/`build()` need exclusive access.

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/geometry.h"
#include "tamp/world/shape.h"

namespace tamp::sim {

/// Tag reported for a hit on the floor plane.
inline constexpr int kFloorTag = -2;
/// Tag of "no hit".
inline constexpr int kNoHitTag = -1;

/// The nearest entry point along a ray.
struct RayHit {
  double t{std::numeric_limits<double>::infinity()};  ///< ray parameter of the entry point
  int tag{kNoHitTag};                                 ///< tag of the shape hit, kFloorTag, or kNoHitTag
  bool hit() const { return tag != kNoHitTag; }
};

/// Entry parameter of the ray `origin + t * dir` into `shape` placed at `world_T_shape`, if it
/// enters at some t in [t_min, t_max]. `dir` need not be unit length. The shape must be valid.
std::optional<double> intersectShape(const world::Shape& shape,
                                     const Eigen::Isometry3d& world_T_shape,
                                     const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                     double t_min, double t_max);

class RayScene {
 public:
  RayScene() = default;

  /// Removes every shape (the floor setting stays).
  void clear();
  /// Adds a solid. Throws std::invalid_argument when the shape is invalid or the pose is not
  /// finite. Call `build()` before casting.
  void add(const world::Shape& shape, const Eigen::Isometry3d& world_T_shape, int tag);
  /// A floor plane z = `height` seen from above (reported as `kFloorTag`), or none.
  void setFloor(std::optional<double> height) { floor_ = height; }
  const std::optional<double>& floor() const { return floor_; }
  /// Builds the hierarchy over the shapes added so far.
  void build();
  std::size_t size() const { return prims_.size(); }

  /// Nearest entry along `origin + t * dir` with t in [t_min, t_max]. Precondition: `build()`
  /// called after the last `add()` (throws std::logic_error otherwise).
  RayHit cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min,
              double t_max) const;

 private:
  struct Prim {
    world::ShapeKind kind;
    Eigen::Matrix3d local_R_world;  // rotation world -> shape frame
    Eigen::Vector3d local_t_world;  // translation world -> shape frame
    Eigen::Vector3d half;           // box half extents; cylinder/prism: (r, r, h/2); sphere r
    double radius{0.0};
    const world::Polygon2* polygon{nullptr};  // prisms: points into polygons_
    Aabb box;
    int tag{0};
  };
  struct Node {
    Eigen::Vector3d lo, hi;
    int left{-1}, right{-1};  // children; -1 for a leaf
    int first{0}, count{0};   // leaf: range in order_
  };
  int buildNode(int first, int count);
  std::optional<double> intersectPrim(const Prim& p, const Eigen::Vector3d& o,
                                      const Eigen::Vector3d& d, double t_min,
                                      double t_max) const;

  std::vector<Prim> prims_;
  std::vector<std::unique_ptr<world::Polygon2>> polygons_;
  std::vector<int> order_;
  std::vector<Node> nodes_;
  std::optional<double> floor_{0.0};
  bool built_{true};
};

}  // namespace tamp::sim
