// Sub-tasks (findPossibleActions, findEffectStates, TP(v, s), TP(s, child)): what an object that
// blocks an edge's lazy path spawns in the reachability graph.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include "tamp/core/log.h"
#include "tamp/graph_manager/graph_manager.h"
#include "tamp/world/scenario.h"

namespace tamp::graph_manager {

int GraphManager::spawnSubtasks(EdgeId id, const BranchContext& ctx, int depth) {
  Edge& blocked = graph_.edge(id);
  if (blocked.subtasks_spawned || !blocked.motion) return 0;
  blocked.subtasks_spawned = true;
  const NodeId v = blocked.from;
  const NodeId child = blocked.to;
  const EdgeMotion motion = *blocked.motion;
  // The robot's base poses along the blocked path: placements must keep clear of them.
  // (every 5 cm: the placement sampler keeps clear of poses, not of segments).
  std::vector<Pose2D> swept;
  const auto& wps = motion.lazy_path.waypoints;
  for (std::size_t i = 0; i < wps.size(); ++i) {
    if (wps[i].size() < 3) continue;
    if (i > 0 && wps[i - 1].size() >= 3) {
      const double len = std::hypot(wps[i][0] - wps[i - 1][0], wps[i][1] - wps[i - 1][1]);
      const int n = static_cast<int>(std::ceil(len / 0.05));
      for (int k = 1; k < n; ++k) {
        const double t = static_cast<double>(k) / n;
        swept.push_back(Pose2D{wps[i - 1][0] + t * (wps[i][0] - wps[i - 1][0]),
                               wps[i - 1][1] + t * (wps[i][1] - wps[i - 1][1]), wps[i][2]});
      }
    }
    swept.push_back(Pose2D{wps[i][0], wps[i][1], wps[i][2]});
  }
  const double radius = abstraction_.robot().baseRadius() + params_.keep_clear_margin_m;
  std::vector<std::string> crossed;
  for (const auto& c : motion.crossings) crossed.push_back(c.object_id);
  int objects = 0;
  int fixed = 0;
  std::vector<std::string> unmovable;  // why a crossed object spawned no sub-task (for the failure reason)
  std::vector<std::pair<std::string, std::string>> first_slots;  // per movable object, for the oracle's subsets
  for (const auto& crossing : motion.crossings) {
    if (objects >= blockingObjectsConsidered()) break;
    const world::Object* o = abstraction_.world().findObject(crossing.object_id);
    if (!o || o->kind != world::ObjectKind::kMovable) continue;
    if (ctx.object_poses.count(o->id)) {
      // This branch moved it already: moving it again would chain removals of one object along
      // the way (a push ahead of the base, then another); the branch goes round it instead.
      unmovable.push_back("'" + o->id + "' was moved by this branch already");
      continue;
    }
    ++objects;
    // findPossibleActions: pick and place when the robot can grasp the object, else a push.
    std::string why_not;
    std::vector<std::string> slots = placeSlots(*o, supportAt(v, o->id), crossing, ctx, swept, radius, why_not);
    if (slots.empty()) {
      const std::string no_push = whyNotPushable(*o);
      std::string why_push = no_push;
      if (no_push.empty()) slots = spawnPushes(*o, supportAt(v, o->id), ctx, swept, crossed, radius, why_push);
      if (slots.empty()) {
        unmovable.push_back(why_not + (why_push.empty() ? "" : "; " + why_push));
        // Neither carried nor pushed in this world: later lazy paths go round it if they can (in
        // every branch, or in those whose objects stand as here: see fixed_in_world_).
        const bool intrinsic = !abstraction_.whyNotGraspable(*o).empty() && !no_push.empty();
        std::set<std::string>& into = intrinsic ? fixed_objects_ : fixed_in_world_[objectsKey(ctx)];
        if (!removable_objects_.count(o->id) && into.insert(o->id).second) ++fixed;
        continue;
      }
    }
    removable_objects_.insert(o->id);
    // What the blocked action achieved: the sub-task's second plan must achieve it too.
    const auto& va = graph_.node(v).atoms;
    const auto& ca = graph_.node(child).atoms;
    std::vector<std::string> progress;
    for (const auto& a : ca)
      if (!std::binary_search(va.begin(), va.end(), a)) progress.push_back(a);
    Removal removal{v, objectsKey(ctx), o->id, id, depth, {}};
    for (const auto& s : slots) {
      const EdgeId first =
          addSubtask(v, {"(on " + o->id + " " + s + ")"}, progress, "sub-task: move " + o->id + " to " + s);
      if (first >= 0) removal.firsts.push_back(first);
    }
    if (!removal.firsts.empty()) removals_.push_back(std::move(removal));
    first_slots.emplace_back(o->id, slots.front());
  }
  if (params_.policy == Policy::kOracle) spawnSubsetSubtasks(v, child, first_slots);
  // The edge may have moved: the graph grew.
  Edge& e = graph_.edge(id);
  for (const auto& why : unmovable) e.reason += "; " + why;
  return fixed;
}

std::string GraphManager::supportAt(NodeId v, const std::string& object) const {
  for (const auto& a : graph_.node(v).atoms) {
    const auto t = atomTokens(a);
    if (t.size() == 3 && t[0] == "on" && t[1] == object) return t[2];
  }
  const world::Object* o = abstraction_.world().findObject(object);
  return o ? o->region : std::string();
}

std::vector<std::string> GraphManager::placeSlots(const world::Object& o, const std::string& support, const Crossing& crossing,
                                                  const BranchContext& ctx, const std::vector<Pose2D>& swept,
                                                  double radius, std::string& why) {
  if (why = abstraction_.whyNotGraspable(o); !why.empty()) return {};
  // A base pose beside the object from which the arm reaches it, on the side the robot comes
  // from: back from where the lazy path first touches the object.
  const Pose2D entry = crossing.swept_base.empty() ? ctx.state.base : crossing.swept_base.front();
  const std::optional<GraspOption> chosen = standBeside(o, entry, ctx, swept);
  if (!chosen) {
    log::get("graph_manager")->info("no grasp of {} from any base pose", o.id);
    why = "no grasp of '" + o.id + "' from any base pose";
    return {};
  }
  const std::string near = abstraction_.locationFor(chosen->base_pose, "near_" + o.id);
  // The grasp proves the reach of what the object stands on in this branch (a slot once moved).
  if (!support.empty()) abstraction_.addReach(near, Abstraction::armconfOver(support));
  log::get("graph_manager")->info("sub-task for {}: contact at ({:.2f}, {:.2f}); stand at {} ({:.2f}, {:.2f})", o.id,
                                  entry.x, entry.y, near, chosen->base_pose.x, chosen->base_pose.y);
  // findEffectStates: placements off the swept path, in the object's region first.
  std::vector<std::string> regions;
  if (!o.region.empty()) regions.push_back(o.region);
  for (const auto& r : abstraction_.world().regions())
    if (r.id != o.region) regions.push_back(r.id);
  std::vector<std::string> slots;
  for (const auto& r : regions) {
    if (static_cast<int>(slots.size()) >= params_.placements_per_object) break;
    PlacementQuery pq;
    pq.object_id = o.id;
    pq.region_id = r;
    pq.keep_clear_path = swept;
    pq.keep_clear_radius = radius;
    pq.max_placements = static_cast<unsigned>(params_.placements_per_object);
    auto ps = askPlacements(pq);
    if (!ps) continue;
    for (const auto& p : *ps) {
      if (static_cast<int>(slots.size()) >= params_.placements_per_object) break;
      const std::string s = abstraction_.addSlot(o.id, r, p.object_pose);
      log::get("graph_manager")->info("findEffectStates({}): {} at ({:.2f}, {:.2f}) on {}, base ({:.2f}, {:.2f})", o.id, s,
                                      p.object_pose.translation().x(), p.object_pose.translation().y(), r,
                                      p.base_pose.x, p.base_pose.y);
      abstraction_.locationFor(p.base_pose, "place_" + o.id);
      slots.push_back(s);
    }
  }
  if (slots.empty()) why = "no placement for '" + o.id + "' off the path";
  return slots;
}

EdgeId GraphManager::addSubtask(NodeId v, const std::vector<std::string>& moved, const std::vector<std::string>& progress,
                                const std::string& origin) {
  auto before = planFrom(v, moved, origin);
  if (!before) return -1;
  ++counters_.subtasks;
  EdgeId first = before->empty() ? -1 : before->front();
  NodeId end = before->empty() ? v : graph_.edge(before->back()).to;
  if (!progress.empty()) {
    auto after = planFrom(end, progress, origin);
    if (!after) return first;
    if (first < 0 && !after->empty()) first = after->front();
    if (!after->empty()) end = graph_.edge(after->back()).to;
  }
  if (!isGoal(end)) {
    auto rest = planFrom(end, goal_.atoms, origin);
    if (first < 0 && rest && !rest->empty()) first = rest->front();
  }
  return first;
}

bool GraphManager::fixUnremovable(NodeId v, const BranchContext& ctx, const std::function<bool(EdgeId)>& dead) {
  const std::string world = objectsKey(ctx);
  std::map<EdgeId, int> blocked;  // edge -> the depth it was priced at
  for (const Removal& r : removals_) {
    if (r.from != v || r.world != world || fixed_objects_.count(r.object)) continue;
    if (!std::all_of(r.firsts.begin(), r.firsts.end(), dead)) continue;
    if (!fixed_in_world_[world].insert(r.object).second) continue;
    log::get("graph_manager")
        ->info("every removal of {} failed at its first step from n{}: going round it in this world", r.object, v);
    blocked.emplace(r.blocked, r.depth);
  }
  for (const auto& [e, depth] : blocked) (void)evaluateBaseAgain(e, ctx, depth);
  return !blocked.empty();
}


}  // namespace tamp::graph_manager
