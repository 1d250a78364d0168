#include "tamp/graph_manager/call_log.h"

#include <cstdio>

namespace tamp::graph_manager {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string motionWhat(const MotionQuery& q) {
  std::string w = q.group == Group::kBase ? "base" : "arm";
  w += q.mode == Mode::kLazy ? (q.movable_cost_weight > 0.0 ? " lazy effort-aware" : " lazy")
                             : (q.straight_only ? " straight" : " full");
  if (q.group == Group::kBase) {
    char buf[64];
    std::snprintf(buf, sizeof buf, " to (%.2f, %.2f)", q.goal_base.x, q.goal_base.y);
    w += buf;
  }
  if (!q.held.object_id.empty()) w += " holding " + q.held.object_id;
  if (q.held_padding_m > 0) {
    char buf[48];
    std::snprintf(buf, sizeof buf, " (+%.2f m)", q.held_padding_m);
    w += buf;
  }
  return w;
}

}  // namespace

CallSummary CallSummary::of(const std::vector<TimedCall>& calls) {
  CallSummary s;
  for (const auto& c : calls) {
    PerService* p = c.service == "plan"        ? &s.plan
                    : c.service == "motion"    ? &s.motion
                    : c.service == "placement" ? &s.placement
                    : c.service == "grasp"     ? &s.grasp
                                               : &s.effort;
    ++p->calls;
    p->s += c.s;
  }
  return s;
}

void LoggedServiceClients::add(TimedCall c) {
  std::lock_guard g(mutex_);
  if (log_.size() >= kMaxKept) {
    const std::size_t drop = kMaxKept / 2;
    log_.erase(log_.begin(), log_.begin() + static_cast<std::ptrdiff_t>(drop));
    dropped_ += drop;
  }
  log_.push_back(std::move(c));
}

std::size_t LoggedServiceClients::mark() const {
  std::lock_guard g(mutex_);
  return dropped_ + log_.size();
}

std::vector<TimedCall> LoggedServiceClients::since(std::size_t mark) const {
  std::lock_guard g(mutex_);
  const std::size_t from = mark > dropped_ ? mark - dropped_ : 0;
  if (from >= log_.size()) return {};
  return {log_.begin() + static_cast<std::ptrdiff_t>(from), log_.end()};
}

TaskPlan LoggedServiceClients::plan(const TaskQuery& q) {
  const auto t0 = Clock::now();
  TaskPlan p = inner_.plan(q);
  add({"plan", std::to_string(p.actions.size()) + " actions, " + std::string(toString(p.status)),
       secondsSince(t0), p.time_s});
  return p;
}

std::vector<MotionAnswer> ServiceClients::motions(const std::vector<MotionQuery>& qs) {
  std::vector<MotionAnswer> out;
  out.reserve(qs.size());
  for (const MotionQuery& q : qs) out.push_back(motion(q));
  return out;
}

std::vector<MotionAnswer> LoggedServiceClients::motions(const std::vector<MotionQuery>& qs) {
  const auto t0 = Clock::now();
  std::vector<MotionAnswer> out = inner_.motions(qs);
  // Concurrent calls overlap: each is logged with its own round trip where the inner clients
  // timed it, and the batch's wall time is the first one's (so a sum over the log stays close to
  // the time waited).
  const double wall = secondsSince(t0);
  for (std::size_t i = 0; i < out.size() && i < qs.size(); ++i)
    add({"motion", motionWhat(qs[i]) + ": " + std::string(toString(out[i].status)) + (i ? " (concurrent)" : ""),
         i == 0 ? wall : 0.0, out[i].time_s});
  return out;
}

MotionAnswer LoggedServiceClients::motion(const MotionQuery& q) {
  const auto t0 = Clock::now();
  MotionAnswer a = inner_.motion(q);
  add({"motion", motionWhat(q) + ": " + std::string(toString(a.status)), secondsSince(t0),
       a.time_s});
  return a;
}

Result<std::vector<PlacementOption>> LoggedServiceClients::placements(const PlacementQuery& q) {
  const auto t0 = Clock::now();
  auto r = inner_.placements(q);
  add({"placement",
       q.object_id + " on " + q.region_id + (q.base ? " from the base" : "") + ": " +
           (r ? std::to_string(r->size()) : std::string("error")),
       secondsSince(t0), 0.0});
  return r;
}

Result<std::vector<GraspOption>> LoggedServiceClients::grasps(const GraspQuery& q) {
  const auto t0 = Clock::now();
  auto r = inner_.grasps(q);
  add({"grasp",
       q.object_id + (q.base ? " from a base pose" : " sampled bases") + ": " +
           (r ? std::to_string(r->size()) : std::string("error")),
       secondsSince(t0), 0.0});
  return r;
}

std::vector<EffortAnswer> LoggedServiceClients::effort(const std::vector<EffortQuery>& q) {
  const auto t0 = Clock::now();
  auto r = inner_.effort(q);
  add({"effort", std::to_string(q.size()) + " queries", secondsSince(t0), 0.0});
  return r;
}

}  // namespace tamp::graph_manager
