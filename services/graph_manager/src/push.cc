// Pushes: an object too heavy or too wide to grasp, within the robot's push limit, is moved off a
// blocked path by the base driving straight into it (the domain's `push` action). Candidates
// along the object's footprint axes, by the shortest distance that clears the path, each checked
// collision-free by the motion planner with the object carried ahead of the base. When none is
// free, a push forwards along the path by the shortest distance that opens a way round the object.
#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstdio>
#include <limits>
#include <optional>

#include "tamp/core/log.h"
#include "tamp/graph_manager/graph_manager.h"
#include "tamp/world/polygon.h"

namespace tamp::graph_manager {
namespace {

/// A push's stand and end reuse an existing location only this close (m).
constexpr double kPushPoseReuseM = 0.01;

/// The object's footprint in the world plane.
world::Polygon2 worldFootprint(const world::Object& o, const Eigen::Isometry3d& pose) {
  world::Polygon2 out;
  const Eigen::Matrix2d R = pose.linear().topLeftCorner<2, 2>();
  const Eigen::Vector2d t = pose.translation().head<2>();
  for (const auto& v : o.shape.footprint()) out.push_back(R * v + t);
  return out;
}

/// Push directions: along the footprint's longest edge and across it, both ways.
std::vector<Eigen::Vector2d> pushDirections(const world::Polygon2& footprint) {
  Eigen::Vector2d u(1.0, 0.0);
  double longest = 0.0;
  for (std::size_t i = 0; i < footprint.size(); ++i) {
    const Eigen::Vector2d e = footprint[(i + 1) % footprint.size()] - footprint[i];
    if (e.norm() > longest) longest = e.norm(), u = e / e.norm();
  }
  const Eigen::Vector2d v(-u.y(), u.x());
  return {u, -u, v, -v};
}

/// How far the footprint reaches along `n` from `c` (the largest projection of a vertex).
double reach(const world::Polygon2& poly, const Eigen::Vector2d& c, const Eigen::Vector2d& n) {
  double r = -std::numeric_limits<double>::infinity();
  for (const auto& v : poly) r = std::max(r, (v - c).dot(n));
  return r;
}

/// Whether every pose keeps farther than `keep_clear` from the polygon.
bool clearOf(const world::Polygon2& poly, const std::vector<Pose2D>& poses, double keep_clear) {
  return std::all_of(poses.begin(), poses.end(),
                     [&](const Pose2D& s) { return world::polygonDistance(poly, Eigen::Vector2d(s.x, s.y)) > keep_clear; });
}

/// The way's direction where it passes closest to `c` (over about 0.5 m of it); zero when
/// the way has fewer than two poses.
Eigen::Vector2d wayDirectionAt(const std::vector<Pose2D>& swept, const Eigen::Vector2d& c) {
  if (swept.size() < 2) return Eigen::Vector2d::Zero();
  std::size_t best = 0;
  double best_d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < swept.size(); ++i) {
    const double d = (Eigen::Vector2d(swept[i].x, swept[i].y) - c).norm();
    if (d < best_d) best_d = d, best = i;
  }
  constexpr std::size_t kSpan = 5;  // swept poses are 5 cm apart
  const std::size_t a = best >= kSpan ? best - kSpan : 0, b = std::min(swept.size() - 1, best + kSpan);
  const Eigen::Vector2d d(swept[b].x - swept[a].x, swept[b].y - swept[a].y);
  return d.norm() > 1e-9 ? Eigen::Vector2d(d / d.norm()) : Eigen::Vector2d::Zero();
}

/// A full-mode base motion from `from` to `to`, the rest of the robot as in `ctx`.
MotionQuery fullBaseQuery(const Pose2D& from, const Pose2D& to, const BranchContext& ctx, double budget_s) {
  MotionQuery q;
  q.group = Group::kBase;
  q.mode = Mode::kFull;
  q.start = ctx.state;
  q.start.base = from;
  q.goal_base = to;
  q.budget_s = budget_s;
  return q;
}

/// Why no push of `o` was kept, after `tried` checked pushes.
void noPushWhy(const world::Object& o, int tried, std::string& why) {
  why = tried == 0 ? "no push of '" + o.id + "' within push_max_m clears or opens the way"
                   : "no straight push of '" + o.id + "' is collision-free (" + std::to_string(tried) + " tried)";
}

}  // namespace

