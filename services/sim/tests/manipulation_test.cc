// Pick and place in the simulator: real kinematics (IK of the URDF arm), attachment to the
// gripper, support regions, and the physical checks that make a pick or a place fail.
#include <cmath>

#include <gtest/gtest.h>

#include "sim_test_util.h"

namespace tamp::sim {
namespace {

using namespace tamp::sim::testing;

constexpr double kTableTop = 0.75;

/// A table in front of the robot (x in [0.4, 1.0]) with a can on it, and a second table to the
/// left (y in [0.45, 1.25]) to place the can on.
world::World kitchen(double can_mass = 0.4) {
  world::World w = emptyRoom();
  EXPECT_TRUE(w.addObject(box("table", 0.6, 0.8, kTableTop, at(0.7, 0.0, kTableTop / 2))));
  EXPECT_TRUE(w.addObject(box("side_table", 0.8, 0.8, kTableTop, at(0.0, 0.85, kTableTop / 2))));
  world::Region top;
  top.id = "table_top";
  top.kind = world::RegionKind::kTable;
  top.polygon = {{0.4, -0.4}, {1.0, -0.4}, {1.0, 0.4}, {0.4, 0.4}};
  top.height = kTableTop;
  EXPECT_TRUE(w.addRegion(top));
  top.id = "side_top";
  top.polygon = {{-0.4, 0.45}, {0.4, 0.45}, {0.4, 1.25}, {-0.4, 1.25}};
  EXPECT_TRUE(w.addRegion(top));
  world::Object can;
  can.id = "can";
  can.kind = world::ObjectKind::kMovable;
  can.shape = world::Shape::cylinder(0.03, 0.12);
  can.pose = at(0.58, 0.0, kTableTop + 0.06);
  can.mass = can_mass;
  can.graspable = true;
  can.region = "table_top";
  EXPECT_TRUE(w.addObject(can));
  return w;
}

/// Arm configuration putting the tool (pointing down) at world `p` for a base at the origin.
std::vector<double> topGrasp(const Eigen::Vector3d& p, const std::vector<double>& seed) {
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  target.translation() = p;
  const auto ik = robotModel().inverseKinematics(target, seed);
  EXPECT_TRUE(ik.ok()) << toString(ik.status) << " for " << p.transpose();
  return ik.q;
}

/// A robot in front of the table, arm above the can: pre-grasp and grasp configurations.
struct PickSetup {
  std::vector<double> pregrasp, grasp;
};
PickSetup pickSetup(const Eigen::Vector3d& can) {
  PickSetup s;
  s.pregrasp = topGrasp(can + Eigen::Vector3d(0, 0, 0.10), std::vector<double>{0, 0.5, 1.0, 0, 1.5, 0});
  s.grasp = topGrasp(can, s.pregrasp);
  return s;
}

/// Moves the arm to `q` (checked).
void moveArmTo(Simulator& sim, const std::vector<double>& q, const std::string& id) {
  ASSERT_TRUE(sim.submit(armCommand(id, ActionKind::kMoveArm, {sim.robotState().state.arm, q})));
  const StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  ASSERT_EQ(e.results[0].outcome, Outcome::kSucceeded) << e.results[0].reason;
}

TEST(ManipulationTest, PickAttachesTheObjectAndPlacePutsItOnARegion) {
  const SimParams params = exactParams();
  Simulator sim(kitchen(), robotModel(), upright(), params);
  const Eigen::Vector3d can = sim.world().object("can").pose.translation();
  const PickSetup ps = pickSetup(can);
  moveArmTo(sim, ps.pregrasp, "to_pregrasp");

  ActionCommand pick = armCommand("pick", ActionKind::kPick, {ps.pregrasp, ps.grasp, ps.pregrasp});
  pick.object_id = "can";
  pick.object_pose = sim.world().object("can").pose;
  ASSERT_TRUE(sim.submit(pick));
  StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  ASSERT_EQ(e.results[0].outcome, Outcome::kSucceeded) << e.results[0].reason;
  EXPECT_TRUE(e.world_changed);
  // Held by the tool link, lifted 10 cm with the gripper, no longer on the table region.
  ASSERT_TRUE(sim.world().held());
  EXPECT_EQ(sim.world().held()->object_id, "can");
  EXPECT_EQ(sim.world().held()->link, "gripper_tcp");
  EXPECT_EQ(sim.robotState().held_object_id, "can");
  const world::Object& held = sim.world().object("can");
  EXPECT_TRUE(held.region.empty());
  EXPECT_NEAR(held.pose.translation().z(), can.z() + 0.10, 2e-3);
  // Timing: approach and retreat are the tool's 10 cm, the model with the TRUE pick
  // parameters and the can's true mass on the retreat.
  ASSERT_EQ(e.records.size(), 1u);
  const auto& rec = e.records[0];
  EXPECT_TRUE(rec.action.path.empty());
  EXPECT_NEAR(rec.action.approach_m, 0.10, 2e-3);
  EXPECT_NEAR(rec.action.retreat_m, 0.10, 2e-3);
  EXPECT_DOUBLE_EQ(rec.action.object_mass_kg, 0.4);
  EXPECT_NEAR(e.results[0].duration_s, trueTime(rec, params), 1e-9);

  // Carry it: turn the base; the can moves with the gripper.
  ASSERT_TRUE(sim.submit(moveBase("turn", {{0, 0, 0}, {0, 0, M_PI / 2}})));
  e = runToEnd(sim);
  ASSERT_EQ(e.results.at(0).outcome, Outcome::kSucceeded) << e.results[0].reason;
  EXPECT_DOUBLE_EQ(e.records.at(0).action.object_mass_kg, 0.4);
  const Eigen::Vector3d carried = sim.world().object("can").pose.translation();
  EXPECT_NEAR(carried.x(), -can.y(), 2e-3);  // rotated by +90 deg about the base origin
  EXPECT_NEAR(carried.y(), can.x(), 2e-3);
  const auto tool = robotModel().toolPoseInWorld(sim.robotState().state);
  EXPECT_TRUE((tool * sim.world().held()->link_T_object).translation().isApprox(carried, 1e-9));

  // Place it on the side table (now in front of the robot) at the grasp height.
  Eigen::Isometry3d target = sim.world().object("can").pose;
  target.translation().z() = kTableTop + 0.06;
  ActionCommand place = armCommand("place", ActionKind::kPlace, {ps.pregrasp, ps.grasp, ps.pregrasp});
  place.object_id = "can";
  place.object_pose = target;
  ASSERT_TRUE(sim.submit(place));
  e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].outcome, Outcome::kSucceeded) << e.results[0].reason;
  EXPECT_FALSE(sim.world().held());
  const world::Object& placed = sim.world().object("can");
  EXPECT_EQ(placed.region, "side_top");
  EXPECT_NEAR(placed.pose.translation().z(), kTableTop + 0.06, 1e-9);  // resting on the surface
  EXPECT_LT((placed.pose.translation() - target.translation()).norm(), 3e-3);
  EXPECT_NEAR(placed.pose.linear()(2, 2), 1.0, 1e-12);
  EXPECT_NEAR(e.results[0].duration_s, trueTime(e.records.at(0), params),
              1e-9);
  EXPECT_DOUBLE_EQ(e.records[0].action.object_mass_kg, 0.4);
  // Moving away leaves it there.
  ASSERT_TRUE(sim.submit(moveBase("leave", {{0, 0, M_PI / 2}, {0, 0, 0}})));
  runToEnd(sim);
  EXPECT_TRUE(sim.world().object("can").pose.isApprox(placed.pose, 0));
}

