#pragma once
// Test scenes for perception: ground-truth worlds, camera poses like the robot's mast camera,
// and depth frames rendered from them.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/point_cloud.h"
#include "tamp/world/world.h"

namespace tamp::perception::testing {

/// The simulator's depth camera (tamp::sim::DepthSensor: pinhole, square pixels, noise along
/// the ray growing with depth^2, dropouts).
struct Camera {
  int width{320};
  int height{240};
  double hfov{1.0472};   // rad
  double min_range{0.2}; // m, depth
  double max_range{6.0}; // m, depth
  double noise{0.001};   // m
  double noise_quadratic{0.0015};  // 1/m
  double dropout{0.005};
  std::uint64_t seed{1};
};

/// Optical-frame pose of a mast camera at `height` pitched down by `pitch` on a base at
/// (x, y, yaw) (the URDF's camera: 1.45 m, 0.6 rad).
Eigen::Isometry3d mastCamera(double x, double y, double yaw, double height = 1.45, double pitch = 0.6);
/// A camera at `eye` looking at `target` (optical frame, image rows roughly horizontal).
Eigen::Isometry3d lookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target);

/// Renders every object of `truth` (hidden ones included) and the floor z = 0 with the
/// simulator's depth camera; `frame_index` selects the noise.
PointCloudFrame render(const world::World& truth, const Eigen::Isometry3d& world_T_sensor, const Camera& camera,
                       std::int64_t stamp_ns, std::uint64_t frame_index = 0);
/// Pixels of the frame whose ray first hits object `id` (without noise): its visible size.
int visiblePixels(const world::World& truth, const Eigen::Isometry3d& world_T_sensor, const Camera& camera,
                  const std::string& id);

// World builders.
world::Object box(const std::string& id, double sx, double sy, double sz, double x, double y, double yaw,
                  double base_z = 0.0, world::ObjectKind kind = world::ObjectKind::kMovable);
world::Object cylinder(const std::string& id, double r, double h, double x, double y, double base_z = 0.0,
                       world::ObjectKind kind = world::ObjectKind::kMovable);
/// A floor region over [-10, 10]^2.
world::Region floorRegion();

}  // namespace tamp::perception::testing
