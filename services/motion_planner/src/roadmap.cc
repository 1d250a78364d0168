// The cached static roadmap of the lazy mode (see motion_planner.h, "Worth executing" and
// "Roadmap cache"); its effort-aware search is in roadmap_search.cc.
//
// Nodes: uniform samples of the static free space (own seeded generator), the starts and goals of
// earlier requests and the lazy KPIECE paths of requests the roadmap could not answer (cut every
// `path_node_spacing`); edges: each new node to its k nearest nodes, and a lazy path's own
// segments (statically valid already). An edge's static validity is evaluated at most once per
// roadmap; the movables it touches are evaluated per request (they change between requests).
#include <algorithm>
#include <cmath>
#include <iostream>  // NearestNeighborsGNATNoThreadSafety.h uses std::cout without including it
#include <limits>
#include <numeric>
#include <queue>
#include <stdexcept>
#include <unordered_set>

#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/datastructures/NearestNeighborsGNATNoThreadSafety.h>

#include "internal.h"

namespace tamp::motion_planner::detail {
namespace {

bool sameObject(const std::shared_ptr<const world::Object>& a, const std::shared_ptr<const world::Object>& b) {
  if (a == b) return true;
  if (!a || !b) return false;
  return *a == *b;
}

}  // namespace

bool StaticWorldKey::operator==(const StaticWorldKey& o) const {
  if (group != o.group || fixed != o.fixed || statics.size() != o.statics.size()) return false;
  if (!held != !o.held) return false;
  if (held && (held != o.held && (held->id != o.held->id || !(held->shape == o.held->shape)))) return false;
  if (held && (held_link != o.held_link || !link_T_held.matrix().isApprox(o.link_T_held.matrix(), 1e-12))) {
    return false;
  }
  for (std::size_t i = 0; i < statics.size(); ++i) {
    if (!sameObject(statics[i], o.statics[i])) return false;
  }
  return true;
}

struct StaticRoadmap::Impl {
  ompl::NearestNeighborsGNATNoThreadSafety<int> nn;
  const ob::State* probe{nullptr};  // index -1 in `nn` queries
  std::unordered_set<std::uint64_t> edge_keys;
  std::mt19937 rng;
};

StaticRoadmap::StaticRoadmap(ob::StateSpacePtr space, StaticWorldKey key, std::uint32_t seed, int neighbors)
    : impl_(std::make_unique<Impl>()), space_(std::move(space)), key_(std::move(key)), neighbors_(neighbors) {
  impl_->rng.seed(seed);
  impl_->nn.setDistanceFunction([this](const int& a, const int& b) {
    const ob::State* sa = a < 0 ? impl_->probe : nodes_[static_cast<std::size_t>(a)];
    const ob::State* sb = b < 0 ? impl_->probe : nodes_[static_cast<std::size_t>(b)];
    return space_->distance(sa, sb);
  });
}

namespace {
/// Whether any of `boxes`, grown by `r` in x and y, meets the rectangle [x0, x1] x [y0, y1]: the
/// rigid robot at a base pose in it (reach radius `r`) may touch that box.
bool nearAny(const std::vector<Aabb>& boxes, double r, double x0, double y0, double x1, double y1) {
  return std::any_of(boxes.begin(), boxes.end(), [&](const Aabb& b) {
    return !(b.max.x() + r < x0 || b.min.x() - r > x1 || b.max.y() + r < y0 || b.min.y() - r > y1);
  });
}
}  // namespace

bool StaticRoadmap::syncMovables(const Oracle& oracle, std::vector<int>& g2r) {
  if (!oracle.rigid()) return false;
  if (!mcache_) mcache_ = std::make_unique<MovableCache>();
  MovableCache& c = *mcache_;
  // Changed boxes are grown by the reach radius: any request's value bounds the rigid robot's
  // extent about the base origin (the corners of its parts' AABBs at that yaw are at least as
  // far as any of its points, and those distances do not depend on the yaw).
  c.reach = std::max(c.reach, oracle.reachRadius());
  c.nodes.resize(nodes_.size());
  c.edges.resize(edges_.size());
  std::vector<Aabb> changed;
  const auto& movables = oracle.movables();
  std::vector<char> present(c.seen.size(), 0);
  g2r.assign(c.seen.size(), -1);
  for (std::size_t i = 0; i < movables.size(); ++i) {
    const MovableInfo& m = movables[i];
    auto [it, inserted] = c.ids.emplace(m.id, static_cast<int>(c.seen.size()));
    const auto g = static_cast<std::size_t>(it->second);
    if (inserted) {
      c.seen.emplace_back();
      c.last_box.emplace_back();
      present.push_back(0);
      g2r.push_back(-1);
    }
    present[g] = 1;
    g2r[g] = static_cast<int>(i);
    const auto& before = c.seen[g];
    const bool same = m.object && before && (before == m.object || *before == *m.object);
    if (!same) {
      if (before || !inserted) changed.push_back(c.last_box[g]);  // where it was
      changed.push_back(m.aabb);
      c.seen[g] = m.object;
      c.last_box[g] = m.aabb;
    }
  }
  // Absent in this request (removed or ignored): entries computed now lack it, so its return
  // counts as a change (seen = null).
  for (std::size_t g = 0; g < c.seen.size(); ++g) {
    if (!present[g]) c.seen[g] = nullptr;
  }
  if (!changed.empty()) {
    auto drop = [&](std::vector<MovableCache::Entry>& entries) {
      for (auto& e : entries) {
        if (!e.cached || !nearAny(changed, c.reach, e.x0, e.y0, e.x1, e.y1)) continue;
        e.cached = false;
        e.touched.clear();
      }
    };
    drop(c.nodes);
    drop(c.edges);
  }
  return true;
}

bool StaticWorldKey::extends(const StaticWorldKey& base,
                             std::vector<std::shared_ptr<const world::Object>>& added) const {
  added.clear();
  if (group != base.group || fixed != base.fixed || statics.size() <= base.statics.size()) return false;
  if (!held != !base.held) return false;
  if (held && (held != base.held && (held->id != base.held->id || !(held->shape == base.held->shape)))) return false;
  if (held && (held_link != base.held_link || !link_T_held.matrix().isApprox(base.link_T_held.matrix(), 1e-12)))
    return false;
  // Both sorted by id: every base static must appear, unchanged.
  std::size_t j = 0;
  for (const auto& s : statics) {
    if (j < base.statics.size() && base.statics[j]->id == s->id) {
      if (!sameObject(s, base.statics[j])) return false;
      ++j;
    } else {
      added.push_back(s);
    }
  }
  return j == base.statics.size();
}

std::size_t StaticRoadmap::deriveFrom(const StaticRoadmap& base, Oracle& oracle, const std::vector<Aabb>& added) {
  if (!nodes_.empty()) throw std::logic_error("StaticRoadmap::deriveFrom: the roadmap is not empty");
  if (!oracle.rigid()) throw std::logic_error("StaticRoadmap::deriveFrom: not a rigid base group");
  const double r = oracle.reachRadius();
  auto near = [&](double x0, double y0, double x1, double y1) { return nearAny(added, r, x0, y0, x1, y1); };
  std::vector<int> remap(base.nodes_.size(), -1);
  std::vector<Pose2D> at(base.nodes_.size());
  std::size_t dropped = 0;
  for (std::size_t i = 0; i < base.nodes_.size(); ++i) {
    const Pose2D p = oracle.group().basePose(base.nodes_[i]);
    at[i] = p;
    if (near(p.x, p.y, p.x, p.y) && !oracle.staticFree(base.nodes_[i])) {
      ++dropped;
      continue;
    }
    remap[i] = static_cast<int>(nodes_.size());
    nodes_.push_back(space_->cloneState(base.nodes_[i]));
    request_stamp_.push_back(base.request_stamp_[i]);
    if (base.request_stamp_[i] > 0) ++request_nodes_;
    adj_.emplace_back();
  }
  std::vector<int> all(nodes_.size());
  std::iota(all.begin(), all.end(), 0);
  impl_->nn.add(all);
  std::vector<std::size_t> kept_edges;
  for (std::size_t ei = 0; ei < base.edges_.size(); ++ei) {
    Edge e = base.edges_[ei];
    const auto ua = static_cast<std::size_t>(e.a), ub = static_cast<std::size_t>(e.b);
    e.a = remap[ua];
    e.b = remap[ub];
    if (e.a < 0 || e.b < 0) continue;
    if (e.status == Edge::kValid && near(std::min(at[ua].x, at[ub].x), std::min(at[ua].y, at[ub].y),
                                         std::max(at[ua].x, at[ub].x), std::max(at[ua].y, at[ub].y))) {
      e.status = Edge::kUnknown;
      e.recheck = true;
    }
    const int ni = static_cast<int>(edges_.size());
    edges_.push_back(e);
    kept_edges.push_back(ei);
    adj_[static_cast<std::size_t>(e.a)].push_back(ni);
    adj_[static_cast<std::size_t>(e.b)].push_back(ni);
    impl_->edge_keys.insert((static_cast<std::uint64_t>(std::min(e.a, e.b)) << 32) |
                            static_cast<std::uint32_t>(std::max(e.a, e.b)));
  }
  if (base.mcache_) {
    // Entries stay true: the added obstacles were movables there, absent from this world's
    // movables (their numbers are dropped when read); the edges near them are unknown again.
    mcache_ = std::make_unique<MovableCache>(*base.mcache_);
    std::vector<MovableCache::Entry> node_cache(nodes_.size()), edge_cache(edges_.size());
    for (std::size_t i = 0; i < remap.size() && i < base.mcache_->nodes.size(); ++i)
      if (remap[i] >= 0) node_cache[static_cast<std::size_t>(remap[i])] = base.mcache_->nodes[i];
    for (std::size_t k = 0; k < kept_edges.size(); ++k)
      if (kept_edges[k] < base.mcache_->edges.size()) edge_cache[k] = base.mcache_->edges[kept_edges[k]];
    mcache_->nodes = std::move(node_cache);
    mcache_->edges = std::move(edge_cache);
  }
  densified_ = base.densified_;
  uniform_ = base.uniform_;
  plain_ = base.plain_;
  bridges_ = base.bridges_;
  sampling_interrupted_ = base.sampling_interrupted_;
  impl_->rng = base.impl_->rng;
  return dropped;
}

StaticRoadmap::~StaticRoadmap() {
  for (auto* s : nodes_) space_->freeState(s);
}

void StaticRoadmap::addEdge(int a, int b, bool valid) {
  if (a == b) return;
  const std::uint64_t key =
      (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
  if (!impl_->edge_keys.insert(key).second) {
    if (valid) {
      for (int ei : adj_[static_cast<std::size_t>(a)]) {
        Edge& e = edges_[static_cast<std::size_t>(ei)];
        if (e.a == b || e.b == b) e.status = Edge::kValid;
      }
    }
    return;
  }
  Edge e;
  e.a = a;
  e.b = b;
  e.len = space_->distance(nodes_[static_cast<std::size_t>(a)], nodes_[static_cast<std::size_t>(b)]);
  e.status = valid ? Edge::kValid : Edge::kUnknown;
  const int ei = static_cast<int>(edges_.size());
  edges_.push_back(e);
  adj_[static_cast<std::size_t>(a)].push_back(ei);
  adj_[static_cast<std::size_t>(b)].push_back(ei);
}

int StaticRoadmap::pushNode(const ob::State* s) {
  std::vector<int> nbrs;
  if (!nodes_.empty()) {
    impl_->probe = s;
    impl_->nn.nearestK(-1, static_cast<std::size_t>(neighbors_), nbrs);
    impl_->probe = nullptr;
    if (!nbrs.empty() && space_->distance(s, nodes_[static_cast<std::size_t>(nbrs.front())]) < 1e-9) {
      return nbrs.front();
    }
  }
  const int i = static_cast<int>(nodes_.size());
  nodes_.push_back(space_->cloneState(s));
  request_stamp_.push_back(0);
  adj_.emplace_back();
  impl_->nn.add(i);
  for (int j : nbrs) addEdge(i, j, false);
  return i;
}

int StaticRoadmap::addState(const ob::State* s) { return pushNode(s); }

int StaticRoadmap::addRequestState(const ob::State* s, std::uint64_t request) {
  const std::size_t before = nodes_.size();
  const int i = pushNode(s);
  auto& stamp = request_stamp_[static_cast<std::size_t>(i)];
  if (nodes_.size() > before) ++request_nodes_;
  if (nodes_.size() > before || stamp > 0) stamp = std::max<std::uint64_t>(request, 1);
  return i;
}

std::size_t StaticRoadmap::pruneRequestNodes(std::size_t max_request_nodes) {
  if (request_nodes_ <= max_request_nodes) return 0;
  // The oldest request nodes go, down to half the bound (so pruning is rare).
  std::vector<std::pair<std::uint64_t, int>> by_age;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    if (request_stamp_[i] > 0) by_age.emplace_back(request_stamp_[i], static_cast<int>(i));
  }
  std::sort(by_age.begin(), by_age.end());
  const std::size_t remove = by_age.size() - max_request_nodes / 2;
  std::vector<char> drop(nodes_.size(), 0);
  for (std::size_t k = 0; k < remove; ++k) drop[static_cast<std::size_t>(by_age[k].second)] = 1;

  std::vector<int> remap(nodes_.size(), -1);
  std::vector<ob::State*> nodes;
  std::vector<std::uint64_t> stamps;
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    if (drop[i]) {
      space_->freeState(nodes_[i]);
      continue;
    }
    remap[i] = static_cast<int>(nodes.size());
    nodes.push_back(nodes_[i]);
    stamps.push_back(request_stamp_[i]);
  }
  std::vector<Edge> edges;
  std::vector<MovableCache::Entry> edge_cache;
  impl_->edge_keys.clear();
  std::vector<std::vector<int>> adj(nodes.size());
  for (std::size_t ei = 0; ei < edges_.size(); ++ei) {
    Edge e = edges_[ei];
    e.a = remap[static_cast<std::size_t>(e.a)];
    e.b = remap[static_cast<std::size_t>(e.b)];
    if (e.a < 0 || e.b < 0) continue;
    const int ni = static_cast<int>(edges.size());
    edges.push_back(e);
    adj[static_cast<std::size_t>(e.a)].push_back(ni);
    adj[static_cast<std::size_t>(e.b)].push_back(ni);
    impl_->edge_keys.insert((static_cast<std::uint64_t>(std::min(e.a, e.b)) << 32) |
                            static_cast<std::uint32_t>(std::max(e.a, e.b)));
    if (mcache_ && ei < mcache_->edges.size()) {
      edge_cache.resize(edges.size());
      edge_cache.back() = std::move(mcache_->edges[ei]);
    }
  }
  if (mcache_) {
    std::vector<MovableCache::Entry> node_cache(nodes.size());
    for (std::size_t i = 0; i < remap.size() && i < mcache_->nodes.size(); ++i) {
      if (remap[i] >= 0) node_cache[static_cast<std::size_t>(remap[i])] = std::move(mcache_->nodes[i]);
    }
    mcache_->nodes = std::move(node_cache);
    edge_cache.resize(edges.size());
    mcache_->edges = std::move(edge_cache);
  }
  nodes_ = std::move(nodes);
  request_stamp_ = std::move(stamps);
  edges_ = std::move(edges);
  adj_ = std::move(adj);
  request_nodes_ -= remove;
  impl_->nn.clear();
  std::vector<int> all(nodes_.size());
  std::iota(all.begin(), all.end(), 0);
  impl_->nn.add(all);
  return remove;
}