// The physical world has no ids: perception names an object it found itself ("seen_can_1"), and
// the robot picks what is where the command says. The name stays bound to that object: the place
// names it, the robot reports holding it by that name, and a snapshot keeps the binding.
TEST(ManipulationTest, AnObjectNamedByPerceptionIsPickedAndPlacedWhereTheCommandSaysItIs) {
  const SimParams params = exactParams();
  Simulator sim(kitchen(), robotModel(), upright(), params);
  const Eigen::Vector3d can = sim.world().object("can").pose.translation();
  const PickSetup ps = pickSetup(can);
  moveArmTo(sim, ps.pregrasp, "to_pregrasp");
  // Nothing at the commanded pose: the name binds to nothing, the pick (closing the gripper
  // where the arm stands) fails naming it.
  ActionCommand astray = armCommand("astray", ActionKind::kPick, {ps.pregrasp, ps.pregrasp});
  astray.object_id = "seen_can_1";
  astray.object_pose = at(0.58, 0.3, kTableTop + 0.06);
  ASSERT_TRUE(sim.submit(astray));
  StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.at(0).outcome, Outcome::kFailed);
  EXPECT_NE(e.results[0].reason.find("no object 'seen_can_1'"), std::string::npos) << e.results[0].reason;
  EXPECT_TRUE(sim.snapshot().names.empty());
  // Where the can is, 1 cm off: that is the can.
  ActionCommand pick = armCommand("pick", ActionKind::kPick, {ps.pregrasp, ps.grasp, ps.pregrasp});
  pick.object_id = "seen_can_1";
  pick.object_pose = at(can.x() + 0.01, can.y(), can.z());
  ASSERT_TRUE(sim.submit(pick));
  e = runToEnd(sim);
  ASSERT_EQ(e.results.at(0).outcome, Outcome::kSucceeded) << e.results[0].reason;
  ASSERT_TRUE(sim.world().held());
  EXPECT_EQ(sim.world().held()->object_id, "can");
  EXPECT_EQ(sim.robotState().held_object_id, "seen_can_1");
  EXPECT_EQ(sim.snapshot().names, (std::map<std::string, std::string>{{"seen_can_1", "can"}}));
  ASSERT_TRUE(sim.submit(moveBase("turn", {{0, 0, 0}, {0, 0, M_PI / 2}})));
  ASSERT_EQ(runToEnd(sim).results.at(0).outcome, Outcome::kSucceeded);
  Eigen::Isometry3d target = sim.world().object("can").pose;
  target.translation().z() = kTableTop + 0.06;
  ActionCommand place = armCommand("place", ActionKind::kPlace, {ps.pregrasp, ps.grasp, ps.pregrasp});
  place.object_id = "seen_can_1";
  place.object_pose = target;
  ASSERT_TRUE(sim.submit(place));
  e = runToEnd(sim);
  ASSERT_EQ(e.results.at(0).outcome, Outcome::kSucceeded) << e.results[0].reason;
  EXPECT_FALSE(sim.world().held());
  EXPECT_EQ(sim.world().object("can").region, "side_top");
  EXPECT_EQ(sim.robotState().held_object_id, "");
}

