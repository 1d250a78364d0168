// Contact as evidence of where an object is (contact.h).
#include "tamp/graph_manager/contact.h"

#include <vector>

#include "tamp/collision/scene.h"

namespace tamp::graph_manager {

namespace {

/// The robot's body at `stop` against `object` alone: the nearest points.
collision::DistanceResult bodyDistance(const world::Object& object, const robot::RobotModel& robot,
                                       const robot::RobotState& stop) {
  world::World alone;
  world::Object o = object;
  if (!alone.addObject(o)) return {};
  collision::Scene scene(alone);
  scene.setRobot(robot.collisionGeometry());
  std::vector<Eigen::Isometry3d> links;
  robot.linkPoses(stop, links);
  scene.setLinkPoses(links);
  return scene.robotDistance(collision::Filter::objects({object.id}));
}

}  // namespace

std::optional<ContactCorrection> touchingPose(const world::Object& object, const robot::RobotModel& robot,
                                              const robot::RobotState& stop, double max_shift_m, double touch_m) {
  world::Object o = object;
  Eigen::Vector2d shift = Eigen::Vector2d::Zero();
  // The nearest points in 3-D; the object moves in the plane, so a gap that is partly vertical
  // closes in a few steps (each moves it by the gap's horizontal part).
  for (int step = 0; step < 4; ++step) {
    const collision::DistanceResult d = bodyDistance(o, robot, stop);
    if (!d.found()) return std::nullopt;
    if (d.distance <= touch_m) break;
    const Eigen::Vector2d gap = (d.point_on_robot - d.point_on_object).head<2>();
    // Above or below the body more than beside it: not what a drive in the plane runs into.
    if (gap.norm() < 0.5 * d.distance) return std::nullopt;
    const Eigen::Vector2d move = gap.normalized() * (d.distance - 0.5 * touch_m);
    shift += move;
    if (shift.norm() > max_shift_m) return std::nullopt;
    o.pose.translation().head<2>() += move;
  }
  if (shift.norm() <= touch_m) return std::nullopt;
  return ContactCorrection{o.pose, shift.norm()};
}

}  // namespace tamp::graph_manager
