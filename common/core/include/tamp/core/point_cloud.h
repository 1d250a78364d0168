#pragma once
/// @file
/// One depth-sensor frame: points in the sensor frame plus the sensor's pose in the world at
/// capture time. The contract between a sensor (the simulator's depth camera, or a real driver)
/// and perception; maps 1:1 to `msg::PointCloudFrame`.
///
/// Sensor frame convention (optical): z forward along the viewing axis, x right, y down. Points
/// with no return are NaN triplets (organised clouds keep width x height layout).

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace tamp {

struct PointCloudFrame {
  std::string sensor_id;
  int64_t stamp_ns{0};                 ///< capture time, ns since the Unix epoch
  Eigen::Isometry3d world_T_sensor{Eigen::Isometry3d::Identity()};
  uint32_t width{0};                   ///< organised: columns; unorganised: number of points
  uint32_t height{1};                  ///< organised: rows; unorganised: 1
  std::vector<float> xyz;              ///< x0 y0 z0 x1 y1 z1 ... (metres, sensor frame)

  std::size_t size() const { return xyz.size() / 3; }
  Eigen::Vector3f point(std::size_t i) const { return {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}; }
  bool valid(std::size_t i) const { return xyz[3 * i] == xyz[3 * i]; }  // not NaN
};

}  // namespace tamp
