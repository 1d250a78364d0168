// Lazy refinement of the symbolic abstraction: region-level reach facts that the geometry refutes
// are replaced, for the objects concerned, by slots of their own (see graph_manager.h).
#include "state_atoms.h"
#include "tamp/core/log.h"
#include "tamp/graph_manager/graph_manager.h"

namespace tamp::graph_manager {

bool GraphManager::refineSupport(const std::string& object, const std::string& region, const BranchContext& ctx) {
  if (!abstraction_.isRegion(region) || abstraction_.slot(region) != nullptr) return false;  // already object-sized
  if (ctx.object_poses.count(object)) return false;  // moved by the branch: where it stands is a slot already
  const world::Object* o = abstraction_.world().findObject(object);
  if (o == nullptr || o->kind != world::ObjectKind::kMovable) return false;
  const std::size_t before = abstraction_.slotCount();
  const std::string s = abstraction_.addSlot(object, region, o->pose);
  if (abstraction_.slotCount() == before) return false;
  refined_ = true;
  log::get("graph_manager")->info("refined the abstraction: {} on {} gets its own slot {} (no grasp from where the plan stood)",
                                  object, region, s);
  if (!abstraction_.isReached(Abstraction::armconfOver(s))) {
    // No known base pose reaches it (an object dropped where no location was foreseen): a stand
    // beside it, as for a blocking object, on the side the branch's robot drove in from (not the
    // side of where the refuted plan stood: that may be the far side of the object).
    if (auto g = standBeside(*o, ctx.came_from.value_or(ctx.state.base), ctx)) {
      const std::string near = abstraction_.locationFor(g->base_pose, "near_" + object);
      abstraction_.addReach(near, Abstraction::armconfOver(s));
      log::get("graph_manager")->info("{} is reached from {} ({:.2f}, {:.2f})", s, near, g->base_pose.x, g->base_pose.y);
    }
  }
  return true;
}

bool GraphManager::takeRefinement() {
  const bool r = refined_;
  refined_ = false;
  return r;
}

NodeId GraphManager::refinedNode(NodeId n) {
  std::vector<std::string> atoms = graph_.node(n).atoms;  // a copy: addNode grows the graph
  const std::vector<std::string> refined = abstraction_.refinedSupports(atoms);
  if (refined == atoms) return n;
  return graph_.addNode(refined, "refined abstraction of n" + std::to_string(n));
}

}  // namespace tamp::graph_manager