std::pair<std::size_t, std::size_t> StaticRoadmap::evaluateEdges(Oracle& oracle, double resolution,
                                                                 const Termination& termination, bool& complete) {
  std::size_t evaluated = 0, invalid = 0;
  complete = true;
  for (Edge& e : edges_) {
    if (e.status != Edge::kUnknown) continue;
    if ((evaluated & 63) == 0 && termination()) {
      complete = false;
      break;
    }
    // No movables in `oracle` for this: only the static pass runs.
    const SegmentInfo info = evaluateSegment(oracle, nodes_[static_cast<std::size_t>(e.a)],
                                             nodes_[static_cast<std::size_t>(e.b)], resolution, false);
    e.status = info.valid ? Edge::kValid : Edge::kInvalid;
    ++evaluated;
    if (!info.valid) ++invalid;
  }
  return {evaluated, invalid};
}

void StaticRoadmap::addSamples(Oracle& oracle, const GroupSpace& gs, int count, const Termination& termination,
                               int bridge_count, double bridge_distance) {
  ob::State* tmp = space_->allocState();
  ob::State* other = space_->allocState();
  ob::State* mid = space_->allocState();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto& rng = impl_->rng;
  std::vector<std::pair<double, double>> ranges;
  if (gs.hasBase()) {
    const Aabb& b = gs.baseBounds();
    ranges.emplace_back(b.min.x(), b.max.x());
    ranges.emplace_back(b.min.y(), b.max.y());
    ranges.emplace_back(-M_PI, M_PI);
  }
  if (gs.movesArm()) {
    const ob::StateSpace* arm = gs.hasBase() ? gs.space()->as<ob::CompoundStateSpace>()->getSubspace(1).get()
                                             : gs.space().get();
    const auto& bounds = arm->as<ob::RealVectorStateSpace>()->getBounds();
    for (std::size_t i = 0; i < bounds.low.size(); ++i) ranges.emplace_back(bounds.low[i], bounds.high[i]);
  }
  std::vector<double> v(ranges.size());
  int added = 0;
  sampling_interrupted_ = false;
  for (int attempt = 0; added < count && attempt < 4 * count; ++attempt) {
    if ((attempt & 31) == 0 && termination()) {
      sampling_interrupted_ = true;
      break;
    }
    for (std::size_t i = 0; i < ranges.size(); ++i) {
      v[i] = ranges[i].first + (ranges[i].second - ranges[i].first) * unit(rng);
    }
    gs.setValues(v, tmp);
    if (!oracle.staticFree(tmp)) continue;
    pushNode(tmp);
    ++added;
    ++uniform_;
    ++plain_;
  }
  // Bridge test (Hsu et al., ICRA 2003): two states in static collision, about
  // `bridge_distance` apart, whose midpoint is free -- a state in a narrow passage (doors,
  // gaps between walls), where uniform samples rarely fall.
  std::normal_distribution<double> gauss(0.0, bridge_distance / std::sqrt(static_cast<double>(ranges.size())));
  std::vector<double> w(ranges.size());
  added = 0;
  for (int attempt = 0; added < bridge_count && attempt < 20 * bridge_count; ++attempt) {
    if ((attempt & 31) == 0 && termination()) {
      sampling_interrupted_ = true;
      break;
    }
    for (std::size_t i = 0; i < ranges.size(); ++i) {
      v[i] = ranges[i].first + (ranges[i].second - ranges[i].first) * unit(rng);
      w[i] = std::clamp(v[i] + gauss(rng), ranges[i].first, ranges[i].second);
    }
    gs.setValues(v, tmp);
    if (oracle.staticFree(tmp)) continue;
    gs.setValues(w, other);
    if (oracle.staticFree(other)) continue;
    space_->interpolate(tmp, other, 0.5, mid);
    if (!oracle.staticFree(mid)) continue;
    pushNode(mid);
    ++added;
    ++uniform_;
    ++bridges_;
  }
  space_->freeState(mid);
  space_->freeState(other);
  space_->freeState(tmp);
}

