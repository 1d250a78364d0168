// Edge pricing for Traverse: lazy and full base motions, arm motions, grasps and placements,
// predicted efforts, and the branch context that executing an edge leaves behind.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include "tamp/core/log.h"
#include "tamp/graph_manager/graph_manager.h"
#include "tamp/world/scenario.h"

namespace tamp::graph_manager {
namespace {

/// A timed trajectory through `waypoints` over `names` at a nominal speed (the robot re-times it).
Trajectory timed(const std::vector<std::string>& names, const std::vector<std::vector<double>>& waypoints,
                 double speed) {
  Trajectory t;
  t.joint_names = names;
  double time = 0.0;
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    if (i > 0) {
      double d = 0.0;
      for (std::size_t j = 0; j < waypoints[i].size(); ++j) d = std::max(d, std::abs(waypoints[i][j] - waypoints[i - 1][j]));
      time += std::max(0.2, d / speed);
    }
    t.points.push_back(TrajectoryPoint{time, waypoints[i], {}});
  }
  return t;
}

/// "a, b, c": object ids for a reason or a log line.
template <typename Ids>
std::string joinIds(const Ids& ids) {
  std::string out;
  for (const auto& id : ids) out += (out.empty() ? "" : ", ") + id;
  return out;
}

double maxJointDelta(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0.0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}
}  // namespace

// ---- pricing ---------------------------------------------------------------------------------------

std::pair<double, double> GraphManager::price(const EffortQuery& q) {
  ++counters_.effort_calls;
  auto a = services_.effort({q});
  if (a.empty() || !a[0].ok) {
    // Unpriced is unusable: say why (an estimator that does not answer looks like "no branch").
    log::get("graph_manager")
        ->warn("no effort estimate for {}: {}", toString(q.kind), a.empty() ? std::string("no answer") : a[0].message);
    return {kInfinity, 0.0};
  }
  return {a[0].mean_s, a[0].stddev_s};
}

std::pair<double, double> GraphManager::pricePath(ActionKind kind, const JointPath& path, const BranchContext& ctx) {
  EffortQuery q;
  q.kind = kind;
  q.path = path;
  if (!ctx.held.object_id.empty())
    if (const world::Object* o = abstraction_.world().findObject(ctx.held.object_id)) q.object_mass = o->mass;
  return price(q);
}

MotionAnswer GraphManager::armMotion(const BranchContext& ctx, const std::vector<double>& target) {
  MotionQuery q;
  q.group = Group::kArm;
  q.mode = Mode::kFull;
  q.start = ctx.state;
  q.goal_arm = target;
  q.held = ctx.held;
  q.overrides = overridesOf(ctx);
  q.budget_s = params_.motion_budget_s;
  return askMotion(q);
}

MotionQuery GraphManager::baseQuery(const Edge& e, const BranchContext& ctx) const {
  MotionQuery q;
  q.group = Group::kBase;
  q.mode = e.variant == Variant::kAround ? Mode::kFull : Mode::kLazy;
  q.start = ctx.state;
  if (auto to = abstraction_.locationPose(e.tokens.size() > 2 ? e.tokens[2] : "")) q.goal_base = *to;
  q.held = ctx.held;
  q.overrides = overridesOf(ctx);
  q.movable_cost_weight = 0.0;  // the pure static-only lazy path
  if (q.mode == Mode::kLazy) q.fixed = fixedIn(ctx);
  q.budget_s = params_.motion_budget_s;
  return q;
}

MotionAnswer GraphManager::lazyOrFull(const MotionQuery& q) {
  // The static-only path ignores movables, so it may cross one where a path of about the same
  // length touches nothing (an object beside the way, one this branch put aside): the
  // effort-aware lazy path replaces it when it is clear and hardly longer.
  MotionQuery aware = q;
  aware.movable_cost_weight = 1.0;
  auto better = [&](MotionAnswer& a, MotionAnswer&& b) {
    if (b.ok() && b.blocking.empty() && b.path_length <= params_.clear_path_stretch * a.path_length) a = std::move(b);
  };
  if (q.mode == Mode::kLazy && params_.concurrent_motions) {
    std::vector<MotionAnswer> ab = askMotions({q, aware});
    if (ab[0].ok() && !ab[0].blocking.empty()) better(ab[0], std::move(ab[1]));
    return std::move(ab[0]);
  }
  MotionAnswer a = askMotion(q);
  if (a.ok() && q.mode == Mode::kLazy && !a.blocking.empty()) {
    better(a, askMotion(aware));
  }
  return a;
}

