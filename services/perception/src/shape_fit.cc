#include "tamp/perception/shape_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>

#include "tamp/core/geometry.h"
#include "tamp/world/polygon.h"

namespace tamp::perception {
namespace {

constexpr double kPi = std::numbers::pi;

double cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

double segmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

/// Distance from p to the boundary of a closed polygon (ring of vertices).
double ringDistance(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& ring) {
  if (ring.empty()) return std::numeric_limits<double>::infinity();
  if (ring.size() == 1) return (p - ring[0]).norm();
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < ring.size(); ++i) {
    best = std::min(best, segmentDistance(p, ring[i], ring[(i + 1) % ring.size()]));
  }
  return best;
}

/// Distance from p (xy) to the boundary of a centred rectangle of half extents h in its frame.
double rectBoundaryDistance(const Eigen::Vector2d& local, const Eigen::Vector2d& h) {
  const double dx = std::abs(local.x()) - h.x();
  const double dy = std::abs(local.y()) - h.y();
  if (dx <= 0 && dy <= 0) return std::min(-dx, -dy);  // inside: nearest edge
  return std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
}

Eigen::Vector2d axis(double yaw) { return {std::cos(yaw), std::sin(yaw)}; }

double rms(double sum_sq, std::size_t n) { return n > 0 ? std::sqrt(sum_sq / static_cast<double>(n)) : 0.0; }

}  // namespace

// ---- planar geometry ----------------------------------------------------------------------------

std::vector<Eigen::Vector2d> convexHull(std::vector<Eigen::Vector2d> pts) {
  // Akl-Toussaint: points strictly inside the octagon of the extreme points in 8 directions are
  // no hull vertices; dropping them first (O(n)) leaves little to sort (a floor plane's ~50k
  // inliers: the sort was ~4 % of a frame). The hull is exactly the same.
  if (pts.size() > 64) {
    // Directions CCW: +x, +x+y, +y, -x+y, -x, -x-y, -y, +x-y.
    std::size_t ext[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    double best[8];
    for (int d = 0; d < 8; ++d) best[d] = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double x = pts[i].x(), y = pts[i].y();
      const double sc[8] = {x, x + y, y, y - x, -x, -x - y, -y, x - y};
      for (int d = 0; d < 8; ++d) {
        if (sc[d] > best[d]) {
          best[d] = sc[d];
          ext[d] = i;
        }
      }
    }
    std::vector<Eigen::Vector2d> poly;
    for (int d = 0; d < 8; ++d) {
      const Eigen::Vector2d& v = pts[ext[d]];
      if (poly.empty() || v != poly.back()) poly.push_back(v);
    }
    while (poly.size() > 1 && poly.front() == poly.back()) poly.pop_back();
    if (poly.size() >= 3) {
      auto inside = [&](const Eigen::Vector2d& q) {
        for (std::size_t e = 0; e < poly.size(); ++e) {
          if (cross(poly[e], poly[(e + 1) % poly.size()], q) <= 0) return false;
        }
        return true;
      };
      pts.erase(std::remove_if(pts.begin(), pts.end(), inside), pts.end());
    }
  }
  std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  std::vector<Eigen::Vector2d> hull(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], pts[i]) <= 0) --k;
    hull[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], pts[i - 1]) <= 0) --k;
    hull[k++] = pts[i - 1];
  }
  hull.resize(k - 1);
  return hull;
}

Rect2 minAreaRect(const std::vector<Eigen::Vector2d>& hull) {
  Rect2 best;
  if (hull.empty()) return best;
  if (hull.size() == 1) {
    best.centre = hull[0];
    return best;
  }
  double best_area = std::numeric_limits<double>::infinity();
  const std::size_t edges = hull.size() == 2 ? 1 : hull.size();
  for (std::size_t i = 0; i < edges; ++i) {
    const Eigen::Vector2d e = hull[(i + 1) % hull.size()] - hull[i];
    if (e.norm() < 1e-12) continue;
    const Eigen::Vector2d u = e.normalized();
    const Eigen::Vector2d v(-u.y(), u.x());
    double umin = std::numeric_limits<double>::infinity(), umax = -umin, vmin = umin, vmax = -umin;
    for (const auto& p : hull) {
      const double a = p.dot(u), b = p.dot(v);
      umin = std::min(umin, a);
      umax = std::max(umax, a);
      vmin = std::min(vmin, b);
      vmax = std::max(vmax, b);
    }
    // Ties (equal areas, e.g. both orientations of a segment) keep the first.
    const double area = (umax - umin) * std::max(vmax - vmin, 1e-12);
    if (area < best_area - 1e-15) {
      best_area = area;
      best.centre = u * (0.5 * (umin + umax)) + v * (0.5 * (vmin + vmax));
      best.yaw = std::atan2(u.y(), u.x());
      best.extents = {umax - umin, vmax - vmin};
    }
  }
  // Normalise the yaw to [0, pi/2) (the rectangle is the same under quarter turns with the
  // extents swapped).
  double yaw = std::fmod(best.yaw, kPi);
  if (yaw < 0) yaw += kPi;
  if (yaw >= kPi / 2) {
    yaw -= kPi / 2;
    std::swap(best.extents.x(), best.extents.y());
  }
  if (yaw >= kPi / 2 - 1e-12) yaw = 0.0;
  best.yaw = yaw;
  return best;
}

