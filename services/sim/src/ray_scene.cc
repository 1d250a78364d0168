#include "tamp/sim/ray_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace tamp::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Slab test of the ray against an axis-aligned box; [t0, t1] narrowed in place.
inline bool slab(const Eigen::Vector3d& o, const Eigen::Vector3d& inv_d, const Eigen::Vector3d& lo,
                 const Eigen::Vector3d& hi, double& t0, double& t1) {
  for (int k = 0; k < 3; ++k) {
    double a = (lo[k] - o[k]) * inv_d[k];
    double b = (hi[k] - o[k]) * inv_d[k];
    if (a > b) std::swap(a, b);
    // NaN (0 * inf when the origin lies on a slab plane of a parallel ray) leaves t0/t1 unchanged.
    if (a > t0) t0 = a;
    if (b < t1) t1 = b;
    if (t0 > t1) return false;
  }
  return true;
}

/// Interval of t for which a ray with component (o, d) lies in [-h, h]; false when never.
inline bool axisInterval(double o, double d, double h, double& t0, double& t1) {
  if (d == 0.0) {
    if (o < -h || o > h) return false;
    t0 = -kInf;
    t1 = kInf;
    return true;
  }
  double a = (-h - o) / d;
  double b = (h - o) / d;
  if (a > b) std::swap(a, b);
  t0 = a;
  t1 = b;
  return true;
}

inline bool entryIn(double entry, double exit, double t_min, double t_max) {
  return entry <= exit && entry >= t_min && entry <= t_max;
}

std::optional<double> boxLocal(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                               const Eigen::Vector3d& half, double t_min, double t_max) {
  double entry = -kInf, exit = kInf;
  for (int k = 0; k < 3; ++k) {
    double a, b;
    if (!axisInterval(o[k], d[k], half[k], a, b)) return std::nullopt;
    entry = std::max(entry, a);
    exit = std::min(exit, b);
  }
  if (!entryIn(entry, exit, t_min, t_max)) return std::nullopt;
  return entry;
}

std::optional<double> sphereLocal(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r,
                                  double t_min, double t_max) {
  const double a = d.squaredNorm();
  const double b = o.dot(d);
  const double c = o.squaredNorm() - r * r;
  const double disc = b * b - a * c;
  if (a <= 0.0 || disc < 0.0) return std::nullopt;
  const double s = std::sqrt(disc);
  const double entry = (-b - s) / a;
  const double exit = (-b + s) / a;
  if (!entryIn(entry, exit, t_min, t_max)) return std::nullopt;
  return entry;
}

std::optional<double> cylinderLocal(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r,
                                    double hh, double t_min, double t_max) {
  double entry, exit;
  if (!axisInterval(o.z(), d.z(), hh, entry, exit)) return std::nullopt;
  const double a = d.x() * d.x() + d.y() * d.y();
  const double c = o.x() * o.x() + o.y() * o.y() - r * r;
  if (a < 1e-18) {
    if (c > 0.0) return std::nullopt;  // parallel to the axis, outside the circle
  } else {
    const double b = o.x() * d.x() + o.y() * d.y();
    const double disc = b * b - a * c;
    if (disc < 0.0) return std::nullopt;
    const double s = std::sqrt(disc);
    entry = std::max(entry, (-b - s) / a);
    exit = std::min(exit, (-b + s) / a);
  }
  if (!entryIn(entry, exit, t_min, t_max)) return std::nullopt;
  return entry;
}

inline double cross2(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }

