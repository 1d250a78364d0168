#include "tamp/core/geometry.h"

#include <ostream>

namespace tamp {

double wrapAngle(double a) {
  if (!std::isfinite(a)) return a;
  double r = std::fmod(a + M_PI, 2.0 * M_PI);
  if (r < 0) r += 2.0 * M_PI;
  r -= M_PI;
  // fmod rounding can land exactly on +pi; keep the half-open interval.
  return r >= M_PI ? -M_PI : r;
}

Eigen::Isometry3d Pose2D::toIsometry(double z) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  T.linear() = Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

Pose2D Pose2D::fromIsometry(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d xaxis = T.linear().col(0);
  return Pose2D{T.translation().x(), T.translation().y(), std::atan2(xaxis.y(), xaxis.x())};
}

Pose2D Pose2D::compose(const Pose2D& local) const {
  const double c = std::cos(theta), s = std::sin(theta);
  return Pose2D{x + c * local.x - s * local.y, y + s * local.x + c * local.y,
                wrapAngle(theta + local.theta)};
}

std::ostream& operator<<(std::ostream& os, const Pose2D& p) {
  return os << "(" << p.x << ", " << p.y << ", " << p.theta << ")";
}

}  // namespace tamp
