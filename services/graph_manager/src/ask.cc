// The graph manager's questions to the motion planner's services, through the memo of answers
// given in the world as it stands (query_memo.h). Counters count the questions the services
// answered; `memo_hits` those answered from memory.
#include <algorithm>

#include "tamp/graph_manager/graph_manager.h"

namespace tamp::graph_manager {

MotionQuery GraphManager::withHeldMargin(MotionQuery q) const {
  const bool in_hand = !q.held.object_id.empty() && q.held.link != abstraction_.robot().options().base_link;
  q.held_padding_m = in_hand ? held_padding_m_ : 0.0;
  q.world_version = world_version_;
  q.added = unseenObjects();
  std::vector<std::string> skip = q.ignored;
  if (!q.held.object_id.empty()) skip.push_back(q.held.object_id);
  addCorrections(q.overrides, skip);
  return q;
}

void GraphManager::addCorrections(std::vector<ObjectOverride>& overrides, const std::vector<std::string>& skip) const {
  for (const auto& [id, c] : corrections_) {
    auto named = [&](const ObjectOverride& o) { return o.object_id == id; };
    if (std::find(skip.begin(), skip.end(), id) != skip.end() || std::any_of(overrides.begin(), overrides.end(), named))
      continue;
    overrides.push_back(ObjectOverride{id, false, c.pose});
  }
}

namespace {
/// The mission is being aborted: nothing more is asked (the Traverse asking is discarded).
MotionAnswer notAskedWhileAborting() {
  MotionAnswer a;
  a.status = MotionOutcome::kUnavailable;
  a.reason = "not asked: the mission is being aborted";
  return a;
}
}  // namespace

MotionAnswer GraphManager::askMotion(const MotionQuery& query) {
  const MotionQuery q = withHeldMargin(query);
  if (const MotionAnswer* kept = params_.memoise_answers ? memo_.motion(q) : nullptr) {
    ++counters_.memo_hits;
    return *kept;
  }
  if (interrupted_ && interrupted_()) return notAskedWhileAborting();
  ++counters_.motion_calls;
  MotionAnswer a = services_.motion(q);
  if (params_.memoise_answers) memo_.keep(q, a);
  return a;
}

std::vector<MotionAnswer> GraphManager::askMotions(const std::vector<MotionQuery>& queries) {
  std::vector<MotionQuery> qs;
  for (const auto& q : queries) qs.push_back(withHeldMargin(q));
  std::vector<MotionAnswer> out(qs.size());
  std::vector<MotionQuery> ask;
  std::vector<std::size_t> where;
  for (std::size_t i = 0; i < qs.size(); ++i) {
    if (const MotionAnswer* kept = params_.memoise_answers ? memo_.motion(qs[i]) : nullptr) {
      ++counters_.memo_hits;
      out[i] = *kept;
    } else {
      ask.push_back(qs[i]);
      where.push_back(i);
    }
  }
  if (ask.empty()) return out;
  if (interrupted_ && interrupted_()) {
    for (std::size_t i : where) out[i] = notAskedWhileAborting();
    return out;
  }
  counters_.motion_calls += static_cast<int>(ask.size());
  std::vector<MotionAnswer> answers = ask.size() == 1 ? std::vector<MotionAnswer>{services_.motion(ask[0])}
                                                      : services_.motions(ask);
  for (std::size_t j = 0; j < answers.size() && j < where.size(); ++j) {
    if (params_.memoise_answers) memo_.keep(ask[j], answers[j]);
    out[where[j]] = std::move(answers[j]);
  }
  return out;
}

Result<std::vector<GraspOption>> GraphManager::askGrasps(GraspQuery q) {
  q.world_version = world_version_;
  q.added = unseenObjects();
  addCorrections(q.overrides);
  if (const std::vector<GraspOption>* kept = params_.memoise_answers ? memo_.grasps(q) : nullptr) {
    ++counters_.memo_hits;
    return *kept;
  }
  ++counters_.grasp_calls;
  auto g = services_.grasps(q);
  if (g && params_.memoise_answers) memo_.keep(q, *g);
  return g;
}

Result<std::vector<PlacementOption>> GraphManager::askPlacements(PlacementQuery q) {
  q.world_version = world_version_;
  q.added = unseenObjects();
  addCorrections(q.overrides, {q.object_id});
  ++counters_.placement_calls;
  return services_.placements(q);
}

}  // namespace tamp::graph_manager