MotionAnswer GraphManager::planBase(const MotionQuery& q) {
  MotionAnswer a = lazyOrFull(q);
  // A base that starts facing away from its way (it faced the object it handled) may find only
  // a long detour: paths interpolate the heading while driving, which a narrow passage forbids.
  // The robot turns in place first (as it executes base motions: stop, turn, drive), so plan
  // from the heading towards the goal when that turn is free.
  const double dx = q.goal_base.x - q.start.base.x, dy = q.goal_base.y - q.start.base.y;
  const double straight = std::hypot(dx, dy);
  const double heading = std::atan2(dy, dx);
  if (straight < 1e-3 || std::abs(std::remainder(heading - q.start.base.theta, 2 * M_PI)) < 0.3) return a;
  if (a.ok() && a.path_length <= params_.turn_first_ratio * straight) return a;
  MotionQuery turn = q;
  turn.mode = Mode::kFull;
  turn.goal_base = Pose2D{q.start.base.x, q.start.base.y, heading};
  if (!askMotion(turn).ok()) return a;
  MotionQuery from_turned = q;
  from_turned.start.base.theta = heading;
  MotionAnswer b = lazyOrFull(from_turned);
  if (!b.ok() || (a.ok() && b.path_length >= a.path_length)) return a;
  // Prepend the turn: the start pose, then the turned path.
  std::vector<double> start{q.start.base.x, q.start.base.y, q.start.base.theta};
  if (!b.path.waypoints.empty()) {
    // Keep the heading unwrapped next to the turned start.
    start[2] = b.path.waypoints.front()[2] - std::remainder(b.path.waypoints.front()[2] - q.start.base.theta, 2 * M_PI);
    b.path.waypoints.insert(b.path.waypoints.begin(), start);
  }
  if (!b.trajectory.empty()) {
    const double turn_s = std::abs(b.trajectory.points.front().positions[2] - start[2]) / 0.5 + 0.2;
    for (auto& p : b.trajectory.points) p.time_from_start += turn_s;
    TrajectoryPoint p0;
    p0.time_from_start = 0.0;
    p0.positions = start;
    if (!b.trajectory.points.front().velocities.empty()) p0.velocities.assign(start.size(), 0.0);
    b.trajectory.points.insert(b.trajectory.points.begin(), p0);
  }
  return b;
}

double GraphManager::evaluateBase(Edge& e, const BranchContext& ctx, int depth) {
  const MotionQuery q = baseQuery(e, ctx);
  MotionAnswer a = planBase(q);
  e.motion_outcome = a.status;
  if (!a.ok()) {
    e.state = EdgeState::kInfeasible;
    e.reason = std::string(toString(a.status)) + (a.reason.empty() ? "" : ": " + a.reason);
    if (!q.fixed.empty()) e.reason += " (going round what the robot can neither carry nor push: " + joinIds(q.fixed) + ")";
    if (e.variant == Variant::kAround && params_.policy == Policy::kInfeasible && a.status == MotionOutcome::kNoPath &&
        depth < params_.max_subtask_depth + 1) {
      // Policy `infeasible`: only a proof that there is no way around lets objects be moved.
      // Copies: spawning sub-tasks grows the graph (its edge vector and out(from)).
      const std::vector<EdgeId> twins = graph_.out(e.from);
      const NodeId to = e.to;
      const std::string action = e.action;
      for (EdgeId twin : twins) {
        const Edge& d = graph_.edge(twin);
        if (d.to == to && d.action == action && d.variant == Variant::kDirect && d.state == EdgeState::kLazy &&
            spawnSubtasks(twin, ctx, depth) > 0)
          (void)evaluateBaseAgain(twin, ctx, depth);
      }
    }
    return kInfinity;
  }
  EdgeMotion m;
  m.lazy_path = a.path;
  for (const auto& c : a.blocking) {
    if (c.object_id == ctx.held.object_id) continue;
    m.blocking.push_back(c.object_id);
    m.crossings.push_back(c);
  }
  m.trajectory = a.trajectory;
  const auto [mean, sd] = pricePath(ActionKind::kMoveBase, a.path, ctx);
  e.motion = m;
  if (e.variant == Variant::kDirect && !m.blocking.empty()) {
    // Not executable as is: the detour is a parallel edge, removals are sub-tasks.
    e.state = EdgeState::kLazy;
    e.effort_mean_s = kInfinity;
    e.reason = "the lazy path crosses " + joinIds(m.blocking);
    {
      const Crossing& c0 = m.crossings.front();
      const Pose2D at = c0.swept_base.empty() ? Pose2D{} : c0.swept_base.front();
      std::string moved;
      for (const auto& [oid, pose] : ctx.object_poses)
        moved += " " + oid + "@(" + std::to_string(pose.translation().x()) + "," + std::to_string(pose.translation().y()) + ")";
      log::get("graph_manager")->debug("{}: {} from {:.2f} to {:.2f} of the path, robot at ({:.2f}, {:.2f}); moved:{}",
                                       e.action, e.reason, c0.enter_fraction, c0.exit_fraction, at.x, at.y, moved);
    }
    // addVariant appends to the graph's edges: `e` may dangle after it, so keep the id.
    const EdgeId id = e.id;
    const std::string origin = e.origin;
    graph_.addVariant(id, Variant::kAround, origin);
    const bool may_move = params_.policy != Policy::kInfeasible || aroundProvenImpossible(graph_.edge(id));
    if (may_move && depth <= params_.max_subtask_depth && spawnSubtasks(id, ctx, depth) > 0)
      return evaluateBaseAgain(id, ctx, depth);
    return kInfinity;
  }
  e.state = EdgeState::kFeasible;
  e.effort_mean_s = mean;
  e.effort_stddev_s = sd;
  log::get("graph_manager")->debug("{}{}: {:.2f} m, {} waypoints, {:.1f} s", e.action,
                                   e.variant == Variant::kAround ? " [around]" : "", a.path_length,
                                   a.path.waypoints.size(), mean);
  return mean;
}

