// Where the robot stands to grasp an object (GraphManager::standBeside): base poses derived from
// the robot's description (its base footprint and the arm's reach) and the object's footprint,
// nearest first, each checked by the grasp service (IK and collisions); the grasp service's own
// samples last.
#include <cmath>

#include "object_geometry.h"
#include "tamp/core/log.h"
#include "tamp/graph_manager/graph_manager.h"

namespace tamp::graph_manager {

namespace {

/// How far ahead of base_link the arm can put the tool at height `z` (m): the reach sphere cut
/// at that height, plus the sphere's offset from base_link. An upper bound: orientation
/// constraints (a top-down grasp) reach less.
double horizontalReach(const robot::RobotModel& robot, double z) {
  const robot::RobotModel::ReachSphere s = robot.armReach();
  const double dz = z - s.centre.z();
  if (!std::isfinite(s.radius)) return kInfinity;
  if (std::abs(dz) >= s.radius) return 0.0;
  return s.centre.head<2>().norm() + std::sqrt(s.radius * s.radius - dz * dz);
}

/// Index of the pose of `path` nearest to `p` (in the plane).
std::size_t nearestIndex(const std::vector<Pose2D>& path, const Pose2D& p) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < path.size(); ++i)
    if (std::hypot(path[i].x - p.x, path[i].y - p.y) < std::hypot(path[best].x - p.x, path[best].y - p.y)) best = i;
  return best;
}

}  // namespace

std::vector<Pose2D> GraphManager::standCandidates(const world::Object& o, const Pose2D& entry,
                                                  const std::vector<Pose2D>& approach, const BranchContext& ctx) const {
  const robot::RobotModel& robot = abstraction_.robot();
  const Eigen::Vector2d c = o.pose.translation().head<2>();
  const double reach = horizontalReach(robot, o.pose.translation().z());
  const double margin = params_.keep_clear_margin_m;
  std::vector<Pose2D> out;
  // On the robot's own way in, back from where it would touch the object, heading as it drives
  // there (the way is clear of everything else): any heading, so the base's radius is kept.
  if (!approach.empty()) {
    double last = -kInfinity;
    for (std::size_t i = nearestIndex(approach, entry) + 1; i-- > 0 && out.size() < kStandSteps;) {
      const Eigen::Vector2d b(approach[i].x, approach[i].y);
      const double d = (b - c).norm();
      if (d > reach) break;
      if (d < 1e-6 || d < robot.baseRadius() + detail::objectExtentAlong(o, (b - c) / d) + margin) continue;
      if (d < last + kStandStep_m) continue;
      out.push_back(approach[i]);
      last = d;
    }
  }
  // Facing the object from the side of `entry`: the base's front kept `margin` off it.
  Eigen::Vector2d away = Eigen::Vector2d(entry.x, entry.y) - c;
  if (away.norm() < 1e-6) away = Eigen::Vector2d(ctx.state.base.x, ctx.state.base.y) - c;
  if (away.norm() < 1e-6) away = Eigen::Vector2d(-1.0, 0.0);
  away.normalize();
  const double clear = detail::baseFront(robot) + detail::objectExtentAlong(o, away) + margin;
  for (std::size_t k = 0; k < kStandSteps; ++k) {
    const double d = clear + static_cast<double>(k) * kStandStep_m;
    if (d > reach) break;
    const Eigen::Vector2d b = c + d * away;
    out.push_back(Pose2D{b.x(), b.y(), std::atan2(-away.y(), -away.x())});
  }
  return out;
}

std::optional<GraspOption> GraphManager::standBeside(const world::Object& o, const Pose2D& entry, const BranchContext& ctx,
                                                     const std::vector<Pose2D>& approach) {
  for (const Pose2D& base : standCandidates(o, entry, approach, ctx)) {
    GraspQuery gq;
    gq.object_id = o.id;
    gq.base = base;
    gq.overrides = overridesOf(ctx, o.id);
    auto g = askGrasps(gq);
    log::get("graph_manager")->debug("stand beside {} at ({:.2f}, {:.2f}, {:.2f}): {}", o.id, base.x, base.y, base.theta,
                                     g ? std::to_string(g->size()) + " grasps" : g.error().message);
    if (g && !g->empty()) {
      GraspOption chosen = g->front();
      chosen.base_pose = base;
      return chosen;
    }
  }
  // The grasp service's own base samples round the object, the one nearest to `entry`.
  GraspQuery gq;
  gq.object_id = o.id;
  gq.max_grasps = 8;
  gq.overrides = overridesOf(ctx, o.id);
  auto g = askGrasps(gq);
  std::optional<GraspOption> chosen;
  if (g) {
    for (const auto& x : *g) {
      if (!chosen || std::hypot(x.base_pose.x - entry.x, x.base_pose.y - entry.y) <
                         std::hypot(chosen->base_pose.x - entry.x, chosen->base_pose.y - entry.y))
        chosen = x;
    }
  }
  return chosen;
}

}  // namespace tamp::graph_manager