/// Picks the can of `kitchen()` and turns the base so that it is over the side table.
void pickAndTurn(Simulator& sim, const PickSetup& ps) {
  moveArmTo(sim, ps.pregrasp, "to_pregrasp");
  ActionCommand pick = armCommand("pick", ActionKind::kPick, {ps.pregrasp, ps.grasp, ps.pregrasp});
  pick.object_id = "can";
  pick.object_pose = sim.world().object("can").pose;
  ASSERT_TRUE(sim.submit(pick));
  StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.at(0).outcome, Outcome::kSucceeded) << e.results[0].reason;
  ASSERT_TRUE(sim.submit(moveBase("turn", {{0, 0, 0}, {0, 0, M_PI / 2}})));
  e = runToEnd(sim);
  ASSERT_EQ(e.results.at(0).outcome, Outcome::kSucceeded) << e.results[0].reason;
}

// A place whose arm motion takes the held object a little into its support (the robot believed
// the object shorter, or held higher, than it is: a cup learned at the gripper from a partial
// view) is a place with the arm's compliance: the object is pressed onto the support and released
// there, resting on its surface, as far as settle() accepts a release into the support (2 cm).
// Deeper, the robot stops before the contact, as before any other object.
TEST(ManipulationTest, APlacePressingTheObjectUpTo2cmIntoItsSupportSucceeds) {
  for (const double press : {0.012, 0.035}) {
    Simulator sim(kitchen(), robotModel(), upright(), exactParams());
    const Eigen::Vector3d can = sim.world().object("can").pose.translation();
    const PickSetup ps = pickSetup(can);
    pickAndTurn(sim, ps);
    const PickSetup low = pickSetup(can - Eigen::Vector3d(0, 0, press));
    Eigen::Isometry3d target = sim.world().object("can").pose;
    target.translation().z() = kTableTop + 0.06 - press;  // what the robot believed
    ActionCommand place = armCommand("place", ActionKind::kPlace, {ps.pregrasp, low.grasp, ps.pregrasp});
    place.object_id = "can";
    place.object_pose = target;
    ASSERT_TRUE(sim.submit(place));
    const StepEvents e = runToEnd(sim);
    ASSERT_EQ(e.results.size(), 1u);
    if (press < 0.02) {
      EXPECT_EQ(e.results[0].outcome, Outcome::kSucceeded) << "press " << press << ": " << e.results[0].reason;
      EXPECT_FALSE(sim.world().held());
      const world::Object& placed = sim.world().object("can");
      EXPECT_EQ(placed.region, "side_top");
      EXPECT_NEAR(placed.pose.translation().z(), kTableTop + 0.06, 1e-9) << "resting on the surface";
    } else {
      EXPECT_EQ(e.results[0].outcome, Outcome::kBlocked) << "press " << press << ": " << e.results[0].reason;
      EXPECT_EQ(e.results[0].blocking_object_id, "side_table");
      EXPECT_TRUE(sim.world().held());
    }
  }
}