std::vector<std::string> GraphManager::fixedIn(const BranchContext& ctx) const {
  std::set<std::string> all = fixed_objects_;
  if (auto it = fixed_in_world_.find(objectsKey(ctx)); it != fixed_in_world_.end())
    all.insert(it->second.begin(), it->second.end());
  return {all.begin(), all.end()};
}

double GraphManager::evaluateBaseAgain(EdgeId id, const BranchContext& ctx, int depth) {
  Edge& e = graph_.edge(id);
  log::get("graph_manager")->info("{}: planned again round what the robot cannot move ({})", e.action,
                                  joinIds(fixedIn(ctx)));
  e.state = EdgeState::kUnevaluated;
  e.subtasks_spawned = false;
  e.motion.reset();
  e.reason.clear();
  return evaluateBase(e, ctx, depth);
}

bool GraphManager::aroundProvenImpossible(const Edge& e) const {
  for (EdgeId twin : graph_.out(e.from)) {
    const Edge& d = graph_.edge(twin);
    if (d.to == e.to && d.action == e.action && d.variant == Variant::kAround && d.state == EdgeState::kInfeasible &&
        d.motion_outcome == MotionOutcome::kNoPath)
      return true;
  }
  return false;
}

bool GraphManager::occludesFromBase(const std::string& object, const std::string& region,
                                    const Eigen::Isometry3d& pose, const BranchContext& ctx) const {
  const world::Object* x = abstraction_.world().findObject(object);
  if (!x) return false;
  world::Object placed = *x;
  placed.pose = pose;
  const Eigen::Vector2d approach(ctx.state.base.x, ctx.state.base.y);
  for (const auto& o : abstraction_.world().objects()) {
    if (o.id == object || o.kind != world::ObjectKind::kMovable) continue;
    world::Object there = o;
    if (auto it = ctx.object_poses.find(o.id); it != ctx.object_poses.end()) there.pose = it->second;
    const world::Region* below = abstraction_.world().regionBelow(
        there.pose.translation() - Eigen::Vector3d(0, 0, there.shape.halfHeight()));
    if (!below || below->id != region) continue;  // only objects on the same support
    // The room a top grasp of the other object needs: the gripper's opening and a finger's width.
    const double margin = abstraction_.robot().gripperLimits().upper + 0.02;
    if (world::occludes(placed, there, approach, margin)) return true;
  }
  return false;
}

