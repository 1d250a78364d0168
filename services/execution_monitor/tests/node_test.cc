// The execution monitor over real DDS: the simulator (tamp_sim_service on the NAMO corridor) and
// the monitor (tamp_execution_monitor_service) as processes on an isolated domain; the test
// process publishes the world model (the scenario's planner world, as perception would) and the
// graph manager's ExecuteCommands, and reads what the services publish.
//
//  - a straight, collision-free move_base ends SUCCEEDED with the robot's measured duration and
//    exactly one forwarded ExecutionRecord carrying the prediction and the command id; the same
//    command id sent again is answered, not executed (one robot result, one record);
//  - a command whose start is not the robot's, and malformed ones, fail naming what is wrong and
//    never reach the robot;
//  - an object appearing on the remaining path mid-action (injected into the simulator, reported
//    by the world model) stops the robot: BLOCKED with the object's id, FAILURE_NEW_OBSTACLE;
//  - the carried object dropped during a move (an injected fault): FAILED, FAILURE_OBJECT_DROPPED;
//  - an overrun beyond the prediction and its margin: cancelled, FAILED, FAILURE_TIMEOUT.
#include <cmath>
#include <condition_variable>
#include <fstream>
#include <functional>
#include <csignal>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

#include "../../../tests/integration/integration_util.h"
#include "execution_monitor_node.h"
#include "tamp/core/paths.h"
#include "tamp/dds/convert.h"
#include "tamp/dds/topics.h"
#include "tamp/dds/world_sync.h"
#include "tamp/world/scenario.h"

namespace tamp::execution_monitor {
namespace {

using integration::readFile;
using integration::serviceSpec;
using integration::tempFile;

/// Samples from a reader callback, with bounded waits for a match or a count of matches.
template <typename T>
class Log {
 public:
  void push(const T& v) {
    std::lock_guard l(m_);
    items_.push_back(v);
    cv_.notify_all();
  }
  std::optional<T> waitFor(const std::function<bool(const T&)>& pred, double seconds = 30.0) {
    std::unique_lock l(m_);
    std::optional<T> found;
    cv_.wait_for(l, std::chrono::duration<double>(seconds), [&] {
      for (const auto& x : items_) {
        if (pred(x)) {
          found = x;
          return true;
        }
      }
      return false;
    });
    return found;
  }
  /// Waits until `n` samples match; returns how many match then (or at the timeout).
  std::size_t waitCount(const std::function<bool(const T&)>& pred, std::size_t n,
                        double seconds = 30.0) {
    std::unique_lock l(m_);
    std::size_t count = 0;
    cv_.wait_for(l, std::chrono::duration<double>(seconds), [&] {
      count = static_cast<std::size_t>(std::count_if(items_.begin(), items_.end(), pred));
      return count >= n;
    });
    return count;
  }
  std::size_t count(const std::function<bool(const T&)>& pred) {
    std::lock_guard l(m_);
    return static_cast<std::size_t>(std::count_if(items_.begin(), items_.end(), pred));
  }
  std::optional<T> last() {
    std::lock_guard l(m_);
    if (items_.empty()) return std::nullopt;
    return items_.back();
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  std::vector<T> items_;
};

bool isFinal(msg::ExecState s) {
  return s == msg::ExecState::EXEC_SUCCEEDED || s == msg::ExecState::EXEC_FAILED ||
         s == msg::ExecState::EXEC_BLOCKED || s == msg::ExecState::EXEC_CANCELLED;
}

class MonitorNodeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_ = integration::isolatedDomain();
    const std::string scenario = (configDir() / "scenarios" / scenario_name_).string();
    sim_config_ = tempFile("tamp_em_sim.yaml");
    {
      std::ofstream out(sim_config_);  // no periodic clouds and a tiny camera: nobody reads them
      out << "cloud_period_s: 0\nsensor: {width: 16, height: 12}\n";
    }
    monitor_config_ = tempFile("tamp_em_monitor.yaml");
    {
      std::ofstream out(monitor_config_);
      out << monitor_yaml_;
    }
    sup_.add(serviceSpec("tamp_sim_service", "sim", domain_,
                         {"--config", sim_config_.string(), "--scenario", scenario}));
    auto monitor = serviceSpec("tamp_execution_monitor_service", "execution_monitor", domain_,
                               {"--config", monitor_config_.string(), "--scenario", scenario});
    if (!run_dir_.empty()) {  // the monitor's journal there; restarted when killed
      std::filesystem::remove_all(run_dir_);
      std::filesystem::create_directories(run_dir_);
      monitor.env["TAMP_RUN_DIR"] = run_dir_.string();
      monitor.restart = true;
      monitor.restart_backoff_s = 0.2;
    }
    sup_.add(std::move(monitor));
    ASSERT_TRUE(sup_.startAll().ok());
    auto p = dds::Participant::create(
        {domain_, dds::kProfileDefault, "tamp/execution_monitor_test", {}});
    ASSERT_TRUE(p) << p.error().toString();
    participant_ = *p;
    auto sc = world::loadScenario(scenario);
    ASSERT_TRUE(sc) << sc.error().toString();
    world_ = sc->plannerWorld();

