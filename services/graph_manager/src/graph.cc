#include "tamp/graph_manager/graph.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "tamp/graph_manager/abstraction.h"

namespace tamp::graph_manager {

std::string_view toString(EdgeState s) {
  switch (s) {
    case EdgeState::kUnevaluated: return "unevaluated";
    case EdgeState::kLazy: return "lazy";
    case EdgeState::kFeasible: return "feasible";
    case EdgeState::kInfeasible: return "infeasible";
    case EdgeState::kExecuting: return "executing";
    case EdgeState::kExecuted: return "executed";
    case EdgeState::kFailed: return "failed";
  }
  return "?";
}

std::string_view toString(Variant v) { return v == Variant::kDirect ? "direct" : "around"; }

std::optional<ActionKind> actionKindOf(const std::string& name) { return actionKindFromString(name); }

NodeId ReachabilityGraph::addNode(std::vector<std::string> atoms, const std::string& origin) {
  std::sort(atoms.begin(), atoms.end());
  atoms.erase(std::unique(atoms.begin(), atoms.end()), atoms.end());
  if (auto it = index_.find(atoms); it != index_.end()) return it->second;
  Node n;
  n.id = static_cast<NodeId>(nodes_.size());
  n.atoms = atoms;
  n.origin = origin;
  index_[atoms] = n.id;
  nodes_.push_back(std::move(n));
  ++version_;
  return nodes_.back().id;
}

std::optional<NodeId> ReachabilityGraph::findNode(const std::vector<std::string>& atoms) const {
  auto it = index_.find(atoms);
  if (it == index_.end()) return std::nullopt;
  return it->second;
}

const std::vector<EdgeId>& ReachabilityGraph::out(NodeId n) const {
  static const std::vector<EdgeId> kNone;
  auto it = out_.find(n);
  return it == out_.end() ? kNone : it->second;
}

std::vector<EdgeId> ReachabilityGraph::addPlan(const std::vector<std::string>& actions,
                                               const std::vector<std::vector<std::string>>& states,
                                               const std::string& origin) {
  if (states.size() != actions.size() + 1)
    throw std::invalid_argument("addPlan: " + std::to_string(states.size()) + " states for " +
                                std::to_string(actions.size()) + " actions");
  std::vector<EdgeId> path;
  NodeId prev = addNode(states[0], origin);
  for (std::size_t i = 0; i < actions.size(); ++i) {
    const NodeId next = addNode(states[i + 1], origin);
    std::string action;
    auto tokens = atomTokens(actions[i]);
    for (std::size_t k = 0; k < tokens.size(); ++k) action += (k ? " " : "(") + tokens[k];
    action += ")";
    EdgeId found = -1;
    for (EdgeId e : out(prev)) {
      const Edge& x = edges_[static_cast<std::size_t>(e)];
      if (x.to == next && x.action == action && x.variant == Variant::kDirect) found = e;
    }
    if (found < 0) {
      Edge e;
      e.id = static_cast<EdgeId>(edges_.size());
      e.from = prev;
      e.to = next;
      e.action = action;
      e.tokens = tokens;
      e.kind = actionKindOf(tokens.empty() ? "" : tokens[0]).value_or(ActionKind::kMoveBase);
      e.origin = origin;
      edges_.push_back(std::move(e));
      out_[prev].push_back(edges_.back().id);
      found = edges_.back().id;
      ++version_;
    }
    path.push_back(found);
    prev = next;
  }
  return path;
}

EdgeId ReachabilityGraph::addVariant(EdgeId id, Variant v, const std::string& origin) {
  const Edge base = edge(id);
  for (EdgeId e : out(base.from)) {
    const Edge& x = edge(e);
    if (x.to == base.to && x.action == base.action && x.variant == v) return e;
  }
  Edge e;
  e.id = static_cast<EdgeId>(edges_.size());
  e.from = base.from;
  e.to = base.to;
  e.action = base.action;
  e.tokens = base.tokens;
  e.kind = base.kind;
  e.variant = v;
  e.origin = origin;
  e.lower_bound_s = base.lower_bound_s;
  edges_.push_back(std::move(e));
  out_[base.from].push_back(edges_.back().id);
  ++version_;
  return edges_.back().id;
}

namespace {
std::string dotEscape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o;
}
}  // namespace

std::string ReachabilityGraph::toDot(const std::vector<EdgeId>& chosen, NodeId current) const {
  std::ostringstream os;
  os << "digraph reachability {\n  rankdir=LR;\n  node [shape=box, fontsize=9, fontname=\"Helvetica\"];\n"
     << "  edge [fontsize=8, fontname=\"Helvetica\"];\n";
  for (const Node& n : nodes_) {
    std::string label = "n" + std::to_string(n.id);
    for (const auto& a : n.atoms) {
      if (a.rfind("(robot-at", 0) == 0 || a.rfind("(holding", 0) == 0 || a.rfind("(arm-at", 0) == 0)
        label += "\\n" + dotEscape(a);
    }
    os << "  n" << n.id << " [label=\"" << label << "\"";
    if (n.id == current) os << ", style=filled, fillcolor=\"#cfe8ff\"";
    if (!n.healthy) os << ", color=red";
    os << "];\n";
  }
  for (const Edge& e : edges_) {
    const bool on_best = std::find(chosen.begin(), chosen.end(), e.id) != chosen.end();
    char effort[64];
    if (std::isfinite(e.effort_mean_s))
      std::snprintf(effort, sizeof effort, "%.1f s", e.effort_mean_s);
    else
      std::snprintf(effort, sizeof effort, ">= %.1f s", e.lower_bound_s);
    os << "  n" << e.from << " -> n" << e.to << " [label=\"" << dotEscape(e.action)
       << (e.variant == Variant::kAround ? " [around]" : "") << "\\n" << effort << " (" << toString(e.state) << ")\"";
    if (on_best || e.state == EdgeState::kExecuted)
      os << ", color=\"#1565c0\", penwidth=2.5";
    else if (e.cut || e.state == EdgeState::kInfeasible || e.state == EdgeState::kLazy)
      os << ", color=gray70, fontcolor=gray50, style=dashed";
    os << "];\n";
  }
  os << "}\n";
  return os.str();
}

}  // namespace tamp::graph_manager
