#include "tamp/collision/clearance_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace tamp::collision {
namespace {

/// Squared distance of no obstacle (finite: the transform subtracts these).
constexpr double kFar = 1e20;

/// One-dimensional squared Euclidean distance transform of `f` (0 on obstacles, kFar elsewhere)
/// into `d` (Felzenszwalb and Huttenlocher, "Distance Transforms of Sampled Functions").
void transform1d(const std::vector<double>& f, std::vector<double>& d, std::vector<int>& v, std::vector<double>& z) {
  const int n = static_cast<int>(f.size());
  d.assign(f.size(), kFar);
  v.assign(f.size(), 0);
  z.assign(f.size() + 1, 0.0);
  int k = 0;
  v[0] = 0;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  auto meet = [&](int q, int p) {
    return ((f[static_cast<std::size_t>(q)] + double(q) * q) - (f[static_cast<std::size_t>(p)] + double(p) * p)) /
           (2.0 * q - 2.0 * p);
  };
  for (int q = 1; q < n; ++q) {
    double s = meet(q, v[static_cast<std::size_t>(k)]);
    while (k > 0 && s <= z[static_cast<std::size_t>(k)]) {
      --k;
      s = meet(q, v[static_cast<std::size_t>(k)]);
    }
    ++k;
    v[static_cast<std::size_t>(k)] = q;
    z[static_cast<std::size_t>(k)] = s;
    z[static_cast<std::size_t>(k) + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[static_cast<std::size_t>(k) + 1] < q) ++k;
    const int p = v[static_cast<std::size_t>(k)];
    d[static_cast<std::size_t>(q)] = double(q - p) * (q - p) + f[static_cast<std::size_t>(p)];
  }
}

}  // namespace

namespace {

/// Marks the cells of `sq` (nx x ny, row-major) that a footprint occupies (see the header).
class Rasteriser {
 public:
  Rasteriser(std::vector<double>& sq, Eigen::Vector2d origin, double h, int nx, int ny)
      : sq_(sq), origin_(std::move(origin)), h_(h), nx_(nx), ny_(ny) {}

  void add(const world::Polygon2& poly) {
    for (std::size_t i = 0; i < poly.size(); ++i) edge(poly[i], poly[(i + 1) % poly.size()]);
    if (poly.size() >= 3) interior(poly);
  }

 private:
  int cellX(double x) const { return std::clamp(static_cast<int>(std::floor((x - origin_.x()) / h_)), 0, nx_ - 1); }
  int cellY(double y) const { return std::clamp(static_cast<int>(std::floor((y - origin_.y()) / h_)), 0, ny_ - 1); }
  void mark(int ix, int iy) { sq_[static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(ix)] = 0.0; }

  /// Samples h/2 apart: every point of the edge is within h/4 of one, so its cell is one of the
  /// 3 x 3 round the sample's.
  void edge(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / (0.5 * h_))));
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / steps);
      const int cx = cellX(p.x()), cy = cellY(p.y());
      for (int iy = std::max(0, cy - 1); iy <= std::min(ny_ - 1, cy + 1); ++iy)
        for (int ix = std::max(0, cx - 1); ix <= std::min(nx_ - 1, cx + 1); ++ix) mark(ix, iy);
    }
  }

  /// Cells whose centre lies inside (even-odd), row by row.
  void interior(const world::Polygon2& poly) {
    double y0 = poly[0].y(), y1 = poly[0].y();
    for (const auto& p : poly) y0 = std::min(y0, p.y()), y1 = std::max(y1, p.y());
    std::vector<double> xs;
    for (int iy = cellY(y0); iy <= cellY(y1); ++iy) {
      const double yc = origin_.y() + (iy + 0.5) * h_;
      xs.clear();
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const Eigen::Vector2d& a = poly[i];
        const Eigen::Vector2d& b = poly[(i + 1) % poly.size()];
        if ((a.y() <= yc) == (b.y() <= yc)) continue;
        xs.push_back(a.x() + (yc - a.y()) / (b.y() - a.y()) * (b.x() - a.x()));
      }
      std::sort(xs.begin(), xs.end());
      for (std::size_t k = 0; k + 1 < xs.size(); k += 2) {
        // Centres x_c = origin + (ix + 0.5) h within [xs[k], xs[k + 1]].
        const int from = std::max(0, static_cast<int>(std::ceil((xs[k] - origin_.x()) / h_ - 0.5)));
        const int to = std::min(nx_ - 1, static_cast<int>(std::floor((xs[k + 1] - origin_.x()) / h_ - 0.5)));
        for (int ix = from; ix <= to; ++ix) mark(ix, iy);
      }
    }
  }

  std::vector<double>& sq_;
  Eigen::Vector2d origin_;
  double h_;
  int nx_, ny_;
};

}  // namespace

