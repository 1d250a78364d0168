// The effort-aware roadmap search of the lazy mode (see motion_planner.h, "Worth executing").
//
// Nodes: the lazy path's states (cut every `path_node_spacing`) plus uniform samples of the
// static free space; edges: k nearest neighbours, and the lazy path's own segments (statically
// valid already). Edge cost from u to v along e:
//   w(u, e, v) = length(e) x seconds_per_unit + sum of cost(o) over objects touched along e but
//                not at u   (an object is paid when the path enters it)
// which, before e is evaluated, is bounded below by using the objects touched at v instead of
// along e. A* (admissible heuristic: distance to the goal x seconds_per_unit) finds the best
// path under the current costs; its unevaluated edges are evaluated in order (static validity,
// then the movables touched, densely) until one is invalid; the search repeats until a path is
// found whose every edge is evaluated and whose cost did not rise (LazySP).
#include <algorithm>
#include <cmath>
#include <iostream>  // NearestNeighborsGNATNoThreadSafety.h uses std::cout without including it
#include <queue>
#include <unordered_set>

#include <ompl/base/StateSampler.h>
#include <ompl/datastructures/NearestNeighborsGNATNoThreadSafety.h>

#include "internal.h"

namespace tamp::motion_planner::detail {
namespace {

struct Node {
  ob::State* s{nullptr};
  std::vector<int> touched;
  double h{0.0};
};

struct Edge {
  int a{0}, b{0};
  double len{0.0};
  enum Status : unsigned char { kUnknown, kValid, kInvalid } status{kUnknown};
  bool static_valid{false};
  std::vector<int> touched;  // when kValid
};

/// Sum of costs of objects in `in` but not in `minus` (both sorted).
double enteringCost(const Oracle& oracle, const std::vector<int>& in, const std::vector<int>& minus) {
  double c = 0.0;
  auto it = minus.begin();
  for (int o : in) {
    while (it != minus.end() && *it < o) ++it;
    if (it != minus.end() && *it == o) continue;
    c += oracle.movables()[static_cast<std::size_t>(o)].cost_s;
  }
  return c;
}

}  // namespace

std::optional<og::PathGeometric> effortRoadmapSearch(Oracle& oracle, const ob::SpaceInformationPtr& si,
                                                     const og::PathGeometric& seed_path, const LazyParams& params,
                                                     double resolution, double seconds_per_unit,
                                                     const Termination& termination, PlanningStats& stats) {
  const Termination term = termination.tightened(Deadline::in(params.optimize_budget_s));
  const auto& space = si->getStateSpace();
  std::vector<Node> nodes;
  std::vector<Edge> edges;
  struct Freer {
    std::vector<Node>& n;
    const ob::StateSpacePtr& sp;
    ~Freer() {
      for (auto& x : n) sp->freeState(x.s);
    }
  } freer{nodes, space};
  if (seed_path.getStateCount() < 2) return std::nullopt;

  // 1. The lazy path, cut into nodes; its segments are statically valid.
  std::unordered_set<std::uint64_t> edge_keys;
  auto addEdge = [&](int a, int b, bool static_valid) {
    if (a == b) return;
    const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
    if (!edge_keys.insert(key).second) {
      if (static_valid) {
        for (auto& e : edges) {
          if ((e.a == a && e.b == b) || (e.a == b && e.b == a)) e.static_valid = true;
        }
      }
      return;
    }
    Edge e;
    e.a = a;
    e.b = b;
    e.len = space->distance(nodes[static_cast<std::size_t>(a)].s, nodes[static_cast<std::size_t>(b)].s);
    e.static_valid = static_valid;
    edges.push_back(std::move(e));
  };
  {
    nodes.push_back(Node{space->cloneState(seed_path.getState(0)), {}, 0.0});
    for (std::size_t i = 0; i + 1 < seed_path.getStateCount(); ++i) {
      const ob::State* a = seed_path.getState(i);
      const ob::State* b = seed_path.getState(i + 1);
      const int pieces = std::max(1, static_cast<int>(std::ceil(space->distance(a, b) / params.path_node_spacing)));
      for (int k = 1; k <= pieces; ++k) {
        ob::State* s = space->allocState();
        if (k == pieces) {
          space->copyState(s, b);
        } else {
          space->interpolate(a, b, static_cast<double>(k) / pieces, s);
        }
        nodes.push_back(Node{s, {}, 0.0});
        addEdge(static_cast<int>(nodes.size()) - 2, static_cast<int>(nodes.size()) - 1, true);
      }
    }
  }
  const int start = 0;
  const int goal = static_cast<int>(nodes.size()) - 1;

  // 2. Uniform samples of the static free space.
  {
    auto sampler = si->allocStateSampler();
    ob::State* tmp = space->allocState();
    int added = 0;
    for (int attempt = 0; added < params.roadmap_samples && attempt < 4 * params.roadmap_samples; ++attempt) {
      if ((attempt & 31) == 0 && term()) break;
      sampler->sampleUniform(tmp);
      if (!oracle.staticFree(tmp)) continue;
      nodes.push_back(Node{space->cloneState(tmp), {}, 0.0});
      ++added;
    }
    space->freeState(tmp);
  }
  for (auto& n : nodes) {
    oracle.touched(n.s, n.touched);
    n.h = space->distance(n.s, nodes[static_cast<std::size_t>(goal)].s) * seconds_per_unit;
  }
  if (term()) return std::nullopt;

  // 3. k nearest neighbours.
  {
    ompl::NearestNeighborsGNATNoThreadSafety<int> nn;
    nn.setDistanceFunction([&](const int& a, const int& b) {
      return space->distance(nodes[static_cast<std::size_t>(a)].s, nodes[static_cast<std::size_t>(b)].s);
    });
    std::vector<int> all(nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) all[i] = static_cast<int>(i);
    nn.add(all);
    std::vector<int> nbrs;
    for (int i : all) {
      nn.nearestK(i, static_cast<std::size_t>(params.roadmap_neighbors) + 1, nbrs);
      for (int j : nbrs) addEdge(i, j, false);
    }
  }
  std::vector<std::vector<int>> adj(nodes.size());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    adj[static_cast<std::size_t>(edges[e].a)].push_back(static_cast<int>(e));
    adj[static_cast<std::size_t>(edges[e].b)].push_back(static_cast<int>(e));
  }
  stats.roadmap_nodes = nodes.size();
  stats.roadmap_edges = edges.size();

