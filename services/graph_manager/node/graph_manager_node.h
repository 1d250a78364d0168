#pragma once
/// @file
/// The graph manager's DDS adapter: takes `MissionCommand`s (tamp/mission/command), runs each
/// mission with the graph_manager library on its own thread, and publishes `MissionStatus`
/// (transient-local; the final one carries the JSON report and the graph) and `GraphSnapshot`
/// (after every Traverse). It reaches the planners, the effort estimator and the execution
/// monitor through dds_clients.h.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "dds_clients.h"
#include "oracle_clients.h"
#include "tamp/dds/service_node.h"
#include "tamp/msg_validation/validate.h"
#include "tamp/graph_manager/journal.h"
#include "tamp/graph_manager/params.h"

namespace tamp::graph_manager {

class GraphManagerNode : public dds::ServiceNode {
 public:
  /// Reads `args.config_file` (default: configDir()/services/graph_manager.yaml). Errors: bad
  /// parameters (exit 30).
  static Result<std::unique_ptr<dds::ServiceNode>> create(const dds::ServiceArgs& args);
  GraphManagerNode(const dds::ServiceArgs& args, GraphManagerParams params, const robot::RobotModel& robot);
  ~GraphManagerNode() override;
  /// A robot state, a world model, and every service it calls matched (an execution monitor
  /// included): what a mission starts from.
  std::string notReadyBecause() const override;

 private:
  msgv::RejectLog rejects_{"graph_manager"};  // malformed input: logged once per kind, rate-limited
  void onCommand(const msg::MissionCommand& c);
  void worker(std::stop_token stop);
  /// runOne, a failure of it (an exception) published as the mission's failure.
  void runGuarded(const msg::MissionCommand& c, const MissionRecord* resumed);
  /// `resumed`: the journal's record of a mission this node takes up after a restart.
  void runOne(const msg::MissionCommand& c, const MissionRecord* resumed = nullptr);
  /// Reads the journal ($TAMP_RUN_DIR/graph_manager.journal.json): a mission it left unfinished
  /// is taken up first; its id (finished or not) is never started anew.
  void openJournal();
  /// Journals `record` (a warning when it cannot be written: the executor then refuses to send).
  void journal(const MissionRecord& record);
  void publish(const std::string& mission, msg::MissionState state, const std::string& message);

  // runOne's steps.
  using Clock = std::chrono::steady_clock;
  /// Where a mission's efforts, motions and world come from: the services, or the oracle's.
  struct Backends {
    ServiceClients* services;
    WorldSource* source;
  };
  /// The services for `policy`; the oracle's (its world kept in `oracle_source`) for the oracle.
  Result<Backends> backendsFor(const std::string& mission, Policy policy,
                               std::optional<OracleWorldSource>& oracle_source);
  /// Publishes the mission's progress: states, actions, graph snapshots; and the abort flag.
  MissionObserver observerFor(const std::string& mission, Clock::time_point t0);
  /// A mission that failed before it ran: journaled and published with its reason.
  void failMission(const msg::MissionCommand& c, MissionRecord& record, MissionOutcome o, const std::string& why);
  /// A mission that ran: journaled, and its final status published with the report.
  void finishMission(const std::string& mission, MissionRecord& record, const MissionReport& r,
                     const std::string& scenario_path, const GraphManagerParams& p, Clock::time_point t0);

  dds::ServiceArgs args_;
  GraphManagerParams params_;
  dds::Writer<msg::MissionStatus> status_;
  dds::Writer<msg::GraphSnapshot> graph_;
  std::mutex mutex_;
  std::condition_variable_any cv_;
  std::deque<msg::MissionCommand> queue_;
  std::set<std::string> seen_;
  std::atomic<bool> abort_{false};
  std::string running_;
  msg::MissionStatus current_;
  std::optional<MissionJournal> journal_;  // none without a run folder
  std::optional<MissionRecord> resume_;    // an unfinished mission of the journal, taken up first
  // The node's reach into the other services lives as long as the node: its readers and writers
  // are matched (and, under DDS Security, their crypto tokens exchanged) before the first mission
  // arrives, not at the start of each one. Used by the worker thread only.
  DdsServiceClients clients_;
  OracleServiceClients oracle_clients_;  // policy oracle: efforts and truth from the simulator
  DdsExecutor executor_;
  DdsWorldSource source_;
  std::shared_ptr<dds::WorkWatch> mission_watch_;  // the worker, watched while a mission runs
  std::jthread thread_;
  std::unique_ptr<dds::Reader<msg::MissionCommand>> commands_;
};

}  // namespace tamp::graph_manager
