#include "tamp/perception/visibility.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "tamp/perception/shape_fit.h"

namespace tamp::perception {
namespace {
constexpr float kEmpty = std::numeric_limits<float>::infinity();
constexpr double kMaxTan = 4.0;  // ~76 deg off axis: wider than any depth camera
}  // namespace

RangeImage::RangeImage(const PointCloudFrame& frame, double bin)
    : world_T_sensor_(frame.world_T_sensor), sensor_T_world_(frame.world_T_sensor.inverse()), bin_(bin) {
  if (!(bin > 0) || !std::isfinite(bin)) {
    throw std::invalid_argument("RangeImage: bin must be positive, got " + std::to_string(bin));
  }
  // Extent of the returns in tangent coordinates.
  double umin = kMaxTan, umax = -kMaxTan, vmin = kMaxTan, vmax = -kMaxTan;
  const std::size_t n = frame.size();
  for (std::size_t i = 0; i < n; ++i) {
    const float x = frame.xyz[3 * i], y = frame.xyz[3 * i + 1], z = frame.xyz[3 * i + 2];
    if (!std::isfinite(x) || !(z > 0)) continue;
    const double u = std::clamp(double(x) / z, -kMaxTan, kMaxTan), v = std::clamp(double(y) / z, -kMaxTan, kMaxTan);
    umin = std::min(umin, u);
    umax = std::max(umax, u);
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
  }
  if (umin > umax) return;  // no return at all
  u0_ = umin;
  v0_ = vmin;
  cols_ = static_cast<long>(std::floor((umax - umin) / bin_)) + 1;
  rows_ = static_cast<long>(std::floor((vmax - vmin) / bin_)) + 1;
  nearest_.assign(static_cast<std::size_t>(cols_ * rows_), kEmpty);
  for (std::size_t i = 0; i < n; ++i) {
    const float x = frame.xyz[3 * i], y = frame.xyz[3 * i + 1], z = frame.xyz[3 * i + 2];
    if (!std::isfinite(x) || !(z > 0)) continue;
    const long b = binOf(Eigen::Vector3d(x, y, z));
    if (b < 0) continue;
    const float r = std::sqrt(x * x + y * y + z * z);
    float& slot = nearest_[static_cast<std::size_t>(b)];
    slot = std::min(slot, r);
  }
}

long RangeImage::binOf(const Eigen::Vector3d& q) const {
  if (!(q.z() > 0) || cols_ == 0) return -1;
  const double u = q.x() / q.z(), v = q.y() / q.z();
  const double cu = std::floor((u - u0_) / bin_), cv = std::floor((v - v0_) / bin_);
  if (cu < 0 || cv < 0 || cu >= double(cols_) || cv >= double(rows_)) return -1;
  return static_cast<long>(cv) * cols_ + static_cast<long>(cu);
}

double RangeImage::nearestRange(const Eigen::Vector3d& p) const {
  const long b = binOf(sensor_T_world_ * p);
  if (b < 0) return -1.0;
  const float r = nearest_[static_cast<std::size_t>(b)];
  return std::isfinite(r) ? double(r) : -1.0;
}

bool RangeImage::seenThrough(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double margin) const {
  if (cols_ == 0) return false;
  const Eigen::Vector3d origin = world_T_sensor_.translation();
  double umin = kMaxTan, umax = -kMaxTan, vmin = kMaxTan, vmax = -kMaxTan, far = 0.0;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
    const Eigen::Vector3d q = sensor_T_world_ * corner;
    if (!(q.z() > 1e-6)) return false;
    umin = std::min(umin, q.x() / q.z());
    umax = std::max(umax, q.x() / q.z());
    vmin = std::min(vmin, q.y() / q.z());
    vmax = std::max(vmax, q.y() / q.z());
    far = std::max(far, (corner - origin).norm());
  }
  const double c0 = std::floor((umin - u0_) / bin_), c1 = std::floor((umax - u0_) / bin_);
  const double r0 = std::floor((vmin - v0_) / bin_), r1 = std::floor((vmax - v0_) / bin_);
  if (c0 < 0 || r0 < 0 || c1 >= double(cols_) || r1 >= double(rows_)) return false;
  const float limit = static_cast<float>(far + margin);
  for (long r = static_cast<long>(r0); r <= static_cast<long>(r1); ++r) {
    for (long c = static_cast<long>(c0); c <= static_cast<long>(c1); ++c) {
      const float nearest = nearest_[static_cast<std::size_t>(r * cols_ + c)];
      if (!std::isfinite(nearest) || nearest <= limit) return false;
    }
  }
  return true;
}

std::size_t RangeImage::binsWithReturns() const {
  return static_cast<std::size_t>(std::count_if(nearest_.begin(), nearest_.end(), [](float r) { return std::isfinite(r); }));
}

ObjectVisibility RangeImage::checkObject(const world::Object& object, double margin, int n, double bottom_band) const {
  ObjectVisibility vis;
  const double band = std::min(bottom_band, object.shape.halfHeight() * 0.5);
  const std::vector<Eigen::Vector3d> samples = volumeSamples(object.shape, object.pose, n, band);
  const Eigen::Vector3d origin = world_T_sensor_.translation();
  const double bottom_z = object.pose.translation().z() - object.shape.halfHeight();
  for (const Eigen::Vector3d& s : samples) {
    ++vis.samples;
    const Eigen::Vector3d q = sensor_T_world_ * s;
    const long b = binOf(q);
    if (b < 0) continue;
    const float rf = nearest_[static_cast<std::size_t>(b)];
    if (!std::isfinite(rf)) continue;
    ++vis.testable;
    const double r = rf, rs = q.norm();
    const Eigen::Vector3d hit = origin + (s - origin) * (r / rs);
    if (r > rs + margin) {
      ++vis.through;
    } else if (pointInShape(object.shape, object.pose, hit, margin) && hit.z() > bottom_z + band) {
      ++vis.present;
    } else if (r < rs - margin) {
      ++vis.occluded;
    }
  }
  return vis;
}

}  // namespace tamp::perception
