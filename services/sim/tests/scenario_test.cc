// The simulator built from the shipped scenarios (config/scenarios): true parameters, start
// state, hidden objects and scripted faults as the scenario loader gives them.
#include <gtest/gtest.h>

#include "sim_test_util.h"
#include "tamp/sim/setup.h"

namespace tamp::sim {
namespace {

using namespace tamp::sim::testing;

std::string scenarioPath(const std::string& name) {
  return (std::filesystem::path(TAMP_SOURCE_DIR) / "config/scenarios" / (name + ".yaml")).string();
}

TEST(ScenarioSetupTest, TakesTheTrueParametersFromTheScenario) {
  SimParams params = exactParams();
  params.scenario = scenarioPath("occluded_can");
  auto setup = loadSetup(params);
  ASSERT_TRUE(setup) << setup.error().toString();
  const DynamicsParams& d = params.dynamics;
  EXPECT_EQ(d.base.linear_speed, 0.45);
  EXPECT_EQ(d.base.linear_accel, 0.4);
  EXPECT_EQ(d.base.angular_speed, 0.9);
  EXPECT_EQ(d.base.angular_accel, 1.2);
  EXPECT_EQ(d.base.settle_s, 0.25);
  EXPECT_EQ(d.arm.max_speed, 0.8);
  EXPECT_EQ(d.arm.settle_s, 0.25);
  EXPECT_EQ(d.hand.close_s, 1.8);
  EXPECT_EQ(d.hand.open_s, 1.2);
  EXPECT_EQ(params.duration_noise, 0.05);
  EXPECT_EQ(params.seed, 11u);
  // Not in the scenario schema: the simulator's own values.
  EXPECT_EQ(d.base.latency_s, DynamicsParams{}.base.latency_s);
  EXPECT_EQ(d.base.linear_jerk, DynamicsParams{}.base.linear_jerk);
  // The ground truth keeps what the planner does not see.
  auto scenario = world::loadScenario(params.scenario);
  ASSERT_TRUE(scenario);
  EXPECT_EQ(setup->world.objectCount(), scenario->world.objectCount());
  EXPECT_TRUE(setup->initial.base == scenario->startState().base);
  Simulator sim(setup->world, setup->robot, setup->initial, params, setup->faults);
  EXPECT_EQ(sim.world().objectCount(), scenario->world.objectCount());
}

// Every shipped scenario (config/scenarios/*.yaml) builds a simulator whose dynamics are valid
// and carry the scenario's `sim` values, and executes a short base motion.
TEST(ScenarioSetupTest, EveryShippedScenarioLoadsIntoTheSimulatorsDynamics) {
  int loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(TAMP_SOURCE_DIR) / "config/scenarios")) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    SimParams params = exactParams();
    params.scenario = entry.path().string();
    auto setup = loadSetup(params);
    ASSERT_TRUE(setup) << setup.error().toString();
    ASSERT_TRUE(params.validate()) << params.validate().error().toString();
    auto scenario = world::loadScenario(params.scenario);
    ASSERT_TRUE(scenario);
    EXPECT_EQ(params.dynamics.base.linear_speed, scenario->sim.base_max_linear_speed);
    EXPECT_EQ(params.dynamics.arm.max_speed, scenario->sim.arm_max_joint_speed);
    EXPECT_EQ(params.dynamics.hand.close_s, scenario->sim.grasp_duration);
    EXPECT_EQ(params.seed, scenario->sim.seed);
    Simulator sim(setup->world, setup->robot, setup->initial, params, setup->faults);
    const Pose2D from = setup->initial.base;
    auto turn = moveBase("turn", {from, Pose2D{from.x, from.y, from.theta + 0.2}});
    auto oracle = sim.nominalDuration(turn);
    ASSERT_TRUE(oracle) << oracle.error().toString();
    EXPECT_GT(*oracle, 0.0);
    ++loaded;
  }
  EXPECT_GE(loaded, 12);
}

