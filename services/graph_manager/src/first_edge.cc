// Replanning latency (issue 12): the next command goes out once Traverse has proven its first
// edge best; the rest of the branch is priced while the robot executes it.
//
// Branch-and-bound decides the first edge of the branch as soon as a complete branch through it
// is known and every other way on from the start is bounded by that branch's cost (each explored
// until its partial cost plus bound reaches it, or completed above it). What lies below the first
// edge (which placement, which grasp, which way round further on) cannot change that choice: it
// only lowers the cost through the first edge. So below it nothing more is explored before the
// command; a Traverse from the first edge's end, run while the robot executes it, chooses the rest
// as the full search would have: the best branch below the first edge (ties and the evaluation
// budget aside, which the two searches spend differently).
//
// The first edge settled is the best complete branch's so far. When a branch through another
// first edge beats it (session 30: after an overrun, the branch the robot was following is the
// first completed, and a way it had cut before wins once the models are refitted), the new one is
// settled and the one it replaces is explored again from the start against the new cost, for
// what was left unexplored below it. Before, the search ended unproven there and a full Traverse
// followed, which priced the whole subtree below the winning first edge before the command
// (namo_big_crossing's overrun re-traverse: 0.06-0.11 s of its 0.35-0.58 s).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "tamp/core/log.h"
#include "tamp/graph_manager/graph_manager.h"

namespace tamp::graph_manager {

std::vector<EdgeId> GraphManager::firstEdgeOf(const std::vector<EdgeId>& branch) const {
  if (branch.empty()) return {};
  // An arm motion into a manipulation is decided with it: its target is that manipulation's
  // pre-grasp, and the manipulation is priced with the grasp the arm motion prepared.
  if (branch.size() > 1 && graph_.edge(branch[0]).kind == ActionKind::kMoveArm &&
      armKey(branch[0], branch[1]) >= 0)
    return {branch[0], branch[1]};
  return {branch[0]};
}

BranchContext GraphManager::advanceAlong(const std::vector<EdgeId>& edges,
                                         const BranchContext& ctx) const {
  BranchContext c = ctx;
  for (std::size_t i = 0; i < edges.size(); ++i)
    c = advance(edges[i], i + 1 < edges.size() ? edges[i + 1] : -1, c);
  return c;
}

std::string GraphManager::contextKey(const BranchContext& ctx) const {
  std::string k = worldKey(ctx);
  char buf[64];
  for (double q : ctx.state.arm) {
    std::snprintf(buf, sizeof buf, ",%.4f", q);
    k += buf;
  }
  k += "|held " + ctx.held.object_id;
  // A manipulation is priced with the grasp or placement the arm motion before it prepared.
  if (ctx.pending_grasp) {
    k += "|grasp";
    for (double q : ctx.pending_grasp->pregrasp) {
      std::snprintf(buf, sizeof buf, ",%.4f", q);
      k += buf;
    }
  }
  if (ctx.pending_place) {
    const Eigen::Vector3d t = ctx.pending_place->translation();
    std::snprintf(buf, sizeof buf, "|place %.3f,%.3f,%.3f", t.x(), t.y(), t.z());
    k += buf;
  }
  for (const auto& o : abstraction_.world().objects()) {
    if (o.kind != world::ObjectKind::kMovable) continue;
    const Eigen::Vector3d t = o.pose.translation();
    std::snprintf(buf, sizeof buf, "@%.3f,%.3f,%.3f,%.3f", t.x(), t.y(), t.z(),
                  std::atan2(o.pose.linear()(1, 0), o.pose.linear()(0, 0)));
    k += "|" + o.id + buf;
  }
  return k;
}

bool GraphManager::plannedIn(EdgeId id, EdgeId next, const BranchContext& ctx) const {
  const Edge& e = graph_.edge(id);
  if (e.kind == ActionKind::kPick || e.kind == ActionKind::kPlace)
    return e.state == EdgeState::kFeasible && e.motion && !e.motion->deferred &&
           e.motion->prepared && !e.motion->trajectory.empty() && !e.motion->planned_in.empty() &&
           e.motion->planned_in == contextKey(ctx);
  if (e.kind != ActionKind::kMoveArm) return false;
  const EdgeId arm = id;
  const EdgeId key = armKey(arm, next);
  const auto m = e.motion_by_next.find(key);
  const auto effort = e.effort_by_next.find(key);
  if (m == e.motion_by_next.end() || effort == e.effort_by_next.end() ||
      !std::isfinite(effort->second.first)) {
    log::get("graph_manager")->debug("plannedIn {}: no motion for this next ({})", e.action, key);
    return false;
  }
  const std::string now = contextKey(ctx);
  if (m->second.planned_in != now)
    log::get("graph_manager")->debug("plannedIn {}: planned in '{}', now '{}' (prepared {}, deferred {})", e.action,
                                     m->second.planned_in, now, m->second.prepared.has_value(), m->second.deferred);
  return key >= 0 && m->second.prepared && !m->second.deferred && !m->second.trajectory.empty() &&
         !m->second.planned_in.empty() && m->second.planned_in == now;
}

TraverseResult GraphManager::traverseFirstEdge(NodeId from, const BranchContext& context) {
  // The best branch found always goes through the settled first edge (both follow the cheapest
  // complete branch), so a found branch has its first edge decided. When the budget ran out
  // before every other way on was bounded, that edge is the best so far and is executed, as a
  // full search out of budget executes its best branch so far (before session 33 a full search
  // followed here, with a budget of its own: two deadlines before namo_moghaddam_07's command).
  TraverseResult r = search(from, context, true);
  if (r.found && !r.proven && !r.branch.empty())
    log::get("graph_manager")
        ->info("first-edge search from n{}: not proven within the budget ({} evaluations, {:.1f} s); the best first "
               "edge so far is executed",
               from, r.evaluations, r.time_s);
  return r;
}

}  // namespace tamp::graph_manager