int StaticRoadmap::addObjectRingSamples(Oracle& oracle, const GroupSpace& gs, const std::vector<int>& objects,
                                        int per_object, const Termination& termination) {
  if (!oracle.rigid() || per_object <= 0) return 0;
  const double reach = oracle.reachRadius();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto& rng = impl_->rng;
  std::vector<double> v(3);
  ob::State* tmp = space_->allocState();
  int added = 0;
  for (int o : objects) {
    const MovableInfo& m = oracle.movables()[static_cast<std::size_t>(o)];
    auto known = std::find_if(densified_.begin(), densified_.end(), [&](const auto& d) { return d.first == m.id; });
    if (known != densified_.end() && known->second.min.isApprox(m.aabb.min, 1e-6) &&
        known->second.max.isApprox(m.aabb.max, 1e-6)) {
      continue;  // done at this box already
    }
    if (known == densified_.end()) {
      densified_.emplace_back(m.id, m.aabb);
    } else {
      known->second = m.aabb;
    }
    // Points on the rectangle of the box grown by d, by perimeter length.
    for (int k = 0, attempts = 0; k < per_object && attempts < 4 * per_object; ++attempts) {
      if ((attempts & 15) == 0 && termination()) break;
      const double d = reach * (0.5 + unit(rng));
      const double x0 = m.aabb.min.x() - d, x1 = m.aabb.max.x() + d;
      const double y0 = m.aabb.min.y() - d, y1 = m.aabb.max.y() + d;
      const double w = x1 - x0, h = y1 - y0;
      double t = unit(rng) * 2 * (w + h);
      double x, y;
      if (t < w) {
        x = x0 + t, y = y0;
      } else if ((t -= w) < h) {
        x = x1, y = y0 + t;
      } else if ((t -= h) < w) {
        x = x1 - t, y = y1;
      } else {
        x = x0, y = y1 - (t - w);
      }
      v[0] = x;
      v[1] = y;
      v[2] = -M_PI + 2 * M_PI * unit(rng);
      gs.setValues(v, tmp);
      if (!gs.space()->satisfiesBounds(tmp) || !oracle.staticFree(tmp)) continue;
      pushNode(tmp);
      ++k;
      ++added;
    }
  }
  space_->freeState(tmp);
  return added;
}

std::pair<int, int> StaticRoadmap::addPath(const og::PathGeometric& path, double spacing) {
  ob::State* s = space_->allocState();
  int prev = pushNode(path.getState(0));
  const int first = prev;
  for (std::size_t i = 0; i + 1 < path.getStateCount(); ++i) {
    const ob::State* a = path.getState(i);
    const ob::State* b = path.getState(i + 1);
    const int pieces = std::max(1, static_cast<int>(std::ceil(space_->distance(a, b) / spacing)));
    for (int k = 1; k <= pieces; ++k) {
      if (k == pieces) {
        space_->copyState(s, b);
      } else {
        space_->interpolate(a, b, static_cast<double>(k) / pieces, s);
      }
      const int cur = pushNode(s);
      addEdge(prev, cur, true);
      prev = cur;
    }
  }
  space_->freeState(s);
  return {first, prev};
}

}  // namespace tamp::motion_planner::detail
