#include "tamp/sim/depth_sensor.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "tamp/sim/ray_scene.h"

namespace tamp::sim {
namespace {

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Uniform in (0, 1) from the top 53 bits.
inline double unit(std::uint64_t bits) {
  return (static_cast<double>(bits >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

}  // namespace

Status DepthSensorParams::validate() const {
  std::vector<std::string> bad;
  auto check = [&](bool ok, const std::string& field, const std::string& what) {
    if (!ok) bad.push_back("sensor." + field + ": " + what);
  };
  check(!sensor_id.empty(), "sensor_id", "must not be empty");
  check(!frame.empty(), "frame", "must name a robot link");
  check(width >= 1 && width <= 4096, "width", "must be in [1, 4096], got " + std::to_string(width));
  check(height >= 1 && height <= 4096, "height",
        "must be in [1, 4096], got " + std::to_string(height));
  check(std::isfinite(horizontal_fov_rad) && horizontal_fov_rad > 0.0 &&
            horizontal_fov_rad < std::numbers::pi,
        "horizontal_fov_rad", "must be in (0, pi), got " + std::to_string(horizontal_fov_rad));
  check(std::isfinite(min_range_m) && min_range_m >= 0.0, "min_range_m",
        "must be finite and >= 0, got " + std::to_string(min_range_m));
  check(std::isfinite(max_range_m) && max_range_m > min_range_m, "max_range_m",
        "must be finite and > min_range_m, got " + std::to_string(max_range_m));
  check(std::isfinite(noise_stddev_m) && noise_stddev_m >= 0.0, "noise_stddev_m",
        "must be finite and >= 0, got " + std::to_string(noise_stddev_m));
  check(std::isfinite(noise_quadratic) && noise_quadratic >= 0.0, "noise_quadratic",
        "must be finite and >= 0, got " + std::to_string(noise_quadratic));
  check(dropout_probability >= 0.0 && dropout_probability < 1.0, "dropout_probability",
        "must be in [0, 1), got " + std::to_string(dropout_probability));
  if (bad.empty()) return Status::Ok();
  std::string msg;
  for (const auto& b : bad) msg += (msg.empty() ? "" : "; ") + b;
  return Error(ErrorCode::kInvalidArgument, msg,
               SourceLocation{"", 0, 0, bad.front().substr(0, bad.front().find(':'))});
}

double DepthSensorParams::focalPx() const { return 0.5 * width / std::tan(0.5 * horizontal_fov_rad); }

double DepthSensorParams::verticalFovRad() const {
  return 2.0 * std::atan(0.5 * height / focalPx());
}

DepthSensor::DepthSensor(DepthSensorParams params) : params_(std::move(params)) {
  if (Status s = params_.validate(); !s) {
    throw std::invalid_argument("DepthSensor: " + s.error().message);
  }
  fx_ = params_.focalPx();
  cx_ = 0.5 * (params_.width - 1);
  cy_ = 0.5 * (params_.height - 1);
}

Eigen::Vector3d DepthSensor::pixelRay(int u, int v) const {
  return {(u - cx_) / fx_, (v - cy_) / fx_, 1.0};
}

PointCloudFrame DepthSensor::capture(const world::World& world,
                                     const Eigen::Isometry3d& world_T_sensor,
                                     std::int64_t stamp_ns, GroundTruthLabels* labels) {
  return render(world, world_T_sensor, stamp_ns, nullptr, labels);
}

PointCloudFrame DepthSensor::capture(const world::World& world, const robot::RobotModel& robot,
                                     const robot::RobotState& state, std::int64_t stamp_ns,
                                     GroundTruthLabels* labels) {
  auto pose = robot.linkPoseInWorld(params_.frame, state);
  if (!pose) {
    throw std::invalid_argument("DepthSensor: robot '" + robot.name() + "' has no link '" +
                                params_.frame + "' (sensor.frame)");
  }
  const RobotView view{&robot, &state};
  return render(world, *pose, stamp_ns, params_.see_robot ? &view : nullptr, labels);
}

PointCloudFrame DepthSensor::render(const world::World& world,
                                    const Eigen::Isometry3d& world_T_sensor,
                                    std::int64_t stamp_ns, const RobotView* robot,
                                    GroundTruthLabels* labels) {
  if (!world_T_sensor.matrix().allFinite()) {
    throw std::invalid_argument("DepthSensor: sensor pose is not finite");
  }
  // Frustum culling: a shape whose world box lies entirely behind the sensor, beyond its range,
  // or outside one of the four side planes cannot be hit by any pixel's ray.
  const Eigen::Isometry3d sensor_T_world = world_T_sensor.inverse();
  const double tan_x = (cx_ + 0.5) / fx_, tan_y = (cy_ + 0.5) / fx_;
  auto visible = [&](const world::Shape& shape, const Eigen::Isometry3d& pose) {
    const Aabb box = shape.aabb(pose);
    int out[6] = {0, 0, 0, 0, 0, 0};
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d corner((k & 1) ? box.max.x() : box.min.x(), (k & 2) ? box.max.y() : box.min.y(),
                                   (k & 4) ? box.max.z() : box.min.z());
      const Eigen::Vector3d p = sensor_T_world * corner;
      out[0] += p.z() <= 0.0;
      out[1] += p.z() > params_.max_range_m;
      out[2] += p.x() > tan_x * p.z();
      out[3] += p.x() < -tan_x * p.z();
      out[4] += p.y() > tan_y * p.z();
      out[5] += p.y() < -tan_y * p.z();
    }
    for (int n : out) {
      if (n == 8) return false;
    }
    return true;
  };
  RayScene scene;
  scene.setFloor(0.0);
  std::vector<std::string> ids;
  ids.reserve(world.objectCount());
  for (const world::Object& o : world.objects()) {
    if (visible(o.shape, o.pose)) scene.add(o.shape, o.pose, static_cast<int>(ids.size()));
    ids.push_back(o.id);
  }
  if (robot != nullptr) {
    std::vector<Eigen::Isometry3d> link_poses;
    robot->robot->linkPoses(*robot->state, link_poses);
    const auto& geometry = robot->robot->collisionGeometry();
    const int first_link_tag = static_cast<int>(ids.size());
    for (const auto& name : geometry.links) ids.push_back(name);
    for (const auto& part : geometry.parts) {
      const Eigen::Isometry3d pose = link_poses[part.link] * part.link_T_shape;
      if (visible(part.shape, pose)) scene.add(part.shape, pose, first_link_tag + part.link);
    }
  }
  scene.build();

  const int w = params_.width, h = params_.height;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  PointCloudFrame frame;
  frame.sensor_id = params_.sensor_id;
  frame.stamp_ns = stamp_ns;
  frame.world_T_sensor = world_T_sensor;
  frame.width = static_cast<uint32_t>(w);
  frame.height = static_cast<uint32_t>(h);
  frame.xyz.assign(3 * n, std::numeric_limits<float>::quiet_NaN());
  if (labels != nullptr) {
    labels->pixel.assign(n, GroundTruthLabels::kNone);
    labels->ids = ids;
  }

  const Eigen::Matrix3d R = world_T_sensor.linear();
  const Eigen::Vector3d origin = world_T_sensor.translation();
  const double max_range = params_.max_range_m;
  const double min_range = params_.min_range_m;
  const double sigma0 = params_.noise_stddev_m, sigma2 = params_.noise_quadratic;
  const double p_drop = params_.dropout_probability;
  const std::uint64_t frame_key = splitmix64(params_.seed ^ splitmix64(frames_));
  ++frames_;
  // Columns of R scaled by the pixel offsets: dir = R * ((u - cx)/fx, (v - cy)/fx, 1).
  const Eigen::Vector3d rx = R.col(0) / fx_, ry = R.col(1) / fx_, rz = R.col(2);
  for (int v = 0; v < h; ++v) {
    const Eigen::Vector3d row = rz + (v - cy_) * ry;
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector3d dir = row + (u - cx_) * rx;
      // A unit-depth ray: the ray parameter is the depth z. Cast from just in front of the lens
      // so that nearer surfaces occlude even when they are below min_range (then: no return).
      const RayHit hit = scene.cast(origin, dir, 1e-6, max_range);
      if (!hit.hit()) continue;
      const std::size_t i = static_cast<std::size_t>(v) * w + u;
      if (labels != nullptr) {
        labels->pixel[i] = hit.tag == kFloorTag ? GroundTruthLabels::kFloor : hit.tag;
      }
      if (hit.t < min_range) continue;
      double z = hit.t;
      if (p_drop > 0.0 || sigma0 > 0.0 || sigma2 > 0.0) {
        const std::uint64_t k = splitmix64(frame_key ^ (0x632be59bd9b4e019ULL * (i + 1)));
        const std::uint64_t k2 = splitmix64(k);
        if (p_drop > 0.0 && unit(k) < p_drop) continue;
        const double sigma = sigma0 + sigma2 * z * z;
        if (sigma > 0.0) {
          // Box-Muller (cosine branch) from two independent uniforms.
          const double g = std::sqrt(-2.0 * std::log(unit(k2))) *
                           std::cos(2.0 * std::numbers::pi * unit(splitmix64(k2)));
          z += sigma * g;
          if (z <= 0.0) continue;
        }
      }
      const double x = (u - cx_) / fx_ * z;
      const double y = (v - cy_) / fx_ * z;
      frame.xyz[3 * i] = static_cast<float>(x);
      frame.xyz[3 * i + 1] = static_cast<float>(y);
      frame.xyz[3 * i + 2] = static_cast<float>(z);
    }
  }
  return frame;
}

}  // namespace tamp::sim