TEST(ScenarioSetupTest, ScriptedFaultsOfHoldingStartFaults) {
  SimParams params = exactParams();
  params.scenario = scenarioPath("holding_start_faults");
  auto setup = loadSetup(params);
  ASSERT_TRUE(setup) << setup.error().toString();
  ASSERT_EQ(setup->faults.size(), 3u);
  EXPECT_EQ(setup->faults[0].type, FaultType::kDropHeldObject);
  EXPECT_EQ(setup->faults[1].type, FaultType::kFailAction);
  EXPECT_EQ(setup->faults[1].action, ActionKind::kPick);
  EXPECT_EQ(setup->faults[1].trigger.step, 2);
  EXPECT_EQ(setup->faults[2].type, FaultType::kSpawnObject);
  Simulator sim(setup->world, setup->robot, setup->initial, params, setup->faults);
  ASSERT_TRUE(sim.world().held());
  EXPECT_EQ(sim.robotState().held_object_id, "cup");
  // t = 2 s: the cup slips out of the gripper. The arm is at `carry` (the tool ahead of the
  // base): it falls onto the floor patch in front of the robot and stays there.
  StepEvents e = sim.step(2.5);
  ASSERT_EQ(e.faults.size(), 1u);
  EXPECT_EQ(e.faults[0].object_id, "cup");
  EXPECT_NEAR(e.faults[0].time_s, 2.0, 1e-12);
  EXPECT_FALSE(sim.world().held());
  EXPECT_EQ(sim.robotState().held_object_id, "");
  const world::Object cup = sim.world().object("cup");
  EXPECT_EQ(cup.region, "floor_patch");
  (void)sim.step(1.0);
  EXPECT_NEAR((sim.world().object("cup").pose.translation() - cup.pose.translation()).norm(), 0.0, 1e-9);
  // t = 20 s: the parcel appears on the table.
  e = sim.step(20.0 - sim.time() + 0.01);
  ASSERT_EQ(e.faults.size(), 1u);
  EXPECT_EQ(e.faults[0].object_id, "parcel");
  const world::Object* parcel = sim.world().findObject("parcel");
  ASSERT_NE(parcel, nullptr);
  EXPECT_NEAR(parcel->pose.translation().z(), 0.75 + 0.05, 1e-9);
}

TEST(ScenarioSetupTest, AFailureFilteredByKindHitsTheFirstMatchingAction) {
  Fault fail;
  fail.id = "grasp_missed";
  fail.type = FaultType::kFailAction;
  fail.trigger.step = 0;
  fail.action = ActionKind::kMoveArm;
  fail.reason = "grasp missed";
  Simulator sim(emptyRoom(), robotModel(), upright(), exactParams(), {fail});
  // Step 0 is a move_base: not hit.
  ASSERT_TRUE(sim.submit(moveBase("b0", {{0, 0, 0}, {0.5, 0, 0}})));
  EXPECT_EQ(runToEnd(sim).results.at(0).outcome, Outcome::kSucceeded);
  // Step 1, a move_arm: fails half-way.
  ASSERT_TRUE(sim.submit(armCommand("a1", ActionKind::kMoveArm, {std::vector<double>(6, 0.0), {0, 0, 0, 0, 0, 1.0}})));
  const StepEvents e = runToEnd(sim);
  EXPECT_EQ(e.results.at(0).outcome, Outcome::kFailed);
  EXPECT_NE(e.results[0].reason.find("grasp missed"), std::string::npos);
  EXPECT_NEAR(e.results[0].progress, 0.5, 1e-9);
  // Only once.
  ASSERT_TRUE(sim.submit(armCommand("a2", ActionKind::kMoveArm, {sim.robotState().state.arm, {0, 0, 0, 0, 0, 0}})));
  EXPECT_EQ(runToEnd(sim).results.at(0).outcome, Outcome::kSucceeded);
}

TEST(ScenarioSetupTest, UnknownScenarioIsAnError) {
  SimParams params = exactParams();
  params.scenario = "/nonexistent/scenario.yaml";
  auto setup = loadSetup(params);
  ASSERT_FALSE(setup);
  EXPECT_NE(setup.error().toString().find("/nonexistent/scenario.yaml"), std::string::npos);
}

}  // namespace
}  // namespace tamp::sim
