#include "tamp/perception/self_filter.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <stdexcept>

#include "tamp/perception/shape_fit.h"

namespace tamp::perception {
namespace {

/// A solid brought into the sensor frame: its box there (of the padded local box) for culling,
/// and the transform back into its own frame for the exact test.
struct SensorSolid {
  const world::Shape* shape;
  Eigen::Isometry3f shape_T_sensor;
  Eigen::AlignedBox3f box;
};

}  // namespace

std::optional<StampedRobotState> robotStateAt(const std::deque<StampedRobotState>& samples, std::int64_t stamp_ns,
                                              double max_age_s) {
  if (samples.empty()) return std::nullopt;
  // The first sample at or after the stamp.
  const auto after = std::lower_bound(samples.begin(), samples.end(), stamp_ns,
                                      [](const StampedRobotState& s, std::int64_t t) { return s.stamp_ns < t; });
  if (after != samples.end() && after->stamp_ns == stamp_ns) return *after;
  if (after == samples.begin() || after == samples.end()) {
    const StampedRobotState& nearest = after == samples.end() ? samples.back() : samples.front();
    const double age = std::abs(static_cast<double>(nearest.stamp_ns - stamp_ns)) * 1e-9;
    if (age > max_age_s) return std::nullopt;
    return nearest;
  }
  const StampedRobotState& a = *std::prev(after);
  const StampedRobotState& b = *after;
  const double f = static_cast<double>(stamp_ns - a.stamp_ns) / static_cast<double>(b.stamp_ns - a.stamp_ns);
  StampedRobotState out = f < 0.5 ? a : b;
  out.stamp_ns = stamp_ns;
  out.state.base.x = a.state.base.x + f * (b.state.base.x - a.state.base.x);
  out.state.base.y = a.state.base.y + f * (b.state.base.y - a.state.base.y);
  out.state.base.theta =
      std::remainder(a.state.base.theta + f * std::remainder(b.state.base.theta - a.state.base.theta, 2 * M_PI), 2 * M_PI);
  if (a.state.arm.size() == b.state.arm.size()) {
    for (std::size_t i = 0; i < a.state.arm.size(); ++i)
      out.state.arm[i] = a.state.arm[i] + f * (b.state.arm[i] - a.state.arm[i]);
    out.state.gripper = a.state.gripper + f * (b.state.gripper - a.state.gripper);
  }
  return out;
}

RobotBody robotBodyAt(const robot::RobotModel& robot, const robot::RobotState& state,
                      std::string held_object_id, std::int64_t stamp_ns) {
  RobotBody body;
  std::vector<Eigen::Isometry3d> poses;
  robot.linkPoses(state, poses);  // throws on a wrong arm size
  const collision::RobotGeometry& g = robot.collisionGeometry();
  body.parts.reserve(g.parts.size());
  for (const collision::RobotPart& p : g.parts) {
    const auto link = static_cast<std::size_t>(p.link);
    body.parts.push_back(BodyPart{g.links[link], p.shape, poses[link] * p.link_T_shape});
  }
  body.world_T_tool = robot.toolPoseInWorld(state);
  body.base_link = robot.options().base_link;
  body.held_object_id = std::move(held_object_id);
  body.stamp_ns = stamp_ns;
  return body;
}

std::size_t removeBodyPoints(PointCloudFrame& frame, const RobotBody& body,
                             const world::Object* held, double padding) {
  if (!(padding >= 0) || !std::isfinite(padding)) {
    throw std::invalid_argument("removeBodyPoints: padding must be finite and >= 0, got " +
                                std::to_string(padding));
  }
  const Eigen::Isometry3d sensor_T_world = frame.world_T_sensor.inverse();
  std::vector<SensorSolid> solids;
  Eigen::AlignedBox3f all;  // empty
  auto add = [&](const world::Shape& shape, const Eigen::Isometry3d& world_T_shape) {
    const Eigen::Isometry3d sensor_T_shape = sensor_T_world * world_T_shape;
    const Aabb local = shape.localAabb();
    const Eigen::Vector3d lo = local.min.array() - padding, hi = local.max.array() + padding;
    Eigen::AlignedBox3f box;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(),
                                   (c & 4) ? hi.z() : lo.z());
      box.extend((sensor_T_shape * corner).cast<float>());
    }
    all.extend(box);
    solids.push_back(SensorSolid{&shape, sensor_T_shape.inverse().cast<float>(), box});
  };
  for (const BodyPart& p : body.parts) add(p.shape, p.world_T_shape);
  if (held != nullptr) add(held->shape, held->pose);
  if (solids.empty()) return 0;

  const Eigen::Isometry3d identity = Eigen::Isometry3d::Identity();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::size_t removed = 0;
  const std::size_t n = frame.size();
  for (std::size_t i = 0; i < n; ++i) {
    float* xyz = &frame.xyz[3 * i];
    if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2])) continue;
    const Eigen::Vector3f p(xyz[0], xyz[1], xyz[2]);
    if (!all.contains(p)) continue;
    for (const SensorSolid& s : solids) {
      if (!s.box.contains(p)) continue;
      const Eigen::Vector3d q = (s.shape_T_sensor * p).cast<double>();
      if (pointInShape(*s.shape, identity, q, padding)) {
        xyz[0] = xyz[1] = xyz[2] = nan;
        ++removed;
        break;
      }
    }
  }
  return removed;
}

}  // namespace tamp::perception