std::vector<ObjectOverride> GraphManager::overridesOf(const BranchContext& ctx, const std::string& except) {
  std::vector<ObjectOverride> out;
  for (const auto& [id, pose] : ctx.object_poses) {
    if (id != except) out.push_back(ObjectOverride{id, false, pose});
  }
  return out;
}

std::string GraphManager::worldKey(const BranchContext& ctx) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "%.3f,%.3f,%.3f", ctx.state.base.x, ctx.state.base.y, ctx.state.base.theta);
  return buf + objectsKey(ctx);
}

std::string GraphManager::objectsKey(const BranchContext& ctx) {
  char buf[96];
  std::string k;
  for (const auto& [id, pose] : ctx.object_poses) {
    std::snprintf(buf, sizeof buf, "|%.3f,%.3f,%.3f", pose.translation().x(), pose.translation().y(),
                  pose.translation().z());
    k += id + buf;
  }
  return k + "|held " + ctx.held.object_id;
}

void GraphManager::clearWorldCaches() {
  memo_.clear();
  grasp_cache_.clear();
  placement_cache_.clear();
  push_cache_.clear();
  fixed_objects_.clear();
  fixed_in_world_.clear();
  removable_objects_.clear();
  removals_.clear();
}

std::optional<std::pair<GraspOption, Eigen::Isometry3d>> GraphManager::preparePlace(
    const std::string& object, const std::string& region, const BranchContext& ctx, std::string& why, int skip) {
  if (ctx.held.object_id != object) {
    why = "place of " + object + " while not holding it";
    return std::nullopt;
  }
  const Slot* slot = abstraction_.slot(region);
  if (!slot) return sampledPlace(object, region, ctx, why, skip);
  // A slot is one pose: the arm reaches it and the pre-place pose above it, or not.
  const robot::RobotModel& robot = abstraction_.robot();
  const Eigen::Isometry3d base_inv = ctx.state.base.toIsometry(0.0).inverse();
  robot::IkOptions io;
  io.max_attempts = 16;
  const Eigen::Isometry3d world_T_tool = slot->pose * ctx.held.link_T_object.inverse();
  Eigen::Isometry3d pre = world_T_tool;
  pre.translation().z() += params_.approach_m;
  auto pre_ik = robot.inverseKinematics(base_inv * pre, ctx.state.arm, io);
  auto at_ik = pre_ik.ok() ? robot.inverseKinematics(base_inv * world_T_tool, pre_ik.q, io) : pre_ik;
  if (!pre_ik.ok() || !at_ik.ok() || skip > 0) {
    why = "the arm does not reach slot " + region + " for " + object + " from this base pose";
    return std::nullopt;
  }
  GraspOption g;
  g.pregrasp = pre_ik.q;
  g.grasp = at_ik.q;
  g.base_pose = ctx.state.base;
  g.gripper_in_object = ctx.held.link_T_object.inverse();
  return std::make_pair(g, slot->pose);
}

std::optional<std::pair<GraspOption, Eigen::Isometry3d>> GraphManager::sampledPlace(
    const std::string& object, const std::string& region, const BranchContext& ctx, std::string& why, int skip) {
  // Placements the arm reaches from where the base stands, with the object held as it is and
  // collision-free place and pre-place configurations (the motion planner checks them), in the
  // branch's world, per base pose and world. Asked for 4 at first, then 8, then 16, only when every placement kept so far was tried (the
  // motion planner's sampler is seeded: a larger request repeats the smaller one's placements
  // first). Most places take the first.
  constexpr std::uint32_t kFirstAsk = 4, kMaxAsk = 16;
  PlacementCacheEntry& entry = placement_cache_[object + "@" + region + "@" + worldKey(ctx)];
  while (skip >= static_cast<int>(entry.kept.size()) && !entry.exhausted && entry.asked < kMaxAsk) {
    PlacementQuery pq;
    pq.object_id = object;
    pq.region_id = region;
    pq.max_placements = entry.asked == 0 ? kFirstAsk : 2 * entry.asked;
    pq.base = ctx.state.base;
    pq.object_T_tool = ctx.held.link_T_object.inverse();
    pq.approach_m = params_.approach_m;
    pq.overrides = overridesOf(ctx, object);
    entry.asked = pq.max_placements;
    auto p = askPlacements(pq);
    entry.exhausted = !p || p->size() < pq.max_placements;
    if (!p) {  // the placements kept from a smaller request stay
      entry.why = "placements of " + object + " on " + region + ": " + p.error().message;
      break;
    }
    std::vector<PlacementOption> kept = *p;
    // A place does not bring back occlusion: from where the arm works, the placed object must
    // stand in front of no other object (the domain's place adds no `occludes`).
    kept.erase(std::remove_if(kept.begin(), kept.end(),
                              [&](const PlacementOption& o) { return occludesFromBase(object, region, o.object_pose, ctx); }),
               kept.end());
    entry.why = !p->empty() && kept.empty()
                    ? "every placement of " + object + " on " + region + " reachable from this base pose hides another object"
                    : std::string();
    entry.kept = std::move(kept);
  }
  const std::vector<PlacementOption>& kept = entry.kept;
  if (skip < static_cast<int>(kept.size())) {
    const PlacementOption& opt = kept[static_cast<std::size_t>(skip)];
    GraspOption g;
    g.pregrasp = opt.pre_arm;
    g.grasp = opt.arm;
    g.base_pose = ctx.state.base;
    g.gripper_in_object = ctx.held.link_T_object.inverse();
    return std::make_pair(g, opt.object_pose);
  }
  if (why.empty()) why = entry.why;
  if (why.empty())
    why = kept.empty() ? "the arm reaches no free placement of " + object + " on " + region + " from this base pose"
                             : "every placement of " + object + " on " + region + " tried from this base pose failed";
  return std::nullopt;
}