bool isPush(const Edge& e) { return !e.tokens.empty() && e.tokens[0] == "push"; }

bool pushesIn(const std::string& domain_pddl) {
  // PDDL is case-insensitive and free in its whitespace: compare on lower-case tokens.
  std::string flat;
  bool space = true;
  for (char c : domain_pddl) {
    const bool ws = std::isspace(static_cast<unsigned char>(c)) != 0;
    if (ws && !space) flat += ' ';
    if (!ws) flat += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    space = ws;
  }
  return flat.find("(push-to ") != std::string::npos && flat.find("(:action push ") != std::string::npos;
}

bool GraphManager::domainPushes() const { return domain_pushes_; }

std::string GraphManager::whyNotPushable(const world::Object& o) const {
  if (!domainPushes()) return "the domain has no push action";
  if (params_.pushes_per_object <= 0) return "pushes_per_object is 0";
  const robot::RobotModel& robot = abstraction_.robot();
  if (o.kind != world::ObjectKind::kMovable) return "'" + o.id + "' is static";
  if (o.mass > robot.pushLimit()) {
    char b[160];
    std::snprintf(b, sizeof b, "'%s' (%.1f kg) exceeds the robot's push limit of %.1f kg", o.id.c_str(), o.mass,
                  robot.pushLimit());
    return b;
  }
  const world::Region* r = abstraction_.world().findRegion(o.region);
  if (r == nullptr || r->kind != world::RegionKind::kFloor) return "'" + o.id + "' does not stand on the floor";
  return "";
}

MotionQuery GraphManager::pushQuery(const std::string& object, const Eigen::Isometry3d& object_pose, const Pose2D& from,
                                    const Pose2D& to, const BranchContext& ctx) const {
  MotionQuery q = fullBaseQuery(from, to, ctx, params_.push_budget_s);
  q.straight_only = true;  // a push is straight (straightPush): nothing else needs planning
  q.held.object_id = object;
  q.held.link = abstraction_.robot().options().base_link;
  q.held.link_T_object = from.toIsometry(0.0).inverse() * object_pose;
  q.overrides = overridesOf(ctx, object);
  return q;
}

bool GraphManager::straightPush(const MotionAnswer& a, const Pose2D& from, const Pose2D& to) {
  if (!a.ok() || a.path.waypoints.empty()) return false;
  const Eigen::Vector2d p0(from.x, from.y), p1(to.x, to.y);
  const Eigen::Vector2d d = p1 - p0;
  if (a.path_length > d.norm() + 0.05) return false;
  const int ix = a.path.indexOf("base_x"), iy = a.path.indexOf("base_y");
  if (ix < 0 || iy < 0) return false;
  for (const auto& w : a.path.waypoints) {
    const Eigen::Vector2d p(w[static_cast<std::size_t>(ix)], w[static_cast<std::size_t>(iy)]);
    const double t = std::clamp((p - p0).dot(d) / std::max(1e-12, d.squaredNorm()), 0.0, 1.0);
    if ((p0 + t * d - p).norm() > 0.02) return false;
  }
  return true;
}

double GraphManager::pushBackoff() const {
  double front = 0.0, circumradius = 0.0;
  for (const auto& v : abstraction_.robot().baseFootprint()) {
    front = std::max(front, v.x());
    circumradius = std::max(circumradius, v.norm());
  }
  return params_.push_backoff_m + std::max(0.0, circumradius - front);
}