// A parallel-jaw gripper closing on an object that is off-centre between its fingers (within the
// pick tolerances) pushes it to the centre, and turns a box that stands a little askew flat against
// the pads: the object is held where the fingers put it, not where it stood. Along the other
// axes it stays where it was. (Perception's estimate of a thin box is often 2 cm and a few
// degrees off; the planner's grasp assumes the object centred between the fingers.)
TEST(ManipulationTest, TheClosingFingersCentreTheObjectAndSquareABox) {
  world::World w = emptyRoom();
  ASSERT_TRUE(w.addObject(box("table", 0.6, 0.8, kTableTop, at(0.7, 0.0, kTableTop / 2))));
  world::Region top;
  top.id = "table_top";
  top.kind = world::RegionKind::kTable;
  top.polygon = {{0.4, -0.4}, {1.0, -0.4}, {1.0, 0.4}, {0.4, 0.4}};
  top.height = kTableTop;
  ASSERT_TRUE(w.addRegion(top));
  const Eigen::Isometry3d believed = at(0.58, 0.0, kTableTop + 0.06);
  // The truth: 1.5 cm along the closing axis (world y for a top grasp), 4 mm along the tool's x,
  // turned by 0.08 rad; 5 cm thick across the fingers.
  world::Object thin = box("thin", 0.20, 0.05, 0.12, at(0.584, 0.015, kTableTop + 0.06, 0.08), true);
  thin.graspable = true;
  thin.region = "table_top";
  ASSERT_TRUE(w.addObject(thin));
  Simulator sim(w, robotModel(), upright(), exactParams());
  const PickSetup ps = pickSetup(believed.translation());
  moveArmTo(sim, ps.pregrasp, "to_pregrasp");
  ActionCommand pick = armCommand("pick", ActionKind::kPick, {ps.pregrasp, ps.grasp, ps.pregrasp});
  pick.object_id = "thin";
  pick.object_pose = believed;
  ASSERT_TRUE(sim.submit(pick));
  const StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  ASSERT_EQ(e.results[0].outcome, Outcome::kSucceeded) << e.results[0].reason;
  ASSERT_TRUE(sim.world().held());
  const robot::RobotState at_grasp{Pose2D{}, ps.grasp, 0.0};
  const Eigen::Isometry3d tool_at_grasp = robotModel().toolPoseInWorld(at_grasp);
  const Eigen::Isometry3d before = tool_at_grasp.inverse() * thin.pose;
  const Eigen::Isometry3d held = sim.world().held()->link_T_object;
  EXPECT_NEAR(held.translation().y(), 0.0, 1e-9) << "not centred between the fingers";
  EXPECT_NEAR(std::abs(held.linear()(1, 1)), 1.0, 1e-9) << "the box's faces are not flat against the pads";
  EXPECT_NEAR(held.translation().x(), before.translation().x(), 1e-9);
  EXPECT_NEAR(held.translation().z(), before.translation().z(), 1e-9);
  EXPECT_GT(std::abs(before.translation().y()), 0.01);  // the test's premise: it was off-centre
}