std::optional<EdgeMotion> GraphManager::armTarget(const Edge& arm_edge, EdgeId next, const BranchContext& ctx,
                                                  std::vector<double>& target, std::string& why, int alternative) {
  const robot::RobotModel& robot = abstraction_.robot();
  const std::string to_conf = arm_edge.tokens.size() > 3 ? arm_edge.tokens[3] : "stow";
  EdgeMotion m;
  if (to_conf == "stow" || next < 0) {
    // `stow` is the base-motion configuration: folded when empty-handed, `carry` when holding.
    const bool holding = !ctx.held.object_id.empty() && robot.namedConfiguration("carry").has_value();
    auto named = robot.namedConfiguration(to_conf == "stow" ? (holding ? "carry" : "stow") : "ready");
    if (!named) {
      why = "the robot has no named configuration '" + to_conf + "'";
      return std::nullopt;
    }
    target = *named;
    return m;
  }
  const Edge& f = graph_.edge(next);
  if (f.tokens.size() < 3) {
    why = "malformed manipulation " + f.action;
    return std::nullopt;
  }
  const std::string& object = f.tokens[1];
  const std::string& region = f.tokens[2];
  if (f.kind == ActionKind::kPick) {
    const std::string key = object + "@" + worldKey(ctx);
    auto it = grasp_cache_.find(key);
    if (it == grasp_cache_.end()) {
      GraspQuery gq;
      gq.object_id = object;
      gq.base = ctx.state.base;
      gq.max_grasps = 8;
      gq.overrides = overridesOf(ctx, object);
      auto g = askGrasps(gq);
      it = grasp_cache_.emplace(key, g ? *g : std::vector<GraspOption>{}).first;
      if (!g) why = "grasps of " + object + ": " + g.error().message;
    }
    if (it->second.empty()) {
      if (!ctx.object_poses.empty()) {
        // Objects this branch moved may be what hides every grasp today: price the arm motion to
        // the ready configuration and plan the grasp when the edge is about to run.
        auto ready = robot.namedConfiguration("ready");
        if (ready) {
          target = *ready;
          m.deferred = true;
          return m;
        }
      }
      if (why.empty()) {
        why = "no grasp of " + object + " from the base pose of " + arm_edge.tokens[1];
        (void)refineSupport(object, region, ctx);
      }
      return std::nullopt;
    }
    if (alternative >= static_cast<int>(it->second.size())) {
      why = "every grasp of " + object + " tried from " + arm_edge.tokens[1] + " is in collision";
      return std::nullopt;
    }
    m.prepared = it->second[static_cast<std::size_t>(alternative)];
    target = m.prepared->pregrasp;
    return m;
  }
  if (f.kind == ActionKind::kPlace) {
    auto prepared = preparePlace(object, region, ctx, why, alternative);
    if (!prepared) return std::nullopt;
    m.prepared = prepared->first;
    m.prepared_place = prepared->second;
    target = prepared->first.pregrasp;
    return m;
  }
  auto named = robot.namedConfiguration("ready");
  target = named ? *named : ctx.state.arm;
  return m;
}

