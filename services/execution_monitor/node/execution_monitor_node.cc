#include "execution_monitor_node.h"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <thread>

#include "tamp/core/log.h"
#include "tamp/core/paths.h"
#include "tamp/dds/cdr.h"
#include "tamp/dds/convert.h"
#include "tamp/world/scenario.h"

namespace tamp::execution_monitor {
namespace {

const std::shared_ptr<spdlog::logger>& logger() {
  static const auto l = tamp::log::get("execution_monitor");
  return l;
}

Error bad(const std::string& field, const std::string& message) {
  return Error(ErrorCode::kInvalidArgument, field + ": " + message,
               SourceLocation{"", 0, 0, field});
}

/// A record not acknowledged by the effort estimator is sent again after this long (s).
constexpr double kRecordResendPeriodS = 2.0;
/// A clean stop waits at most this long for the effort estimator to acknowledge the records still
/// in the outbox (the last action's, sent a moment before the mission ended and the run stopped).
constexpr double kStopDrainS = 2.0;
/// ... sending each again this often meanwhile.
constexpr double kStopResendPeriodS = 0.5;

}  // namespace

Result<ExecutionCommand> fromMsg(const msg::ExecuteCommand& m) {
  ExecutionCommand c;
  c.command_id = m.command_id();
  c.mission_id = m.mission_id();
  c.edge_id = m.edge_id();
  c.pddl_action = m.pddl_action();
  const int kind = static_cast<int>(m.kind());
  if (kind < 0 || kind > static_cast<int>(msg::ActionKind::ACTION_PLACE)) {
    return bad("kind", "unknown action kind " + std::to_string(kind));
  }
  c.kind = dds::fromMsg(m.kind());
  auto t = dds::fromMsg(m.trajectory(), "trajectory");
  if (!t) return t.error();
  c.trajectory = std::move(t).value();
  c.object_id = m.object_id();
  c.region_id = m.region_id();
  if (m.object_target_given()) {
    auto pose = dds::fromMsg(m.object_target(), "object_target");
    if (!pose) return pose.error();
    c.object_target = *pose;
  }
  c.expected_duration_s = m.expected_duration_s();
  c.expected_stddev_s = m.expected_stddev_s();
  c.world_version = m.world_version();
  c.cancel = m.cancel();
  return c;
}

Result<RobotObservation> fromMsg(const msg::RobotState& m, const robot::RobotModel& robot,
                                 std::int64_t stamp_ns) {
  if (m.joint_names().size() != m.joint_positions().size()) {
    return bad("joint_positions", std::to_string(m.joint_positions().size()) + " values for " +
                                      std::to_string(m.joint_names().size()) + " joints");
  }
  RobotObservation o;
  auto base = dds::fromMsg(m.base(), "base");
  if (!base) return base.error();
  auto s = robot.fromJointValues(m.joint_names(), m.joint_positions(), robot.defaultState(*base));
  if (!s) return s.error();
  o.state = std::move(s).value();
  for (double v : m.joint_positions()) {
    if (!std::isfinite(v)) return bad("joint_positions", "not finite");
  }
  o.held_object_id = m.held_object_id();
  o.moving = m.moving();
  o.stamp_ns = stamp_ns;
  return o;
}

Result<RobotResult> fromMsg(const msg::ActionResult& m, std::int64_t stamp_ns) {
  RobotResult r;
  r.command_id = m.command_id();
  switch (m.outcome()) {
    case msg::ActionOutcome::OUTCOME_SUCCEEDED:
      r.outcome = RobotOutcome::kSucceeded;
      break;
    case msg::ActionOutcome::OUTCOME_BLOCKED:
      r.outcome = RobotOutcome::kBlocked;
      break;
    case msg::ActionOutcome::OUTCOME_FAILED:
      r.outcome = RobotOutcome::kFailed;
      break;
    case msg::ActionOutcome::OUTCOME_CANCELLED:
      r.outcome = RobotOutcome::kCancelled;
      break;
    default:
      return bad("outcome", "unknown outcome " + std::to_string(static_cast<int>(m.outcome())));
  }
  r.duration_s = m.duration_s();
  r.progress = m.progress();
  r.blocking_object_id = m.blocking_object_id();
  r.reason = m.reason();
  r.stamp_ns = stamp_ns;
  return r;
}

msg::ExecState toMsg(ExecState s) {
  switch (s) {
    case ExecState::kAccepted:
      return msg::ExecState::EXEC_ACCEPTED;
    case ExecState::kRunning:
      return msg::ExecState::EXEC_RUNNING;
    case ExecState::kSucceeded:
      return msg::ExecState::EXEC_SUCCEEDED;
    case ExecState::kFailed:
      return msg::ExecState::EXEC_FAILED;
    case ExecState::kBlocked:
      return msg::ExecState::EXEC_BLOCKED;
    case ExecState::kCancelled:
      return msg::ExecState::EXEC_CANCELLED;
  }
  return msg::ExecState::EXEC_FAILED;
}

msg::ExecuteStatus toMsg(const StatusUpdate& s) {
  msg::ExecuteStatus m;
  m.command_id(s.command_id);
  m.state(toMsg(s.state));
  m.progress(s.progress);
  m.elapsed_s(s.elapsed_s);
  m.reason(s.reason);
  m.blocking_object_id(s.blocking_object_id);
  m.measured_duration_s(s.measured_duration_s);
  m.held_object_id(s.held_object_id);
  m.stopped_at_contact(s.stopped_at_contact);
  return m;
}

msg::FailureEvent toMsg(const FailureReport& f, std::uint64_t seq) {
  msg::FailureEvent m;
  m.header().stamp_ns(dds::nowNs());
  m.header().frame_id("world");
  m.header().seq(seq);
  m.command_id(f.command_id);
  switch (f.type) {
    case FailureType::kBlocked:
      m.type(msg::FailureType::FAILURE_BLOCKED);
      break;
    case FailureType::kObjectDropped:
      m.type(msg::FailureType::FAILURE_OBJECT_DROPPED);
      break;
    case FailureType::kActionFailed:
      m.type(msg::FailureType::FAILURE_ACTION_FAILED);
      break;
    case FailureType::kNewObstacle:
      m.type(msg::FailureType::FAILURE_NEW_OBSTACLE);
      break;
    case FailureType::kTimeout:
      m.type(msg::FailureType::FAILURE_TIMEOUT);
      break;
    case FailureType::kPrecondition:
      m.type(msg::FailureType::FAILURE_PRECONDITION);
      break;
  }
  m.object_id(f.object_id);
  m.robot_base(dds::toMsg(f.robot_base));
  m.description(f.description);
  return m;
}

msg::TrajectoryCommand toMsg(const RobotRequest& r) {
  msg::TrajectoryCommand m;
  m.command_id(r.command.command_id);
  m.kind(dds::toMsg(r.command.kind));
  if (r.type == RobotRequest::Type::kCancel) {
    m.cancel(true);
    return m;
  }
  m.trajectory(dds::toMsg(r.command.trajectory));
  m.object_id(r.command.object_id);
  if (r.command.object_target) m.object_target(dds::toMsg(*r.command.object_target));
  m.cancel(false);
  return m;
}

Result<std::unique_ptr<dds::ServiceNode>> ExecutionMonitorNode::create(
    const dds::ServiceArgs& args) {
  std::filesystem::path file = args.config_file;
  if (file.empty() &&
      std::filesystem::exists(configDir() / "services" / "execution_monitor.yaml")) {
    file = configDir() / "services" / "execution_monitor.yaml";
  }
  auto params = file.empty() ? Result<MonitorParams>(MonitorParams{}) : loadMonitorParams(file);
  if (!params) return params.error();
  std::filesystem::path description = params->robot_description;
  if (description.empty() && !args.scenario_file.empty()) {
    auto sc = world::loadScenario(args.scenario_file);
    if (!sc) return sc.error();
    description = sc->robot.description;
  }
  auto robot = description.empty() ? robot::RobotModel::loadDefault()
                                   : robot::RobotModel::loadDescription(description);
  if (!robot) return robot.error();
  try {
    return std::unique_ptr<dds::ServiceNode>(std::make_unique<ExecutionMonitorNode>(
        args, std::move(params).value(), std::move(robot).value()));
  } catch (const std::invalid_argument& e) {
    return Error(ErrorCode::kInvalidArgument, e.what());
  }
}

ExecutionMonitorNode::ExecutionMonitorNode(const dds::ServiceArgs& args, MonitorParams params,
                                           robot::RobotModel robot)
    : ServiceNode(args) {
  const std::string world_id = params.world_id;
  monitor_ = std::make_unique<ExecutionMonitor>(std::move(params), std::move(robot));
  openJournal();
  openOutbox();
  const auto& p = participant();
  status_writer_ =
      std::make_unique<dds::Writer<msg::ExecuteStatus>>(p, dds::topics::kExecuteStatus);
  failure_writer_ =
      std::make_unique<dds::Writer<msg::FailureEvent>>(p, dds::topics::kFailureEvents);
  trajectory_writer_ =
      std::make_unique<dds::Writer<msg::TrajectoryCommand>>(p, dds::topics::kTrajectoryCommand);
  record_writer_ =
      std::make_unique<dds::Writer<msg::ExecutionRecord>>(p, dds::topics::kExecutionRecords);
  mirror_ = std::make_unique<dds::WorldMirror>(p, world_id);
  mirror_->onChange([this] { world_dirty_ = true; });
  state_reader_ = std::make_unique<dds::Reader<msg::RobotState>>(
      p, dds::topics::kRobotState,
      [this](const msg::RobotState& m, const dds::SampleMeta& meta) { onState(m, meta); });
  result_reader_ = std::make_unique<dds::Reader<msg::ActionResult>>(
      p, dds::topics::kActionResult,
      [this](const msg::ActionResult& m, const dds::SampleMeta& meta) { onResult(m, meta); });
  ack_reader_ = std::make_unique<dds::Reader<msg::RecordAck>>(
      p, dds::topics::kRecordAcks, [this](const msg::RecordAck& m, const dds::SampleMeta&) { onRecordAck(m); });
  record_reader_ = std::make_unique<dds::Reader<msg::ExecutionRecord>>(
      p, dds::topics::kRobotRecords,
      [this](const msg::ExecutionRecord& m, const dds::SampleMeta&) { onRecord(m); });
  command_reader_ = std::make_unique<dds::Reader<msg::ExecuteCommand>>(
      p, dds::topics::kExecuteCommand,
      [this](const msg::ExecuteCommand& m, const dds::SampleMeta&) { onCommand(m); });
}

void ExecutionMonitorNode::openJournal() {
  const char* run_dir = std::getenv("TAMP_RUN_DIR");
  if (!run_dir || !*run_dir) return;
  auto j = SentJournal::open(std::filesystem::path(run_dir) / "execution_monitor.sent");
  if (!j) throw std::runtime_error("execution monitor: " + j.error().toString());
  journal_ = std::make_unique<SentJournal>(std::move(j).value());
  if (!journal_->previous().empty()) {
    logger()->info("journal {}: {} command(s) sent by a previous run; a repeat of one is joined, "
                   "not executed again", journal_->path().string(), journal_->previous().size());
  }
  monitor_->resume(journal_->previous());
}

void ExecutionMonitorNode::openOutbox() {
  const char* run_dir = std::getenv("TAMP_RUN_DIR");
  if (!run_dir || !*run_dir) return;  // in memory: records survive the estimator's restarts only
  auto box = RecordOutbox::open(std::filesystem::path(run_dir) / "execution_monitor.records");
  if (!box) throw std::runtime_error("execution monitor: " + box.error().toString());
  outbox_ = std::move(box).value();
  if (outbox_.pending() > 0) {
    logger()->info("outbox {}: {} execution record(s) not acknowledged by the effort estimator yet; sending "
                   "them again", outbox_.path().string(), outbox_.pending());
  }
}

ExecutionMonitorNode::~ExecutionMonitorNode() {
  // Input first (callbacks use the monitor and the writers), then the mirror.
  command_reader_.reset();
  ack_reader_.reset();
  record_reader_.reset();
  result_reader_.reset();
  state_reader_.reset();
  mirror_.reset();
}

double ExecutionMonitorNode::now() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

void ExecutionMonitorNode::flushRobotRequests() {
  if (unsent_.empty()) return;
  if (trajectory_writer_->matchedReaders() == 0) {
    if (!waiting_for_robot_) {
      logger()->warn("{} request(s) for the robot wait: no robot driver matched on {}", unsent_.size(),
                     dds::topics::kTrajectoryCommand.name);
    }
    waiting_for_robot_ = true;
    return;
  }
  if (waiting_for_robot_) logger()->info("robot driver matched: sending {} waiting request(s)", unsent_.size());
  waiting_for_robot_ = false;
  std::vector<RobotRequest> pending;
  pending.swap(unsent_);
  for (const auto& r : pending) sendToRobot(r);
}

void ExecutionMonitorNode::sendToRobot(const RobotRequest& r) {
  if (journal_ && r.type == RobotRequest::Type::kExecute) {
    if (Status j = journal_->append(r.command.command_id); !j) {
      // Not sent: a command the journal does not hold could be executed twice after a restart.
      logger()->error("command '{}' not sent to the robot: {}", r.command.command_id,
                      j.error().toString());
      return;
    }
  }
  if (Status s = trajectory_writer_->write(toMsg(r)); !s) {
    logger()->error("{} of '{}' not sent to the robot: {}",
                    r.type == RobotRequest::Type::kCancel ? "cancel" : "command",
                    r.command.command_id, s.error().toString());
  } else {
    logger()->info("{} '{}' ({})", r.type == RobotRequest::Type::kCancel ? "cancel" : "execute",
                   r.command.command_id,
                   r.command.pddl_action.empty() ? std::string(toString(r.command.kind))
                                                 : r.command.pddl_action);
  }
}

void ExecutionMonitorNode::publish(const Outputs& out) {
  // Robot requests first. A command written before this writer has matched the robot's reader
  // would be lost (the topic is VOLATILE, and a reader's match is not the writer's): requests wait
  // in order until the robot is matched; the command's timeout still runs meanwhile.
  for (const auto& r : out.robot) unsent_.push_back(r);
  flushRobotRequests();
  for (const auto& f : out.failures) {
    logger()->warn("failure '{}' ({}): {}", f.command_id, toString(f.type), f.description);
    if (Status s = failure_writer_->write(toMsg(f, ++failure_seq_)); !s) {
      logger()->error("failure event of '{}' not published: {}", f.command_id,
                      s.error().toString());
    }
  }
  for (const auto& st : out.statuses) {
    if (isFinal(st.state)) {
      logger()->info("'{}' {} after {:.3f} s{}{}", st.command_id, toString(st.state),
                     st.measured_duration_s, st.reason.empty() ? "" : ": ", st.reason);
    }
    if (Status s = status_writer_->write(toMsg(st)); !s) {
      logger()->error("status of '{}' not published: {}", st.command_id, s.error().toString());
    }
  }
}

void ExecutionMonitorNode::onCommand(const msg::ExecuteCommand& m) {
  try {
    std::lock_guard lock(mutex_);
    if (Status bad = msgv::screen(m, dds::topics::kExecuteCommand.name, rejects_); !bad.ok()) {
      // With an id the sender hears why (a FAILED status naming the field); without, dropped.
      if (!m.command_id().empty() && m.command_id().size() <= msgv::Limits{}.max_id_length)
        publish(monitor_->onMalformedCommand(m.command_id(), bad.error(), now()));
      return;
    }
    auto c = fromMsg(m);
    publish(c ? monitor_->onCommand(*c, now())
              : monitor_->onMalformedCommand(m.command_id(), c.error(), now()));
  } catch (const std::exception& e) {
    logger()->error("command '{}': {}", m.command_id(), e.what());
  }
}

// Both inputs every command is validated against (a command without them fails before it starts).
std::string ExecutionMonitorNode::notReadyBecause() const {
  std::string missing;
  if (!have_state_) missing = std::string("no robot state yet (") + dds::topics::kRobotState.name + ")";
  if (mirror_ == nullptr || mirror_->publishedVersion() == 0) {
    missing += missing.empty() ? "" : ", ";
    missing += std::string("no world model yet (") + dds::topics::kWorldMeta.name + " and its objects)";
  }
  return missing;
}

void ExecutionMonitorNode::onState(const msg::RobotState& m, const dds::SampleMeta& meta) {
  try {
    if (!msgv::accept(m, dds::topics::kRobotState.name, rejects_)) return;
    std::lock_guard lock(mutex_);
    auto o = fromMsg(m, monitor_->robot(), meta.source_stamp_ns);
    if (!o) {
      logger()->warn("robot state ignored: {}", o.error().toString());
      return;
    }
    publish(monitor_->onRobotState(*o, now()));
    have_state_ = true;
  } catch (const std::exception& e) {
    logger()->error("robot state: {}", e.what());
  }
}

void ExecutionMonitorNode::onResult(const msg::ActionResult& m, const dds::SampleMeta& meta) {
  try {
    if (!msgv::accept(m, dds::topics::kActionResult.name, rejects_)) return;
    std::lock_guard lock(mutex_);
    auto r = fromMsg(m, meta.source_stamp_ns);
    if (!r) {
      logger()->warn("result of '{}' ignored: {}", m.command_id(), r.error().toString());
      return;
    }
    publish(monitor_->onRobotResult(*r, now()));
  } catch (const std::exception& e) {
    logger()->error("result of '{}': {}", m.command_id(), e.what());
  }
}

void ExecutionMonitorNode::onRecord(const msg::ExecutionRecord& m) {
  try {
    if (!msgv::accept(m, dds::topics::kRobotRecords.name, rejects_)) return;
    std::optional<RecordAnnotation> a;
    {
      std::lock_guard lock(mutex_);
      a = monitor_->onRobotRecord(m.record_id(), m.command_id());
    }
    if (!a) return;
    msg::ExecutionRecord out = m;
    out.predicted_s(a->predicted_s);
    out.predicted_stddev_s(a->predicted_stddev_s);
    out.command_id(a->command_id);
    out.mission_id(a->mission_id);
    {
      std::lock_guard lock(records_mu_);
      auto added = outbox_.add(out.record_id(), dds::toCdr(out));
      if (!added) {
        // Sent once all the same; a restart of the monitor before its acknowledgement loses it.
        logger()->error("execution record '{}' not kept until acknowledged: {}", m.record_id(),
                        added.error().toString());
        if (Status s = record_writer_->write(out); !s) {
          logger()->error("execution record '{}' not forwarded: {}", m.record_id(), s.error().toString());
        }
        return;
      }
    }
    sendDueRecords(kRecordResendPeriodS);
  } catch (const std::exception& e) {
    logger()->error("record '{}': {}", m.record_id(), e.what());
  }
}

void ExecutionMonitorNode::onRecordAck(const msg::RecordAck& m) {
  try {
    if (!msgv::accept(m, dds::topics::kRecordAcks.name, rejects_)) return;
    std::lock_guard lock(records_mu_);
    if (!outbox_.acknowledge(m.record_id())) return;  // a repeat, or not ours
    if (!m.stored()) {
      logger()->warn("execution record '{}' refused by '{}' for good; not sent again", m.record_id(),
                     m.estimator());
    }
  } catch (const std::exception& e) {
    logger()->error("acknowledgement of '{}': {}", m.record_id(), e.what());
  }
}

void ExecutionMonitorNode::sendDueRecords(double resend_period_s) {
  std::lock_guard lock(records_mu_);
  for (const auto& e : outbox_.due(now(), resend_period_s)) {
    auto record = dds::fromCdr<msg::ExecutionRecord>(e.payload);
    if (!record) {
      logger()->error("execution record '{}' in the outbox cannot be read back; dropped", e.record_id);
      (void)outbox_.acknowledge(e.record_id);
      continue;
    }
    if (e.sends > 1) logger()->info("execution record '{}' sent again (send {})", e.record_id, e.sends);
    if (Status s = record_writer_->write(*record); !s) {
      logger()->error("execution record '{}' not forwarded: {}", e.record_id, s.error().toString());
    }
  }
}

void ExecutionMonitorNode::onStop() {
  auto pending = [this] {
    std::lock_guard lock(records_mu_);
    return outbox_.pending();
  };
  if (pending() == 0) return;
  const double until = now() + kStopDrainS;
  while (pending() > 0 && now() < until) {
    sendDueRecords(kStopResendPeriodS);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (const std::size_t left = pending(); left > 0)
    logger()->warn("stopping with {} execution record(s) not acknowledged within {:.1f} s; kept in {} and sent again "
                   "when a monitor starts on it",
                   left, kStopDrainS, outbox_.path().string());
  else
    logger()->info("every execution record acknowledged before the stop");
}

void ExecutionMonitorNode::spinOnce() {
  try {
    sendDueRecords(kRecordResendPeriodS);
  } catch (const std::exception& e) {
    logger()->error("records: {}", e.what());
  }
  try {
    std::lock_guard lock(mutex_);
    flushRobotRequests();
    if (world_dirty_.exchange(false)) {
      const world::World w = mirror_->snapshot();
      const std::uint64_t v = mirror_->publishedVersion();
      publish(monitor_->onWorld(w, v, now()));
    }
    publish(monitor_->onTick(now()));
  } catch (const std::exception& e) {
    logger()->error("spin: {}", e.what());
  }
}

}  // namespace tamp::execution_monitor
