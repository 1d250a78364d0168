// Placement sampling for findEffectStates (placement.h).
#include <algorithm>
#include <cmath>
#include <functional>

#include "planner_impl.h"

namespace tamp::motion_planner {
namespace {

constexpr double kSupportGap = 0.002;  // m

bool segmentsCross(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c, const Eigen::Vector2d& d) {
  auto orient = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    return (q.x() - p.x()) * (r.y() - p.y()) - (q.y() - p.y()) * (r.x() - p.x());
  };
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  return ((o1 > 0) != (o2 > 0)) && ((o3 > 0) != (o4 > 0));
}

/// True when `inner` lies inside `outer` with every vertex at least `margin` from its boundary.
bool insideWithMargin(const world::Polygon2& inner, const world::Polygon2& outer, double margin) {
  for (const auto& v : inner) {
    if (!world::containsPoint(outer, v)) return false;
    for (std::size_t i = 0; i < outer.size(); ++i) {
      if (world::segmentDistance(v, outer[i], outer[(i + 1) % outer.size()]) < margin) return false;
    }
  }
  // A non-convex region: no boundary edge may cut through the footprint.
  for (std::size_t i = 0; i < inner.size(); ++i) {
    for (std::size_t j = 0; j < outer.size(); ++j) {
      if (segmentsCross(inner[i], inner[(i + 1) % inner.size()], outer[j], outer[(j + 1) % outer.size()])) return false;
    }
  }
  for (const auto& v : outer) {
    if (world::containsPoint(inner, v)) return false;
  }
  return true;
}

/// The placement at `pose` as reached from the request's base: the arm takes the tool to the
/// held grasp's pose there (or a top grasp of the object) and, with a held grasp, to the
/// pre-place pose `approach` above it, both with collision-free IK. None when it cannot.
std::optional<Placement> placeFromBase(MotionPlanner::Impl& impl, const PlacementRequest& req,
                                       const Eigen::Isometry3d& pose, const collision::Filter& others,
                                       std::uint32_t salt, const Termination& termination) {
  const robot::RobotModel* m = impl.robot.model();
  const world::Object* obj = impl.world.findObject(req.object_id);
  std::vector<Eigen::Isometry3d> tool_in_object;
  if (req.held_object_T_tool) {
    tool_in_object.push_back(*req.held_object_T_tool);
  } else {
    for (const auto& c : graspCandidates(obj->shape, impl.params.grasp, m->gripperLimits().upper)) {
      if (c.type == GraspType::kTop) tool_in_object.push_back(c.object_T_tool);
    }
  }
  for (const auto& t : tool_in_object) {
    const Eigen::Isometry3d at = pose * t;
    Eigen::Isometry3d pre = at;
    pre.translation().z() += req.approach;
    auto q_pre = solveIk(impl, *req.base, pre, m->defaultState().arm, others, 0.0, salt * 131 + 1, 24, termination);
    if (!q_pre) continue;
    auto q_at = solveIk(impl, *req.base, at, *q_pre, others, 0.0, salt * 131 + 2, 24, termination);
    if (!q_at) continue;
    Placement pl;
    pl.object_pose = pose;
    pl.base_pose = *req.base;
    pl.arm_configuration = *q_at;
    pl.pre_arm_configuration = *q_pre;
    return pl;
  }
  return std::nullopt;
}

/// How the object stands at a placement, before its yaw: upright, or, for a held object whose
/// grasp would point the tool upwards with the object upright (a grasp given as the identity
/// with the object's z axis along the tool's approach axis), upside down on its top face so that
/// the tool points down as the arm holds it. Box, cylinder and prism frames are centred, so both
/// faces rest at the same height; a sphere has no preferred face.
Eigen::Matrix3d standingRotation(const PlacementRequest& req) {
  const Eigen::Matrix3d upright = Eigen::Matrix3d::Identity();
  if (!req.held_object_T_tool) return upright;
  const Eigen::Matrix3d flipped = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d tool = req.held_object_T_tool->linear();
  // The z component of the tool's approach axis in the world (yaw does not change it).
  const double up_upright = (upright * tool).col(2).z();
  const double up_flipped = (flipped * tool).col(2).z();
  return up_flipped < up_upright - 1e-6 && up_upright > 0.0 ? flipped : upright;
}

}  // namespace

