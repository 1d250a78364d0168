#pragma once
/// @file
/// The execution monitor's DDS adapter: maps `tamp::execution_monitor::ExecutionMonitor` onto
/// the topics (idl/execution.idl, idl/effort.idl).
///
/// Subscribes: tamp/execute/command (ExecuteCommand), tamp/robot/state (RobotState),
/// tamp/robot/result (ActionResult; by command id), tamp/robot/record (the robot's raw
/// ExecutionRecords), the world model tamp/world/objects + tamp/world/meta (WorldMirror).
/// Publishes: tamp/execute/status (ExecuteStatus, keyed by command id), tamp/execute/failure
/// (FailureEvent), tamp/robot/trajectory (TrajectoryCommand: execute, or `cancel`),
/// tamp/execution/record (ExecutionRecord with predicted_s, predicted_stddev_s, command_id,
/// mission_id filled). Each forwarded record is kept (`RecordOutbox`, on disk in the run folder)
/// and sent again every kRecordResendPeriodS until the effort estimator acknowledges its id on
/// tamp/execution/record_ack; the estimator stores an id once, so records arrive exactly once
/// across restarts of either side.
///
/// Every callback takes one mutex around the library and publishes what it returns; a periodic
/// spin (every 50 ms) feeds world model changes and ticks. Nothing escapes a callback: malformed
/// messages become EXEC_FAILED statuses naming the field and log lines.
///
/// Sample stamps: robot states and results are ordered by their DDS source timestamps (both are
/// written by the robot's process), so "a state written after the result" is well defined.

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <vector>

#include "tamp/dds/service_node.h"
#include "tamp/msg_validation/validate.h"
#include "tamp/dds/topics.h"
#include "tamp/dds/world_sync.h"
#include "tamp/execution_monitor/monitor.h"
#include "tamp/execution_monitor/record_outbox.h"
#include "tamp/execution_monitor/sent_journal.h"

namespace tamp::execution_monitor {

// ---- conversions (the node's boundary; exposed for tests) ---------------------------------------
/// kInvalidArgument naming the field (kind, trajectory.*, object_target).
Result<ExecutionCommand> fromMsg(const msg::ExecuteCommand& m);
/// kInvalidArgument naming the field (joint_names, joint_positions).
Result<RobotObservation> fromMsg(const msg::RobotState& m, const robot::RobotModel& robot,
                                 std::int64_t stamp_ns);
/// kInvalidArgument for an unknown outcome.
Result<RobotResult> fromMsg(const msg::ActionResult& m, std::int64_t stamp_ns);
msg::ExecuteStatus toMsg(const StatusUpdate& s);
msg::FailureEvent toMsg(const FailureReport& f, std::uint64_t seq);
msg::TrajectoryCommand toMsg(const RobotRequest& r);
msg::ExecState toMsg(ExecState s);

class ExecutionMonitorNode : public dds::ServiceNode {
 public:
  /// Parameters from --config (else configDir()/services/execution_monitor.yaml when it exists,
  /// else the defaults); the robot from the parameters' robot_description, else the --scenario's
  /// robot, else the default robot. Errors name file, line and field (exit 30).
  static Result<std::unique_ptr<dds::ServiceNode>> create(const dds::ServiceArgs& args);
  /// Throws std::invalid_argument for invalid params, std::runtime_error when DDS fails.
  ExecutionMonitorNode(const dds::ServiceArgs& args, MonitorParams params, robot::RobotModel robot);
  ~ExecutionMonitorNode() override;

 protected:
  void spinOnce() override;
  /// Waits (kStopDrainS at most) for the effort estimator to acknowledge the records still in
  /// the outbox, sending them again meanwhile.
  void onStop() override;
  /// Not ready until a robot state arrived: a command before it would fail its precondition.
  std::string notReadyBecause() const override;
  double spinPeriodSeconds() const override { return 0.05; }

 private:
  msgv::RejectLog rejects_{"execution_monitor"};  // malformed input: logged once per kind, rate-limited
  double now() const;
  void publish(const Outputs& out);
  void flushRobotRequests();
  void sendToRobot(const RobotRequest& r);
  void onCommand(const msg::ExecuteCommand& m);
  void onState(const msg::RobotState& m, const dds::SampleMeta& meta);
  void onResult(const msg::ActionResult& m, const dds::SampleMeta& meta);
  void onRecord(const msg::ExecutionRecord& m);
  void onRecordAck(const msg::RecordAck& m);
  /// Sends the records the estimator has not acknowledged: new ones, and the others every
  /// `resend_period_s` (kRecordResendPeriodS while running, shorter while stopping).
  void sendDueRecords(double resend_period_s);
  /// With $TAMP_RUN_DIR (set by `tamp launch`): <run_dir>/execution_monitor.sent, read back into
  /// the monitor (`resume`) and appended before every command sent to the robot.
  void openJournal();
  /// <run_dir>/execution_monitor.records with $TAMP_RUN_DIR, else in memory (record_outbox.h).
  void openOutbox();

  std::chrono::steady_clock::time_point t0_{std::chrono::steady_clock::now()};
  std::mutex mutex_;  // guards monitor_ and the writers' ordering
  std::unique_ptr<ExecutionMonitor> monitor_;
  std::unique_ptr<SentJournal> journal_;
  std::mutex records_mu_;  // guards outbox_ (record and acknowledgement callbacks, the spin)
  RecordOutbox outbox_;
  std::unique_ptr<dds::Writer<msg::ExecuteStatus>> status_writer_;
  std::unique_ptr<dds::Writer<msg::FailureEvent>> failure_writer_;
  std::unique_ptr<dds::Writer<msg::TrajectoryCommand>> trajectory_writer_;
  std::unique_ptr<dds::Writer<msg::ExecutionRecord>> record_writer_;
  std::unique_ptr<dds::WorldMirror> mirror_;
  std::unique_ptr<dds::Reader<msg::ExecuteCommand>> command_reader_;
  std::unique_ptr<dds::Reader<msg::RobotState>> state_reader_;
  std::unique_ptr<dds::Reader<msg::ActionResult>> result_reader_;
  std::unique_ptr<dds::Reader<msg::ExecutionRecord>> record_reader_;
  std::unique_ptr<dds::Reader<msg::RecordAck>> ack_reader_;
  std::atomic<bool> world_dirty_{true};
  std::atomic<bool> have_state_{false};  // a robot state was accepted (notReadyBecause)
  std::uint64_t failure_seq_{0};
  std::vector<RobotRequest> unsent_;  // robot requests waiting for the robot driver's match, in order
  bool waiting_for_robot_{false};
};

}  // namespace tamp::execution_monitor
