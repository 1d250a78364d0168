#include "tamp/perception/validation.h"

#include <cmath>
#include <string>

namespace tamp::perception {
namespace {

Status bad(const std::string& field, const std::string& message) {
  return Error(ErrorCode::kInvalidArgument, "malformed point cloud: " + message, SourceLocation{"", 0, 0, field});
}

}  // namespace

Status validateFrame(const PointCloudFrame& frame, std::size_t max_points) {
  const std::size_t values = frame.xyz.size();
  if (values == 0) return bad("xyz", "empty cloud (no points)");
  if (values % 3 != 0) {
    return bad("xyz", "size " + std::to_string(values) + " is not a multiple of 3 (x y z triplets)");
  }
  const std::size_t n = values / 3;
  if (n > max_points) {
    return bad("xyz", std::to_string(n) + " points exceed the limit of " + std::to_string(max_points));
  }
  if (frame.width != 0 && static_cast<std::size_t>(frame.width) * frame.height != n) {
    return bad(frame.height == 0 ? "height" : "width",
               "width x height = " + std::to_string(frame.width) + " x " + std::to_string(frame.height) +
                   " does not match the " + std::to_string(n) + " points");
  }
  const Eigen::Matrix4d& M = frame.world_T_sensor.matrix();
  if (!M.allFinite()) return bad("world_T_sensor", "sensor pose is not finite (NaN or infinite)");
  const Eigen::Matrix3d R = frame.world_T_sensor.linear();
  const double ortho = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (ortho > 1e-3 || std::abs(R.determinant() - 1.0) > 1e-3) {
    return bad("world_T_sensor", "sensor rotation is not a rotation (orthonormality error " + std::to_string(ortho) +
                                     ", determinant " + std::to_string(R.determinant()) + ")");
  }
  if (M.row(3).cwiseAbs().sum() != 1.0 || M(3, 3) != 1.0) {
    return bad("world_T_sensor", "last row of the sensor pose is not [0 0 0 1]");
  }
  for (std::size_t i = 0; i < n; ++i) {
    const float x = frame.xyz[3 * i], y = frame.xyz[3 * i + 1], z = frame.xyz[3 * i + 2];
    const int finite = int(std::isfinite(x)) + int(std::isfinite(y)) + int(std::isfinite(z));
    if (finite != 0 && finite != 3) {
      return bad("xyz[" + std::to_string(i) + "]", "point mixes finite and non-finite coordinates (" +
                                                        std::to_string(x) + ", " + std::to_string(y) + ", " +
                                                        std::to_string(z) + ")");
    }
  }
  return Status::Ok();
}

}  // namespace tamp::perception