Circle fitCircle(const std::vector<Eigen::Vector2d>& points) {
  Circle c;
  const std::size_t n = points.size();
  if (n < 3) return c;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(n);
  // Kasa: x^2 + y^2 + D x + E y + F = 0 in centred coordinates.
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd b(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d q = points[i] - mean;
    A(static_cast<Eigen::Index>(i), 0) = q.x();
    A(static_cast<Eigen::Index>(i), 1) = q.y();
    A(static_cast<Eigen::Index>(i), 2) = 1.0;
    b(static_cast<Eigen::Index>(i)) = -q.squaredNorm();
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  qr.setThreshold(1e-10);
  if (qr.rank() < 3) return c;
  const Eigen::Vector3d s = qr.solve(b);
  Eigen::Vector2d centre(-s(0) / 2, -s(1) / 2);
  double r2 = centre.squaredNorm() - s(2);
  if (!(r2 > 0) || !std::isfinite(r2)) return c;
  double r = std::sqrt(r2);
  // Gauss-Newton on the geometric residuals |p - c| - r.
  for (int it = 0; it < 20; ++it) {
    Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
    Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
    for (const auto& p : points) {
      const Eigen::Vector2d d = (p - mean) - centre;
      const double dn = d.norm();
      if (dn < 1e-12) continue;
      const Eigen::Vector3d J(-d.x() / dn, -d.y() / dn, -1.0);
      const double res = dn - r;
      JtJ += J * J.transpose();
      Jtr += J * res;
    }
    const Eigen::Vector3d step = JtJ.ldlt().solve(-Jtr);
    if (!step.allFinite()) break;
    centre += step.head<2>();
    r += step(2);
    if (step.norm() < 1e-9) break;
  }
  if (!(r > 0) || !std::isfinite(r) || !centre.allFinite()) return c;
  double sum = 0;
  for (const auto& p : points) {
    const double res = ((p - mean) - centre).norm() - r;
    sum += res * res;
  }
  c.centre = centre + mean;
  c.radius = r;
  c.rms = rms(sum, n);
  c.ok = true;
  return c;
}

Circle fitCircleFixedRadius(const std::vector<Eigen::Vector2d>& points, double radius,
                            const Eigen::Vector2d& initial) {
  Circle c;
  c.centre = initial;
  c.radius = radius;
  if (points.empty() || !(radius > 0)) return c;
  Eigen::Vector2d centre = initial;
  double lambda = 1e-6;
  auto cost = [&](const Eigen::Vector2d& cc) {
    double s = 0;
    for (const auto& p : points) {
      const double res = (p - cc).norm() - radius;
      s += res * res;
    }
    return s;
  };
  double current = cost(centre);
  for (int it = 0; it < 30; ++it) {
    Eigen::Matrix2d JtJ = Eigen::Matrix2d::Zero();
    Eigen::Vector2d Jtr = Eigen::Vector2d::Zero();
    for (const auto& p : points) {
      const Eigen::Vector2d d = p - centre;
      const double dn = d.norm();
      if (dn < 1e-12) continue;
      const Eigen::Vector2d J = -d / dn;
      JtJ += J * J.transpose();
      Jtr += J * (dn - radius);
    }
    // Levenberg-Marquardt damping: the fixed-radius problem is ill-posed along a short arc.
    const Eigen::Vector2d step = (JtJ + lambda * Eigen::Matrix2d::Identity()).ldlt().solve(-Jtr);
    if (!step.allFinite()) break;
    const double next = cost(centre + step);
    if (next < current) {
      centre += step;
      current = next;
      lambda *= 0.3;
      if (step.norm() < 1e-9) break;
    } else {
      lambda *= 10;
      if (lambda > 1e6) break;
    }
  }
  c.centre = centre;
  c.rms = rms(current, points.size());
  c.ok = centre.allFinite();
  return c;
}

// ---- detections ---------------------------------------------------------------------------------

double Detection::majorExtent() const { return std::max(rect.extents.x(), rect.extents.y()); }
double Detection::minorExtent() const { return std::min(rect.extents.x(), rect.extents.y()); }

Detection describeCluster(std::vector<Eigen::Vector3d> points, double support_z, const ClusterParams& params) {
  require(points.size() >= 3, "describeCluster: need >= 3 points, got " + std::to_string(points.size()));
  Detection d;
  d.points = std::move(points);
  d.support_z = support_z;
  d.top_z = -std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector2d> xy;
  xy.reserve(d.points.size());
  for (const auto& p : d.points) {
    d.top_z = std::max(d.top_z, p.z());
    xy.emplace_back(p.x(), p.y());
  }
  d.height = std::max(d.top_z - support_z, 0.0);
  const std::vector<Eigen::Vector2d> hull = convexHull(xy);

  // Points near the hull boundary carry the outline (the interior is the top face).
  const double band = std::max(0.01, 0.5 * params.tolerance);
  for (const auto& p : xy) {
    if (ringDistance(p, hull) <= band) d.boundary.push_back(p);
  }
  if (d.boundary.size() < 3) d.boundary = xy;

  // Orientation: among the hull's edge directions, the rectangle whose edges the outline points
  // lie on (closeness criterion, as in L-shape fitting). The minimum-area rectangle alone is
  // ambiguous for an L-shaped view of two faces: its triangle hull has three rectangles of the
  // same area.
  d.rect = minAreaRect(hull);
  if (hull.size() >= 3) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < hull.size(); ++i) {
      const Eigen::Vector2d e = hull[(i + 1) % hull.size()] - hull[i];
      if (e.norm() < 1e-9) continue;
      const double yaw = std::atan2(e.y(), e.x());
      const Eigen::Vector2d u = axis(yaw), v = axis(yaw + kPi / 2);
      double umin = std::numeric_limits<double>::infinity(), umax = -umin, vmin = umin, vmax = -umin;
      for (const auto& p : hull) {
        umin = std::min(umin, p.dot(u));
        umax = std::max(umax, p.dot(u));
        vmin = std::min(vmin, p.dot(v));
        vmax = std::max(vmax, p.dot(v));
      }
      double score = 0;
      for (const auto& p : d.boundary) {
        const double du = std::min(p.dot(u) - umin, umax - p.dot(u));
        const double dv = std::min(p.dot(v) - vmin, vmax - p.dot(v));
        score += std::min(du, dv);
      }
      score += 1e-6 * (umax - umin) * (vmax - vmin);  // ties: the smaller rectangle
      if (score < best - 1e-12) {
        best = score;
        Rect2 r;
        r.centre = u * (0.5 * (umin + umax)) + v * (0.5 * (vmin + vmax));
        r.extents = {umax - umin, vmax - vmin};
        double y = std::fmod(yaw, kPi);
        if (y < 0) y += kPi;
        if (y >= kPi / 2) {
          y -= kPi / 2;
          std::swap(r.extents.x(), r.extents.y());
        }
        r.yaw = y >= kPi / 2 - 1e-12 ? 0.0 : y;
        d.rect = r;
      }
    }
  }
  // The extents come from trimmed quantiles along the rectangle's axes, so that range noise
  // smearing a few returns outwards does not grow the object.
  if (xy.size() >= 50) {
    const Eigen::Vector2d u = axis(d.rect.yaw), v = axis(d.rect.yaw + kPi / 2);
    std::vector<double> pu, pv;
    pu.reserve(xy.size());
    pv.reserve(xy.size());
    for (const auto& p : xy) {
      pu.push_back(p.dot(u));
      pv.push_back(p.dot(v));
    }
    auto quantile = [](std::vector<double>& a, double q) {
      const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(a.size() - 1));
      std::nth_element(a.begin(), a.begin() + k, a.end());
      return a[static_cast<std::size_t>(k)];
    };
    constexpr double kTrim = 0.02;
    const double u0 = quantile(pu, kTrim), u1 = quantile(pu, 1 - kTrim);
    const double v0 = quantile(pv, kTrim), v1 = quantile(pv, 1 - kTrim);
    d.rect.centre = u * (0.5 * (u0 + u1)) + v * (0.5 * (v0 + v1));
    d.rect.extents = {u1 - u0, v1 - v0};
  }

  const Eigen::Vector2d a0 = axis(d.rect.yaw), a1 = axis(d.rect.yaw + kPi / 2);
  const Eigen::Vector2d half = d.rect.extents / 2;
  double sum = 0;
  for (const auto& p : d.boundary) {
    const Eigen::Vector2d q = p - d.rect.centre;
    const double dist = rectBoundaryDistance({q.dot(a0), q.dot(a1)}, half);
    sum += dist * dist;
  }
  d.rect_rms = rms(sum, d.boundary.size());
  d.circle = fitCircle(d.boundary);

  // A cylinder when a circle explains the outline clearly better than a rectangle and is about
  // as large as the points' spread (a straight face fits a huge circle with a small residual).
  const bool cylinder = d.circle.ok && d.circle.rms < params.cylinder_residual_ratio * d.rect_rms &&
                        d.circle.radius <= 0.65 * d.majorExtent() + 0.01 && d.rect_rms > 0.002;
  const double h = std::max(d.height, 1e-3);
  if (cylinder) {
    d.kind = world::ShapeKind::kCylinder;
    d.shape = world::Shape::cylinder(std::max(d.circle.radius, 1e-3), h);
    d.pose = uprightPose(d.circle.centre.x(), d.circle.centre.y(), support_z + h / 2, 0.0);
  } else {
    d.kind = world::ShapeKind::kBox;
    d.shape = world::Shape::box(std::max(d.rect.extents.x(), 1e-3), std::max(d.rect.extents.y(), 1e-3), h);
    d.pose = uprightPose(d.rect.centre.x(), d.rect.centre.y(), support_z + h / 2, d.rect.yaw);
  }
  return d;
}