double GraphManager::evaluateArm(Edge& e, EdgeId next, const BranchContext& ctx) {
  // The target follows from the manipulation after it; a target the planner finds in collision
  // (IK does not check collisions) gives way to the next placement, a few at most.
  std::optional<EdgeMotion> m;
  MotionAnswer a;
  for (int alternative = 0; alternative < 4; ++alternative) {
    std::vector<double> target;
    std::string why;
    m = armTarget(e, next, ctx, target, why, alternative);
    if (!m) {
      if (alternative == 0 || e.reason.empty()) e.reason = why;
      e.effort_by_next[next] = {kInfinity, 0.0};
      return kInfinity;
    }
    a = armMotion(ctx, target);
    if (a.ok()) break;
    e.reason = "arm motion: " + std::string(toString(a.status)) + (a.reason.empty() ? "" : ": " + a.reason);
    const bool manipulation_next = next >= 0 && (graph_.edge(next).kind == ActionKind::kPlace ||
                                                  graph_.edge(next).kind == ActionKind::kPick);
    if (a.status != MotionOutcome::kGoalInCollision || !manipulation_next) break;
  }
  if (!a.ok()) {
    e.effort_by_next[next] = {kInfinity, 0.0};
    return kInfinity;
  }
  m->trajectory = a.trajectory;
  m->lazy_path = a.path;
  m->planned_in = contextKey(ctx);
  const auto [mean, sd] = pricePath(ActionKind::kMoveArm, a.path, ctx);
  e.motion_by_next[next] = *m;
  e.effort_by_next[next] = {mean, sd};
  e.state = EdgeState::kFeasible;
  e.effort_mean_s = std::min(e.effort_mean_s, mean);
  e.effort_stddev_s = sd;
  return mean;
}

double GraphManager::evaluateManipulation(Edge& e, const BranchContext& ctx) {
  const robot::RobotModel& robot = abstraction_.robot();
  const std::string object = e.tokens.size() > 1 ? e.tokens[1] : "";
  const world::Object* o = abstraction_.world().findObject(object);
  if (!o) {
    e.state = EdgeState::kInfeasible;
    e.reason = "unknown object " + object;
    return kInfinity;
  }
  std::optional<GraspOption> g = ctx.pending_grasp;
  if (!g && e.kind == ActionKind::kPick) {
    // No move_arm prepared this pick (the arm is already over the region, e.g. after a failed
    // pick): a grasp from where the base stands, approached from the current arm configuration.
    GraspQuery gq;
    gq.object_id = object;
    gq.base = ctx.state.base;
    gq.overrides = overridesOf(ctx, object);
    auto grasps = askGrasps(gq);
    if (grasps && !grasps->empty()) g = grasps->front();
  }
  std::optional<Eigen::Isometry3d> place_pose = ctx.pending_place;
  if (!g && e.kind == ActionKind::kPlace && e.tokens.size() > 2) {
    // No move_arm prepared this place (the arm is over the region already): prepare it here,
    // with the first placement whose pre-place configuration is free (IK does not check that).
    for (int alternative = 0; alternative < 8; ++alternative) {
      std::string why;
      auto prepared = preparePlace(object, e.tokens[2], ctx, why, alternative);
      if (!prepared) {
        if (alternative == 0) e.reason = why;
        break;
      }
      const MotionAnswer a = armMotion(ctx, prepared->first.pregrasp);
      if (a.status == MotionOutcome::kGoalInCollision) {
        e.reason = "every pre-place configuration tried is in collision";
        continue;
      }
      g = prepared->first;
      place_pose = prepared->second;
      e.reason.clear();
      break;
    }
  }
  if (!g && e.kind == ActionKind::kPick && !ctx.object_poses.empty()) return priceDeferredPick(e, *o, ctx);
  if (!g) {
    e.state = EdgeState::kInfeasible;
    if (!e.reason.empty()) return kInfinity;
    e.reason = "no prepared " + std::string(e.kind == ActionKind::kPick ? "grasp" : "placement") + " for " + object;
    return kInfinity;
  }
  EdgeMotion m;
  m.object_id = object;
  m.region_id = e.tokens.size() > 2 ? e.tokens[2] : "";
  m.object_mass = o->mass;
  m.gripper_in_object = g->gripper_in_object;
  m.prepared = g;
  // The arm is not at the pre-grasp (no move_arm prepared this manipulation): an arm motion
  // there first, executed as its own move_arm, then the approach, the gripper and the retreat.
  double transfer_s = 0.0, transfer_sd = 0.0;
  if (maxJointDelta(ctx.state.arm, g->pregrasp) > 1e-3) {
    MotionAnswer a = armMotion(ctx, g->pregrasp);
    if (!a.ok()) {
      e.state = EdgeState::kInfeasible;
      e.reason = "arm motion to the pre-grasp: " + std::string(toString(a.status)) + (a.reason.empty() ? "" : ": " + a.reason);
      return kInfinity;
    }
    m.transfer = a.trajectory;
    std::tie(transfer_s, transfer_sd) = pricePath(ActionKind::kMoveArm, a.path, ctx);
  }
  m.trajectory = timed(robot.armJointNames(), {g->pregrasp, g->grasp, g->pregrasp}, 0.5);
  const double approach = (robot.toolPose(g->pregrasp).translation() - robot.toolPose(g->grasp).translation()).norm();
  m.approach_m = approach;
  m.retreat_m = approach;
  if (e.kind == ActionKind::kPlace) {
    if (!place_pose) {
      e.state = EdgeState::kInfeasible;
      e.reason = "no place pose for " + object;
      return kInfinity;
    }
    m.object_target = place_pose;
  } else {
    m.object_target = ctx.object_poses.count(object) ? ctx.object_poses.at(object) : o->pose;
  }
  EffortQuery eq;
  eq.kind = e.kind;
  eq.object_mass = o->mass;
  eq.approach_m = m.approach_m;
  eq.retreat_m = m.retreat_m;
  const auto [mean, sd] = price(eq);
  m.transfer_effort_s = transfer_s;
  m.transfer_stddev_s = transfer_sd;
  m.planned_in = contextKey(ctx);
  e.motion = m;
  e.state = std::isfinite(mean + transfer_s) ? EdgeState::kFeasible : EdgeState::kInfeasible;
  e.effort_mean_s = mean + transfer_s;
  e.effort_stddev_s = std::hypot(sd, transfer_sd);
  return e.effort_mean_s;
}