TEST(ManipulationTest, PickFailsWhenTheObjectIsNotWhereTheCommandSays) {
  Simulator sim(kitchen(), robotModel(), upright(), exactParams());
  const world::Object can = sim.world().object("can");
  const PickSetup ps = pickSetup(can.pose.translation());
  moveArmTo(sim, ps.pregrasp, "to_pregrasp");
  // The command believes the can is 10 cm further to the side.
  ActionCommand pick = armCommand("pick", ActionKind::kPick, {ps.pregrasp, ps.grasp, ps.pregrasp});
  pick.object_id = "can";
  pick.object_pose = can.pose * at(0, 0.10, 0);
  ASSERT_TRUE(sim.submit(pick));
  const StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].outcome, Outcome::kFailed);
  EXPECT_NE(e.results[0].reason.find("not where the command says"), std::string::npos) << e.results[0].reason;
  EXPECT_FALSE(e.records.at(0).success);
  EXPECT_FALSE(sim.world().held());
  EXPECT_TRUE(sim.world().object("can").pose.isApprox(can.pose, 0));
  EXPECT_EQ(sim.world().object("can").region, "table_top");
  // The arm still completed its retreat (the gripper closed on nothing).
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(sim.robotState().state.arm[j], ps.pregrasp[j], 1e-9);
}

TEST(ManipulationTest, PickFailsForAnObjectOutOfTheGripperNotGraspableOrTooHeavy) {
  {
    // The gripper closes 10 cm beside the can.
    Simulator sim(kitchen(), robotModel(), upright(), exactParams());
    const Eigen::Vector3d can = sim.world().object("can").pose.translation();
    const PickSetup ps = pickSetup(can + Eigen::Vector3d(0, 0.10, 0));
    moveArmTo(sim, ps.pregrasp, "to_pregrasp");
    ActionCommand pick = armCommand("pick", ActionKind::kPick, {ps.pregrasp, ps.grasp, ps.pregrasp});
    pick.object_id = "can";
    ASSERT_TRUE(sim.submit(pick));
    const StepEvents e = runToEnd(sim);
    EXPECT_EQ(e.results.at(0).outcome, Outcome::kFailed);
    EXPECT_NE(e.results[0].reason.find("m away from 'can'"), std::string::npos) << e.results[0].reason;
    EXPECT_FALSE(sim.world().held());
  }
  {
    world::World w = kitchen();
    world::Object can = w.object("can");
    can.graspable = false;  // e.g. glued down, or too slippery
    ASSERT_TRUE(w.updateObject(can));
    Simulator sim(w, robotModel(), upright(), exactParams());
    const PickSetup ps = pickSetup(can.pose.translation());
    moveArmTo(sim, ps.pregrasp, "to_pregrasp");
    ActionCommand pick = armCommand("pick", ActionKind::kPick, {ps.pregrasp, ps.grasp, ps.pregrasp});
    pick.object_id = "can";
    ASSERT_TRUE(sim.submit(pick));
    const StepEvents e = runToEnd(sim);
    EXPECT_EQ(e.results.at(0).outcome, Outcome::kFailed);
    EXPECT_NE(e.results[0].reason.find("'can' is not graspable"), std::string::npos) << e.results[0].reason;
    EXPECT_FALSE(sim.world().held());
  }
  {
    Simulator sim(kitchen(/*can_mass=*/12.0), robotModel(), upright(), exactParams());
    const PickSetup ps = pickSetup(sim.world().object("can").pose.translation());
    moveArmTo(sim, ps.pregrasp, "to_pregrasp");
    ActionCommand pick = armCommand("pick", ActionKind::kPick, {ps.pregrasp, ps.grasp, ps.pregrasp});
    pick.object_id = "can";
    ASSERT_TRUE(sim.submit(pick));
    const StepEvents e = runToEnd(sim);
    EXPECT_EQ(e.results.at(0).outcome, Outcome::kFailed);
    EXPECT_NE(e.results[0].reason.find("payload limit"), std::string::npos) << e.results[0].reason;
    // A failed pick is recorded without the object's mass (nothing was carried).
    EXPECT_DOUBLE_EQ(e.records.at(0).action.object_mass_kg, 0.0);
  }
}