// ---- known shapes -------------------------------------------------------------------------------

namespace {

/// Where, along `along` from the detection's rectangle centre, the face across `along` that the
/// sensor sees stands: the median of the points below the top (not the top face) and inside the
/// rectangle's width `width` along `across`, `margin` clear of its ends (not the side faces). On a
/// box seen from outside these are that face's points alone. nullopt: too few to tell.
std::optional<double> nearFace(const Detection& det, const Eigen::Vector2d& along, const Eigen::Vector2d& across,
                               double width, double margin) {
  constexpr std::size_t kMinPoints = 12;
  const double half = width / 2 - margin;
  if (half < 0.02) return std::nullopt;
  const double below_top = det.top_z - std::max(0.01, 0.2 * det.height);
  std::vector<double> at;
  for (const auto& p : det.points) {
    if (p.z() > below_top) continue;
    const Eigen::Vector2d q = p.head<2>() - det.rect.centre;
    if (std::abs(q.dot(across)) > half) continue;
    at.push_back(q.dot(along));
  }
  if (at.size() < kMinPoints) return std::nullopt;
  auto mid = at.begin() + static_cast<std::ptrdiff_t>(at.size() / 2);
  std::nth_element(at.begin(), mid, at.end());
  return *mid;
}

/// The rectangle a box-like shape is fitted by, in the shape's own frame.
struct BoxInFrame {
  Eigen::Vector2d dims;    ///< full extents, along `turn` and across
  Eigen::Vector2d offset;  ///< its centre
  double turn{0.0};        ///< its first axis' angle, rad
};

BoxInFrame boxInFrame(const world::Shape& shape, const Aabb& local) {
  if (shape.kind == world::ShapeKind::kPrism && shape.polygon.size() >= 3) {
    const Rect2 r = minAreaRect(convexHull(shape.polygon));
    // An axis-aligned polygon's rectangle is its bounding box (turn 0, as before).
    if (r.extents.x() * r.extents.y() < (local.max.x() - local.min.x()) * (local.max.y() - local.min.y()) - 1e-9)
      return {r.extents, r.centre, r.yaw};
  }
  return {Eigen::Vector2d(local.max.x() - local.min.x(), local.max.y() - local.min.y()),
          0.5 * Eigen::Vector2d(local.max.x() + local.min.x(), local.max.y() + local.min.y()), 0.0};
}

}  // namespace

