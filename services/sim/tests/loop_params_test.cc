#include <atomic>
#include <fstream>

#include <gtest/gtest.h>

#include "sim_test_util.h"
#include "tamp/sim/loop.h"
#include "tamp/sim/params.h"

namespace tamp::sim {
namespace {

using namespace tamp::sim::testing;

TEST(SimParamsTest, ShippedConfigLoads) {
  auto p = loadSimParams(std::filesystem::path(TAMP_SOURCE_DIR) / "config/services/sim.yaml");
  ASSERT_TRUE(p) << p.error().toString();
  EXPECT_TRUE(p->validate());
  EXPECT_TRUE(p->scenario.empty());
}

TEST(SimParamsTest, ParsesEveryBlock) {
  const std::string yaml = R"(
realtime_factor: 0
state_period_s: 0.1
cloud_period_s: 1.0
checkpoint_period_s: 0.5
checkpoint_idle_period_s: 2.0
duration_noise: 0.02
seed: 5
max_step_m: 0.005
start_tolerance: {position_m: 0.1, angle_rad: 0.2}
grasp: {position_tolerance_m: 0.05, tcp_tolerance_m: 0.01, max_payload_kg: 3}
place: {max_drop_m: 0.02}
dynamics:
  base: {linear_speed: 0.7, latency_s: 1.5}
  hand: {close_s: 3.0}
  stall: {probability: 0.2}
sensor: {width: 64, height: 48, horizontal_fov_rad: 1.2, see_robot: true}
)";
  auto p = parseSimParams(yaml, "sim.yaml");
  ASSERT_TRUE(p) << p.error().toString();
  EXPECT_EQ(p->realtime_factor, 0.0);
  EXPECT_EQ(p->checkpoint_period_s, 0.5);
  EXPECT_EQ(p->checkpoint_idle_period_s, 2.0);
  EXPECT_EQ(p->seed, 5u);
  EXPECT_EQ(p->max_step_m, 0.005);
  EXPECT_EQ(p->start_tolerance.angle_rad, 0.2);
  EXPECT_EQ(p->grasp.max_payload_kg, 3.0);
  EXPECT_EQ(p->place.max_drop_m, 0.02);
  EXPECT_EQ(p->dynamics.base.linear_speed, 0.7);
  EXPECT_EQ(p->dynamics.base.latency_s, 1.5);
  EXPECT_EQ(p->dynamics.hand.close_s, 3.0);
  EXPECT_EQ(p->dynamics.stall.probability, 0.2);
  // Unnamed parameters keep the simulated robot's values.
  EXPECT_EQ(p->dynamics.base.settle_s, DynamicsParams{}.base.settle_s);
  EXPECT_EQ(p->sensor.width, 64);
  EXPECT_TRUE(p->sensor.see_robot);
}

TEST(SimParamsTest, ErrorsNameFileLineAndField) {
  struct Case {
    std::string yaml, expected;
  };
  const std::vector<Case> cases{
      {"realtime_factor: -1\n", "field 'realtime_factor'"},
      {"max_stepp_m: 0.1\n", "unknown key 'max_stepp_m'"},
      {"grasp:\n  max_payload_kg: 0\n", "field 'grasp.max_payload_kg'"},
      {"dynamics:\n  base: {linear_speed: -1}\n", "linear_speed"},
      {"dynamics:\n  fly: {speed: 1}\n", "unknown key 'fly'"},
      {"dynamics:\n  hand: {approach_sped: 1}\n", "unknown key 'approach_sped'"},
      {"dynamics:\n  stall: {probability: 2}\n", "probability"},
      // The effort-model parameters of before the simulator's own dynamics: refused, with the file,
      // line, column and field.
      {"realtime_factor: 1\ntime_parameters:\n  pick: {gripper_time: 1}\n",
       "sim.yaml:2:1: field 'time_parameters': unknown key 'time_parameters'"},
      {"dynamics:\n  base: {corner_threshold_rad: 0.05}\n", "field 'dynamics.base.corner_threshold_rad': unknown key"},
      {"sensor:\n  width: 0\n", "sim.yaml:2:"},
      {"duration_noise: abc\n", "field 'duration_noise'"},
      {"push:\n  lateral_slip: -0.1\n", "field 'push.lateral_slip'"},
      {"push:\n  max_contact_gap_m: 0\n", "field 'push.max_contact_gap_m'"},
      {"checkpoint_period_s: 0\n", "field 'checkpoint_period_s'"},
      {"checkpoint_idle_period_s: -1\n", "field 'checkpoint_idle_period_s'"},
  };
  for (const auto& c : cases) {
    auto p = parseSimParams(c.yaml, "sim.yaml");
    ASSERT_FALSE(p) << c.yaml;
    EXPECT_NE(p.error().toString().find(c.expected), std::string::npos)
        << c.yaml << " -> " << p.error().toString();
  }
  SimParams bad;
  bad.dynamics.arm.jerk = 0.0;
  EXPECT_FALSE(bad.validate());
  EXPECT_THROW(Simulator(emptyRoom(), robotModel(), upright(), bad), std::invalid_argument);
}

TEST(SimulationLoopTest, ReportsStatesResultsRecordsAndClouds) {
  SimParams params = exactParams();
  params.state_period_s = 0.1;
  params.cloud_period_s = 2.0;
  params.sensor.width = 32;
  params.sensor.height = 24;
  Simulator sim(emptyRoom(), robotModel(), upright(), params);
  std::vector<double> state_times;
  std::vector<ActionResult> results;
  std::vector<effort_model::ExecutionRecord> records;
  std::vector<std::int64_t> cloud_stamps;
  LoopCallbacks cb;
  cb.on_state = [&](const RobotStateSample& s, std::int64_t) { state_times.push_back(s.time_s); };
  cb.on_result = [&](const ActionResult& r) { results.push_back(r); };
  cb.on_record = [&](const effort_model::ExecutionRecord& r) { records.push_back(r); };
  cb.on_cloud = [&](const PointCloudFrame& f) { cloud_stamps.push_back(f.stamp_ns); };
  SimulationLoop loop(sim, cb);
  // A malformed command is answered through on_result too.
  auto bad = moveBase("bad", {{0, 0, 0}, {1, 0, 0}});
  bad.trajectory.points[1].positions[1] = NAN;
  EXPECT_FALSE(loop.submit(bad));
  ASSERT_EQ(results.size(), 1u);
  EXPECT_EQ(results[0].outcome, Outcome::kFailed);
  EXPECT_NE(results[0].reason.find("trajectory.points[1].positions[1]"), std::string::npos);
  ASSERT_TRUE(loop.submit(moveBase("ok", {{0, 0, 0}, {1, 0, 0}})));
  while (loop.busy()) loop.tick();
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[1].outcome, Outcome::kSucceeded);
  ASSERT_EQ(records.size(), 1u);
  // States every 0.1 s of simulated time, in order; clouds at t = 0.1 (first tick), every 2 s,
  // and one after the action.
  for (std::size_t i = 1; i < state_times.size(); ++i) EXPECT_NEAR(state_times[i] - state_times[i - 1], 0.1, 1e-9);
  const double t_end = state_times.back();
  EXPECT_GE(cloud_stamps.size(), static_cast<std::size_t>(t_end / 2.0) + 1);
  EXPECT_EQ(loop.stampNs(1.0) - loop.stampNs(0.0), 1000000000);
  loop.requestCloud();
  const std::size_t before = cloud_stamps.size();
  loop.tick();
  EXPECT_EQ(cloud_stamps.size(), before + 1);
}

TEST(SimulationLoopTest, ThreadedAsFastAsPossible) {
  SimParams params = exactParams();  // realtime_factor 0
  Simulator sim(emptyRoom(), robotModel(), upright(), params);
  std::mutex m;
  std::condition_variable cv;
  std::vector<ActionResult> results;
  LoopCallbacks cb;
  cb.on_result = [&](const ActionResult& r) {
    std::lock_guard l(m);
    results.push_back(r);
    cv.notify_all();
  };
  SimulationLoop loop(sim, cb);
  loop.start();
  // 6 m at 0.45 m/s: more than 6 / 0.45 s of simulated time, done in far less wall time (not asserted: no timing
  // in tests; a generous wait only bounds a hang).
  ASSERT_TRUE(loop.submit(moveBase("far", {{0, 0, 0}, {6, 0, 0}})));
  std::unique_lock l(m);
  ASSERT_TRUE(cv.wait_for(l, std::chrono::seconds(60), [&] { return !results.empty(); }));
  EXPECT_EQ(results[0].outcome, Outcome::kSucceeded);
  EXPECT_GT(loop.simTime(), 6.0 / params.dynamics.base.linear_speed);
  l.unlock();
  loop.stop();
}

}  // namespace
}  // namespace tamp::sim