double GraphManager::priceDeferredPick(Edge& e, const world::Object& o, const BranchContext& ctx) {
  EdgeMotion m;
  m.object_id = o.id;
  m.region_id = e.tokens.size() > 2 ? e.tokens[2] : "";
  m.object_mass = o.mass;
  m.approach_m = params_.approach_m;
  m.retreat_m = params_.approach_m;
  m.deferred = true;
  m.object_target = ctx.object_poses.count(o.id) ? ctx.object_poses.at(o.id) : o.pose;
  // A nominal top grasp (tool z down through the object's centre), for the rest of the branch:
  // the carried object's geometry and the arm's pose after the pick.
  const robot::RobotModel& robot = abstraction_.robot();
  GraspOption g;
  g.gripper_in_object = Eigen::Isometry3d(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()));
  g.base_pose = ctx.state.base;
  const Eigen::Isometry3d base_inv = ctx.state.base.toIsometry(0.0).inverse();
  const Eigen::Isometry3d at = *m.object_target * g.gripper_in_object;
  Eigen::Isometry3d pre = at;
  pre.translation().z() += params_.approach_m;
  robot::IkOptions io;
  io.max_attempts = 16;
  auto pre_ik = robot.inverseKinematics(base_inv * pre, ctx.state.arm, io);
  g.pregrasp = pre_ik.ok() ? pre_ik.q : ctx.state.arm;
  g.grasp = g.pregrasp;
  m.prepared = g;
  m.gripper_in_object = g.gripper_in_object;
  EffortQuery eq;
  eq.kind = ActionKind::kPick;
  eq.object_mass = o.mass;
  eq.approach_m = m.approach_m;
  eq.retreat_m = m.retreat_m;
  const auto [mean, sd] = price(eq);
  e.motion = m;
  e.state = std::isfinite(mean) ? EdgeState::kFeasible : EdgeState::kInfeasible;
  e.effort_mean_s = mean;
  e.effort_stddev_s = sd;
  return mean;
}

