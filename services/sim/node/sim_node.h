#pragma once
/// @file
/// The simulator's DDS adapter: maps `tamp::sim::SimulationLoop` onto the robot's topics.
///
/// Subscribes: tamp/robot/trajectory (TrajectoryCommand; `cancel` cancels the command with that
/// id), tamp/sim/fault (FaultInjection).
/// Publishes: tamp/robot/state (RobotState, every `state_period_s` of simulated time),
/// tamp/sensor/cloud (PointCloudFrame: every `cloud_period_s`, after each action), tamp/robot/result
/// (ActionResult; a rejected command gets OUTCOME_FAILED with the reason naming the field),
/// tamp/robot/record (ExecutionRecord, one per finished action, record_id = the command id; the
/// execution monitor adds the prediction and forwards it on tamp/execution/record).
///
/// Serves (only when the oracle is enabled: `ServiceArgs`-independent, $TAMP_ORACLE=1, which
/// `tamp run --policy oracle` sets for the run): tamp/sim/oracle (OracleRequest -> OracleReply):
/// the true nominal durations of a batch of effort queries (`sim::nominalDuration` with this
/// simulator's dynamics), and on request the hidden objects and the scripted faults. Evaluation
/// only: a normal deployment does not expose the truth.
///
/// Nothing escapes a DDS callback: malformed messages become failed results and log lines.

#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>

#include "tamp/dds/rpc.h"
#include "tamp/dds/service_node.h"
#include "tamp/msg_validation/validate.h"
#include "tamp/dds/topics.h"
#include "tamp/sim/loop.h"
#include "tamp/sim/setup.h"
#include "tamp/sim/simulator.h"

namespace tamp::sim {

// ---- conversions (the node's boundary; exposed for tests) ---------------------------------------
// (point clouds: dds::toMsg / dds::fromMsg)
/// kInvalidArgument naming the field (trajectory.*, object_target, kind).
Result<ActionCommand> fromMsg(const msg::TrajectoryCommand& m);
msg::ActionResult toMsg(const ActionResult& r);
msg::ExecutionRecord toMsg(const effort_model::ExecutionRecord& r);
/// kInvalidArgument naming the field (type, object_id, shape, pose).
Result<Fault> fromMsg(const msg::FaultInjection& m);
msg::RobotState toMsg(const RobotStateSample& s, const std::vector<std::string>& joint_names,
                      const std::string& robot_id, std::int64_t stamp_ns, std::uint64_t seq);

/// The oracle's durations: one estimate per query, mean_s the true nominal duration with
/// `params.dynamics` (no noise, no stall), stddev_s the true execution noise around it
/// (`duration_noise` x mean: the log-normal factor's spread, stalls not included); a malformed
/// query gets INVALID_ARGUMENT naming the field. Exposed for tests.
std::vector<msg::EffortEstimate> oracleDurations(const SimParams& params, const robot::RobotModel& robot,
                                                 const std::vector<msg::EffortQuery>& queries);

/// Whether this process serves the oracle ($TAMP_ORACLE is "1" or "true").
bool oracleEnabled();

class SimNode : public dds::ServiceNode {
 public:
  /// Loads the parameters (--config, else configDir()/services/sim.yaml when it exists, else the
  /// defaults) and the scenario they name, then builds the node. With $TAMP_RUN_DIR, a checkpoint
  /// found there (a restart within the run) is resumed from instead of the scenario's start state.
  /// Errors: bad parameters or scenario, a checkpoint that cannot be read or does not fit the
  /// scenario (naming the file, line and field; the simulator does not start: the world it would
  /// start from is unknown) (exit 30 through serviceMain).
  static Result<std::unique_ptr<dds::ServiceNode>> create(const dds::ServiceArgs& args);
  /// Builds the node around an explicit setup (tests, embedding). With `checkpoint_file` (create()
  /// passes $TAMP_RUN_DIR/sim.checkpoint) the node resumes from `resume_from` when given
  /// (`Simulator::resume`: a restarted robot driver) and checkpoints its physical state there
  /// (checkpoint.h). Throws std::runtime_error when DDS fails and std::invalid_argument when the
  /// setup is invalid or `resume_from` does not fit it.
  SimNode(const dds::ServiceArgs& args, SimSetup setup, SimParams params,
          std::filesystem::path checkpoint_file = {}, std::optional<SimSnapshot> resume_from = std::nullopt);
  ~SimNode() override;

  /// The running loop (e.g. for in-process tests to read the ground truth).
  SimulationLoop& loop() { return *loop_; }

 private:
  msgv::RejectLog rejects_{"sim"};  // malformed input: logged once per kind, rate-limited
  void onCommand(const msg::TrajectoryCommand& m);
  void onFault(const msg::FaultInjection& m);
  msg::OracleReply onOracle(const msg::OracleRequest& req);

  std::unique_ptr<Simulator> sim_;
  std::vector<std::string> joint_names_;
  std::string robot_id_;
  std::unique_ptr<dds::Writer<msg::RobotState>> state_writer_;
  std::unique_ptr<dds::Writer<msg::PointCloudFrame>> cloud_writer_;
  std::unique_ptr<dds::Writer<msg::ActionResult>> result_writer_;
  std::unique_ptr<dds::Writer<msg::ExecutionRecord>> record_writer_;
  std::unique_ptr<SimulationLoop> loop_;
  std::unique_ptr<dds::Reader<msg::TrajectoryCommand>> command_reader_;
  std::unique_ptr<dds::Reader<msg::FaultInjection>> fault_reader_;
  std::vector<Fault> scripted_;  ///< the scenario's faults, for the oracle
  std::unique_ptr<dds::RpcServer<msg::OracleRequest, msg::OracleReply>> oracle_;
  std::atomic<std::uint64_t> state_seq_{0}, cloud_seq_{0};
  std::atomic<std::uint64_t> commands_{0}, rejected_{0};

  /// Writes the checkpoint now (any thread; serialised). `why` is for the log.
  void checkpoint(const char* why);
  /// A periodic checkpoint (loop thread, from the state callback): every `checkpoint_period_s`
  /// while an action runs, every `checkpoint_idle_period_s` otherwise.
  void checkpointPeriodically(const RobotStateSample& s);
  std::filesystem::path checkpoint_file_;  ///< empty: no checkpoint
  double checkpoint_period_s_{0.2}, checkpoint_idle_period_s_{1.0};
  std::mutex checkpoint_mutex_;            ///< guards the write and the fields below
  double last_checkpoint_s_{-1.0};         ///< simulated time of the last one
  bool checkpoint_failed_{false};
  std::uint64_t checkpoint_writes_{0};
  double checkpoint_total_ms_{0.0}, checkpoint_max_ms_{0.0};
  std::size_t checkpoint_bytes_{0};
};

}  // namespace tamp::sim