    statuses_ = std::make_unique<dds::Reader<msg::ExecuteStatus>>(
        participant_, dds::topics::kExecuteStatus,
        [this](const msg::ExecuteStatus& m, const dds::SampleMeta&) { status_log_.push(m); });
    failures_ = std::make_unique<dds::Reader<msg::FailureEvent>>(
        participant_, dds::topics::kFailureEvents,
        [this](const msg::FailureEvent& m, const dds::SampleMeta&) { failure_log_.push(m); });
    results_ = std::make_unique<dds::Reader<msg::ActionResult>>(
        participant_, dds::topics::kActionResult,
        [this](const msg::ActionResult& m, const dds::SampleMeta&) { result_log_.push(m); });
    states_ = std::make_unique<dds::Reader<msg::RobotState>>(
        participant_, dds::topics::kRobotState,
        [this](const msg::RobotState& m, const dds::SampleMeta&) { state_log_.push(m); });
    // The test is the effort estimator too: it acknowledges each record (the monitor sends a
    // record again until then).
    acks_ = std::make_unique<dds::Writer<msg::RecordAck>>(participant_, dds::topics::kRecordAcks);
    records_ = std::make_unique<dds::Reader<msg::ExecutionRecord>>(
        participant_, dds::topics::kExecutionRecords,
        [this](const msg::ExecutionRecord& m, const dds::SampleMeta&) {
          record_log_.push(m);
          msg::RecordAck ack;
          ack.record_id(m.record_id());
          ack.estimator("test");
          ack.stored(true);
          (void)acks_->write(ack);
        });
    robot_records_ = std::make_unique<dds::Reader<msg::ExecutionRecord>>(
        participant_, dds::topics::kRobotRecords,
        [this](const msg::ExecutionRecord& m, const dds::SampleMeta&) {
          robot_record_log_.push(m);
        });
    publisher_ = std::make_unique<dds::WorldPublisher>(participant_);
    ASSERT_TRUE(publisher_->publish(world_));
    commands_ = std::make_unique<dds::Writer<msg::ExecuteCommand>>(participant_,
                                                                   dds::topics::kExecuteCommand);
    faults_ = std::make_unique<dds::Writer<msg::FaultInjection>>(participant_,
                                                                 dds::topics::kFaultInjection);