ShapeFit fitShape(const Detection& det, const world::Shape& shape, const Eigen::Vector3d& sensor,
                  const TrackingParams& params, double yaw_hint, const std::optional<Eigen::Vector2d>& origin_hint,
                  const std::function<bool(const Eigen::Vector3d&)>& seen_free, bool known_size) {
  ShapeFit fit;
  const bool hinted = std::isfinite(yaw_hint);  // a track's yaw; NaN: a first sighting
  const double hint = hinted ? yaw_hint : 0.0;
  const Aabb local = shape.localAabb();
  const double shape_height = local.max.z() - local.min.z();
  fit.height_error = det.height - shape_height;
  const Eigen::Vector2d sensor_xy = sensor.head<2>();
  const double z = det.support_z - local.min.z();  // bottom face on the support

  if (shape.kind == world::ShapeKind::kCylinder || shape.kind == world::ShapeKind::kSphere) {
    const double r = shape.radius;
    Eigen::Vector2d init;
    if (det.circle.ok && std::abs(det.circle.radius - r) < 0.3 * r) {
      init = det.circle.centre;
    } else {
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      for (const auto& p : det.boundary) mean += p;
      mean /= static_cast<double>(std::max<std::size_t>(det.boundary.size(), 1));
      Eigen::Vector2d away = mean - sensor_xy;
      away = away.norm() > 1e-9 ? away.normalized() : Eigen::Vector2d(1, 0);
      init = mean + 0.5 * r * away;
    }
    Circle c = fitCircleFixedRadius(det.boundary, r, init);
    // A fit that wandered off the points (short arcs are ambiguous) falls back to the start.
    if (!c.ok || (c.centre - init).norm() > r + params.size_tolerance) c = fitCircleFixedRadius({}, r, init);
    fit.pose = uprightPose(c.centre.x(), c.centre.y(), z, 0.0);
    fit.residual = c.rms;
    fit.excess = std::max(0.0, det.majorExtent() - 2 * r);
    fit.deficit = std::max(0.0, 2 * r - det.rect.extents.x()) + std::max(0.0, 2 * r - det.rect.extents.y());
  } else {
    // A box, or a prism by its minimum-area rectangle in its own frame: turned by `turn` there,
    // centred at `offset` (a NAMO world's rotated box is a prism whose corners are turned in a
    // frame of yaw 0; by its bounding box the fit turned it a second time, by the rectangle's
    // own angle, and planned drives through its corners: moghaddam world 16). The fit places
    // the rectangle; the object's frame is the rectangle's turned back by `turn`.
    const BoxInFrame box = boxInFrame(shape, local);
    const Eigen::Vector2d dims = box.dims, offset = box.offset;
    const double turn = box.turn;
    const double rect_hint = hint + turn;  // the rectangle's yaw where the track has the object
    const Eigen::Vector2d e = det.rect.extents;
    // By the worst axis, as a cylinder's (its major extent against the diameter). The sum over
    // both axes counted the range noise twice: a far view of occluded_can's 5 x 7 cm box exceeded
    // it by 5.6 cm and fitted the neighbouring can (3.3 cm), whose track then took the box's place.
    auto excessOf = [&](const Eigen::Vector2d& L) { return std::max({0.0, e.x() - L.x(), e.y() - L.y()}); };
    auto deficitOf = [&](const Eigen::Vector2d& L) {
      return std::max(0.0, L.x() - e.x()) + std::max(0.0, L.y() - e.y());
    };
    const Eigen::Vector2d La = dims, Lb(dims.y(), dims.x());
    const double xa = excessOf(La), xb = excessOf(Lb);
    // Which of the box's sides lies along the detection's first axis. A view that shows too
    // little of the box to tell (a face seen from afar fits either side within the size
    // tolerance) keeps the side the track had: a guess would turn a nearly square box a quarter
    // turn and shift its centre by half the sides' difference, towards the robot.
    bool swapped = xb < xa - 1e-9 || (std::abs(xb - xa) <= 1e-9 && deficitOf(Lb) < deficitOf(La) - 1e-9);
    if (std::abs(xb - xa) <= 1e-9 && std::abs(deficitOf(Lb) - deficitOf(La)) <= params.size_tolerance &&
        hinted) {
      const double off_a = std::abs(std::remainder(det.rect.yaw - rect_hint, kPi));
      const double off_b = std::abs(std::remainder(det.rect.yaw + kPi / 2 - rect_hint, kPi));
      swapped = off_b < off_a;
    }
    const Eigen::Vector2d L = swapped ? Lb : La;
    fit.excess = swapped ? xb : xa;
    fit.deficit = deficitOf(L);

    // Anchor each axis on the face the sensor saw.
    const Eigen::Vector2d a0 = axis(det.rect.yaw), a1 = axis(det.rect.yaw + kPi / 2);
    const Eigen::Vector2d s = sensor_xy - det.rect.centre;
    const double su[2] = {s.dot(a0), s.dot(a1)};
    double c[2] = {0, 0};
    const double anchor_tol = 0.5 * params.size_tolerance;
    // The track's box centre (its frame origin plus the bounding box's offset, at its yaw).
    std::optional<Eigen::Vector2d> centre_hint;
    if (origin_hint) centre_hint = *origin_hint + offset.x() * axis(hint) + offset.y() * axis(hint + kPi / 2);
    // Whether the seen end on side `sign` of axis `i` is a face: the space just beyond it, at
    // half the detection's height, is seen free.
    auto faceAt = [&](int i, double sign) {
      if (!centre_hint || !seen_free) return true;
      const Eigen::Vector2d p = det.rect.centre + sign * (e(i) / 2 + 2 * anchor_tol) * (i == 0 ? a0 : a1);
      return seen_free(Eigen::Vector3d(p.x(), p.y(), det.support_z + det.height / 2));
    };
    for (int i = 0; i < 2; ++i) {
      if (e(i) >= L(i) - anchor_tol) continue;
      const bool beyond = std::abs(su[i]) > e(i) / 2;
      const double sign = su[i] < 0 ? -1.0 : 1.0;
      if (beyond && faceAt(i, sign)) {
        c[i] = sign * (e(i) / 2 - L(i) / 2);
      } else if (centre_hint) {
        const double slack = (L(i) - e(i)) / 2;
        c[i] = std::clamp((*centre_hint - det.rect.centre).dot(i == 0 ? a0 : a1), -slack, slack);
      }
    }
    // An axis seen end to end whose near end is the face the sensor looks at most directly:
    // that end is the trimmed extreme of a face smeared by range noise along the rays, towards
    // the sensor as much as away (the fit sat 1-2 cm towards the camera: transport_drop's
    // re-picks). The face's own points place it: their median, the box's length behind it. A
    // face seen at a grazing angle is not used: the other face's points, smeared along the rays,
    // reach into it.
    for (int i = 0; known_size && i < 2; ++i) {
      if (std::abs(su[i]) < std::abs(su[1 - i])) continue;
      // Seen end to end, and no longer than the box by more than the noise (a detection longer
      // than the shape it is fitted to, e.g. a shape still growing from views, stays centred).
      if (e(i) < L(i) - anchor_tol || e(i) > L(i) + params.size_tolerance || std::abs(su[i]) <= e(i) / 2) continue;
      const double sign = su[i] < 0 ? -1.0 : 1.0;
      if (auto face = nearFace(det, i == 0 ? a0 : a1, i == 0 ? a1 : a0, e(i == 0 ? 1 : 0), params.size_tolerance))
        c[i] = *face - sign * L(i) / 2;
    }
    const Eigen::Vector2d centre = det.rect.centre + c[0] * a0 + c[1] * a1;
    double yaw = det.rect.yaw + (swapped ? kPi / 2 : 0.0);
    // The symmetric equivalent closest to the hint.
    const double sym = yawSymmetry(world::Shape::box(dims.x(), dims.y(), 1.0));
    yaw = rect_hint + wrapAngle(yaw - rect_hint);
    yaw -= sym * std::round((yaw - rect_hint) / sym);
    yaw = wrapAngle(yaw);
    // Residual: boundary points against the fitted rectangle.
    const Eigen::Vector2d b0 = axis(yaw), b1 = axis(yaw + kPi / 2);
    double sum = 0;
    for (const auto& p : det.boundary) {
      const Eigen::Vector2d q = p - centre;
      const double dist = rectBoundaryDistance({q.dot(b0), q.dot(b1)}, dims / 2);
      sum += dist * dist;
    }
    fit.residual = rms(sum, det.boundary.size());
    // The object's frame: the rectangle's yaw turned back; its origin the rectangle's centre
    // minus the offset, turned by the object's yaw.
    const double object_yaw = wrapAngle(yaw - turn);
    const Eigen::Vector2d origin = centre - (offset.x() * axis(object_yaw) + offset.y() * axis(object_yaw + kPi / 2));
    fit.pose = uprightPose(origin.x(), origin.y(), z, object_yaw);
  }
  const double height_tol = std::max(params.height_tolerance, 0.1 * shape_height);
  fit.compatible = fit.excess <= params.size_tolerance && std::abs(fit.height_error) <= height_tol;
  return fit;
}

