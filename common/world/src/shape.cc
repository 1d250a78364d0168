#include "tamp/world/shape.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tamp::world {

std::string_view toString(ShapeKind kind) {
  switch (kind) {
    case ShapeKind::kBox:
      return "box";
    case ShapeKind::kCylinder:
      return "cylinder";
    case ShapeKind::kSphere:
      return "sphere";
    case ShapeKind::kPrism:
      return "prism";
  }
  return "unknown";
}

std::optional<ShapeKind> shapeKindFromString(std::string_view name) {
  if (name == "box") return ShapeKind::kBox;
  if (name == "cylinder") return ShapeKind::kCylinder;
  if (name == "sphere") return ShapeKind::kSphere;
  if (name == "prism") return ShapeKind::kPrism;
  return std::nullopt;
}

Shape Shape::box(double sx, double sy, double sz) {
  Shape s;
  s.kind = ShapeKind::kBox;
  s.size = Eigen::Vector3d(sx, sy, sz);
  return s;
}

Shape Shape::cylinder(double radius, double height) {
  Shape s;
  s.kind = ShapeKind::kCylinder;
  s.radius = radius;
  s.height = height;
  return s;
}

Shape Shape::sphere(double radius) {
  Shape s;
  s.kind = ShapeKind::kSphere;
  s.radius = radius;
  return s;
}

Shape Shape::prism(Polygon2 polygon, double height) {
  Shape s;
  s.kind = ShapeKind::kPrism;
  s.polygon = cleanPolygon(polygon);
  s.height = height;
  return s;
}

namespace {
bool positive(double v) { return std::isfinite(v) && v > 0.0; }
std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}
}  // namespace

std::optional<std::string> Shape::invalidReason() const {
  switch (kind) {
    case ShapeKind::kBox:
      if (!positive(size.x()) || !positive(size.y()) || !positive(size.z())) {
        return "box size must be positive and finite, got [" + num(size.x()) + ", " +
               num(size.y()) + ", " + num(size.z()) + "]";
      }
      return std::nullopt;
    case ShapeKind::kCylinder:
      if (!positive(radius)) return "cylinder radius must be positive, got " + num(radius);
      if (!positive(height)) return "cylinder height must be positive, got " + num(height);
      return std::nullopt;
    case ShapeKind::kSphere:
      if (!positive(radius)) return "sphere radius must be positive, got " + num(radius);
      return std::nullopt;
    case ShapeKind::kPrism: {
      if (!positive(height)) return "prism height must be positive, got " + num(height);
      if (polygon.size() < 3) {
        return "prism polygon needs at least 3 distinct, non-collinear vertices, got " +
               std::to_string(polygon.size());
      }
      for (const auto& p : polygon) {
        if (!p.allFinite()) return "prism polygon has a non-finite vertex";
      }
      if (std::abs(signedArea(polygon)) < 1e-12) return "prism polygon has zero area";
      return std::nullopt;
    }
  }
  return "unknown shape kind";
}

Aabb Shape::localAabb() const {
  Aabb b;
  switch (kind) {
    case ShapeKind::kBox:
      b.min = -0.5 * size;
      b.max = 0.5 * size;
      break;
    case ShapeKind::kCylinder:
      b.min = Eigen::Vector3d(-radius, -radius, -0.5 * height);
      b.max = Eigen::Vector3d(radius, radius, 0.5 * height);
      break;
    case ShapeKind::kSphere:
      b.min = Eigen::Vector3d::Constant(-radius);
      b.max = Eigen::Vector3d::Constant(radius);
      break;
    case ShapeKind::kPrism:
      for (const auto& p : polygon) {
        b.extend(Eigen::Vector3d(p.x(), p.y(), -0.5 * height));
        b.extend(Eigen::Vector3d(p.x(), p.y(), 0.5 * height));
      }
      break;
  }
  return b;
}