Result<std::vector<Placement>> MotionPlanner::samplePlacements(const PlacementRequest& req,
                                                               const Termination& termination) {
  Impl& impl = *impl_;
  const auto& P = impl.params.placement;
  auto hypothetical = overriddenWorld(impl.world, req.added_objects, req.object_overrides, req.object_id);
  if (!hypothetical) return hypothetical.error();
  const world::World original = std::move(*hypothetical);  // the request's world
  const world::Object* obj = original.findObject(req.object_id);
  if (!obj) return Error(ErrorCode::kNotFound, "object_id: no object '" + req.object_id + "' in the world");
  if (obj->kind != world::ObjectKind::kMovable) {
    return Error(ErrorCode::kInvalidArgument, "object_id: object '" + req.object_id + "' is static");
  }
  const world::Region* region = impl.world.findRegion(req.region_id);
  if (!region) return Error(ErrorCode::kNotFound, "region_id: no region '" + req.region_id + "' in the world");
  if (!std::isfinite(req.keep_clear_radius) || req.keep_clear_radius < 0) {
    return Error(ErrorCode::kInvalidArgument, "keep_clear_radius: must be finite and >= 0");
  }
  for (std::size_t i = 0; i < req.keep_clear_path.size(); ++i) {
    const auto& p = req.keep_clear_path[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.theta)) {
      return Error(ErrorCode::kInvalidArgument, "keep_clear_path[" + std::to_string(i) + "]: not finite");
    }
  }
  if (req.base && (!std::isfinite(req.base->x) || !std::isfinite(req.base->y) || !std::isfinite(req.base->theta))) {
    return Error(ErrorCode::kInvalidArgument, "base: not finite");
  }
  if (req.held_object_T_tool && !req.base) {
    return Error(ErrorCode::kInvalidArgument, "held_object_T_tool: given without base");
  }
  if (req.held_object_T_tool && !req.held_object_T_tool->matrix().allFinite()) {
    return Error(ErrorCode::kInvalidArgument, "held_object_T_tool: not finite");
  }
  if (!std::isfinite(req.approach) || req.approach < 0) {
    return Error(ErrorCode::kInvalidArgument, "approach: must be finite and >= 0");
  }
  if (req.base && !impl.robot.model()) {
    return Error(ErrorCode::kInvalidArgument, "base: the robot has no arm to place from a given base pose");
  }
  for (std::size_t i = 0; i < req.keep_clear_states.size(); ++i) {
    const auto& s = req.keep_clear_states[i];
    if (s.arm.size() != impl.robot.armDof()) {
      return Error(ErrorCode::kInvalidArgument, "keep_clear_states[" + std::to_string(i) + "].arm: expected " +
                                                    std::to_string(impl.robot.armDof()) + " values");
    }
    bool fin = std::isfinite(s.base.x) && std::isfinite(s.base.y) && std::isfinite(s.base.theta);
    for (double q : s.arm) fin = fin && std::isfinite(q);
    if (!fin) return Error(ErrorCode::kInvalidArgument, "keep_clear_states[" + std::to_string(i) + "]: not finite");
  }
  if (req.max_placements == 0) return Error(ErrorCode::kInvalidArgument, "max_placements: must be >= 1");

  const world::Polygon2 local = obj->shape.footprint(24);
  Aabb rb;
  for (const auto& v : region->polygon) rb.extend(Eigen::Vector3d(v.x(), v.y(), 0));
  if (req.base) {
    // From a given base, only the part of the region within the arm's reach.
    const double r = P.base_distance_max;
    rb.min = rb.min.cwiseMax(Eigen::Vector3d(req.base->x - r, req.base->y - r, 0));
    rb.max = rb.max.cwiseMin(Eigen::Vector3d(req.base->x + r, req.base->y + r, 0));
    if ((rb.max - rb.min).head<2>().minCoeff() < 0) return std::vector<Placement>{};
  }
  const std::uint64_t seed = req.seed != 0 ? req.seed
                                           : impl.params.seed ^ std::hash<std::string>{}(req.object_id + "@" + req.region_id);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(rb.min.x(), rb.max.x()), uy(rb.min.y(), rb.max.y()), uyaw(-M_PI, M_PI);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const Aabb world_box = impl.world.bounds();
  const collision::Filter others = collision::Filter::allBut({req.object_id});
  const collision::Filter only_obj{collision::kMovableObjects, {req.object_id}, {}};
  const robot::RobotModel* m = impl.robot.model();
  const auto tops = m ? graspCandidates(obj->shape, impl.params.grasp, m->gripperLimits().upper)
                      : std::vector<GraspCandidate>{};
  struct Restore {  // the scene goes back to the planner's world
    Impl& impl;
    ~Restore() { impl.scene.syncWorld(impl.world); }
  } restore{impl};
  impl.scene.syncWorld(original);

  const Eigen::Matrix3d stand = standingRotation(req);
  std::vector<Placement> out;
  std::vector<Eigen::Isometry3d> poses;
  const Eigen::Vector2d from(obj->pose.translation().x(), obj->pose.translation().y());
  for (int attempt = 0; attempt < P.max_attempts && out.size() < req.max_placements; ++attempt) {
    if (termination()) {
      if (out.empty()) return Error(ErrorCode::kTimeout, "the deadline passed before a placement was found");
      break;
    }
    const double x = ux(rng), y = uy(rng), yaw = uyaw(rng);
    if (req.base && std::hypot(x - req.base->x, y - req.base->y) > P.base_distance_max) continue;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * stand;
    pose.translation() = Eigen::Vector3d(x, y, region->height + obj->shape.halfHeight());
    // Stable: the footprint inside the region.
    world::Polygon2 fp;
    for (const auto& v : local) {
      const Eigen::Vector3d w = pose * Eigen::Vector3d(v.x(), v.y(), 0.0);
      fp.emplace_back(w.x(), w.y());
    }
    if (!insideWithMargin(fp, region->polygon, P.support_margin)) continue;
    // Clear of the swept base path.
    bool clear = true;
    for (const auto& p : req.keep_clear_path) {
      if (world::polygonDistance(fp, Eigen::Vector2d(p.x, p.y)) <= req.keep_clear_radius) {
        clear = false;
        break;
      }
    }
    if (!clear) continue;
    // Collision-free among the other objects. Checked 2 mm above the surface: resting on the
    // support (the table the region lies on) is contact, not collision.
    Eigen::Isometry3d lifted = pose;
    lifted.translation().z() += kSupportGap;
    if (impl.scene.shapeInCollision(obj->shape, lifted, others)) continue;
    // With the object there: clear of the swept robot states, and reachable.
    world::World moved = original;
    if (!moved.setObjectPose(req.object_id, pose).ok()) continue;
    impl.scene.syncWorld(moved);
    for (const auto& s : req.keep_clear_states) {
      impl.robot.linkPoses(s, poses);
      impl.scene.setLinkPoses(poses);
      if (impl.scene.robotInCollision(only_obj)) {
        clear = false;
        break;
      }
    }
    if (!clear) continue;
    std::optional<Placement> found;
    if (req.base) {
      found = placeFromBase(impl, req, pose, others, static_cast<std::uint32_t>(attempt), termination);
      if (!found) continue;
    }
    const double dmin = m ? P.base_distance_min : impl.robot.footprintRadius() + 0.01;
    const double dmax = m ? P.base_distance_max : std::max(dmin, P.planar_reach);
    for (int k = 0; k < P.base_poses_per_placement && !found && !req.base; ++k) {
      const double d = dmin + (dmax - dmin) * u01(rng);
      const double a = 2 * M_PI * u01(rng);
      const Pose2D base{x + d * std::cos(a), y + d * std::sin(a), wrapAngle(a + M_PI)};
      if (!world_box.empty() && (base.x < world_box.min.x() || base.x > world_box.max.x() ||
                                 base.y < world_box.min.y() || base.y > world_box.max.y())) {
        continue;
      }
      robot::RobotState rs = m ? m->defaultState(base) : robot::RobotState{base, {}, 0.0};
      impl.robot.linkPoses(rs, poses);
      impl.scene.setLinkPoses(poses);
      if (impl.scene.robotInCollision(collision::Filter::all())) continue;
      Placement pl;
      pl.object_pose = pose;
      pl.base_pose = base;
      if (m) {
        // A grasp of the object at the placement, or the point above its top when none fits.
        std::vector<Eigen::Isometry3d> targets;
        for (const auto& c : tops) {
          if (c.type == GraspType::kTop) targets.push_back(pose * c.object_T_tool);
        }
        if (targets.empty()) {
          Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
          t.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
          t.translation() = pose.translation() + Eigen::Vector3d(0, 0, obj->shape.halfHeight() + P.tool_clearance);
          targets.push_back(t);
        }
        for (const auto& t : targets) {
          auto q = solveIk(impl, base, t, m->defaultState().arm, others, 0.0, static_cast<std::uint32_t>(attempt * 131 + k),
                           24, termination);
          if (q) {
            pl.arm_configuration = *q;
            found = pl;
            break;
          }
        }
      } else {
        found = pl;
      }
    }
    if (!found) continue;
    impl.scene.syncWorld(original);
    found->clearance = std::max(0.0, impl.scene.shapeDistance(obj->shape, lifted, others).distance);
    found->transfer_distance = (Eigen::Vector2d(x, y) - from).norm();
    out.push_back(std::move(*found));
  }
  std::sort(out.begin(), out.end(),
            [](const Placement& a, const Placement& b) { return a.transfer_distance < b.transfer_distance; });
  return out;
}

}  // namespace tamp::motion_planner