std::optional<MotionAnswer> GraphManager::pushMotion(const std::string& object, const Eigen::Isometry3d& pose,
                                                     const Eigen::Isometry3d& target, const Pose2D& from,
                                                     const Pose2D& apex, const Pose2D& to, const BranchContext& ctx,
                                                     std::string& why, PushBlock* block) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%.3f,%.3f,%.3f>%.3f,%.3f>%.3f,%.3f|%.3f,%.3f>%.3f,%.3f@", from.x, from.y, from.theta,
                apex.x, apex.y, to.x, to.y, pose.translation().x(), pose.translation().y(), target.translation().x(),
                target.translation().y());
  const std::string key = object + ":" + buf + objectsKey(ctx);
  auto it = push_cache_.find(key);
  if (it == push_cache_.end()) {
    PushCacheEntry entry;
    entry.answer = planPushMotion(object, pose, target, from, apex, to, ctx, entry.why, entry.block);
    it = push_cache_.emplace(key, std::move(entry)).first;
  }
  why = it->second.why;
  if (block != nullptr) *block = it->second.block;
  return it->second.answer;
}

std::optional<MotionAnswer> GraphManager::planPushMotion(const std::string& object, const Eigen::Isometry3d& pose,
                                                         const Eigen::Isometry3d& target, const Pose2D& from,
                                                         const Pose2D& apex, const Pose2D& to,
                                                         const BranchContext& ctx, std::string& why,
                                                         PushBlock& block) {
  const MotionQuery push = pushQuery(object, pose, from, apex, ctx);
  const bool backs_off = std::hypot(apex.x - to.x, apex.y - to.y) >= 1e-6;
  // The base backs off, straight, leaving the object where it pushed it: room to turn.
  MotionQuery back = fullBaseQuery(apex, to, ctx, params_.push_budget_s);
  back.straight_only = true;
  back.overrides = overridesOf(ctx, object);
  back.overrides.push_back(ObjectOverride{object, false, target});
  // Straight away from the object it touches: the object is no obstacle to that.
  back.ignored = {object};
  std::vector<MotionAnswer> answers;
  answers.reserve(2);  // `a` below stays valid when the back-off is asked after it
  if (backs_off && params_.concurrent_motions) {
    answers = askMotions({push, back});
  } else {
    answers.push_back(askMotion(push));
  }
  MotionAnswer& a = answers.front();
  if (!straightPush(a, from, apex)) {
    why = a.ok() ? "the push is not straight" : std::string(toString(a.status)) + (a.reason.empty() ? "" : ": " + a.reason);
    // Where the base stands to push is the same for every distance along this direction.
    block = a.status == MotionOutcome::kStartInCollision ? PushBlock::kAtStart : PushBlock::kFurtherOn;
    return std::nullopt;
  }
  if (!backs_off) return std::move(a);
  if (answers.size() < 2) {
    answers.push_back(askMotion(back));
  }
  const MotionAnswer& b = answers.back();
  if (!straightPush(b, apex, to)) {
    why = b.ok() ? "the back-off is not straight" : "back-off: " + std::string(toString(b.status)) + (b.reason.empty() ? "" : ": " + b.reason);
    block = PushBlock::kFurtherOn;
    return std::nullopt;
  }
  // One trajectory: the push, then the back-off (its first point is the push's last).
  for (std::size_t i = 1; i < b.path.waypoints.size(); ++i) a.path.waypoints.push_back(b.path.waypoints[i]);
  const double t0 = a.trajectory.points.empty() ? 0.0 : a.trajectory.points.back().time_from_start;
  for (std::size_t i = 1; i < b.trajectory.points.size(); ++i) {
    TrajectoryPoint p = b.trajectory.points[i];
    p.time_from_start += t0;
    a.trajectory.points.push_back(std::move(p));
  }
  a.path_length += b.path_length;
  return a;
}

