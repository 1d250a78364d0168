// The effort-aware LazySP search of the cached static roadmap (StaticRoadmap::search; the
// roadmap itself, its sampling and its caches are in roadmap.cc).
//
// Edge cost from u to v along e:
//   w(u, e, v) = length(e) x seconds_per_unit + sum of cost(o) over objects touched along e but
//                not at u   (an object is paid when the path enters it)
// which, before e is evaluated in this request, is bounded below by using the objects touched at
// v instead of along e. A* (admissible heuristic: distance to the nearest goal x
// seconds_per_unit, raised by Adaptive A* as the search learns) finds the best path under the
// current costs; its unevaluated edges are evaluated in order (static validity unless known, then
// the movables touched, densely; all of them, also after an invalid one); the search repeats
// until a path is found whose every edge is evaluated and whose cost did not rise (LazySP).
#include <algorithm>
#include <limits>
#include <queue>

#include "internal.h"

namespace tamp::motion_planner::detail {
namespace {

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

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

/// One request's search: the per-request state (movables touched, weights, the learned
/// heuristic) over the roadmap's nodes and edges, whose static validity it updates.
class StaticRoadmap::Search {
 public:
  enum class Outcome { kFound, kDisconnected, kBudget, kUnconnected };

  Search(StaticRoadmap& roadmap, Oracle& oracle, int start, const std::vector<int>& goals, double resolution,
         double seconds_per_unit, const Termination& term, PlanningStats& stats);

  /// LazySP; `known_only`: over the edges known to be statically valid (no static checks, only
  /// the movables along them are evaluated). Up to `max_evaluations` edge evaluations; gives up
  /// (kUnconnected) after `invalid_cap` edges newly found invalid when > 0.
  Outcome lazySp(bool known_only, int max_evaluations, int invalid_cap);
  /// The movables the route crosses (request indices, sorted); every route edge is evaluated
  /// after kFound.
  std::vector<int> routeObjects() const;
  og::PathGeometric path(const ob::SpaceInformationPtr& si) const;

 private:
  using Entry = MovableCache::Entry;
  void fromCache(const Entry& e, std::vector<int>& out) const;
  void toCache(Entry& e, const std::vector<int>& touched, const ob::State* a, const ob::State* b) const;
  const std::vector<int>& touchedAt(int i);
  double heuristic(int i);
  /// The weight of edge `ei` entered from node `u` (computed once per direction: a node's
  /// movables are fixed within a request, so only an edge's evaluation changes its weights).
  double weight(int u, int ei);
  void forgetWeight(std::size_t ei) { weights_[2 * ei] = weights_[2 * ei + 1] = -1.0; }
  /// After an edge's evaluation: a raised weight means the route must be searched again; a
  /// lowered one (a stale cross-request cache entry) would break the learned heuristic's bound,
  /// which then starts over from the distance.
  void settle(double before, double after);
  /// A* under the current weights; the goal node reached, or -1.
  int aStar(bool known_only);
  /// Adaptive A* (Koenig & Likhachev, AAMAS 2005): g(goal) - g(u) is a lower bound of u's cost to
  /// the goal under the current weights, and stays one (and consistent) because evaluating an
  /// edge only raises its weight. Later iterations then expand little more than the region where
  /// the route changed, instead of most of the roadmap each time.
  void learnHeuristic(int reached);
  void takeRoute(int reached);
  /// Evaluates the route's unevaluated edges; an outcome when the search must stop.
  std::optional<Outcome> evaluateRoute(int max_evaluations, int invalid_cap);