    // Both services up: the simulator streams its state, the monitor reads commands and its
    // status writer has matched us.
    ASSERT_TRUE(state_log_.waitFor([](const msg::RobotState&) { return true; }))
        << "no robot state";
    ASSERT_TRUE(commands_->waitForReaders(Termination::after(30.0)))
        << "the monitor reads no commands";
    ASSERT_TRUE(statuses_->waitForWriters(Termination::after(30.0)))
        << "the monitor publishes no status";
    ASSERT_TRUE(faults_->waitForReaders(Termination::after(30.0)));
    ASSERT_TRUE(acks_->waitForReaders(Termination::after(30.0))) << "the monitor reads no acknowledgements";
  }

  void TearDown() override {
    statuses_.reset();
    failures_.reset();
    results_.reset();
    states_.reset();
    records_.reset();
    robot_records_.reset();
    sup_.poll();
    for (const auto& st : sup_.status()) {
      if (st.phase != process::ProcessPhase::kRunning || HasFailure()) {
        ADD_FAILURE() << st.name << " (" << st.last_exit << "):\n"
                      << readFile(tempFile("tamp_it_" + st.name + ".log"));
      }
    }
    sup_.stopAll(5.0);
    for (const auto& st : sup_.status()) {
      EXPECT_TRUE(st.last_exit == "exit 0" || st.last_exit.rfind("signal 15", 0) == 0)
          << st.name << " ended with " << st.last_exit;
    }
    std::filesystem::remove(sim_config_);
    std::filesystem::remove(monitor_config_);
  }

  Pose2D robotBase() {
    auto s = state_log_.last();
    EXPECT_TRUE(s);
    return s ? Pose2D{s->base().x(), s->base().y(), s->base().theta()} : Pose2D{};
  }

  /// A straight move_base from `from` by `distance` m along its heading (1 s per metre).
  msg::ExecuteCommand moveBase(const std::string& id, const Pose2D& from, double distance,
                               double turn = 0.0) {
    Trajectory t;
    t.joint_names = {"base_x", "base_y", "base_theta"};
    t.points.push_back({0.0, {from.x, from.y, from.theta}, {}});
    t.points.push_back({std::max(1.0, distance),
                        {from.x + distance * std::cos(from.theta),
                         from.y + distance * std::sin(from.theta), from.theta + turn},
                        {}});
    msg::ExecuteCommand c;
    c.command_id(id);
    c.mission_id("it_mission");
    c.edge_id("e_" + id);
    c.pddl_action("(move-base start somewhere)");
    c.kind(msg::ActionKind::ACTION_MOVE_BASE);
    c.trajectory(dds::toMsg(t));
    c.expected_duration_s(4.0);
    c.expected_stddev_s(0.4);
    c.world_version(publisher_->publishedVersion());
    return c;
  }

  std::optional<msg::ExecuteStatus> finalOf(const std::string& id, double seconds = 60.0) {
    return status_log_.waitFor(
        [&](const msg::ExecuteStatus& s) { return s.command_id() == id && isFinal(s.state()); },
        seconds);
  }

  /// Sends a turn on the spot and waits for its end: everything the robot did for earlier
  /// commands has been published by then (one writer per topic, in order).
  void barrier(const std::string& id) {
    ASSERT_TRUE(commands_->write(moveBase(id, robotBase(), 0.0, 0.3)));
    auto done = finalOf(id);
    ASSERT_TRUE(done) << "no final status of the barrier";
    ASSERT_EQ(done->state(), msg::ExecState::EXEC_SUCCEEDED) << done->reason();
    ASSERT_TRUE(robot_record_log_.waitFor(
        [&](const msg::ExecutionRecord& r) { return r.record_id() == id; }));
    ASSERT_TRUE(
        record_log_.waitFor([&](const msg::ExecutionRecord& r) { return r.record_id() == id; }));
  }

