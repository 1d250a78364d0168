// Conditional planning ("Conditional Planning" of the paper): contingencies known in advance are
// branches of the reachability graph before execution starts; at run time the observation picks
// the branch, without a planner call.
//
// The contingency built here is "the gripper is not empty": the robot must manipulate an object,
// but its hand holds something the planner does not know about. The branch is planned over a
// placeholder item (the object is unknown when the branch is built): put it down wherever the
// planner finds a region, then re-join the first plan. The observation names the object, and the
// branch is instantiated for it by renaming the placeholder.
#include <algorithm>

#include "state_atoms.h"
#include "tamp/core/log.h"
#include "tamp/graph_manager/graph_manager.h"

namespace tamp::graph_manager {
namespace {

constexpr const char* kHandEmpty = "(hand-empty)";

bool has(const std::vector<std::string>& sorted_atoms, const std::string& atom) {
  return std::binary_search(sorted_atoms.begin(), sorted_atoms.end(), atom);
}

/// The plan as actions and the states between them, read back from the graph.
Contingency::Plan planOf(const ReachabilityGraph& g, const std::vector<EdgeId>& edges) {
  Contingency::Plan p;
  if (edges.empty()) return p;
  p.states.push_back(g.node(g.edge(edges.front()).from).atoms);
  for (EdgeId id : edges) {
    p.actions.push_back(g.edge(id).action);
    p.states.push_back(g.node(g.edge(id).to).atoms);
  }
  return p;
}

}  // namespace

int GraphManager::buildContingencies(const std::vector<EdgeId>& plan) {
  if (params_.max_contingencies <= 0 || plan.empty()) return 0;
  // The nodes along the plan: node k is the state before plan[k] (k = plan.size(): the end).
  auto nodeAt = [&](std::size_t k) { return k < plan.size() ? graph_.edge(plan[k]).from : graph_.edge(plan.back()).to; };
  std::vector<std::size_t> at;
  for (std::size_t k = 0; k < plan.size() && static_cast<int>(at.size()) < params_.max_contingencies; ++k) {
    if (k > 0 && graph_.edge(plan[k]).kind != ActionKind::kPick) continue;
    if (has(graph_.node(nodeAt(k)).atoms, kHandEmpty)) at.push_back(k);
  }
  if (at.empty()) return 0;
  const std::string ph = abstraction_.addPlaceholder("unknown_held_object");
  const std::string held = "(holding " + ph + ")";
  int built = 0;
  for (std::size_t k : at) {
    const NodeId n = nodeAt(k);
    std::vector<std::string> atoms = graph_.node(n).atoms;
    atoms.erase(std::find(atoms.begin(), atoms.end(), kHandEmpty));
    atoms.push_back(held);
    Contingency c;
    c.at = n;
    c.observation = "gripper not empty";
    c.placeholder = ph;
    c.branch = graph_.addNode(atoms, "conditional: gripper not empty at n" + std::to_string(n));
    const std::vector<std::string> from = graph_.node(c.branch).atoms;  // a copy: planning grows the graph
    // Put it down, then re-join the plan with the hand empty: at the state before the next pick
    // (or the end) and the ones before it, back to this node, at most `max_rejoin_targets`.
    std::size_t last = k + 1;
    while (last < plan.size() && graph_.edge(plan[last]).kind != ActionKind::kPick) ++last;
    if (k < plan.size() && graph_.edge(plan[k]).kind == ActionKind::kPick) last = k;
    int targets = 0;
    for (std::size_t j = last + 1; j-- > k && targets < params_.max_rejoin_targets;) {
      const NodeId t = nodeAt(j);
      if (!has(graph_.node(t).atoms, kHandEmpty)) continue;
      const std::string origin = "conditional n" + std::to_string(n) + ": put down what the gripper holds, re-join n" +
                                 std::to_string(t);
      auto put_down = planFrom(c.branch, detail::exactly(from, graph_.node(t).atoms), origin);
      if (!put_down || put_down->empty()) {
        log::get("graph_manager")->info("no conditional branch from n{} to n{}: {}", c.branch, t,
                                        put_down ? "empty plan" : put_down.error().message);
        continue;
      }
      ++targets;
      c.plans.push_back(planOf(graph_, *put_down));
      // The end holds the target's atoms and where the object was put: carried along the plan.
      const auto& end = graph_.node(graph_.edge(put_down->back()).to).atoms;
      std::vector<std::string> carried;
      for (const auto& a : end)
        if (detail::mentions(a, {ph})) carried.push_back(a);
      Contingency::Plan ahead;
      (void)carryAhead(t, plan, j, carried, origin, &ahead);
      if (!ahead.actions.empty()) c.plans.push_back(std::move(ahead));
    }
    if (c.plans.empty()) continue;
    contingencies_.push_back(std::move(c));
    ++built;
  }
  return built;
}

std::optional<NodeId> GraphManager::takeContingency(NodeId at, const std::string& object) {
  auto it = std::find_if(contingencies_.begin(), contingencies_.end(), [&](const Contingency& c) { return c.at == at; });
  if (it == contingencies_.end()) return std::nullopt;
  const std::string origin = "conditional: the gripper holds " + object;
  auto rename = [&](const std::string& s) { return detail::renamed(s, it->placeholder, object); };
  for (const auto& p : it->plans) {
    std::vector<std::string> actions;
    std::vector<std::vector<std::string>> states;
    for (const auto& a : p.actions) actions.push_back(rename(a));
    for (const auto& s : p.states) {
      states.emplace_back();
      for (const auto& a : s) states.back().push_back(rename(a));
    }
    (void)graph_.addPlan(actions, states, origin);
  }
  std::vector<std::string> branch;
  for (const auto& a : graph_.node(it->branch).atoms) branch.push_back(rename(a));
  return graph_.addNode(branch, origin);
}

}  // namespace tamp::graph_manager