ClearanceGrid::ClearanceGrid(const std::vector<world::Polygon2>& footprints, const Aabb& bounds, double resolution,
                             std::size_t max_cells) {
  if (!(resolution > 0.0) || !std::isfinite(resolution)) {
    throw std::invalid_argument("ClearanceGrid: resolution must be positive and finite, got " +
                                std::to_string(resolution));
  }
  if (bounds.empty() || !bounds.min.head<2>().allFinite() || !bounds.max.head<2>().allFinite()) {
    throw std::invalid_argument("ClearanceGrid: the bounds are empty or not finite");
  }
  for (std::size_t i = 0; i < footprints.size(); ++i)
    for (const auto& p : footprints[i])
      if (!p.allFinite()) throw std::invalid_argument("ClearanceGrid: footprint " + std::to_string(i) + " has a vertex that is not finite");
  const Eigen::Vector2d extent = (bounds.max - bounds.min).head<2>();
  h_ = resolution;
  const double cells = std::ceil(extent.x() / h_ + 1) * std::ceil(extent.y() / h_ + 1);
  if (cells > static_cast<double>(std::max<std::size_t>(max_cells, 1))) h_ *= std::sqrt(cells / static_cast<double>(max_cells));
  origin_ = bounds.min.head<2>();
  nx_ = std::max(1, static_cast<int>(std::ceil(extent.x() / h_)));
  ny_ = std::max(1, static_cast<int>(std::ceil(extent.y() / h_)));
  const auto at = [this](int ix, int iy) { return static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(ix); };

  std::vector<double> sq(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), kFar);
  Rasteriser raster(sq, origin_, h_, nx_, ny_);
  bool any = false;
  for (const auto& poly : footprints) {
    if (poly.empty()) continue;
    raster.add(poly);
    any = true;
  }
  lower_.assign(sq.size(), any ? 0.0f : std::numeric_limits<float>::infinity());
  if (!any) return;

  // Columns, then rows: squared distances in cells between cell centres.
  std::vector<double> f, d, z;
  std::vector<int> v;
  f.resize(static_cast<std::size_t>(ny_));
  for (int ix = 0; ix < nx_; ++ix) {
    for (int iy = 0; iy < ny_; ++iy) f[static_cast<std::size_t>(iy)] = sq[at(ix, iy)];
    transform1d(f, d, v, z);
    for (int iy = 0; iy < ny_; ++iy) sq[at(ix, iy)] = d[static_cast<std::size_t>(iy)];
  }
  f.resize(static_cast<std::size_t>(nx_));
  for (int iy = 0; iy < ny_; ++iy) {
    for (int ix = 0; ix < nx_; ++ix) f[static_cast<std::size_t>(ix)] = sq[at(ix, iy)];
    transform1d(f, d, v, z);
    for (int ix = 0; ix < nx_; ++ix) {
      const double bound = std::sqrt(d[static_cast<std::size_t>(ix)]) * h_ - h_ * std::sqrt(2.0);
      float stored = static_cast<float>(std::max(0.0, bound));
      if (static_cast<double>(stored) > bound) stored = std::nextafter(stored, 0.0f);  // round down
      lower_[at(ix, iy)] = std::max(0.0f, stored);
    }
  }
}

world::Polygon2 floorFootprint(const world::Object& object) {
  const Eigen::Matrix3d& r = object.pose.linear();
  if (std::abs(r(2, 2) - 1.0) > 1e-9) {
    const Aabb b = object.aabb();
    return {{b.min.x(), b.min.y()}, {b.max.x(), b.min.y()}, {b.max.x(), b.max.y()}, {b.min.x(), b.max.y()}};
  }
  constexpr int kSegments = 24;
  world::Polygon2 local = object.shape.footprint(kSegments);
  if (object.shape.kind == world::ShapeKind::kCylinder || object.shape.kind == world::ShapeKind::kSphere)
    for (auto& p : local) p /= std::cos(M_PI / kSegments);  // circumscribed: the circle inside it
  world::Polygon2 out;
  out.reserve(local.size());
  for (const auto& p : local) out.push_back((object.pose * Eigen::Vector3d(p.x(), p.y(), 0.0)).head<2>());
  return out;
}

double ClearanceGrid::clearance(double x, double y) const {
  const double fx = (x - origin_.x()) / h_, fy = (y - origin_.y()) / h_;
  if (!(fx >= 0.0) || !(fy >= 0.0) || fx >= nx_ || fy >= ny_) return 0.0;  // NaN included
  const auto ix = static_cast<std::size_t>(fx), iy = static_cast<std::size_t>(fy);
  return lower_[iy * static_cast<std::size_t>(nx_) + ix];
}

}  // namespace tamp::collision