Aabb Shape::aabb(const Eigen::Isometry3d& pose) const {
  Aabb out;
  if (kind == ShapeKind::kSphere) {
    out.min = pose.translation() - Eigen::Vector3d::Constant(radius);
    out.max = pose.translation() + Eigen::Vector3d::Constant(radius);
    return out;
  }
  if (kind == ShapeKind::kPrism) {
    for (const auto& p : polygon) {
      out.extend(pose * Eigen::Vector3d(p.x(), p.y(), -0.5 * height));
      out.extend(pose * Eigen::Vector3d(p.x(), p.y(), 0.5 * height));
    }
    return out;
  }
  const Aabb l = localAabb();
  if (l.empty()) return out;
  // Centre/half-extent transform of a box: |R| * half.
  const Eigen::Vector3d c = pose * (0.5 * (l.min + l.max));
  const Eigen::Vector3d h = pose.linear().cwiseAbs() * (0.5 * (l.max - l.min));
  out.min = c - h;
  out.max = c + h;
  return out;
}

Polygon2 Shape::footprint(int segments) const {
  Polygon2 out;
  switch (kind) {
    case ShapeKind::kBox: {
      const double hx = 0.5 * size.x(), hy = 0.5 * size.y();
      out = {{-hx, -hy}, {hx, -hy}, {hx, hy}, {-hx, hy}};
      break;
    }
    case ShapeKind::kCylinder:
    case ShapeKind::kSphere: {
      const int n = std::max(segments, 3);
      for (int i = 0; i < n; ++i) {
        const double a = 2 * M_PI * i / n;
        out.emplace_back(radius * std::cos(a), radius * std::sin(a));
      }
      break;
    }
    case ShapeKind::kPrism:
      out = polygon;
      break;
  }
  return out;
}

double Shape::volume() const {
  switch (kind) {
    case ShapeKind::kBox:
      return size.prod();
    case ShapeKind::kCylinder:
      return M_PI * radius * radius * height;
    case ShapeKind::kSphere:
      return 4.0 / 3.0 * M_PI * radius * radius * radius;
    case ShapeKind::kPrism:
      return std::abs(signedArea(polygon)) * height;
  }
  return 0.0;
}

double Shape::halfHeight() const {
  switch (kind) {
    case ShapeKind::kBox:
      return 0.5 * size.z();
    case ShapeKind::kSphere:
      return radius;
    case ShapeKind::kCylinder:
    case ShapeKind::kPrism:
      return 0.5 * height;
  }
  return 0.0;
}

bool operator==(const Shape& a, const Shape& b) {
  if (a.kind != b.kind) return false;
  switch (a.kind) {
    case ShapeKind::kBox:
      return a.size == b.size;
    case ShapeKind::kCylinder:
      return a.radius == b.radius && a.height == b.height;
    case ShapeKind::kSphere:
      return a.radius == b.radius;
    case ShapeKind::kPrism:
      return a.height == b.height && a.polygon == b.polygon;
  }
  return false;
}

Shape shrunk(Shape sh, double by) {
  if (!(by > 0.0)) return sh;
  constexpr double kMin = 1e-3;
  switch (sh.kind) {
    case ShapeKind::kBox:
      sh.size = (sh.size.array() - 2.0 * by).max(kMin).matrix();
      break;
    case ShapeKind::kCylinder:
      sh.radius = std::max(kMin, sh.radius - by);
      sh.height = std::max(kMin, sh.height - 2.0 * by);
      break;
    case ShapeKind::kSphere:
      sh.radius = std::max(kMin, sh.radius - by);
      break;
    case ShapeKind::kPrism:
      break;  // as it is
  }
  return sh;
}

bool samePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double tolerance) {
  if (tolerance <= 0.0) return a.matrix() == b.matrix();
  return (a.translation() - b.translation()).cwiseAbs().maxCoeff() <= tolerance &&
         (a.linear() - b.linear()).cwiseAbs().maxCoeff() <= tolerance;
}

}  // namespace tamp::world
