#include "test_scenes.h"

#include <cmath>

#include "tamp/sim/depth_sensor.h"

namespace tamp::perception::testing {
namespace {

sim::DepthSensorParams sensorParams(const Camera& c) {
  sim::DepthSensorParams p;
  p.sensor_id = "test_camera";
  p.width = c.width;
  p.height = c.height;
  p.horizontal_fov_rad = c.hfov;
  p.min_range_m = c.min_range;
  p.max_range_m = c.max_range;
  p.noise_stddev_m = c.noise;
  p.noise_quadratic = c.noise_quadratic;
  p.dropout_probability = c.dropout;
  p.seed = c.seed;
  return p;
}

}  // namespace

Eigen::Isometry3d mastCamera(double x, double y, double yaw, double height, double pitch) {
  Eigen::Matrix3d link = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()))
                             .toRotationMatrix();
  Eigen::Matrix3d optical;
  optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // columns: optical x, y, z in the link frame
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = link * optical;
  T.translation() = Eigen::Vector3d(x, y, height);
  return T;
}

Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitX();
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

PointCloudFrame render(const world::World& truth, const Eigen::Isometry3d& world_T_sensor, const Camera& cam,
                       std::int64_t stamp_ns, std::uint64_t frame_index) {
  // The simulator's depth camera; each frame index gets its own noise (seed).
  Camera c = cam;
  c.seed = cam.seed * 100003ULL + frame_index;
  sim::DepthSensor sensor(sensorParams(c));
  return sensor.capture(truth, world_T_sensor, stamp_ns);
}

int visiblePixels(const world::World& truth, const Eigen::Isometry3d& world_T_sensor, const Camera& cam,
                  const std::string& id) {
  Camera quiet = cam;
  quiet.noise = quiet.noise_quadratic = quiet.dropout = 0.0;
  sim::DepthSensor sensor(sensorParams(quiet));
  sim::GroundTruthLabels labels;
  (void)sensor.capture(truth, world_T_sensor, 0, &labels);
  int n = 0;
  for (auto l : labels.pixel) {
    if (l >= 0 && labels.ids[static_cast<std::size_t>(l)] == id) ++n;
  }
  return n;
}

world::Object box(const std::string& id, double sx, double sy, double sz, double x, double y, double yaw,
                  double base_z, world::ObjectKind kind) {
  world::Object o;
  o.id = id;
  o.label = id;
  o.kind = kind;
  o.shape = world::Shape::box(sx, sy, sz);
  o.pose = Eigen::Isometry3d::Identity();
  o.pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  o.pose.translation() = Eigen::Vector3d(x, y, base_z + sz / 2);
  o.mass = kind == world::ObjectKind::kMovable ? 1.0 : 0.0;
  return o;
}

world::Object cylinder(const std::string& id, double r, double h, double x, double y, double base_z,
                       world::ObjectKind kind) {
  world::Object o;
  o.id = id;
  o.label = id;
  o.kind = kind;
  o.shape = world::Shape::cylinder(r, h);
  o.pose = Eigen::Isometry3d::Identity();
  o.pose.translation() = Eigen::Vector3d(x, y, base_z + h / 2);
  o.mass = kind == world::ObjectKind::kMovable ? 0.5 : 0.0;
  return o;
}

world::Region floorRegion() {
  return world::Region{"floor", "floor", world::RegionKind::kFloor, {{-10, -10}, {10, -10}, {10, 10}, {-10, 10}}, 0.0};
}

}  // namespace tamp::perception::testing
