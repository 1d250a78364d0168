// Missions end to end over real processes: `tamp run` (the product's main job) starts every service
// of the default deployment on its own DDS domain, executes the scenario's mission in the
// simulator and writes the report. Each test judges the mission by the simulator's ground truth at
// the end (sim_final_world.json) and by the report, never by what the planner believes.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mission_util.h"
#include "tamp/core/paths.h"
#include "tamp/world/scenario.h"

namespace tamp::integration {
namespace {

namespace fs = std::filesystem;

bool insideCorridor(const nlohmann::json& p) {
  const double x = p["x"].get<double>(), y = p["y"].get<double>();
  return x > 4.3 && x < 6.7 && y > 0.85 && y < 1.55;
}

/// The corridor variants' goal (8.5, 1.2): the robot ends within 10 cm of it.
void expectAtTheCorridorGoal(const Mission& m) {
  EXPECT_LT(distance(m.truth["robot"], 8.5, 1.2), 0.10) << m.truth.dump();
}

/// The corridor box ends within 2 cm of where it stood, (4.62, 1.2).
void expectTheBoxUntouched(const Mission& m) {
  EXPECT_LT(distance(m.truth["objects"]["box"], 4.62, 1.2), 0.02) << "the box was not to be touched: " << m.truth.dump();
}

TEST(MissionTest, CorridorEffortPolicyMovesTheLightBoxAndReachesTheGoal) {
  const Mission m = run("namo_corridor.yaml", {"--policy", "effort"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  expectAtTheCorridorGoal(m);
  EXPECT_FALSE(insideCorridor(m.truth["objects"]["box"])) << m.truth["objects"]["box"].dump();
  EXPECT_EQ(m.report["status"], "succeeded");
  EXPECT_EQ(m.report["objects_moved"], nlohmann::json::array({"box"})) << m.report.dump(1);
  // The detour was priced and lost: a decision lists it with a larger (or cut) effort.
  bool detour_seen = false;
  for (const auto& d : m.report["decisions"])
    for (const auto& a : d["alternatives"])
      if (a["alternative"].get<std::string>().find("[around]") != std::string::npos && !a["chosen"].get<bool>())
        detour_seen = true;
  EXPECT_TRUE(detour_seen) << m.report["decisions"].dump(1);
  // Every action the report lists was measured by the robot, and they add up.
  double measured = 0.0;
  for (const auto& a : m.report["actions"]) measured += a["measured_s"].get<double>();
  EXPECT_NEAR(measured, m.report["executed_effort_s"].get<double>(), 1e-6);
  // Where the time to the first command went: the task plan and the detour's and removal's
  // motions were asked for before it, each call timed.
  const auto& first = m.report["first_action_breakdown"];
  EXPECT_GE(first["per_service"]["plan"]["calls"].get<int>(), 1) << first.dump(1);
  EXPECT_GE(first["per_service"]["motion"]["calls"].get<int>(), 2) << first.dump(1);
  EXPECT_EQ(first["calls"].size(), first["critical_calls"].get<std::size_t>());
  EXPECT_LE(first["critical_calls_s"].get<double>(), m.report["planning_time_to_first_action_s"].get<double>() + 1e-6);
  // The last run's report is also where a script finds it without the run's id: OUT/report.json,
  // and OUT/latest points at the run folder.
  const fs::path out = m.run_dir.parent_path();
  EXPECT_EQ(readFile(out / "report.json"), readFile(m.run_dir / "report.json"));
  ASSERT_TRUE(fs::is_symlink(out / "latest")) << m.output;
  EXPECT_EQ(fs::canonical(out / "latest"), fs::canonical(m.run_dir));
}

// A hall that is one large floor region: the first plan picks the parcel from wherever "reaches"
// the hall; the grasp service refutes it and the abstraction is refined (the parcel on a slot of
// its own), so the mission picks it from where the arm reaches it and brings it to the dock.
TEST(MissionTest, AParcelOnALargeFloorRegionIsPickedWhereTheArmReachesItAndDocked) {
  const Mission m = run("hall_transport.yaml", {"--policy", "effort"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  const auto& box = m.truth["objects"]["box"];
  EXPECT_GT(box["x"].get<double>(), 6.1) << box.dump();
  EXPECT_LT(box["x"].get<double>(), 6.8) << box.dump();
  EXPECT_GT(box["y"].get<double>(), 1.5) << box.dump();
  EXPECT_LT(box["y"].get<double>(), 2.5) << box.dump();
  bool picked_from_slot = false;
  for (const auto& a : m.report["actions"]) {
    const std::string action = a["action"].get<std::string>();
    if (action.rfind("(pick box slot_box", 0) == 0) picked_from_slot = true;
  }
  EXPECT_TRUE(picked_from_slot) << m.report["actions"].dump(1);
}

// Issue 12: a held object dropped mid-transport. The parcel slips out of the gripper during the
// carrying move_base and falls in front of the robot; it is picked up again from where it fell
// (a re-join after the drop event) and docked, and no command is executed twice.
TEST(MissionTest, AParcelDroppedMidTransportIsPickedUpWhereItFellAndDocked) {
  const Mission m = run("transport_drop.yaml", {"--policy", "effort"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  const auto& box = m.truth["objects"]["box"];
  EXPECT_GT(box["x"].get<double>(), 6.1) << box.dump();
  EXPECT_LT(box["x"].get<double>(), 6.8) << box.dump();
  EXPECT_GT(box["y"].get<double>(), 1.5) << box.dump();
  EXPECT_LT(box["y"].get<double>(), 2.5) << box.dump();
  EXPECT_EQ(m.truth["robot"]["held"], "") << m.truth.dump();
  std::map<std::string, int> executions;
  for (const auto& a : m.truth["action_log"]) ++executions[a.is_object() ? a["command_id"].get<std::string>() : a.get<std::string>()];
  for (const auto& [id, n] : executions) EXPECT_EQ(n, 1) << id << " executed " << n << " times";
  bool drop_replanned = false;
  for (const auto& r : m.report["replanning"]) drop_replanned |= r["event"] == "object_dropped";
  EXPECT_TRUE(drop_replanned) << m.report["replanning"].dump(1);
  int picks = 0;
  for (const auto& a : m.report["actions"])
    if (a["action"].get<std::string>().rfind("(pick box", 0) == 0 && a["outcome"] == "succeeded") ++picks;
  EXPECT_GE(picks, 2) << "picked, dropped, picked again: " << m.report["actions"].dump(1);
}

TEST(MissionTest, CorridorInfeasibilityPolicyGoesRoundAndLeavesTheBox) {
  const Mission m = run("namo_corridor.yaml", {"--policy", "infeasible"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  expectAtTheCorridorGoal(m);
  expectTheBoxUntouched(m);
  EXPECT_TRUE(m.report["objects_moved"].empty());
}

TEST(MissionTest, CorridorHeavyBoxAboveThePayloadIsGoneRound) {
  const Mission m = run("namo_corridor_heavy.yaml");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  expectAtTheCorridorGoal(m);
  expectTheBoxUntouched(m);
  EXPECT_EQ(m.report["grasp_calls"], 0) << "a box above the payload offers no removal to price";
}

// S-NAMO 01_basic: the only way to the goal leads through a box 1 m wide, far wider than the
// gripper (no grasp) but within the base's push limit. The robot pushes it off the way, drives on
// to the goal, and the simulator's world shows the box moved.
TEST(MissionTest, ABoxTooWideToGraspIsPushedOffTheWayToTheGoal) {
  auto sc = world::loadScenario(configDir() / "scenarios" / "namo_basic.yaml");
  ASSERT_TRUE(sc.ok()) << sc.error().toString();
  const world::Location* goal = sc->world.findLocation("goal_01");
  ASSERT_NE(goal, nullptr);
  const Eigen::Vector3d box = sc->world.object("movable_box").pose.translation();
  const Mission m = run("namo_basic.yaml");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  EXPECT_EQ(m.report["status"], "succeeded") << m.report["reason"];
  EXPECT_LT(distance(m.truth["robot"], goal->pose.x, goal->pose.y), 0.10) << m.truth.dump();
  EXPECT_GT(distance(m.truth["objects"]["movable_box"], box.x(), box.y()), 0.5) << m.truth.dump();
  EXPECT_EQ(m.report["objects_moved"], nlohmann::json::array({"movable_box"})) << m.report.dump(1);
  int pushes = 0;
  for (const auto& a : m.report["actions"])
    if (a["action"].get<std::string>().rfind("(push movable_box ", 0) == 0 && a["outcome"] == "succeeded") ++pushes;
  EXPECT_EQ(pushes, 1) << m.report["actions"].dump(1);
  EXPECT_EQ(m.report["grasp_calls"].get<int>() > 0, true) << "the grasp was tried first, and refuted";
}

// A crate too heavy to lift stands in the only doorway between two rooms; the door frame leaves
// no room to push it sideways. The robot pushes it ahead into the next room, far enough to drive
// round it, and goes on to the goal.
// Back in CI since 2026-12-05 (session 11): it was disabled at 12 of 14 runs, the misses the
// product's (the base path round the pushed crate kept no clearance, and the simulator stopped the
// robot beside it). With base paths keeping 5 cm where there is room: 17 of 17 runs, 16 of them
// beside a busy loop. Not all cleanly: in 7 of 18 runs the monitor stopped or refused a drive
// when perception's side-on estimate of the crate drifted onto the path, and the mission recovered.
TEST(MissionTest, ACrateInTheOnlyDoorwayIsPushedIntoTheNextRoomAndDrivenRound) {
  auto sc = world::loadScenario(configDir() / "scenarios" / "namo_doorway.yaml");
  ASSERT_TRUE(sc.ok()) << sc.error().toString();
  const world::Location* goal = sc->world.findLocation("goal");
  ASSERT_NE(goal, nullptr);
  const world::Object& crate = sc->world.object("crate");
  const double door_x = crate.pose.translation().x();  // the crate stands centred in the doorway
  const Mission m = run("namo_doorway.yaml");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  EXPECT_EQ(m.report["status"], "succeeded") << m.report["reason"];
  EXPECT_LT(distance(m.truth["robot"], goal->pose.x, goal->pose.y), 0.10) << m.truth.dump();
  // Out of the doorway, on the far side: its near face past the frame (0.1 m each side of the
  // doorway's centre line) by more than the robot could squeeze through otherwise.
  const double half = crate.shape.size.x() / 2;
  EXPECT_GT(m.truth["objects"]["crate"]["x"].get<double>() - half, door_x + 0.1) << m.truth.dump();
  EXPECT_EQ(m.report["objects_moved"], nlohmann::json::array({"crate"})) << m.report.dump(1);
  int pushes = 0;
  for (const auto& a : m.report["actions"])
    if (a["action"].get<std::string>().rfind("(push crate ", 0) == 0 && a["outcome"] == "succeeded") ++pushes;
  EXPECT_GE(pushes, 1) << m.report["actions"].dump(1);
}

// namosim's 03_big_crossing: a chair too heavy to lift in the mouth of the start corridor, another
// beside it, a third in the mouth of the goal corridor. The first is pushed ahead into the room,
// the third aside; a motion the monitor refuses because a pushed chair's estimate lags behind its
// slot is planned again where perception sees the chair (before, the same motion was planned again
// and refused until the mission gave up).
// The clean-clone CI of 2026-12-04 failed on it once: perception made a ghost box of a far,
// partial view of room_1_chair3, which then stood where the robot had to stand to push the chair
// (fixed: SceneTest.AFarPartialViewOfAKnownObjectIsNoNewObject).
TEST(MissionTest, ChairsInTheMouthsOfTwoCorridorsArePushedOutOfTheWay) {
  auto sc = world::loadScenario(configDir() / "scenarios" / "namo_big_crossing.yaml");
  ASSERT_TRUE(sc.ok()) << sc.error().toString();
  const world::Location* goal = sc->world.findLocation("goal_01");
  ASSERT_NE(goal, nullptr);
  const Mission m = run("namo_big_crossing.yaml");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  EXPECT_EQ(m.report["status"], "succeeded") << m.report["reason"];
  EXPECT_LT(distance(m.truth["robot"], goal->pose.x, goal->pose.y), 0.10) << m.truth.dump();
  const Eigen::Vector3d chair1 = sc->world.object("room_1_chair1").pose.translation();
  EXPECT_GT(distance(m.truth["objects"]["room_1_chair1"], chair1.x(), chair1.y()), 0.5) << m.truth.dump();
  for (const auto& a : m.report["actions"])
    if (a["action"].get<std::string>().rfind("(pick ", 0) == 0) ADD_FAILURE() << "a chair above the payload was picked";
}

// Moghaddam & Masehian's world 07 (27 movable boxes, all wider than the gripper): the way the
// static-only lazy path takes crosses movable_10, above the payload with no free push; the
// graph manager fixes it (and every other object it can neither carry nor push) and plans the
// drive again round them, through boxes it can push. It failed with "no branch" until session
// 13 under every policy. Judged by the simulator's world: the robot at the goal, movable_10 where
// it stood, something pushed, nothing picked.
// Its first Traverse takes 20-30 s of lazy paths (docs/benchmarks.md), the whole of the shipped
// 30 s `traverse_budget_s` on a loaded machine, where it ran out ("no branch ... within the
// evaluation budget"; disabled in CI from session 14 to 32). The time is the benchmark's to
// measure, not this test's: the run's graph manager has 120 s. (The other failure of its runs, a
// floor plane missed by RANSAC that made a "new static box" over three of the boxes, was fixed in
// perception in session 32: SceneTest.TheFloorIsFoundInEveryFrameWhereWallsFillTheImage.)
TEST(MissionTest, AWayRoundWhatTheRobotCannotMoveIsOpenedByPushingOthers) {
  auto sc = world::loadScenario(configDir() / "scenarios" / "namo_moghaddam_07.yaml");
  ASSERT_TRUE(sc.ok()) << sc.error().toString();
  const world::Location* goal = sc->world.findLocation("goal");
  ASSERT_NE(goal, nullptr);
  const fs::path out = tempFile("tamp_mission_namo_moghaddam_07");
  fs::remove_all(out);
  fs::create_directories(out / "deploy" / "store");
  const fs::path deployment =
      withServiceKeys(fastDeployment(out / "deploy", 2.0), "graph_manager", {{"traverse_budget_s", "120.0"}});
  const Mission m = runWith(out, deployment, "namo_moghaddam_07.yaml");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  EXPECT_EQ(m.report["status"], "succeeded") << m.report["reason"];
  EXPECT_LT(distance(m.truth["robot"], goal->pose.x, goal->pose.y), 0.10) << m.truth.dump();
  const Eigen::Vector3d heavy = sc->world.object("movable_10").pose.translation();
  EXPECT_LT(distance(m.truth["objects"]["movable_10"], heavy.x(), heavy.y()), 0.02) << m.truth.dump();
  int moved = 0;
  for (const auto& o : sc->world.objects()) {
    if (o.kind != world::ObjectKind::kMovable) continue;
    const Eigen::Vector3d p = o.pose.translation();
    moved += distance(m.truth["objects"][o.id], p.x(), p.y()) > 0.3 ? 1 : 0;
  }
  EXPECT_GE(moved, 1) << m.truth.dump();
  for (const auto& a : m.report["actions"])
    if (a["action"].get<std::string>().rfind("(pick ", 0) == 0) ADD_FAILURE() << "a box wider than the gripper was picked";
}

// Also run with `--realtime-factor 5`, which overrides the deployment's simulator parameters
// (2x here) for this run: the simulator says so in its log.
TEST(MissionTest, CorridorShortDetourIsTakenInsteadOfMovingTheBox) {
  const Mission m = run("namo_corridor_short.yaml", {"--realtime-factor", "5"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  expectAtTheCorridorGoal(m);
  expectTheBoxUntouched(m);
  EXPECT_NE(m.output.find("runs at 5x real time"), std::string::npos) << m.output;
  const std::string sim_log = readFile(m.run_dir / "sim.log");
  EXPECT_NE(sim_log.find("simulated time runs at 5x real time"), std::string::npos) << sim_log;
}

// Every pick of the corridor box misses (scripted). The pick is tried max_action_failures (2)
// times, then given up: every re-joining branch goes through that pick, so the graph manager plans
// from scratch and the robot goes round. The box stays where it was; the mission succeeds.
TEST(MissionTest, APickThatKeepsFailingIsGivenUpForTheWayRound) {
  const Mission m = run("namo_corridor_slippery.yaml", {"--policy", "effort"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  expectAtTheCorridorGoal(m);
  expectTheBoxUntouched(m);
  int failed_picks = 0;
  for (const auto& a : m.report["actions"])
    if (a["action"].get<std::string>().rfind("(pick box", 0) == 0 && a["outcome"] == "failed") ++failed_picks;
  EXPECT_EQ(failed_picks, 2) << m.report["actions"].dump(1);
  // The replanning after the second failed pick is the one that gives the pick up. Later events of
  // the way round (an overrun, a blocked base motion) may follow it, so it is found by its action.
  std::vector<nlohmann::json> after_pick;
  for (const auto& rp : m.report["replanning"])
    if (rp["event"] == "action_failed" && rp["action"].get<std::string>().rfind("(pick box", 0) == 0) after_pick.push_back(rp);
  ASSERT_EQ(after_pick.size(), 2u) << m.report["replanning"].dump(1);
  EXPECT_EQ(after_pick.back()["how"], "from scratch") << m.report["replanning"].dump(1);
}

// The DDS Security profile (deploy/security/): every service with its own certificate and
// permissions, everything encrypted; the mission must still succeed. A topic a node uses but the
// access table does not grant it makes that node fail to start (or the call fail), so this is
// also the check that deploy/security/access.txt covers the code.
TEST(MissionTest, SecuredCorridorMissionSucceeds) {
  const fs::path pki = tempFile("tamp_mission_pki");
  const fs::path pki_log = tempFile("tamp_mission_pki", ".log");
  fs::remove_all(pki);
  const std::string cmd = std::string("bash ") + TAMP_SOURCE_DIR + "/deploy/security/make_certs.sh '" + pki.string() +
                          "' > '" + pki_log.string() + "' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << readFile(pki_log);
  // No second attempt: a secured mission that fails once would fail a customer's (docs/benchmarks.md,
  // "With DDS Security on and off": the lost replies, and their cure in RpcServer).
  const Mission m = run("namo_corridor.yaml", {"--policy", "effort", "--security", pki.string()});
  fs::remove_all(pki);
  ASSERT_EQ(m.exit_code, 0) << m.output;
  EXPECT_NE(m.output.find("ok"), std::string::npos) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  expectAtTheCorridorGoal(m);
  EXPECT_EQ(m.report["status"], "succeeded") << m.report.dump(1);
  // Whether the box is moved is the effort decision, checked unsecured by
  // CorridorEffortPolicyMovesTheLightBoxAndReachesTheGoal; here only that the secured mission
  // reaches the goal.
}

// The gripper holds a cup at the start; it slips 2 s in (it falls in front of the base, where the
// mast camera cannot see), a parcel appears on the table later, and the first pick of the can
// misses. The robot must end holding the can, with the cup on the floor where it fell (the world
// model put it there: the way to the table is planned round it, not through it), having replanned
// after the failed pick, and no command executed twice.
// The cluttered table (issue 11): the can stands behind a cereal box and a cup as seen from the
// only side the arm reaches the table from. The occluders are moved, the can reaches the counter.
TEST(MissionTest, TheOccludedCanReachesTheCounter) {
  const Mission m = run("occluded_can.yaml");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  const auto& can = m.truth["objects"]["can"];
  EXPECT_GT(can["x"].get<double>(), -0.4) << can.dump();
  EXPECT_LT(can["x"].get<double>(), 0.4) << can.dump();
  EXPECT_GT(can["y"].get<double>(), 1.6) << can.dump();
  EXPECT_LT(can["y"].get<double>(), 2.2) << can.dump();
  EXPECT_NEAR(can["z"].get<double>(), 0.70 + 0.06, 0.02) << "standing on the counter: " << can.dump();
  EXPECT_EQ(m.truth["robot"]["held"], "") << m.truth.dump();
  std::map<std::string, int> executions;
  for (const auto& a : m.truth["action_log"]) ++executions[a.is_object() ? a["command_id"].get<std::string>() : a.get<std::string>()];
  for (const auto& [id, n] : executions) EXPECT_EQ(n, 1) << id << " executed " << n << " times";
}

TEST(MissionTest, HoldingStartWithFaultsEndsHoldingTheCan) {
  const Mission m = run("holding_start_faults.yaml");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  EXPECT_EQ(m.truth["robot"]["held"], "can") << m.truth.dump();
  EXPECT_LT(m.truth["objects"]["cup"]["z"].get<double>(), 0.1) << "the cup is not on the floor: " << m.truth.dump();
  std::map<std::string, int> executions;
  for (const auto& a : m.truth["action_log"]) ++executions[a.is_object() ? a["command_id"].get<std::string>() : a.get<std::string>()];
  for (const auto& [id, n] : executions) EXPECT_EQ(n, 1) << id << " executed " << n << " times";
  bool failed_pick_replanned = false;
  for (const auto& r : m.report["replanning"]) failed_pick_replanned |= r["event"] == "action_failed";
  EXPECT_TRUE(failed_pick_replanned) << m.report["replanning"].dump(1);
}

// Conditional planning: the gripper holds a cup that the planner was not told about. The graph
// manager plans from what it was told (the hand empty) and prebuilds the branch "gripper not
// empty" before executing anything; the robot's report of its gripper selects that branch before
// the first action, with no planner call. The robot ends holding the can, with the cup standing on
// the table, and no command executed twice.
TEST(MissionTest, AHandNotEmptyThatThePlannerDidNotKnowTakesThePrebuiltBranch) {
  const Mission m = run("holding_unknown.yaml");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  EXPECT_EQ(m.truth["robot"]["held"], "can") << m.truth.dump();
  const auto& cup = m.truth["objects"]["cup"];
  EXPECT_GT(cup["x"].get<double>(), 1.25) << "the cup is not on the table: " << m.truth.dump();
  EXPECT_LT(cup["x"].get<double>(), 2.05) << m.truth.dump();
  EXPECT_NEAR(cup["z"].get<double>(), 0.75 + 0.05, 0.03) << "the cup is not standing on the table: " << m.truth.dump();
  std::map<std::string, int> executions;
  for (const auto& a : m.truth["action_log"]) ++executions[a.is_object() ? a["command_id"].get<std::string>() : a.get<std::string>()];
  for (const auto& [id, n] : executions) EXPECT_EQ(n, 1) << id << " executed " << n << " times";
  ASSERT_EQ(m.report["conditionals"].size(), 1u) << m.report.dump(1);
  const auto& c = m.report["conditionals"][0];
  EXPECT_TRUE(c["prebuilt"].get<bool>()) << c.dump();
  EXPECT_EQ(c["at_node"], "n0") << c.dump();
  EXPECT_NE(c["observation"].get<std::string>().find("cup"), std::string::npos) << c.dump();
  ASSERT_TRUE(c["planner_calls"].is_number()) << "no command followed the observation: " << c.dump();
  EXPECT_EQ(c["planner_calls"].get<int>(), 0) << c.dump();
  EXPECT_EQ(m.report["replans"].get<int>(), 0) << m.report["replanning"].dump(1);
}

// --fresh: the estimator starts from the default models in a store of the run's own; the store the
// deployment configures (which the first run taught) is neither read nor changed.
TEST(MissionTest, FreshStartsFromTheDefaultModelsAndLeavesTheLearnedStoreAlone) {
  const fs::path out = tempFile("tamp_mission_fresh");
  fs::remove_all(out);
  fs::create_directories(out / "deploy" / "store");
  const fs::path deployment = fastDeployment(out / "deploy", 2.0);
  const Mission taught = runWith(out, deployment, "namo_corridor_short.yaml");
  ASSERT_EQ(taught.exit_code, 0) << taught.output;
  auto snapshot = [&] {
    std::map<std::string, std::uintmax_t> files;
    for (const auto& e : fs::recursive_directory_iterator(out / "deploy" / "store"))
      if (e.is_regular_file()) files[e.path().string()] = e.file_size();
    return files;
  };
  const auto learned = snapshot();
  ASSERT_FALSE(learned.empty()) << "the first run wrote no store";

  const Mission fresh = runWith(out, deployment, "namo_corridor_short.yaml", {"--fresh"});
  ASSERT_EQ(fresh.exit_code, 0) << fresh.output;
  ASSERT_FALSE(fresh.run_dir.empty());
  const std::string log = readFile(fresh.run_dir / "effort_estimator.log");
  EXPECT_NE(log.find((fresh.run_dir / "effort_store").string()), std::string::npos) << log;
  EXPECT_NE(log.find(" 0 records loaded"), std::string::npos) << log;
  EXPECT_EQ(snapshot(), learned) << "--fresh changed the configured store";
  expectAtTheCorridorGoal(fresh);
}

// A mission out of time (`--mission-timeout`) is aborted, the action under way cancelled, and its
// report is still written: the actions done, the decisions taken, the status "aborted". Before, tamp run exited 20 leaving no
// report, and the graph manager, still in its Traverse, was killed when the services stopped.
TEST(MissionTest, AMissionOutOfTimeIsAbortedAndStillLeavesItsReport) {
  const Mission m = run("namo_corridor.yaml", {"--mission-timeout", "4"});
  EXPECT_EQ(m.exit_code, 20) << m.output;
  ASSERT_TRUE(m.report.is_object()) << "no report.json: " << m.output;
  EXPECT_EQ(m.report["status"], "aborted") << m.report.dump(1);
  EXPECT_FALSE(m.report["decisions"].empty()) << m.report.dump(1);
  // The first drive (about 14 simulated seconds) was under way: it was cancelled, the robot
  // stopped where it was rather than finish it.
  ASSERT_FALSE(m.report["actions"].empty()) << m.report.dump(1);
  EXPECT_EQ(m.report["actions"].back()["outcome"], "cancelled") << m.report["actions"].dump(1);
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  // At twice real time four seconds are not enough to reach the goal (8.5, 1.2) from (1.5, 1.2).
  EXPECT_GT(distance(m.truth["robot"], 8.5, 1.2), 1.0) << m.truth.dump();
  EXPECT_EQ(m.output.find("ended with signal 9"), std::string::npos) << "a service had to be killed: " << m.output;
}

// The report is the mission's result: one that cannot be written is an error (exit 50, what and
// where), not a silent success. OUT/report.json is a folder here, so the copy there fails; the
// run folder's own report was written first and stays.
TEST(MissionTest, AReportThatCannotBeWrittenIsAnOutputError) {
  const fs::path out = tempFile("tamp_mission_unwritable_report");
  fs::remove_all(out);
  fs::create_directories(out / "report.json" / "in_the_way");
  fs::create_directories(out / "deploy" / "store");
  const Mission m = runWith(out, fastDeployment(out / "deploy", 5.0), "namo_corridor_short.yaml");
  EXPECT_EQ(m.exit_code, 50) << m.output;
  EXPECT_NE(m.output.find("the report was not written"), std::string::npos) << m.output;
  EXPECT_NE(m.output.find((out / "report.json").string()), std::string::npos) << m.output;
  ASSERT_TRUE(m.report.is_object()) << m.output;
  EXPECT_EQ(m.report["status"], "succeeded");
}

TEST(MissionTest, ABadScenarioIsAnInputErrorBeforeAnyServiceStarts) {
  const fs::path bad = tempFile("tamp_bad_scenario", ".yaml");
  std::ofstream(bad) << "name: bad\npddl:\n  domain: nowhere.pddl\nrobot: {start: start}\n";
  const auto [code, out] = runCommand(binDir() / "tamp-run", {bad.string(), "--domain", std::to_string(isolatedDomain())}, 60.0);
  EXPECT_EQ(code, 30) << out;
  EXPECT_NE(out.find(bad.string()), std::string::npos) << "the error names the file: " << out;
  EXPECT_EQ(out.find("SERVICE"), std::string::npos) << "no service was started: " << out;
}

}  // namespace
}  // namespace tamp::integration