// ---- poses and shapes ---------------------------------------------------------------------------

double yawOf(const Eigen::Isometry3d& pose) {
  const Eigen::Matrix3d R = pose.rotation();
  return wrapAngle(std::atan2(R(1, 0), R(0, 0)));
}

Eigen::Isometry3d uprightPose(double x, double y, double z, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

double yawSymmetry(const world::Shape& shape, double square_tolerance) {
  switch (shape.kind) {
    case world::ShapeKind::kCylinder:
    case world::ShapeKind::kSphere:
      return 0.0;
    case world::ShapeKind::kBox:
      return std::abs(shape.size.x() - shape.size.y()) <= square_tolerance ? kPi / 2 : kPi;
    case world::ShapeKind::kPrism:
      return 2 * kPi;
  }
  return 2 * kPi;
}

double yawError(const world::Shape& shape, double a, double b) {
  const double sym = yawSymmetry(shape);
  if (sym <= 0) return 0.0;
  double d = a - b;
  d -= sym * std::round(d / sym);
  return std::abs(d);
}

bool pointNearSurface(const world::Shape& shape, const Eigen::Isometry3d& pose, const Eigen::Vector3d& p,
                      double tolerance) {
  if (!pointInShape(shape, pose, p, tolerance)) return false;
  const Eigen::Vector3d q = pose.inverse() * p;
  switch (shape.kind) {
    case world::ShapeKind::kBox:
      return !(q.array().abs() < (shape.size.array() / 2 - tolerance)).all();
    case world::ShapeKind::kCylinder:
      return !(std::abs(q.z()) < shape.height / 2 - tolerance && q.head<2>().norm() < shape.radius - tolerance);
    case world::ShapeKind::kSphere:
      return !(q.norm() < shape.radius - tolerance);
    case world::ShapeKind::kPrism: {
      const Eigen::Vector2d xy = q.head<2>();
      const bool deep = std::abs(q.z()) < shape.height / 2 - tolerance && world::containsPoint(shape.polygon, xy) &&
                        ringDistance(xy, shape.polygon) > tolerance;
      return !deep;
    }
  }
  return false;
}

bool pointInShape(const world::Shape& shape, const Eigen::Isometry3d& pose, const Eigen::Vector3d& p, double margin) {
  const Eigen::Vector3d q = pose.inverse() * p;
  switch (shape.kind) {
    case world::ShapeKind::kBox:
      return (q.array().abs() <= (shape.size.array() / 2 + margin)).all();
    case world::ShapeKind::kCylinder:
      return std::abs(q.z()) <= shape.height / 2 + margin && q.head<2>().norm() <= shape.radius + margin;
    case world::ShapeKind::kSphere:
      return q.norm() <= shape.radius + margin;
    case world::ShapeKind::kPrism: {
      if (std::abs(q.z()) > shape.height / 2 + margin) return false;
      const Eigen::Vector2d xy = q.head<2>();
      if (world::containsPoint(shape.polygon, xy)) return true;
      return margin > 0 && ringDistance(xy, shape.polygon) <= margin;
    }
  }
  return false;
}

std::vector<Eigen::Vector3d> volumeSamples(const world::Shape& shape, const Eigen::Isometry3d& pose, int n,
                                           double min_above_bottom) {
  require(n >= 2, "volumeSamples: n must be >= 2, got " + std::to_string(n));
  const Aabb b = shape.localAabb();
  std::vector<Eigen::Vector3d> out;
  out.reserve(static_cast<std::size_t>(n * n * n));
  const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3d t(i / double(n - 1), j / double(n - 1), k / double(n - 1));
        const Eigen::Vector3d q = b.min + t.cwiseProduct(b.max - b.min);
        if (q.z() < b.min.z() + min_above_bottom) continue;
        if (!pointInShape(shape, identity, q, 1e-9)) continue;
        out.push_back(pose * q);
      }
    }
  }
  return out;
}

}  // namespace tamp::perception