/// First entry into an extruded polygon (possibly non-convex): the top/bottom cap at the slab
/// entry if the ray is inside the polygon there, else the first side edge crossed from outside.
std::optional<double> prismLocal(const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                                 const world::Polygon2& poly, double hh, double t_min,
                                 double t_max) {
  double tz0, tz1;
  if (!axisInterval(o.z(), d.z(), hh, tz0, tz1)) return std::nullopt;
  const double lo = std::max(tz0, t_min);
  const double hi = std::min(tz1, t_max);
  if (lo > hi) return std::nullopt;
  // Cap entry: the ray enters the slab at tz0 (finite) inside the polygon.
  if (std::isfinite(tz0) && tz0 >= t_min && tz0 <= t_max &&
      world::containsPoint(poly, Eigen::Vector2d(o.x() + tz0 * d.x(), o.y() + tz0 * d.y()))) {
    return tz0;
  }
  double best = kInf;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto& a = poly[i];
    const auto& b = poly[(i + 1) % n];
    const double ex = b.x() - a.x(), ey = b.y() - a.y();
    const double denom = cross2(d.x(), d.y(), ex, ey);
    if (denom >= 0.0) continue;  // parallel, or leaving through this edge (ccw: outward = (ey,-ex))
    const double ax = a.x() - o.x(), ay = a.y() - o.y();
    const double t = cross2(ax, ay, ex, ey) / denom;
    if (t < lo || t > hi || t >= best) continue;
    const double s = cross2(ax, ay, d.x(), d.y()) / denom;
    if (s < 0.0 || s >= 1.0) continue;
    best = t;
  }
  if (best == kInf) return std::nullopt;
  return best;
}

}  // namespace

std::optional<double> intersectShape(const world::Shape& shape,
                                     const Eigen::Isometry3d& world_T_shape,
                                     const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                     double t_min, double t_max) {
  const Eigen::Matrix3d Rt = world_T_shape.linear().transpose();
  const Eigen::Vector3d o = Rt * (origin - world_T_shape.translation());
  const Eigen::Vector3d d = Rt * dir;
  switch (shape.kind) {
    case world::ShapeKind::kBox:
      return boxLocal(o, d, 0.5 * shape.size, t_min, t_max);
    case world::ShapeKind::kSphere:
      return sphereLocal(o, d, shape.radius, t_min, t_max);
    case world::ShapeKind::kCylinder:
      return cylinderLocal(o, d, shape.radius, 0.5 * shape.height, t_min, t_max);
    case world::ShapeKind::kPrism:
      return prismLocal(o, d, shape.polygon, 0.5 * shape.height, t_min, t_max);
  }
  return std::nullopt;
}

void RayScene::clear() {
  prims_.clear();
  polygons_.clear();
  order_.clear();
  nodes_.clear();
  built_ = true;
}

void RayScene::add(const world::Shape& shape, const Eigen::Isometry3d& world_T_shape, int tag) {
  if (auto why = shape.invalidReason()) throw std::invalid_argument("RayScene::add: " + *why);
  if (!world_T_shape.matrix().allFinite()) {
    throw std::invalid_argument("RayScene::add: pose of the shape with tag " + std::to_string(tag) +
                                " is not finite");
  }
  Prim p;
  p.kind = shape.kind;
  p.local_R_world = world_T_shape.linear().transpose();
  p.local_t_world = -p.local_R_world * world_T_shape.translation();
  switch (shape.kind) {
    case world::ShapeKind::kBox:
      p.half = 0.5 * shape.size;
      break;
    case world::ShapeKind::kSphere:
      p.radius = shape.radius;
      break;
    case world::ShapeKind::kCylinder:
      p.radius = shape.radius;
      p.half = Eigen::Vector3d(shape.radius, shape.radius, 0.5 * shape.height);
      break;
    case world::ShapeKind::kPrism:
      p.half = Eigen::Vector3d(0.0, 0.0, 0.5 * shape.height);
      polygons_.push_back(std::make_unique<world::Polygon2>(shape.polygon));
      p.polygon = polygons_.back().get();
      break;
  }
  p.box = shape.aabb(world_T_shape);
  p.tag = tag;
  prims_.push_back(std::move(p));
  built_ = false;
}

int RayScene::buildNode(int first, int count) {
  Node node;
  node.lo = Eigen::Vector3d::Constant(kInf);
  node.hi = Eigen::Vector3d::Constant(-kInf);
  Eigen::Vector3d clo = node.lo, chi = node.hi;  // bounds of the centres
  for (int i = first; i < first + count; ++i) {
    const Aabb& b = prims_[order_[i]].box;
    node.lo = node.lo.cwiseMin(b.min);
    node.hi = node.hi.cwiseMax(b.max);
    const Eigen::Vector3d c = 0.5 * (b.min + b.max);
    clo = clo.cwiseMin(c);
    chi = chi.cwiseMax(c);
  }
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back(node);
  if (count <= 2) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const int mid = first + count / 2;
  std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + first + count,
                   [&](int a, int b) {
                     return prims_[a].box.min[axis] + prims_[a].box.max[axis] <
                            prims_[b].box.min[axis] + prims_[b].box.max[axis];
                   });
  const int left = buildNode(first, mid - first);
  const int right = buildNode(mid, first + count - mid);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