  StaticRoadmap& rm_;
  Oracle& oracle_;
  const int start_;
  const double resolution_;
  const double seconds_per_unit_;
  const Termination& term_;
  PlanningStats& stats_;
  const std::vector<int>& goals_;
  std::vector<char> is_goal_;
  // Per request: the movables touched at nodes and along edges, the heuristic (all lazily).
  std::vector<char> have_touched_;
  std::vector<std::vector<int>> node_touched_;
  // Cross-request cache (rigid base groups): movable numbers <-> this request's indices.
  bool use_cache_{false};
  std::vector<int> g2r_, r2g_;
  std::vector<double> h_;
  std::vector<char> evaluated_;  // in this request (movables)
  std::vector<std::vector<int>> edge_touched_;
  std::vector<double> weights_;  // per direction: 2 * edge + (u is the edge's b)
  std::vector<double> g_;
  std::vector<int> parent_edge_;
  std::vector<char> closed_;
  std::vector<int> expanded_;                // closed nodes of the last A* run, for learnHeuristic
  std::vector<std::pair<int, int>> route_;  // (from node, edge) start -> goal
  bool changed_{false};
  // Per lazySp call.
  int evaluations_{0};
  int new_invalid_{0};
};

StaticRoadmap::Search::Search(StaticRoadmap& roadmap, Oracle& oracle, int start, const std::vector<int>& goals,
                              double resolution, double seconds_per_unit, const Termination& term,
                              PlanningStats& stats)
    : rm_(roadmap),
      oracle_(oracle),
      start_(start),
      resolution_(resolution),
      seconds_per_unit_(seconds_per_unit),
      term_(term),
      stats_(stats),
      goals_(goals) {
  const std::size_t n = rm_.nodes_.size();
  const std::size_t m = rm_.edges_.size();
  is_goal_.assign(n, 0);
  for (int g : goals) is_goal_[static_cast<std::size_t>(g)] = 1;
  have_touched_.assign(n, 0);
  node_touched_.resize(n);
  use_cache_ = rm_.syncMovables(oracle_, g2r_);
  if (use_cache_) {
    r2g_.assign(oracle_.movables().size(), -1);
    for (std::size_t g = 0; g < g2r_.size(); ++g) {
      if (g2r_[g] >= 0) r2g_[static_cast<std::size_t>(g2r_[g])] = static_cast<int>(g);
    }
  }
  h_.assign(n, -1.0);
  evaluated_.assign(m, 0);
  edge_touched_.resize(m);
  weights_.assign(2 * m, -1.0);
  g_.resize(n);
  parent_edge_.resize(n);
  closed_.resize(n);
  expanded_.reserve(n);
}

void StaticRoadmap::Search::fromCache(const Entry& e, std::vector<int>& out) const {
  out.clear();
  for (int g : e.touched) {
    const int r = g2r_[static_cast<std::size_t>(g)];
    if (r >= 0) out.push_back(r);  // absent objects (ignored, removed) dropped
  }
  std::sort(out.begin(), out.end());
}

void StaticRoadmap::Search::toCache(Entry& e, const std::vector<int>& touched, const ob::State* a,
                                    const ob::State* b) const {
  e.touched.clear();
  for (int r : touched) e.touched.push_back(r2g_[static_cast<std::size_t>(r)]);
  const Pose2D pa = oracle_.group().basePose(a), pb = oracle_.group().basePose(b);
  e.x0 = std::min(pa.x, pb.x);
  e.x1 = std::max(pa.x, pb.x);
  e.y0 = std::min(pa.y, pb.y);
  e.y1 = std::max(pa.y, pb.y);
  e.cached = true;
}

const std::vector<int>& StaticRoadmap::Search::touchedAt(int i) {
  const auto u = static_cast<std::size_t>(i);
  if (!have_touched_[u]) {
    if (use_cache_ && rm_.mcache_->nodes[u].cached) {
      fromCache(rm_.mcache_->nodes[u], node_touched_[u]);
    } else {
      oracle_.touched(rm_.nodes_[u], node_touched_[u]);
      if (use_cache_) toCache(rm_.mcache_->nodes[u], node_touched_[u], rm_.nodes_[u], rm_.nodes_[u]);
    }
    have_touched_[u] = 1;
  }
  return node_touched_[u];
}

double StaticRoadmap::Search::heuristic(int i) {
  const auto u = static_cast<std::size_t>(i);
  if (h_[u] < 0) {
    double d = kInf;
    for (int g : goals_) d = std::min(d, rm_.space_->distance(rm_.nodes_[u], rm_.nodes_[static_cast<std::size_t>(g)]));
    h_[u] = d * seconds_per_unit_;
  }
  return h_[u];
}

double StaticRoadmap::Search::weight(int u, int ei) {
  const Edge& e = rm_.edges_[static_cast<std::size_t>(ei)];
  double& w = weights_[2 * static_cast<std::size_t>(ei) + (e.a == u ? 0 : 1)];
  if (w < 0) {
    const int v = e.a == u ? e.b : e.a;
    const auto& objs = evaluated_[static_cast<std::size_t>(ei)] ? edge_touched_[static_cast<std::size_t>(ei)] : touchedAt(v);
    w = e.len * seconds_per_unit_ + enteringCost(oracle_, objs, touchedAt(u));
  }
  return w;
}

void StaticRoadmap::Search::settle(double before, double after) {
  if (after > before + 1e-9) {
    changed_ = true;
  } else if (after < before - 1e-9) {
    std::fill(h_.begin(), h_.end(), -1.0);
  }
}

int StaticRoadmap::Search::aStar(bool known_only) {
  std::fill(g_.begin(), g_.end(), kInf);
  std::fill(parent_edge_.begin(), parent_edge_.end(), -1);
  std::fill(closed_.begin(), closed_.end(), 0);
  expanded_.clear();
  using QItem = std::pair<double, int>;
  std::priority_queue<QItem, std::vector<QItem>, std::greater<>> open;
  g_[static_cast<std::size_t>(start_)] = 0.0;
  open.emplace(heuristic(start_), start_);
  while (!open.empty()) {
    const int u = open.top().second;
    open.pop();
    if (closed_[static_cast<std::size_t>(u)]) continue;
    closed_[static_cast<std::size_t>(u)] = 1;
    if (is_goal_[static_cast<std::size_t>(u)]) return u;
    expanded_.push_back(u);
    for (int ei : rm_.adj_[static_cast<std::size_t>(u)]) {
      const Edge& e = rm_.edges_[static_cast<std::size_t>(ei)];
      if (e.status == Edge::kInvalid || (known_only && e.status != Edge::kValid)) continue;
      const int v = e.a == u ? e.b : e.a;
      if (closed_[static_cast<std::size_t>(v)]) continue;
      const double gv = g_[static_cast<std::size_t>(u)] + weight(u, ei);
      if (gv < g_[static_cast<std::size_t>(v)]) {
        g_[static_cast<std::size_t>(v)] = gv;
        parent_edge_[static_cast<std::size_t>(v)] = ei;
        open.emplace(gv + heuristic(v), v);
      }
    }
  }
  return -1;
}

void StaticRoadmap::Search::learnHeuristic(int reached) {
  const double g_goal = g_[static_cast<std::size_t>(reached)];
  for (int u : expanded_) {
    const auto uu = static_cast<std::size_t>(u);
    h_[uu] = std::max(h_[uu], g_goal - g_[uu]);
  }
  expanded_.clear();
}

void StaticRoadmap::Search::takeRoute(int reached) {
  route_.clear();
  for (int v = reached; v != start_;) {
    const int ei = parent_edge_[static_cast<std::size_t>(v)];
    const Edge& e = rm_.edges_[static_cast<std::size_t>(ei)];
    const int u = e.a == v ? e.b : e.a;
    route_.emplace_back(u, ei);
    v = u;
  }
  std::reverse(route_.begin(), route_.end());
}

std::optional<StaticRoadmap::Search::Outcome> StaticRoadmap::Search::evaluateRoute(int max_evaluations,
                                                                                   int invalid_cap) {
  for (const auto& [u, ei] : route_) {
    const auto eu = static_cast<std::size_t>(ei);
    if (evaluated_[eu]) continue;
    Edge& e = rm_.edges_[eu];
    if (use_cache_ && e.status == Edge::kValid && rm_.mcache_->edges[eu].cached) {  // free: no budget
      const double before = weight(u, ei);
      fromCache(rm_.mcache_->edges[eu], edge_touched_[eu]);
      evaluated_[eu] = 1;
      forgetWeight(eu);
      settle(before, weight(u, ei));
      continue;
    }
    if (term_() || evaluations_ >= max_evaluations) return Outcome::kBudget;
    const double before = weight(u, ei);
    const ob::State* a = rm_.nodes_[static_cast<std::size_t>(e.a)];
    const ob::State* b = rm_.nodes_[static_cast<std::size_t>(e.b)];
    SegmentInfo info = evaluateSegment(oracle_, a, b, resolution_, e.status == Edge::kValid);
    ++evaluations_;
    ++stats_.edges_evaluated;
    if (!info.valid) {
      // The rest of the route is evaluated too: on a new roadmap most candidates cross a
      // wall somewhere, and one A* run per invalid edge found would dominate the time.
      e.status = Edge::kInvalid;
      changed_ = true;
      if (invalid_cap > 0 && !e.recheck && ++new_invalid_ >= invalid_cap) return Outcome::kUnconnected;
      continue;
    }
    e.status = Edge::kValid;
    evaluated_[eu] = 1;
    edge_touched_[eu] = std::move(info.touched);
    forgetWeight(eu);
    if (use_cache_) toCache(rm_.mcache_->edges[eu], edge_touched_[eu], a, b);
    settle(before, weight(u, ei));
  }
  return std::nullopt;
}

StaticRoadmap::Search::Outcome StaticRoadmap::Search::lazySp(bool known_only, int max_evaluations, int invalid_cap) {
  evaluations_ = 0;
  new_invalid_ = 0;
  while (!term_()) {
    ++stats_.search_iterations;
    const int reached = aStar(known_only);
    if (reached < 0) return Outcome::kDisconnected;
    learnHeuristic(reached);
    takeRoute(reached);
    changed_ = false;
    if (auto stop = evaluateRoute(max_evaluations, invalid_cap)) return *stop;
    if (!changed_) return Outcome::kFound;
  }
  return Outcome::kBudget;
}

std::vector<int> StaticRoadmap::Search::routeObjects() const {
  std::vector<int> out;
  for (const auto& [u, ei] : route_) {
    const auto& t = edge_touched_[static_cast<std::size_t>(ei)];
    out.insert(out.end(), t.begin(), t.end());
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

og::PathGeometric StaticRoadmap::Search::path(const ob::SpaceInformationPtr& si) const {
  og::PathGeometric out(si);
  out.append(rm_.nodes_[static_cast<std::size_t>(start_)]);
  for (const auto& [u, ei] : route_) {
    const Edge& e = rm_.edges_[static_cast<std::size_t>(ei)];
    out.append(rm_.nodes_[static_cast<std::size_t>(e.a == u ? e.b : e.a)]);
  }
  return out;
}

std::optional<og::PathGeometric> StaticRoadmap::search(Oracle& oracle, const ob::SpaceInformationPtr& si, int start,
                                                       const std::vector<int>& goals, const LazyParams& params,
                                                       double resolution, double seconds_per_unit,
                                                       const Termination& termination, PlanningStats& stats,
                                                       int max_new_invalid, std::vector<int>* route_objects) {
  const Termination term = termination.tightened(Deadline::in(params.optimize_budget_s));
  stats.roadmap_nodes = nodes_.size();
  stats.roadmap_edges = edges_.size();
  if (goals.empty()) return std::nullopt;
  Search s(*this, oracle, start, goals, resolution, seconds_per_unit, term, stats);
  using Outcome = Search::Outcome;
  Outcome outcome = s.lazySp(false, params.roadmap_max_evaluations, max_new_invalid);
  if (outcome == Outcome::kFound) {
    stats.optimize_completed = true;
  } else if (outcome == Outcome::kBudget) {
    // Anytime completion (evaluation budget spent, not after `max_new_invalid`: a roadmap that
    // keeps finding walls is left to lazy KPIECE): the best path over the edges known to be
    // statically valid (earlier requests, lazy KPIECE paths, this search); their movables are
    // evaluated as needed.
    outcome = s.lazySp(true, std::numeric_limits<int>::max(), 0);
  }
  if (outcome != Outcome::kFound) return std::nullopt;
  if (route_objects) *route_objects = s.routeObjects();
  return s.path(si);
}

}  // namespace tamp::motion_planner::detail