GraphManager::PushGeometry GraphManager::pushGeometry(const world::Object& o, const Eigen::Isometry3d& pose,
                                                     const Eigen::Vector2d& n, double distance) const {
  const world::Polygon2 fp = worldFootprint(o, pose);
  const Eigen::Vector2d c = pose.translation().head<2>();
  double front = 0.0;  // how far the base reaches ahead of base_link
  for (const auto& v : abstraction_.robot().baseFootprint()) front = std::max(front, v.x());
  const double heading = std::atan2(n.y(), n.x());
  // The base's front `push_gap_m` short of the face it pushes, centred on the object.
  const double back = -reach(fp, c, -n) - front - params_.push_gap_m;
  const Eigen::Vector2d start = c + back * n;
  const Eigen::Vector2d apex = start + (distance + params_.push_gap_m) * n;
  const Eigen::Vector2d end = apex - pushBackoff() * n;
  PushGeometry g;
  g.from = Pose2D{start.x(), start.y(), heading};
  g.apex = Pose2D{apex.x(), apex.y(), heading};
  g.to = Pose2D{end.x(), end.y(), heading};
  g.target = pose;
  g.target.translation().head<2>() += distance * n;
  return g;
}

std::optional<std::string> GraphManager::addPushIfFree(const world::Object& o, const std::string& support,
                                                       const Eigen::Isometry3d& pose, const Eigen::Vector2d& n,
                                                       double distance, const BranchContext& ctx, PushBlock* block) {
  const PushGeometry g = pushGeometry(o, pose, n, distance);
  std::string why_not;
  if (!pushMotion(o.id, pose, g.target, g.from, g.apex, g.to, ctx, why_not, block)) {
    log::get("graph_manager")->debug("push of {} by {:.2f} m towards ({:.2f}, {:.2f}): {}", o.id, distance, n.x(), n.y(),
                                     why_not);
    return std::nullopt;
  }
  const std::string slot = abstraction_.addSlot(o.id, support, g.target);
  // Where the push was checked, to the centimetre: a stand a few centimetres off (made when the
  // object's estimate stood elsewhere) touches the object or pushes it short of its slot.
  const std::string l_from = abstraction_.locationFor(g.from, "push_" + o.id, kPushPoseReuseM);
  const std::string l_to = abstraction_.locationFor(g.to, "pushed_" + o.id, kPushPoseReuseM);
  abstraction_.addPush(o.id, support, l_from, l_to, slot);
  log::get("graph_manager")->info("push of {} by {:.2f} m: from {} ({:.2f}, {:.2f}) to {}; {} at ({:.2f}, {:.2f})", o.id,
                                  distance, l_from, g.from.x, g.from.y, l_to, slot, g.target.translation().x(),
                                  g.target.translation().y());
  return slot;
}

std::vector<double> GraphManager::openingPushDistances(const world::Object& o, const Eigen::Isometry3d& pose,
                                                      const Eigen::Vector2d& n, double max_distance,
                                                      const Pose2D& way_end, const std::vector<std::string>& crossed,
                                                      const BranchContext& ctx) {
  // One lazy question per distance, asked together: from where the base ends after the push to
  // where the blocked way ends, with the object at its new place. A path that prices crossings
  // dearly goes round the object when a way round is open; a push after which it crosses neither
  // the object nor any movable that the blocked way did not cross already opens the way (a way
  // "round" it through another object is no opening).
  std::vector<double> distances;
  std::vector<MotionQuery> queries;
  for (double d = params_.push_step_m; d <= max_distance + 1e-9; d += params_.push_step_m) {
    const PushGeometry g = pushGeometry(o, pose, n, d);
    MotionQuery q;
    q.group = Group::kBase;
    q.mode = Mode::kLazy;
    q.start = ctx.state;
    q.start.base = g.to;
    q.goal_base = way_end;
    q.overrides = overridesOf(ctx, o.id);
    q.overrides.push_back(ObjectOverride{o.id, false, g.target});
    // Crossings priced far above any detour within the map: the lazy path crosses an object
    // only where there is no way round it.
    q.movable_cost_weight = 100.0;
    q.budget_s = params_.motion_budget_s;
    distances.push_back(d);
    queries.push_back(std::move(q));
  }
  if (queries.empty()) return {};
  const std::vector<MotionAnswer> answers = askMotions(queries);
  auto opens = [&](std::size_t i) {
    const MotionAnswer& a = answers[i];
    std::string crossing;
    for (const auto& c : a.blocking) crossing += " " + c.object_id;
    log::get("graph_manager")
        ->debug("opening push of {} by {:.2f} m towards ({:.2f}, {:.2f}): {}, crosses:{}", o.id, distances[i], n.x(), n.y(),
                a.ok() ? "solved" : std::string(toString(a.status)) + " " + a.reason, crossing);
    return a.ok() && std::all_of(a.blocking.begin(), a.blocking.end(), [&](const Crossing& c) {
             return c.object_id != o.id && std::find(crossed.begin(), crossed.end(), c.object_id) != crossed.end();
           });
  };
  std::vector<double> out;
  for (std::size_t i = 0; i < answers.size(); ++i)
    if (opens(i)) out.push_back(distances[i]);
  // One step further first when that opens too: the shortest opening leaves the robot a way that
  // hugs the object, lost to the centimetres by which a push misses its slot.
  if (out.size() >= 2 && out[1] - out[0] < params_.push_step_m * 1.5) std::swap(out[0], out[1]);
  return out;
}