void RayScene::build() {
  order_.resize(prims_.size());
  std::iota(order_.begin(), order_.end(), 0);
  nodes_.clear();
  nodes_.reserve(2 * prims_.size());
  if (!prims_.empty()) buildNode(0, static_cast<int>(prims_.size()));
  built_ = true;
}

std::optional<double> RayScene::intersectPrim(const Prim& p, const Eigen::Vector3d& o,
                                              const Eigen::Vector3d& d, double t_min,
                                              double t_max) const {
  const Eigen::Vector3d lo = p.local_R_world * o + p.local_t_world;
  const Eigen::Vector3d ld = p.local_R_world * d;
  switch (p.kind) {
    case world::ShapeKind::kBox:
      return boxLocal(lo, ld, p.half, t_min, t_max);
    case world::ShapeKind::kSphere:
      return sphereLocal(lo, ld, p.radius, t_min, t_max);
    case world::ShapeKind::kCylinder:
      return cylinderLocal(lo, ld, p.radius, p.half.z(), t_min, t_max);
    case world::ShapeKind::kPrism:
      return prismLocal(lo, ld, *p.polygon, p.half.z(), t_min, t_max);
  }
  return std::nullopt;
}

RayHit RayScene::cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min,
                      double t_max) const {
  if (!built_) throw std::logic_error("RayScene::cast: build() not called after add()");
  RayHit best;
  best.t = t_max;
  if (floor_ && dir.z() < 0.0 && origin.z() > *floor_) {
    const double t = (*floor_ - origin.z()) / dir.z();
    if (t >= t_min && t <= best.t) {
      best.t = t;
      best.tag = kFloorTag;
    }
  }
  if (nodes_.empty()) {
    if (!best.hit()) best.t = kInf;
    return best;
  }
  const Eigen::Vector3d inv_d = dir.cwiseInverse();
  // (node, entry parameter of its box); a node whose box starts beyond the best hit is skipped.
  std::array<std::pair<int, double>, 128> stack;
  int top = 0;
  {
    double t0 = t_min, t1 = best.t;
    if (slab(origin, inv_d, nodes_[0].lo, nodes_[0].hi, t0, t1)) stack[top++] = {0, t0};
  }
  while (top > 0) {
    const auto [ni, tnear] = stack[--top];
    if (tnear > best.t) continue;
    const Node& n = nodes_[ni];
    if (n.left < 0) {
      for (int i = n.first; i < n.first + n.count; ++i) {
        const Prim& p = prims_[order_[i]];
        if (auto t = intersectPrim(p, origin, dir, t_min, best.t); t && *t <= best.t) {
          best.t = *t;
          best.tag = p.tag;
        }
      }
      continue;
    }
    double l0 = t_min, l1 = best.t, r0 = t_min, r1 = best.t;
    const bool hl = slab(origin, inv_d, nodes_[n.left].lo, nodes_[n.left].hi, l0, l1);
    const bool hr = slab(origin, inv_d, nodes_[n.right].lo, nodes_[n.right].hi, r0, r1);
    // Push the farther child first so the nearer one is visited first (tightens best.t early).
    if (hl && hr) {
      if (l0 <= r0) {
        stack[top++] = {n.right, r0};
        stack[top++] = {n.left, l0};
      } else {
        stack[top++] = {n.left, l0};
        stack[top++] = {n.right, r0};
      }
    } else if (hl) {
      stack[top++] = {n.left, l0};
    } else if (hr) {
      stack[top++] = {n.right, r0};
    }
  }
  if (!best.hit()) best.t = kInf;
  return best;
}

}  // namespace tamp::sim
