// Contact as evidence of where an object is (contact.h).
#include "tamp/graph_manager/contact.h"

#include <cmath>
#include <numbers>
#include <vector>

#include "tamp/collision/scene.h"

namespace tamp::graph_manager {

namespace {

/// The robot's body at a state against one object, the object moved about.
class BodyProbe {
 public:
  BodyProbe(world::Object object, const robot::RobotModel& robot, const robot::RobotState& stop)
      : object_(std::move(object)) {
    ok_ = static_cast<bool>(alone_.addObject(object_));
    scene_ = collision::Scene(alone_);
    scene_.setRobot(robot.collisionGeometry());
    std::vector<Eigen::Isometry3d> links;
    robot.linkPoses(stop, links);
    scene_.setLinkPoses(links);
  }
  bool ok() const { return ok_; }
  /// The nearest points with the object at its pose moved by `shift` in the plane.
  collision::DistanceResult at(const Eigen::Vector2d& shift) {
    Eigen::Isometry3d pose = object_.pose;
    pose.translation().head<2>() += shift;
    (void)alone_.setObjectPose(object_.id, pose);
    scene_.syncWorld(alone_);
    return scene_.robotDistance(collision::Filter::objects({object_.id}));
  }

 private:
  world::Object object_;
  world::World alone_;
  collision::Scene scene_;
  bool ok_{false};
};

/// The estimate away from the body: moved along the line of the nearest points until it touches
/// (a gap that is partly vertical closes in a few steps, each moving it by the gap's horizontal
/// part). The shift, or none.
std::optional<Eigen::Vector2d> closeGap(BodyProbe& probe, double max_shift_m, double touch_m) {
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
  for (int step = 0; step < 4; ++step) {
    const collision::DistanceResult d = probe.at(shift);
    if (!d.found()) return std::nullopt;
    if (d.distance <= touch_m) break;
    const Eigen::Vector2d gap = (d.point_on_robot - d.point_on_object).head<2>();
    // Above or below the body more than beside it: not what a drive in the plane runs into.
    if (gap.norm() < 0.5 * d.distance) return std::nullopt;
    shift += gap.normalized() * (d.distance - 0.5 * touch_m);
    if (shift.norm() > max_shift_m) return std::nullopt;
  }
  return shift;
}

/// The estimate overlapping the body: the shortest move in the plane (over `kDirections`
/// directions, each bisected) that leaves it just clear of the body. None when no move within
/// `max_shift_m` does.
std::optional<Eigen::Vector2d> openOverlap(BodyProbe& probe, double max_shift_m, double touch_m) {
  constexpr int kDirections = 32;
  constexpr int kBisections = 12;
  auto clear = [&](const Eigen::Vector2d& s) { return probe.at(s).distance > 0.0; };
  std::optional<Eigen::Vector2d> best;
  double best_t = max_shift_m;
  for (int k = 0; k < kDirections; ++k) {
    const double a = 2.0 * std::numbers::pi * k / kDirections;
    const Eigen::Vector2d dir(std::cos(a), std::sin(a));
    if (!clear(best_t * dir)) continue;
    double lo = 0.0, hi = best_t;
    for (int i = 0; i < kBisections; ++i) {
      const double mid = 0.5 * (lo + hi);
      (clear(mid * dir) ? hi : lo) = mid;
    }
    best_t = hi;
    best = dir;
  }
  if (!best) return std::nullopt;
  return *best * std::min(max_shift_m, best_t + 0.5 * touch_m);
}

}  // namespace

std::optional<ContactCorrection> touchingPose(const world::Object& object, const robot::RobotModel& robot,
                                              const robot::RobotState& stop, double max_shift_m, double touch_m) {
  BodyProbe probe(object, robot, stop);
  if (!probe.ok()) return std::nullopt;
  const collision::DistanceResult d = probe.at(Eigen::Vector2d::Zero());
  if (!d.found()) return std::nullopt;
  const bool overlaps = d.distance <= 0.0;
  if (!overlaps && d.distance <= touch_m) return std::nullopt;  // touching: the estimate agrees
  const auto shift = overlaps ? openOverlap(probe, max_shift_m, touch_m) : closeGap(probe, max_shift_m, touch_m);
  if (!shift || shift->norm() <= 0.5 * touch_m) return std::nullopt;
  ContactCorrection c;
  c.pose = object.pose;
  c.pose.translation().head<2>() += *shift;
  c.shift_m = overlaps ? -shift->norm() : shift->norm();
  return c;
}

}  // namespace tamp::graph_manager