TEST(ManipulationTest, ScriptedDropDuringACarryPutsTheObjectOnTheFloor) {
  Fault drop;
  drop.id = "slip";
  drop.type = FaultType::kDropHeldObject;
  drop.trigger.step = 2;  // 0: move_arm, 1: pick, 2: the carry
  drop.trigger.fraction = 0.6;
  Simulator sim(kitchen(), robotModel(), upright(), exactParams(), {drop});
  const PickSetup ps = pickSetup(sim.world().object("can").pose.translation());
  moveArmTo(sim, ps.pregrasp, "to_pregrasp");
  ActionCommand pick = armCommand("pick", ActionKind::kPick, {ps.pregrasp, ps.grasp, ps.pregrasp});
  pick.object_id = "can";
  ASSERT_TRUE(sim.submit(pick));
  ASSERT_EQ(runToEnd(sim).results.at(0).outcome, Outcome::kSucceeded);
  ASSERT_TRUE(sim.world().held());
  // Carry it backwards and away from the table (turn, drive), dropping it on the way.
  ASSERT_TRUE(sim.submit(moveBase("carry", {{0, 0, 0}, {0, 0, -M_PI / 2}, {0, -2, -M_PI / 2}})));
  const StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.faults.size(), 1u);
  EXPECT_EQ(e.faults[0].fault_id, "slip");
  EXPECT_EQ(e.faults[0].object_id, "can");
  EXPECT_FALSE(sim.world().held());
  EXPECT_EQ(sim.robotState().held_object_id, "");
  const world::Object& can = sim.world().object("can");
  EXPECT_NEAR(can.pose.translation().z(), 0.06, 1e-9);  // on the floor, upright
  EXPECT_EQ(can.region, "floor");
  // It fell in front of the robot, on its path: the rest of the drive is blocked by it.
  EXPECT_EQ(e.results.at(0).outcome, Outcome::kBlocked);
  EXPECT_EQ(e.results[0].blocking_object_id, "can");
}