std::optional<std::string> GraphManager::addOpeningPush(const world::Object& o, const std::string& support,
                                                        const Eigen::Isometry3d& pose, const Eigen::Vector2d& n,
                                                        double max_distance, const Pose2D& way_end,
                                                        const std::vector<std::string>& crossed,
                                                        const BranchContext& ctx, int& tried) {
  for (double d : openingPushDistances(o, pose, n, max_distance, way_end, crossed, ctx)) {
    ++tried;
    PushBlock block = PushBlock::kNone;
    if (auto slot = addPushIfFree(o, support, pose, n, d, ctx, &block)) return slot;
    if (block == PushBlock::kAtStart) break;  // as blocked at any other distance
  }
  return std::nullopt;
}

std::vector<std::string> GraphManager::spawnPushes(const world::Object& o, const std::string& support,
                                                   const BranchContext& ctx, const std::vector<Pose2D>& swept,
                                                   const std::vector<std::string>& crossed, double keep_clear,
                                                   std::string& why) {
  const Eigen::Isometry3d pose = ctx.object_poses.count(o.id) ? ctx.object_poses.at(o.id) : o.pose;
  const world::Polygon2 fp = worldFootprint(o, pose);
  struct Candidate {
    Eigen::Vector2d n;
    double distance;
  };
  // Per direction, the shortest push that takes the object off the blocked way; the directions
  // along the way have none (the object stays on it however far it goes).
  std::vector<Candidate> candidates;
  std::vector<Eigen::Vector2d> along;
  for (const Eigen::Vector2d& n : pushDirections(fp)) {
    bool found = false;
    for (double d = params_.push_step_m; d <= params_.push_max_m + 1e-9 && !found; d += params_.push_step_m) {
      world::Polygon2 moved = fp;
      for (auto& v : moved) v += d * n;
      if (clearOf(moved, swept, keep_clear)) candidates.push_back({n, d}), found = true;
    }
    if (!found) along.push_back(n);
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.distance < b.distance; });
  std::vector<std::string> slots;
  auto room = [&] { return static_cast<int>(slots.size()) < params_.pushes_per_object; };
  int tried = 0;
  std::vector<Candidate> blocked_further_on;
  for (const Candidate& k : candidates) {
    if (!room()) break;
    ++tried;
    PushBlock block = PushBlock::kNone;
    if (auto slot = addPushIfFree(o, support, pose, k.n, k.distance, ctx, &block)) slots.push_back(*slot);
    else if (block == PushBlock::kFurtherOn) blocked_further_on.push_back(k);
  }
  if (swept.empty()) {
    if (slots.empty()) noPushWhy(o, tried, why);
    return slots;
  }
  // None of those is free (a chair in a doorway, its sides against the frame or other chairs): a
  // push along the way, out of the doorway into open space, opens a way round it instead. Only
  // forwards: the base pushes from the side it comes from.
  const Eigen::Vector2d forwards = wayDirectionAt(swept, pose.translation().head<2>());
  for (const Eigen::Vector2d& n : along) {
    if (!room()) break;
    if (n.dot(forwards) <= 0.0) continue;
    if (auto slot = addOpeningPush(o, support, pose, n, params_.push_max_m, swept.back(), crossed, ctx, tried))
      slots.push_back(*slot);
  }
  // A push that would take the object off the way runs into something first (a wall a little
  // beyond the way): a shorter push the same way may leave room to pass on the other side.
  for (const Candidate& k : blocked_further_on) {
    if (!room()) break;
    if (auto slot = addOpeningPush(o, support, pose, k.n, k.distance - params_.push_step_m, swept.back(), crossed,
                                   ctx, tried))
      slots.push_back(*slot);
  }
  if (slots.empty()) noPushWhy(o, tried, why);
  return slots;
}