  std::filesystem::path run_dir_;  // non-empty: the monitor keeps its journal there
  std::string scenario_name_{"namo_corridor.yaml"};
  std::string monitor_yaml_{
      "input_wait_s: 15\n"};  // discovery on a loaded machine may take a while
  int domain_{0};
  std::filesystem::path sim_config_, monitor_config_;
  process::Supervisor sup_;
  std::shared_ptr<dds::Participant> participant_;
  world::World world_;
  Log<msg::ExecuteStatus> status_log_;
  Log<msg::FailureEvent> failure_log_;
  Log<msg::ActionResult> result_log_;
  Log<msg::RobotState> state_log_;
  Log<msg::ExecutionRecord> record_log_, robot_record_log_;
  std::unique_ptr<dds::Reader<msg::ExecuteStatus>> statuses_;
  std::unique_ptr<dds::Reader<msg::FailureEvent>> failures_;
  std::unique_ptr<dds::Reader<msg::ActionResult>> results_;
  std::unique_ptr<dds::Reader<msg::RobotState>> states_;
  std::unique_ptr<dds::Writer<msg::RecordAck>> acks_;
  std::unique_ptr<dds::Reader<msg::ExecutionRecord>> records_, robot_records_;
  std::unique_ptr<dds::WorldPublisher> publisher_;
  std::unique_ptr<dds::Writer<msg::ExecuteCommand>> commands_;
  std::unique_ptr<dds::Writer<msg::FaultInjection>> faults_;
};

TEST_F(MonitorNodeTest, ValidMoveSucceedsOnceAndItsRecordIsForwardedOnce) {
  const Pose2D start = robotBase();
  const msg::ExecuteCommand go = moveBase("em_go", start, 0.8);
  ASSERT_TRUE(commands_->write(go));
  auto done = finalOf("em_go");
  ASSERT_TRUE(done) << "no final status";
  EXPECT_EQ(done->state(), msg::ExecState::EXEC_SUCCEEDED) << done->reason();
  EXPECT_GT(done->measured_duration_s(), 0.0);
  EXPECT_EQ(done->held_object_id(), "");
  EXPECT_DOUBLE_EQ(done->progress(), 1.0);
  EXPECT_TRUE(status_log_.waitFor([](const msg::ExecuteStatus& s) {
    return s.command_id() == "em_go" && s.state() == msg::ExecState::EXEC_RUNNING;
  }));
  auto result =
      result_log_.waitFor([](const msg::ActionResult& r) { return r.command_id() == "em_go"; });
  ASSERT_TRUE(result);
  EXPECT_DOUBLE_EQ(done->measured_duration_s(), result->duration_s());
  auto record =
      record_log_.waitFor([](const msg::ExecutionRecord& r) { return r.command_id() == "em_go"; });
  ASSERT_TRUE(record) << "no forwarded execution record";
  EXPECT_EQ(record->record_id(), "em_go");
  EXPECT_EQ(record->mission_id(), "it_mission");
  EXPECT_DOUBLE_EQ(record->predicted_s(), 4.0);
  EXPECT_DOUBLE_EQ(record->predicted_stddev_s(), 0.4);
  EXPECT_DOUBLE_EQ(record->duration_s(), result->duration_s());
  EXPECT_TRUE(record->success());
  EXPECT_EQ(record->source(), "sim");
  const Pose2D after = robotBase();
  EXPECT_NEAR(after.x, start.x + 0.8, 0.05);

  // The same command again: answered with its final status, not executed.
  ASSERT_TRUE(commands_->write(go));
  EXPECT_EQ(status_log_.waitCount(
                [](const msg::ExecuteStatus& s) {
                  return s.command_id() == "em_go" && isFinal(s.state());
                },
                2),
            2u);
  barrier("em_barrier");
  EXPECT_EQ(result_log_.count([](const msg::ActionResult& r) { return r.command_id() == "em_go"; }),
            1u);
  EXPECT_EQ(robot_record_log_.count(
                [](const msg::ExecutionRecord& r) { return r.record_id() == "em_go"; }),
            1u);
  EXPECT_EQ(
      record_log_.count([](const msg::ExecutionRecord& r) { return r.record_id() == "em_go"; }),
      1u);
  EXPECT_EQ(status_log_.count([](const msg::ExecuteStatus& s) {
    return s.command_id() == "em_go" && s.state() == msg::ExecState::EXEC_FAILED;
  }),
            0u);
}

TEST_F(MonitorNodeTest, MismatchedStartAndMalformedCommandsFailNamingTheField) {
  Pose2D elsewhere = robotBase();
  elsewhere.x += 1.0;
  ASSERT_TRUE(commands_->write(moveBase("em_far", elsewhere, 0.5)));
  auto far = finalOf("em_far");
  ASSERT_TRUE(far);
  EXPECT_EQ(far->state(), msg::ExecState::EXEC_FAILED);
  EXPECT_EQ(far->reason().rfind("start:", 0), 0u) << far->reason();
  EXPECT_NE(far->reason().find("base_x"), std::string::npos) << far->reason();
  auto event =
      failure_log_.waitFor([](const msg::FailureEvent& e) { return e.command_id() == "em_far"; });
  ASSERT_TRUE(event);
  EXPECT_EQ(event->type(), msg::FailureType::FAILURE_PRECONDITION);
  EXPECT_EQ(event->description(), far->reason());

  msg::ExecuteCommand unknown = moveBase("em_unknown_joint", robotBase(), 0.5);
  unknown.trajectory().joint_names()[1] = "base_q";
  msg::ExecuteCommand nan = moveBase("em_nan", robotBase(), 0.5);
  nan.trajectory().positions()[4] = std::nan("");
  msg::ExecuteCommand empty = moveBase("em_empty", robotBase(), 0.5);
  empty.trajectory().times().clear();
  empty.trajectory().positions().clear();
  for (const auto* c : {&unknown, &nan, &empty}) ASSERT_TRUE(commands_->write(*c));
  const std::pair<const char*, const char*> expected[] = {
      {"em_unknown_joint", "trajectory.joint_names[1]"},
      {"em_nan", "trajectory.positions"},
      {"em_empty", "trajectory"}};
  for (const auto& [id, field] : expected) {
    auto f = finalOf(id);
    ASSERT_TRUE(f) << id;
    EXPECT_EQ(f->state(), msg::ExecState::EXEC_FAILED) << id;
    EXPECT_NE(f->reason().find(field), std::string::npos) << id << ": " << f->reason();
  }
  barrier("em_barrier");
  for (const char* id : {"em_far", "em_unknown_joint", "em_nan", "em_empty"}) {
    EXPECT_EQ(result_log_.count([&](const msg::ActionResult& r) { return r.command_id() == id; }),
              0u)
        << id << " reached the robot";
  }
}

TEST_F(MonitorNodeTest, ObjectAppearingOnTheRemainingPathBlocksWithItsId) {
  const Pose2D start = robotBase();
  ASSERT_TRUE(commands_->write(moveBase("em_blocked", start, 1.8)));
  ASSERT_TRUE(status_log_.waitFor([](const msg::ExecuteStatus& s) {
    return s.command_id() == "em_blocked" && s.state() == msg::ExecState::EXEC_RUNNING;
  })) << "not started";
  // Mid-action: once the robot has driven 0.2 m, a crate appears 1.6 m ahead of the start, in the
  // simulator's world and in the world model (the simulator would stop before it at ~1.1 m).
  ASSERT_TRUE(state_log_.waitFor([&](const msg::RobotState& s) {
    return std::hypot(s.base().x() - start.x, s.base().y() - start.y) > 0.2;
  })) << "the robot does not move";
  const double d = 1.6;
  const double x = start.x + d * std::cos(start.theta), y = start.y + d * std::sin(start.theta);
  msg::FaultInjection spawn;
  spawn.fault_id("em_spawn");
  spawn.type(msg::FaultType::FAULT_SPAWN_OBJECT);
  spawn.object_id("em_crate");
  spawn.reason("crate");
  spawn.shape().type(msg::ShapeType::SHAPE_BOX);
  spawn.shape().dimensions({0.4, 0.4, 0.4});
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(x, y, 0.2);
  spawn.pose(dds::toMsg(pose));
  ASSERT_TRUE(faults_->write(spawn));
  world::Object crate;
  crate.id = "em_crate";
  crate.label = "crate";
  crate.kind = world::ObjectKind::kStatic;
  crate.shape = world::Shape::box(0.4, 0.4, 0.4);
  crate.pose = pose;
  ASSERT_TRUE(world_.addObject(crate));
  ASSERT_TRUE(publisher_->publish(world_));

  auto done = finalOf("em_blocked");
  ASSERT_TRUE(done);
  EXPECT_EQ(done->state(), msg::ExecState::EXEC_BLOCKED) << done->reason();
  EXPECT_EQ(done->blocking_object_id(), "em_crate");
  EXPECT_GT(done->measured_duration_s(), 0.0);
  auto event = failure_log_.waitFor(
      [](const msg::FailureEvent& e) { return e.command_id() == "em_blocked"; });
  ASSERT_TRUE(event);
  EXPECT_EQ(event->type(), msg::FailureType::FAILURE_NEW_OBSTACLE) << event->description();
  EXPECT_EQ(event->object_id(), "em_crate");
  // The monitor stopped the robot (a cancel), before it reached the crate.
  auto result = result_log_.waitFor(
      [](const msg::ActionResult& r) { return r.command_id() == "em_blocked"; });
  ASSERT_TRUE(result);
  EXPECT_EQ(result->outcome(), msg::ActionOutcome::OUTCOME_CANCELLED) << result->reason();
  EXPECT_LT(robotBase().x, x - 0.2 - 0.3);
}

/// The robot starts with a cup in the gripper (holding_start).
class RestartedMonitorNodeTest : public MonitorNodeTest {
 protected:
  RestartedMonitorNodeTest() { run_dir_ = tempFile("tamp_em_run"); }
  ~RestartedMonitorNodeTest() override { std::filesystem::remove_all(run_dir_); }
};

// kill -9 of the monitor while the robot executes a command; the supervisor restarts it and the
// command comes again: the robot executed it once (one raw record, ended where one move ends),
// and the restarted monitor reports the robot's outcome.
TEST_F(RestartedMonitorNodeTest, ACommandInFlightWhenTheMonitorIsKilledIsNotExecutedTwice) {
  const Pose2D start = robotBase();
  const msg::ExecuteCommand go = moveBase("em_long", start, 2.5);
  ASSERT_TRUE(commands_->write(go));
  ASSERT_TRUE(state_log_.waitFor([&](const msg::RobotState& st) {
    return st.moving() && st.base().x() > start.x + 0.2;
  })) << "the robot did not start moving";
  const int pid_before = sup_.status("execution_monitor")->pid;
  ASSERT_TRUE(sup_.signal("execution_monitor", SIGKILL));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  for (;;) {
    sup_.poll();
    const auto st = sup_.status("execution_monitor");
    if (st && st->restarts >= 1 && st->phase == process::ProcessPhase::kRunning &&
        st->pid != pid_before) {
      break;
    }
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the monitor was not restarted";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // polling the supervisor
  }
  // The graph manager's resend of the command in flight, repeated until the restarted monitor
  // answers (the killed reader stays matched until its lease ends: a write may go to it alone).
  auto fromRestarted = [](const msg::ExecuteStatus& s) {
    // Joined (the robot still runs it) or answered from the robot's result (it ended already).
    return s.command_id() == "em_long" &&
           (s.reason().find("not executed again") != std::string::npos ||
            s.reason().find("executed before") != std::string::npos);
  };
  bool answered = false;
  for (int i = 0; i < 30 && !answered; ++i) {
    ASSERT_TRUE(commands_->write(go));
    answered = status_log_.waitFor(fromRestarted, 1.0).has_value();
  }
  ASSERT_TRUE(answered) << "the restarted monitor never answered the resent command";
  auto done = status_log_.waitFor(
      [&](const msg::ExecuteStatus& s) { return fromRestarted(s) && isFinal(s.state()); },
      60.0);
  ASSERT_TRUE(done) << "no final status from the restarted monitor";
  EXPECT_EQ(done->state(), msg::ExecState::EXEC_SUCCEEDED) << done->reason();
  barrier("em_after_restart");
  EXPECT_EQ(robot_record_log_.count(
                [](const msg::ExecutionRecord& r) { return r.record_id() == "em_long"; }),
            1u);
  EXPECT_NEAR(robotBase().x, start.x + 2.5 * std::cos(start.theta), 0.05);
  EXPECT_NE(readFile(run_dir_ / "execution_monitor.sent").find("em_long\n"), std::string::npos);
}

class HoldingMonitorNodeTest : public MonitorNodeTest {
 protected:
  HoldingMonitorNodeTest() { scenario_name_ = "holding_start.yaml"; }
};

TEST_F(HoldingMonitorNodeTest, DroppingTheCarriedObjectFailsTheMove) {
  ASSERT_TRUE(
      state_log_.waitFor([](const msg::RobotState& s) { return s.held_object_id() == "cup"; }));
  const Pose2D start = robotBase();
  ASSERT_TRUE(commands_->write(moveBase("em_carry", start, 1.2)));
  ASSERT_TRUE(state_log_.waitFor([&](const msg::RobotState& s) {
    return std::hypot(s.base().x() - start.x, s.base().y() - start.y) > 0.2;
  })) << "the robot does not move";
  msg::FaultInjection drop;
  drop.fault_id("em_drop");
  drop.type(msg::FaultType::FAULT_DROP_HELD_OBJECT);
  drop.reason("slipped");
  ASSERT_TRUE(faults_->write(drop));
  auto done = finalOf("em_carry");
  ASSERT_TRUE(done);
  EXPECT_EQ(done->state(), msg::ExecState::EXEC_FAILED) << done->reason();
  EXPECT_EQ(done->reason().rfind("object dropped:", 0), 0u) << done->reason();
  EXPECT_EQ(done->held_object_id(), "");
  EXPECT_GT(done->measured_duration_s(), 0.0);
  auto event =
      failure_log_.waitFor([](const msg::FailureEvent& e) { return e.command_id() == "em_carry"; });
  ASSERT_TRUE(event);
  EXPECT_EQ(event->type(), msg::FailureType::FAILURE_OBJECT_DROPPED) << event->description();
  EXPECT_EQ(event->object_id(), "cup");
}

/// A monitor that allows no more than the predicted duration + 0.5 s, moving or not.
class TightTimeoutMonitorNodeTest : public MonitorNodeTest {
 protected:
  TightTimeoutMonitorNodeTest() {
    monitor_yaml_ = "input_wait_s: 15\ntimeout: {stddevs: 0, margin_s: 0.5, max_factor: 1}\n";
  }
};

TEST_F(TightTimeoutMonitorNodeTest, AnOverrunIsCancelledAsATimeout) {
  msg::ExecuteCommand c = moveBase("em_slow", robotBase(), 1.5);
  c.expected_duration_s(0.5);  // the robot needs several seconds
  c.expected_stddev_s(0.0);
  ASSERT_TRUE(commands_->write(c));
  auto done = finalOf("em_slow");
  ASSERT_TRUE(done);
  EXPECT_EQ(done->state(), msg::ExecState::EXEC_FAILED) << done->reason();
  EXPECT_EQ(done->reason().rfind("timeout:", 0), 0u) << done->reason();
  auto event =
      failure_log_.waitFor([](const msg::FailureEvent& e) { return e.command_id() == "em_slow"; });
  ASSERT_TRUE(event);
  EXPECT_EQ(event->type(), msg::FailureType::FAILURE_TIMEOUT);
  auto result =
      result_log_.waitFor([](const msg::ActionResult& r) { return r.command_id() == "em_slow"; });
  ASSERT_TRUE(result);
  EXPECT_EQ(result->outcome(), msg::ActionOutcome::OUTCOME_CANCELLED) << result->reason();
  EXPECT_NEAR(done->measured_duration_s(), result->duration_s(), 1e-9);
}

TEST(MonitorConversionsTest, MalformedMessagesNameTheField) {
  robot::RobotModel robot = [] {
    auto r = robot::RobotModel::loadDefault();
    EXPECT_TRUE(r);
    return std::move(r).value();
  }();
  msg::ExecuteCommand c;
  c.command_id("c");
  c.kind(static_cast<msg::ActionKind>(9));
  auto bad_kind = fromMsg(c);
  ASSERT_FALSE(bad_kind);
  EXPECT_EQ(bad_kind.error().where.field, "kind");
  c.kind(msg::ActionKind::ACTION_PLACE);
  c.object_target_given(true);  // a zero quaternion
  auto bad_target = fromMsg(c);
  ASSERT_FALSE(bad_target);
  EXPECT_EQ(bad_target.error().where.field.rfind("object_target", 0), 0u)
      << bad_target.error().toString();
  c.object_target().orientation().w(1.0);
  c.expected_duration_s(3.0);
  c.world_version(7);
  auto ok = fromMsg(c);
  ASSERT_TRUE(ok) << ok.error().toString();
  EXPECT_TRUE(ok->object_target.has_value());
  EXPECT_EQ(ok->world_version, 7u);
  EXPECT_DOUBLE_EQ(ok->expected_duration_s, 3.0);
  c.object_target_given(false);
  EXPECT_FALSE(fromMsg(c)->object_target.has_value());

  msg::RobotState st;
  st.joint_names({"base_x", "base_y"});
  st.joint_positions({1.0});
  auto bad_state = fromMsg(st, robot, 5);
  ASSERT_FALSE(bad_state);
  EXPECT_EQ(bad_state.error().where.field, "joint_positions");
  st.joint_names(robot.fullJointNames());
  st.joint_positions(robot.toJointValues(robot.defaultState(Pose2D{1.0, 2.0, 0.5})));
  st.held_object_id("cup");
  auto good_state = fromMsg(st, robot, 5);
  ASSERT_TRUE(good_state) << good_state.error().toString();
  EXPECT_DOUBLE_EQ(good_state->state.base.y, 2.0);
  EXPECT_EQ(good_state->held_object_id, "cup");
  EXPECT_EQ(good_state->stamp_ns, 5);

  msg::ActionResult res;
  res.outcome(static_cast<msg::ActionOutcome>(9));
  EXPECT_FALSE(fromMsg(res, 0));

  RobotRequest cancel;
  cancel.type = RobotRequest::Type::kCancel;
  cancel.command.command_id = "c";
  const msg::TrajectoryCommand tc = toMsg(cancel);
  EXPECT_TRUE(tc.cancel());
  EXPECT_EQ(tc.command_id(), "c");
  StatusUpdate su;
  su.command_id = "c";
  su.state = ExecState::kBlocked;
  su.blocking_object_id = "crate";
  su.measured_duration_s = 1.5;
  su.held_object_id = "cup";
  su.stopped_at_contact = true;
  const msg::ExecuteStatus es = toMsg(su);
  EXPECT_TRUE(es.stopped_at_contact());
  EXPECT_EQ(es.state(), msg::ExecState::EXEC_BLOCKED);
  EXPECT_EQ(es.blocking_object_id(), "crate");
  EXPECT_DOUBLE_EQ(es.measured_duration_s(), 1.5);
  EXPECT_EQ(es.held_object_id(), "cup");
}

}  // namespace
}  // namespace tamp::execution_monitor