// A pick that fails on its retreat, after the fingers closed ("the box slips out of the
// fingers"): the object is not carried away; it falls back onto what is below it, and the robot
// reports an empty gripper. A pick that fails on its approach leaves the object untouched.
TEST(ManipulationTest, APickThatFailsAfterTheGripperClosedLetsTheObjectFall) {
  for (double fraction : {0.2, 0.85}) {
    Fault slip;
    slip.id = "slip";
    slip.type = FaultType::kFailAction;
    slip.action = ActionKind::kPick;
    slip.trigger.step = 1;  // 0: move_arm, 1: the pick
    slip.trigger.fraction = fraction;
    Simulator sim(kitchen(), robotModel(), upright(), exactParams(), {slip});
    const Eigen::Vector3d before = sim.world().object("can").pose.translation();
    const PickSetup ps = pickSetup(before);
    moveArmTo(sim, ps.pregrasp, "to_pregrasp");
    ActionCommand pick = armCommand("pick", ActionKind::kPick, {ps.pregrasp, ps.grasp, ps.pregrasp});
    pick.object_id = "can";
    ASSERT_TRUE(sim.submit(pick));
    const StepEvents e = runToEnd(sim);
    ASSERT_EQ(e.results.size(), 1u);
    EXPECT_EQ(e.results[0].outcome, Outcome::kFailed) << "fraction " << fraction;
    EXPECT_FALSE(sim.world().held()) << "fraction " << fraction;
    EXPECT_EQ(sim.robotState().held_object_id, "") << "fraction " << fraction;
    const world::Object& can = sim.world().object("can");
    EXPECT_EQ(can.region, "table_top") << "fraction " << fraction;
    EXPECT_NEAR(can.pose.translation().z(), before.z(), 1e-6) << "fraction " << fraction;
    EXPECT_LT((can.pose.translation() - before).head<2>().norm(), 0.02) << "fraction " << fraction;
    if (fraction > 0.5) {
      ASSERT_EQ(e.faults.size(), 1u);
      EXPECT_EQ(e.faults[0].object_id, "can");
    }
  }
}

// "It slips while carried": a drop filtered by action kind waits for the first action of that kind
// that starts with something in the gripper (a move_base with an empty gripper does not count).
TEST(ManipulationTest, ADropFilteredByActionWaitsForTheFirstCarryingActionOfThatKind) {
  Fault drop;
  drop.id = "slip";
  drop.type = FaultType::kDropHeldObject;
  drop.trigger.step = 0;
  drop.trigger.fraction = 0.6;
  drop.action = ActionKind::kMoveBase;
  Simulator sim(kitchen(), robotModel(), upright(), exactParams(), {drop});
  // Step 0: a move_base with an empty gripper (a turn there and back): no drop.
  ASSERT_TRUE(sim.submit(moveBase("turn", {{0, 0, 0}, {0, 0, 0.3}, {0, 0, 0}})));
  StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.at(0).outcome, Outcome::kSucceeded);
  EXPECT_TRUE(e.faults.empty());
  const PickSetup ps = pickSetup(sim.world().object("can").pose.translation());
  moveArmTo(sim, ps.pregrasp, "to_pregrasp");
  ActionCommand pick = armCommand("pick", ActionKind::kPick, {ps.pregrasp, ps.grasp, ps.pregrasp});
  pick.object_id = "can";
  ASSERT_TRUE(sim.submit(pick));
  e = runToEnd(sim);
  ASSERT_EQ(e.results.at(0).outcome, Outcome::kSucceeded);
  EXPECT_TRUE(e.faults.empty()) << "a pick is not a move_base";
  ASSERT_TRUE(sim.world().held());
  ASSERT_TRUE(sim.submit(moveBase("carry", {{0, 0, 0}, {0, 0, -M_PI / 2}, {0, -2, -M_PI / 2}})));
  e = runToEnd(sim);
  ASSERT_EQ(e.faults.size(), 1u);
  EXPECT_EQ(e.faults[0].object_id, "can");
  EXPECT_FALSE(sim.world().held());
  EXPECT_EQ(sim.world().object("can").region, "floor");
}

TEST(ManipulationTest, ADropFilteredByActionNeedsAStepTrigger) {
  Fault drop;
  drop.type = FaultType::kDropHeldObject;
  drop.trigger.time_s = 1.0;
  drop.action = ActionKind::kMoveBase;
  const Status s = drop.validate(true);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("action"), std::string::npos) << s.error().message;
  drop.trigger.time_s.reset();
  drop.trigger.step = 1;
  EXPECT_TRUE(drop.validate(true).ok());
  Fault spawn;
  spawn.type = FaultType::kRemoveObject;
  spawn.object_id = "can";
  spawn.action = ActionKind::kPick;
  EXPECT_FALSE(spawn.validate(false).ok()) << "only failing actions and drops take an action kind";
}

}  // namespace
}  // namespace tamp::sim