double GraphManager::evaluatePush(Edge& e, const BranchContext& ctx) {
  // (push ?o ?r ?from ?to ?s)
  const world::Object* o = e.tokens.size() == 6 ? abstraction_.world().findObject(e.tokens[1]) : nullptr;
  const auto from = abstraction_.locationPose(e.tokens.size() == 6 ? e.tokens[3] : "");
  const auto to = abstraction_.locationPose(e.tokens.size() == 6 ? e.tokens[4] : "");
  const Slot* slot = abstraction_.slot(e.tokens.size() == 6 ? e.tokens[5] : "");
  if (!o || !from || !to || !slot) {
    e.state = EdgeState::kInfeasible;
    e.reason = "push without its object, locations or slot";
    return kInfinity;
  }
  const Eigen::Isometry3d pose = ctx.object_poses.count(o->id) ? ctx.object_poses.at(o->id) : o->pose;
  // From where the robot stands when that is the push's start (the base stops a little off
  // where it was sent): the push drives on to the same end.
  Pose2D start = *from;
  const double off = std::hypot(ctx.state.base.x - from->x, ctx.state.base.y - from->y);
  if (off <= abstraction_.params().location_tolerance_m &&
      std::abs(std::remainder(ctx.state.base.theta - from->theta, 2 * M_PI)) <= abstraction_.params().location_tolerance_rad)
    start = ctx.state.base;
  // Where the object ends, and the push's direction: moved along it as far as the slot says.
  Eigen::Isometry3d target = pose;
  target.translation().head<2>() = slot->pose.translation().head<2>();
  Eigen::Vector2d n = slot->pose.translation().head<2>() - pose.translation().head<2>();
  if (n.norm() < 1e-6) n = Eigen::Vector2d(to->x - from->x, to->y - from->y);
  n.normalize();
  const Pose2D apex{to->x + pushBackoff() * n.x(), to->y + pushBackoff() * n.y(), to->theta};
  std::string why;
  const std::optional<MotionAnswer> pushed = pushMotion(o->id, pose, target, start, apex, *to, ctx, why);
  if (!pushed) {
    e.state = EdgeState::kInfeasible;
    e.reason = why + " in this branch's world";
    return kInfinity;
  }
  const MotionAnswer& a = *pushed;
  EdgeMotion m;
  m.lazy_path = a.path;
  m.trajectory = a.trajectory;
  m.object_id = o->id;
  m.region_id = slot->id;
  m.object_mass = o->mass;
  m.object_target = target;
  EffortQuery q;
  q.kind = ActionKind::kMoveBase;
  q.path = a.path;
  q.object_mass = o->mass;
  const auto [mean, sd] = price(q);
  e.motion = m;
  e.state = EdgeState::kFeasible;
  e.effort_mean_s = mean;
  e.effort_stddev_s = sd;
  return mean;
}

}  // namespace tamp::graph_manager