EdgeId GraphManager::armKey(EdgeId arm, EdgeId next) const {
  const Edge& e = graph_.edge(arm);
  if (e.kind != ActionKind::kMoveArm || next < 0) return -1;
  if (e.tokens.size() > 3 && e.tokens[3] == "stow") return -1;
  const ActionKind k = graph_.edge(next).kind;
  return k == ActionKind::kPick || k == ActionKind::kPlace ? next : -1;
}

double GraphManager::evaluate(EdgeId id, EdgeId next, const BranchContext& ctx, int depth) {
  Edge& e = graph_.edge(id);
  next = armKey(id, next);
  ++counters_.evaluations;
  if (const int n = failuresOf(e); n >= params_.max_action_failures) {
    e.state = EdgeState::kInfeasible;
    e.reason = "failed " + std::to_string(n) + " times in this mission (max_action_failures)";
    return kInfinity;
  }
  switch (e.kind) {
    case ActionKind::kMoveBase:
      if (e.state != EdgeState::kUnevaluated) return e.effort_mean_s;
      return isPush(e) ? evaluatePush(e, ctx) : evaluateBase(e, ctx, depth);
    case ActionKind::kMoveArm: {
      if (auto it = e.effort_by_next.find(next); it != e.effort_by_next.end()) return it->second.first;
      return evaluateArm(e, next, ctx);
    }
    case ActionKind::kPick:
    case ActionKind::kPlace:
      return evaluateManipulation(e, ctx);
  }
  return kInfinity;
}

namespace {
std::string manipulationKey(const Edge& e) {
  return std::string(e.kind == ActionKind::kPick ? "pick " : "place ") + (e.tokens.size() > 1 ? e.tokens[1] : "");
}
}  // namespace

int GraphManager::failuresOf(const Edge& e) const {
  if (e.kind != ActionKind::kPick && e.kind != ActionKind::kPlace) return e.failures;
  const auto it = manipulation_failures_.find(manipulationKey(e));
  return it == manipulation_failures_.end() ? 0 : it->second;
}

void GraphManager::noteFailure(Edge& e) {
  if (e.kind == ActionKind::kPick || e.kind == ActionKind::kPlace)
    ++manipulation_failures_[manipulationKey(e)];
  else
    ++e.failures;
}

BranchContext GraphManager::advance(EdgeId id, EdgeId next, const BranchContext& ctx) const {
  const Edge& e = graph_.edge(id);
  next = armKey(id, next);
  BranchContext c = ctx;
  switch (e.kind) {
    case ActionKind::kMoveBase:
      c.came_from = ctx.state.base;
      if (isPush(e)) {
        // (push ?o ?r ?from ?to ?s): the base ends at ?to, the object on slot ?s.
        if (auto to = abstraction_.locationPose(e.tokens.size() == 6 ? e.tokens[4] : "")) c.state.base = *to;
        if (e.motion && e.motion->object_target)
          c.object_poses[e.motion->object_id] = *e.motion->object_target;
        else if (const Slot* s = abstraction_.slot(e.tokens.size() == 6 ? e.tokens[5] : ""))
          c.object_poses[s->object_id] = s->pose;
        break;
      }
      if (auto to = abstraction_.locationPose(e.tokens.size() > 2 ? e.tokens[2] : "")) c.state.base = *to;
      break;
    case ActionKind::kMoveArm: {
      auto it = e.motion_by_next.find(next);
      if (it != e.motion_by_next.end()) {
        if (!it->second.trajectory.empty()) c.state.arm = it->second.trajectory.points.back().positions;
        c.pending_grasp = it->second.prepared;
        c.pending_place = it->second.prepared_place;
      }
      break;
    }
    case ActionKind::kPick:
      if (e.motion && e.motion->prepared) {
        c.held.object_id = e.motion->object_id;
        c.held.link = abstraction_.robot().options().tool_link;
        c.held.link_T_object = e.motion->prepared->gripper_in_object.inverse();
        c.state.arm = e.motion->prepared->pregrasp;
        c.object_poses.erase(e.motion->object_id);
      }
      c.pending_grasp.reset();
      c.pending_place.reset();
      break;
    case ActionKind::kPlace:
      if (e.motion && e.motion->prepared && e.motion->object_target) {
        c.object_poses[e.motion->object_id] = *e.motion->object_target;
        c.state.arm = e.motion->prepared->pregrasp;
      }
      c.held = HeldGrasp{};
      c.pending_grasp.reset();
      c.pending_place.reset();
      break;
  }
  return c;
}

}  // namespace tamp::graph_manager
