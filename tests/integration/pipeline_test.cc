// The services of the robot side as real processes on their own DDS domain: the simulator
// (ground truth of a shipped scenario, depth camera), perception (world model from the clouds),
// the execution monitor (validates and executes commands on the simulator against perception's
// world model, forwards the simulator's records with the prediction) and the effort estimator
// (learns from the forwarded execution records). The test process is the only other
// participant: it reads what the services publish, injects a fault and sends the command a
// graph manager would.
//
//  1. perception publishes a world model with every object of the scenario's planner view;
//  2. an obstacle injected into the simulator's world in front of the robot (fault injection over
//     DDS) is seen by the camera and reported by perception as a new object at its place;
//  3. a move_base ExecuteCommand, validated by the monitor against perception's world model (the
//     new obstacle included) and executed by the simulator, ends SUCCEEDED; the simulator's record
//     reaches the effort estimator through the monitor with the prediction and the command id,
//     and the estimator fits it: its next model snapshot counts the record.
#include <cmath>

#include <gtest/gtest.h>

#include "integration_util.h"
#include "tamp/core/paths.h"
#include "tamp/dds/convert.h"
#include "tamp/dds/participant.h"
#include "tamp/dds/topics.h"
#include "tamp/dds/world_sync.h"
#include "tamp/world/scenario.h"

namespace tamp::integration {
namespace {

using dds::testing::Inbox;

class PipelineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_ = isolatedDomain();  // per process: concurrent test processes have distinct pids
    scenario_file_ = configDir() / "scenarios" / "namo_corridor.yaml";
    store_dir_ = tempFile("tamp_it_effort_store");
    std::filesystem::remove_all(store_dir_);
    effort_config_ = tempFile("tamp_it_effort.yaml");
    {
      std::ofstream out(effort_config_);
      out << "store_directory: " << store_dir_.string() << "\nrefit_batch_size: 1\nrefit_period_s: 0.5\n";
    }
    const std::string scenario = scenario_file_.string();
    sup_.add(serviceSpec("tamp_sim_service", "sim", domain_,
                         {"--config", (configDir() / "services" / "sim.yaml").string(), "--scenario", scenario}));
    sup_.add(serviceSpec("tamp_perception_service", "perception", domain_,
                         {"--config", (configDir() / "services" / "perception.yaml").string(), "--scenario", scenario}));
    sup_.add(serviceSpec("tamp_effort_estimator_service", "effort_estimator", domain_,
                         {"--config", effort_config_.string()}));
    sup_.add(serviceSpec("tamp_execution_monitor_service", "execution_monitor", domain_,
                         {"--config", (configDir() / "services" / "execution_monitor.yaml").string(), "--scenario",
                          scenario}));
    ASSERT_TRUE(sup_.startAll().ok());
    auto p = dds::Participant::create({domain_, dds::kProfileDefault, "tamp/pipeline_test", {}});
    ASSERT_TRUE(p) << p.error().toString();
    participant_ = *p;
  }

  void TearDown() override {
    sup_.poll();
    for (const auto& st : sup_.status()) {
      if (st.phase != process::ProcessPhase::kRunning || HasFailure()) {
        ADD_FAILURE() << st.name << " (" << st.last_exit << "):\n" << readFile(tempFile("tamp_it_" + st.name + ".log"));
      }
    }
    sup_.stopAll(5.0);
    for (const auto& st : sup_.status()) {
      EXPECT_TRUE(st.last_exit == "exit 0" || st.last_exit.rfind("signal 15", 0) == 0)
          << st.name << " ended with " << st.last_exit;
    }
    std::filesystem::remove_all(store_dir_);
    std::filesystem::remove(effort_config_);
  }

  int domain_{0};
  std::filesystem::path scenario_file_, store_dir_, effort_config_;
  process::Supervisor sup_;
  std::shared_ptr<dds::Participant> participant_;
};

const world::Object* objectNear(const world::World& w, const Eigen::Vector2d& xy, double tolerance) {
  for (const auto& o : w.objects()) {
    if ((o.pose.translation().head<2>() - xy).norm() < tolerance) return &o;
  }
  return nullptr;
}

