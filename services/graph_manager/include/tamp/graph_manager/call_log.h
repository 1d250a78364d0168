#pragma once
/// @file
/// Where the replanning latency goes (issue 12, "replanning latency p95 under 300 ms"): every
/// service call the graph manager makes, timed at the client, so that a replanning can say
/// which task-planner, motion, grasp, placement and effort calls stood between the event and
/// the next command, and how long each took.

#include <chrono>
#include <mutex>
#include <string>
#include <vector>

#include "tamp/graph_manager/clients.h"

namespace tamp::graph_manager {

/// One service call, timed at the client.
struct TimedCall {
  std::string service;   ///< "plan", "motion", "placement", "grasp", "effort"
  std::string what;      ///< "base lazy", "arm full", "box on table", ...
  double s{0.0};         ///< wall time of the call at the client (queueing and transport included);
                         ///< in a batch of concurrent motions the first has the batch's, the others 0
  double server_s{0.0};  ///< the service's own time when it reports one (motions, plans), else 0
};

/// Calls and time per service over a stretch of calls.
struct CallSummary {
  struct PerService {
    int calls{0};
    double s{0.0};
  };
  PerService plan, motion, placement, grasp, effort;
  int calls() const {
    return plan.calls + motion.calls + placement.calls + grasp.calls + effort.calls;
  }
  double seconds() const { return plan.s + motion.s + placement.s + grasp.s + effort.s; }
  static CallSummary of(const std::vector<TimedCall>& calls);
};

/// A `ServiceClients` that forwards every call to `inner` and keeps a log of it. The log is
/// safe to read and mark from another thread than the one making the calls.
class LoggedServiceClients : public ServiceClients {
 public:
  explicit LoggedServiceClients(ServiceClients& inner) : inner_(inner) {}
  TaskPlan plan(const TaskQuery& q) override;
  MotionAnswer motion(const MotionQuery& q) override;
  std::vector<MotionAnswer> motions(const std::vector<MotionQuery>& qs) override;
  Result<std::vector<PlacementOption>> placements(const PlacementQuery& q) override;
  Result<std::vector<GraspOption>> grasps(const GraspQuery& q) override;
  std::vector<EffortAnswer> effort(const std::vector<EffortQuery>& q) override;
  /// Forwarded untimed (asked once per Traverse, not a planning call). Without it the wrapper
  /// answered with the base class's "no oracle", and policy oracle lost its knowledge.
  Result<OracleKnowledge> oracle() override { return inner_.oracle(); }

  /// The position in the log now (to read the calls made after it with `since`).
  std::size_t mark() const;
  /// The calls logged after `mark` (at most `max_calls` kept: the log is trimmed to the last
  /// ones, marks before the trimmed part read from its start).
  std::vector<TimedCall> since(std::size_t mark) const;

 private:
  void add(TimedCall c);
  ServiceClients& inner_;
  mutable std::mutex mutex_;
  std::vector<TimedCall> log_;
  std::size_t dropped_{0};  ///< calls trimmed from the front of the log
  static constexpr std::size_t kMaxKept = 4096;
};

}  // namespace tamp::graph_manager
