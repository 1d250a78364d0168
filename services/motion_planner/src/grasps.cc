// Grasp generation for boxes and cylinders (grasps.h).
#include <algorithm>
#include <cmath>

#include "planner_impl.h"

namespace tamp::motion_planner {

std::string_view toString(GraspType type) { return type == GraspType::kTop ? "top" : "side"; }

namespace {

/// Tool frame from its y (closing) and z (approach) axes, at `p`.
Eigen::Isometry3d toolFrame(const Eigen::Vector3d& y, const Eigen::Vector3d& z, const Eigen::Vector3d& p) {
  Eigen::Matrix3d R;
  R.col(1) = y.normalized();
  R.col(2) = z.normalized();
  R.col(0) = R.col(1).cross(R.col(2));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = p;
  return T;
}

constexpr double kFingerDepth = 0.04;  // how far the finger tips reach past the tool centre point

}  // namespace

std::vector<GraspCandidate> graspCandidates(const world::Shape& shape, const GraspParams& params,
                                            double max_opening) {
  std::vector<GraspCandidate> top, side;
  auto fits = [&](double width) { return width / 2 + params.finger_margin <= max_opening + 1e-12; };
  const Eigen::Vector3d Z = Eigen::Vector3d::UnitZ();
  if (shape.kind == world::ShapeKind::kBox) {
    const Eigen::Vector3d s = shape.size;
    const double zt = s.z() / 2 - std::min(kFingerDepth, s.z() / 2);
    const double zs = -s.z() / 2 + params.side_height_fraction * s.z();
    for (int axis = 0; axis < 2; ++axis) {
      const Eigen::Vector3d a = axis == 0 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
      const Eigen::Vector3d b = axis == 0 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitX();
      const double width_a = s[axis];      // closing along a
      const double depth_b = s[1 - axis];  // approaching along b (side)
      for (double sign : {1.0, -1.0}) {
        if (fits(width_a)) top.push_back({GraspType::kTop, toolFrame(sign * a, -Z, Eigen::Vector3d(0, 0, zt)), width_a});
        // Side: approach along sign*b from the -sign*b face, fingers closing along a.
        if (fits(width_a)) {
          const double back = std::max(0.0, depth_b / 2 - kFingerDepth);
          side.push_back({GraspType::kSide, toolFrame(a, sign * b, -sign * back * b + Eigen::Vector3d(0, 0, zs)), width_a});
        }
      }
    }
  } else if (shape.kind == world::ShapeKind::kCylinder) {
    const double r = shape.radius, h = shape.height;
    const double zt = h / 2 - std::min(kFingerDepth, h / 2);
    const double zs = -h / 2 + params.side_height_fraction * h;
    if (fits(2 * r)) {
      for (int k = 0; k < params.cylinder_yaw_samples; ++k) {
        const double phi = 2 * M_PI * k / params.cylinder_yaw_samples;
        const Eigen::Vector3d d(std::cos(phi), std::sin(phi), 0.0);
        const Eigen::Vector3d y(-std::sin(phi), std::cos(phi), 0.0);
        top.push_back({GraspType::kTop, toolFrame(d, -Z, Eigen::Vector3d(0, 0, zt)), 2 * r});
        const double back = std::max(0.0, r - kFingerDepth);
        side.push_back({GraspType::kSide, toolFrame(y, d, -back * d + Eigen::Vector3d(0, 0, zs)), 2 * r});
      }
    }
  }
  top.insert(top.end(), side.begin(), side.end());
  return top;
}

Result<std::vector<Grasp>> MotionPlanner::generateGrasps(const GraspRequest& req, const Termination& termination) {
  Impl& impl = *impl_;
  const auto& P = impl.params.grasp;
  const robot::RobotModel* m = impl.robot.model();
  if (!m) return Error(ErrorCode::kUnsupported, "grasps need a robot with an arm (this robot is planar)");
  // The request's world: the planner's with the added objects and the overrides; the scene goes
  // back after.
  auto hypothetical = overriddenWorld(impl.world, req.added_objects, req.object_overrides, req.object_id);
  if (!hypothetical) return hypothetical.error();
  const world::Object* obj = hypothetical->findObject(req.object_id);
  if (!obj) return Error(ErrorCode::kNotFound, "object_id: no object '" + req.object_id + "' in the world");
  if (obj->kind != world::ObjectKind::kMovable || !obj->graspable) {
    return Error(ErrorCode::kInvalidArgument, "object_id: object '" + req.object_id + "' is not graspable");
  }
  if (obj->shape.kind != world::ShapeKind::kBox && obj->shape.kind != world::ShapeKind::kCylinder) {
    return Error(ErrorCode::kUnsupported, "object_id: grasps of a " + std::string(world::toString(obj->shape.kind)) +
                                              " are not supported (boxes and cylinders only)");
  }
  if (req.base_pose && !(std::isfinite(req.base_pose->x) && std::isfinite(req.base_pose->y) &&
                         std::isfinite(req.base_pose->theta))) {
    return Error(ErrorCode::kInvalidArgument, "base_pose: not finite");
  }
  if (!req.start_arm.empty()) {
    if (req.start_arm.size() != m->armDof()) {
      return Error(ErrorCode::kInvalidArgument, "start_arm: expected " + std::to_string(m->armDof()) + " values, got " +
                                                    std::to_string(req.start_arm.size()));
    }
    for (double q : req.start_arm) {
      if (!std::isfinite(q)) return Error(ErrorCode::kInvalidArgument, "start_arm: not finite");
    }
  }
  if (req.max_grasps == 0) return Error(ErrorCode::kInvalidArgument, "max_grasps: must be >= 1");
  struct Restore {
    MotionPlanner::Impl& impl;
    ~Restore() { impl.scene.syncWorld(impl.world); }
  } restore{impl};
  if (!req.object_overrides.empty() || !req.added_objects.empty()) impl.scene.syncWorld(*hypothetical);

  const double max_open = m->gripperLimits().upper;
  const robot::RobotModel::ReachSphere reach = m->armReach();
  const auto cands = graspCandidates(obj->shape, P, max_open);
  std::vector<Pose2D> bases;
  const Eigen::Vector3d c = obj->pose.translation();
  if (req.base_pose) {
    bases.push_back(*req.base_pose);
  } else {
    for (int ring = 0; ring < 3; ++ring) {
      const double d = P.base_distance_min + (P.base_distance_max - P.base_distance_min) * ring / 2.0;
      for (int k = 0; k < P.base_poses; ++k) {
        const double a = 2 * M_PI * k / P.base_poses;
        bases.push_back(Pose2D{c.x() + d * std::cos(a), c.y() + d * std::sin(a), wrapAngle(a + M_PI)});
      }
    }
  }
  const collision::Filter all = collision::Filter::all();
  const collision::Filter but_object = collision::Filter::allBut({req.object_id});
  std::vector<Grasp> out;
  std::vector<double> seed = req.start_arm.empty() ? m->defaultState().arm : req.start_arm;
  std::uint32_t salt = impl.params.seed;
  for (const auto& cand : cands) {
    if (out.size() >= req.max_grasps) break;
    if (termination()) {
      if (out.empty()) return Error(ErrorCode::kTimeout, "the deadline passed before a grasp was found");
      break;
    }
    const double opening = std::min(max_open, cand.width / 2 + P.finger_margin);
    const double closed = std::min(max_open, cand.width / 2);
    const Eigen::Isometry3d grasp = obj->pose * cand.object_T_tool;
    const Eigen::Isometry3d pre = grasp * Eigen::Translation3d(0, 0, -P.approach_distance);
    const Eigen::Isometry3d retreat = Eigen::Translation3d(0, 0, P.retreat_distance) * grasp;
    for (const Pose2D& b : bases) {
      if (termination()) break;
      // Cheap reject: the tool target must be within the arm's reach (the robot's reach sphere).
      const Eigen::Vector3d rel = b.toIsometry().inverse() * grasp.translation();
      if ((rel - reach.centre).norm() > reach.radius) continue;
      auto q_pre = solveIk(impl, b, pre, seed, all, opening, ++salt, 32, termination);
      if (!q_pre) continue;
      auto q_grasp = solveIk(impl, b, grasp, *q_pre, but_object, opening, ++salt, 32, termination);
      if (!q_grasp) continue;
      auto q_ret = solveIk(impl, b, retreat, *q_grasp, but_object, closed, ++salt, 32, termination);
      if (!q_ret) continue;
      Grasp g;
      g.type = cand.type;
      g.gripper_in_object = cand.object_T_tool;
      g.world_T_tool = grasp;
      g.base_pose = b;
      g.pregrasp_configuration = *q_pre;
      g.grasp_configuration = *q_grasp;
      g.retreat_configuration = *q_ret;
      g.opening = opening;
      g.width = cand.width;
      out.push_back(std::move(g));
      break;
    }
  }
  return out;
}

}  // namespace tamp::motion_planner