TEST_F(PipelineTest, PerceptionSeesAnInjectedObstacleAndTheEstimatorLearnsFromExecution) {
  auto scenario = world::loadScenario(scenario_file_);
  ASSERT_TRUE(scenario) << scenario.error().toString();
  const world::World prior = scenario->plannerWorld();

  Inbox<msg::RobotState> states;
  Inbox<msg::WorldEvent> events;
  Inbox<msg::ActionResult> results;
  Inbox<msg::EffortModelSnapshot> snapshots;
  Inbox<msg::ExecuteStatus> statuses;
  Inbox<msg::ExecutionRecord> records;
  dds::Reader<msg::RobotState> state_reader(participant_, dds::topics::kRobotState,
                                            [&](const msg::RobotState& m, const dds::SampleMeta&) { states.push(m); });
  dds::Reader<msg::WorldEvent> event_reader(participant_, dds::topics::kWorldEvents,
                                            [&](const msg::WorldEvent& m, const dds::SampleMeta&) { events.push(m); });
  dds::Reader<msg::ActionResult> result_reader(
      participant_, dds::topics::kActionResult, [&](const msg::ActionResult& m, const dds::SampleMeta&) { results.push(m); });
  dds::Reader<msg::EffortModelSnapshot> snapshot_reader(
      participant_, dds::topics::kEffortModel,
      [&](const msg::EffortModelSnapshot& m, const dds::SampleMeta&) { snapshots.push(m); });
  dds::Reader<msg::ExecuteStatus> status_reader(
      participant_, dds::topics::kExecuteStatus, [&](const msg::ExecuteStatus& m, const dds::SampleMeta&) { statuses.push(m); });
  dds::Reader<msg::ExecutionRecord> record_reader(
      participant_, dds::topics::kExecutionRecords,
      [&](const msg::ExecutionRecord& m, const dds::SampleMeta&) { records.push(m); });
  dds::WorldMirror mirror(participant_);
  dds::Writer<msg::FaultInjection> faults(participant_, dds::topics::kFaultInjection);
  dds::Writer<msg::ExecuteCommand> commands(participant_, dds::topics::kExecuteCommand);

  // 1. The robot is where the scenario starts it; perception's world holds the planner view.
  auto start = states.waitFor([](const msg::RobotState&) { return true; }, 30.0);
  ASSERT_TRUE(start) << "no robot state from the simulator";
  const world::Location* start_location = prior.findLocation("start");
  ASSERT_NE(start_location, nullptr);
  EXPECT_NEAR(start->base().x(), start_location->pose.x, 1e-6);
  EXPECT_NEAR(start->base().y(), start_location->pose.y, 1e-6);
  ASSERT_TRUE(mirror.waitForPublishedVersion(1, Termination::after(30.0))) << "no world model from perception";
  {
    const world::World seen = mirror.snapshot();
    for (const auto& o : prior.objects()) EXPECT_NE(seen.findObject(o.id), nullptr) << "missing " << o.id;
  }

  // 2. An obstacle appears 1.5 m in front of the robot (a fault injected into the simulator).
  const double yaw = start->base().theta();
  const Eigen::Vector2d where(start->base().x() + 1.5 * std::cos(yaw), start->base().y() + 1.5 * std::sin(yaw));
  ASSERT_EQ(objectNear(mirror.snapshot(), where, 0.5), nullptr) << "the test needs free floor there";
  ASSERT_TRUE(faults.waitForReaders(Termination::after(20.0)));
  msg::FaultInjection spawn;
  spawn.fault_id("it_spawn");
  spawn.type(msg::FaultType::FAULT_SPAWN_OBJECT);
  spawn.object_id("it_crate");
  spawn.reason("crate");
  spawn.shape().type(msg::ShapeType::SHAPE_BOX);
  spawn.shape().dimensions({0.4, 0.4, 0.4});
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(where.x(), where.y(), 0.2);
  spawn.pose(dds::toMsg(pose));
  ASSERT_TRUE(faults.write(spawn));
  auto added = events.waitFor(
      [&](const msg::WorldEvent& e) {
        return e.type() == msg::WorldEventType::WORLD_OBJECT_ADDED &&
               std::hypot(e.pose().position().x() - where.x(), e.pose().position().y() - where.y()) < 0.15;
      },
      30.0);
  ASSERT_TRUE(added) << "perception did not report the new obstacle";
  EXPECT_EQ(prior.findObject(added->object_id()), nullptr) << "a new id, not a known object's";
  const Termination settle = Termination::after(10.0);
  while (!settle() && objectNear(mirror.snapshot(), where, 0.15) == nullptr) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const world::Object* crate = objectNear(mirror.snapshot(), where, 0.15);
  ASSERT_NE(crate, nullptr) << "the world model does not hold the obstacle";
  const Aabb box = crate->aabb();
  EXPECT_NEAR(box.max.z(), 0.4, 0.05) << "its height";

  // 3. A turn on the spot through the execution monitor: a status, a result, a forwarded record,
  //    a refit that counts it.
  Trajectory turn;
  turn.joint_names = {"base_x", "base_y", "base_theta"};
  turn.points.push_back({0.0, {start->base().x(), start->base().y(), yaw}, {}});
  turn.points.push_back({1.0, {start->base().x(), start->base().y(), yaw + 0.4}, {}});
  msg::ExecuteCommand cmd;
  cmd.command_id("it_turn");
  cmd.mission_id("it_mission");
  cmd.kind(msg::ActionKind::ACTION_MOVE_BASE);
  cmd.trajectory(dds::toMsg(turn));
  cmd.expected_duration_s(2.5);
  cmd.expected_stddev_s(0.3);
  cmd.world_version(mirror.publishedVersion());
  ASSERT_TRUE(commands.waitForReaders(Termination::after(20.0)));
  ASSERT_TRUE(commands.write(cmd));
  auto status = statuses.waitFor(
      [](const msg::ExecuteStatus& s) {
        return s.command_id() == "it_turn" && s.state() != msg::ExecState::EXEC_ACCEPTED &&
               s.state() != msg::ExecState::EXEC_RUNNING;
      },
      60.0);
  ASSERT_TRUE(status) << "no final status from the execution monitor";
  EXPECT_EQ(status->state(), msg::ExecState::EXEC_SUCCEEDED) << status->reason();
  auto done = results.waitFor([](const msg::ActionResult& r) { return r.command_id() == "it_turn"; }, 30.0);
  ASSERT_TRUE(done) << "no result for the command";
  EXPECT_EQ(done->outcome(), msg::ActionOutcome::OUTCOME_SUCCEEDED) << done->reason();
  EXPECT_GT(done->duration_s(), 0.0);
  EXPECT_DOUBLE_EQ(status->measured_duration_s(), done->duration_s());
  auto record = records.waitFor([](const msg::ExecutionRecord& r) { return r.record_id() == "it_turn"; }, 30.0);
  ASSERT_TRUE(record) << "the simulator's record was not forwarded";
  EXPECT_EQ(record->command_id(), "it_turn");
  EXPECT_EQ(record->mission_id(), "it_mission");
  EXPECT_DOUBLE_EQ(record->predicted_s(), 2.5);
  EXPECT_DOUBLE_EQ(record->predicted_stddev_s(), 0.3);
  EXPECT_DOUBLE_EQ(record->duration_s(), done->duration_s());
  auto fitted = snapshots.waitFor(
      [](const msg::EffortModelSnapshot& s) {
        for (const auto& m : s.models()) {
          if (m.kind() == msg::ActionKind::ACTION_MOVE_BASE && m.record_count() >= 1 && m.version() >= 1) return true;
        }
        return false;
      },
      30.0);
  EXPECT_TRUE(fitted) << "the effort estimator did not refit move_base from the execution record";
}

}  // namespace
}  // namespace tamp::integration
