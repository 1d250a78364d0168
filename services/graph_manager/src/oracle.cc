// Policy oracle: exhaustive remove-or-avoid (removal subsets), the price of scripted failures,
// and the hidden objects in the world the plans are made in (oracle.h).
#include "tamp/graph_manager/oracle.h"

#include <algorithm>

#include "tamp/core/log.h"
#include "tamp/graph_manager/graph_manager.h"

namespace tamp::graph_manager {

std::vector<std::vector<std::size_t>> removalSubsets(std::size_t n, int max_size) {
  std::vector<std::vector<std::size_t>> out;
  const std::size_t k_max =
      std::min<std::size_t>(n, max_size < 0 ? 0 : static_cast<std::size_t>(max_size));
  for (std::size_t k = 1; k <= k_max; ++k) {
    // Lexicographic k-combinations of {0..n-1}.
    std::vector<std::size_t> c(k);
    for (std::size_t i = 0; i < k; ++i) c[i] = i;
    while (true) {
      out.push_back(c);
      std::size_t i = k;
      while (i > 0 && c[i - 1] == n - k + (i - 1)) --i;
      if (i == 0) break;
      ++c[i - 1];
      for (std::size_t j = i; j < k; ++j) c[j] = c[j - 1] + 1;
    }
  }
  return out;
}

double faultRetryPenalty(const std::vector<OracleFault>& faults, int action_count,
                         const std::vector<BranchStep>& branch, int max_failures) {
  double penalty = 0.0;
  std::vector<int> strikes(branch.size(), 0);
  for (const OracleFault& f : faults) {
    if (f.type != OracleFault::Type::kFailAction || !f.step || *f.step < action_count) continue;
    int command = action_count;  // the simulator's index of the branch's next command
    for (std::size_t i = 0; i < branch.size(); ++i) {
      const BranchStep& s = branch[i];
      const int last = command + s.commands - 1;  // a transfer arm motion goes first
      command += s.commands;
      if (last < *f.step) continue;
      if (f.action && *f.action != s.kind) continue;
      penalty += s.effort_s;  // two faults on one action: it is paid for each
      ++strikes[i];
      break;
    }
  }
  const bool given_up = max_failures > 0 && std::any_of(strikes.begin(), strikes.end(),
                                                        [&](int n) { return n >= max_failures; });
  return given_up ? penalty + kGivenUpPenaltyS : penalty;
}

namespace {

/// Whether perception has `hidden` under an id of its own: a live object's centre lies within its
/// bounding box, or a live movable's footprint box overlaps its own (a thin box's estimate may be
/// centred a little off it).
bool perceivedAs(const world::World& live, const world::Object& hidden) {
  auto footprint = [](Aabb b) {  // seen from above
    b.min.z() = b.max.z() = 0.0;
    return b;
  };
  const Aabb box = footprint(hidden.shape.aabb(hidden.pose));
  return std::any_of(live.objects().begin(), live.objects().end(), [&](const world::Object& x) {
    const Eigen::Vector3d c = x.pose.translation();
    if (box.contains(Eigen::Vector3d(c.x(), c.y(), 0.0))) return true;
    return x.kind == world::ObjectKind::kMovable && footprint(x.shape.aabb(x.pose)).overlaps(box);
  });
}

}  // namespace

world::World withHidden(const world::World& live, const std::vector<world::Object>& hidden,
                        std::set<std::string>* found) {
  world::World out = live;
  for (world::Object o : hidden) {
    if (found && found->count(o.id)) continue;
    if (out.findObject(o.id) != nullptr || perceivedAs(live, o)) {
      if (found) found->insert(o.id);
      continue;
    }
    o.hidden = false;
    if (Status s = out.addObject(o); !s)
      log::get("graph_manager")
          ->warn("oracle: hidden object '{}' not added: {}", o.id, s.error().message);
  }
  return out;
}

// ---- the graph manager under policy oracle ----------------------------------------------

int GraphManager::blockingObjectsConsidered() const {
  return params_.policy == Policy::kOracle
             ? std::max(params_.max_blocking_objects, params_.oracle_max_objects)
             : params_.max_blocking_objects;
}

void GraphManager::refreshOracle() {
  auto k = services_.oracle();
  if (!k) {
    log::get("graph_manager")
        ->warn("oracle: {} (going on with {})", k.error().message,
               oracle_ ? "the last answer" : "no fault knowledge");
    return;
  }
  oracle_ = std::move(k).value();
}

double GraphManager::oraclePenalty(const std::vector<BranchStep>& steps) const {
  if (params_.policy != Policy::kOracle || !oracle_) return 0.0;
  return faultRetryPenalty(oracle_->faults, oracle_->action_count, steps, params_.max_action_failures);
}

std::vector<world::Object> GraphManager::unseenObjects() const {
  std::vector<world::Object> out;
  if (params_.policy != Policy::kOracle || !oracle_) return out;
  for (const world::Object& h : oracle_->hidden) {
    // In the graph's world as told (`withHidden`), not a perceived object under the same id.
    const world::Object* o = abstraction_.world().findObject(h.id);
    if (o && (o->pose.translation() - h.pose.translation()).norm() < 1e-6) out.push_back(*o);
  }
  return out;
}

void GraphManager::spawnSubsetSubtasks(
    NodeId v, NodeId child, const std::vector<std::pair<std::string, std::string>>& slots) {
  // What the blocked action achieved: each sub-task's second plan must achieve it too.
  const auto& va = graph_.node(v).atoms;
  std::vector<std::string> progress;
  for (const auto& a : graph_.node(child).atoms)
    if (!std::binary_search(va.begin(), va.end(), a)) progress.push_back(a);
  for (const auto& subset : removalSubsets(slots.size(), params_.oracle_max_objects)) {
    if (subset.size() < 2) continue;  // single objects: spawnSubtasks' own sub-tasks
    std::vector<std::string> goal;
    std::string what;
    for (std::size_t i : subset) {
      goal.push_back("(on " + slots[i].first + " " + slots[i].second + ")");
      what += (what.empty() ? "" : " and ") + slots[i].first + " to " + slots[i].second;
    }
    addSubtask(v, goal, progress, "sub-task: move " + what);
  }
}

}  // namespace tamp::graph_manager