  auto weight = [&](int u, const Edge& e) {
    const int v = e.a == u ? e.b : e.a;
    const auto& objs = e.status == Edge::kValid ? e.touched : nodes[static_cast<std::size_t>(v)].touched;
    return e.len * seconds_per_unit + enteringCost(oracle, objs, nodes[static_cast<std::size_t>(u)].touched);
  };

  // 4. LazySP with A*.
  std::vector<double> g(nodes.size());
  std::vector<int> parent_edge(nodes.size());
  std::vector<char> closed(nodes.size());
  using QItem = std::pair<double, int>;
  while (!term()) {
    ++stats.search_iterations;
    std::fill(g.begin(), g.end(), std::numeric_limits<double>::infinity());
    std::fill(parent_edge.begin(), parent_edge.end(), -1);
    std::fill(closed.begin(), closed.end(), 0);
    std::priority_queue<QItem, std::vector<QItem>, std::greater<>> open;
    g[start] = 0.0;
    open.emplace(nodes[start].h, start);
    while (!open.empty()) {
      const auto [f, u] = open.top();
      open.pop();
      if (closed[static_cast<std::size_t>(u)]) continue;
      closed[static_cast<std::size_t>(u)] = 1;
      if (u == goal) break;
      for (int ei : adj[static_cast<std::size_t>(u)]) {
        const Edge& e = edges[static_cast<std::size_t>(ei)];
        if (e.status == Edge::kInvalid) continue;
        const int v = e.a == u ? e.b : e.a;
        if (closed[static_cast<std::size_t>(v)]) continue;
        const double gv = g[static_cast<std::size_t>(u)] + weight(u, e);
        if (gv < g[static_cast<std::size_t>(v)]) {
          g[static_cast<std::size_t>(v)] = gv;
          parent_edge[static_cast<std::size_t>(v)] = ei;
          open.emplace(gv + nodes[static_cast<std::size_t>(v)].h, v);
        }
      }
    }
    if (!std::isfinite(g[static_cast<std::size_t>(goal)])) return std::nullopt;  // cannot happen: the seed path
    std::vector<std::pair<int, int>> route;  // (from node, edge) start -> goal
    for (int v = goal; v != start;) {
      const int ei = parent_edge[static_cast<std::size_t>(v)];
      const Edge& e = edges[static_cast<std::size_t>(ei)];
      const int u = e.a == v ? e.b : e.a;
      route.emplace_back(u, ei);
      v = u;
    }
    std::reverse(route.begin(), route.end());
    bool changed = false;
    for (const auto& [u, ei] : route) {
      Edge& e = edges[static_cast<std::size_t>(ei)];
      if (e.status != Edge::kUnknown) continue;
      if (term()) return std::nullopt;
      const double before = weight(u, e);
      SegmentInfo info = evaluateSegment(oracle, nodes[static_cast<std::size_t>(e.a)].s,
                                         nodes[static_cast<std::size_t>(e.b)].s, resolution, e.static_valid);
      ++stats.edges_evaluated;
      if (!info.valid) {
        e.status = Edge::kInvalid;
        changed = true;
        break;
      }
      e.status = Edge::kValid;
      e.touched = std::move(info.touched);
      if (weight(u, e) > before + 1e-9) changed = true;
    }
    if (!changed) {
      og::PathGeometric out(si);
      out.append(nodes[start].s);
      for (const auto& [u, ei] : route) {
        const Edge& e = edges[static_cast<std::size_t>(ei)];
        out.append(nodes[static_cast<std::size_t>(e.a == u ? e.b : e.a)].s);
      }
      stats.optimize_completed = true;
      return out;
    }
  }
  return std::nullopt;
}

}  // namespace tamp::motion_planner::detail
