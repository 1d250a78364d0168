#pragma once
/// @file
/// Policy `oracle` at the node: the simulator's truth over DDS (service tamp/sim/oracle, served
/// only in an evaluation run, $TAMP_ORACLE=1). `OracleServiceClients` takes its efforts from the
/// simulator's true nominal durations instead of the effort estimator and answers
/// `ServiceClients::oracle()`; everything else goes to the ordinary clients. `OracleWorldSource`
/// adds the hidden objects to the live world, so that the graph is built in the true world.

#include <memory>
#include <mutex>
#include <set>

#include "dds_clients.h"

namespace tamp::graph_manager {

class OracleServiceClients : public ServiceClients {
 public:
  /// `base` serves plans, motions, placements and grasps; it must outlive this.
  OracleServiceClients(std::shared_ptr<dds::Participant> p, ServiceClients& base);
  TaskPlan plan(const TaskQuery& q) override { return base_.plan(q); }
  MotionAnswer motion(const MotionQuery& q) override { return base_.motion(q); }
  std::vector<MotionAnswer> motions(const std::vector<MotionQuery>& qs) override { return base_.motions(qs); }
  Result<std::vector<PlacementOption>> placements(const PlacementQuery& q) override {
    return base_.placements(q);
  }
  Result<std::vector<GraspOption>> grasps(const GraspQuery& q) override { return base_.grasps(q); }
  /// The true nominal durations (stddev: the simulator's execution noise), from the simulator.
  std::vector<EffortAnswer> effort(const std::vector<EffortQuery>& q) override;
  /// Hidden objects, scripted faults, accepted commands. kUnavailable when no oracle is served.
  Result<OracleKnowledge> oracle() override;

 private:
  ServiceClients& base_;
  dds::RpcClient<msg::OracleRequest, msg::OracleReply> oracle_;
};

/// The live world plus the oracle's hidden objects that perception has not found yet
/// (`withHidden`).
class OracleWorldSource : public WorldSource {
 public:
  OracleWorldSource(WorldSource& live, std::vector<world::Object> hidden)
      : live_(live), hidden_(std::move(hidden)) {}
  world::World world() override {
    world::World live = live_.world();
    std::lock_guard<std::mutex> lock(mu_);
    return withHidden(live, hidden_, &found_);
  }
  Observation robot() override { return live_.robot(); }
  std::uint64_t version() override { return live_.version(); }

 private:
  WorldSource& live_;
  std::vector<world::Object> hidden_;
  std::mutex mu_;
  std::set<std::string> found_;  ///< hidden objects perception has found: never added again
};

}  // namespace tamp::graph_manager
