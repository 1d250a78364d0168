// The checks of one command against the NAMO corridor's planner world and the project's robot:
// malformed commands named by field, the trajectory start against the robot, the held object, a
// pick's object, and the swept path check (blocked, allowed contacts, the remaining part only).
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "tamp/execution_monitor/checks.h"
#include "test_fixtures.h"

namespace tamp::execution_monitor {
namespace {

using namespace testing;

class ChecksTest : public ::testing::Test {
 protected:
  const robot::RobotModel& robot_ = robotModel();
  const world::World world_ = corridor().plannerWorld();
  const robot::RobotState start_ = corridor().startState();  // (1.5, 1.2, 0), arm stowed
};

std::string fieldOf(const Status& s) { return s ? "" : s.error().where.field; }

TEST_F(ChecksTest, MalformedCommandsNameTheField) {
  const ExecutionCommand good = moveBase("c", {{1.5, 1.2, 0}, {2.5, 1.2, 0}});
  EXPECT_TRUE(validateCommand(good, robot_));

  ExecutionCommand c = good;
  c.trajectory.points.clear();
  EXPECT_EQ(fieldOf(validateCommand(c, robot_)), "trajectory.points");

  c = good;
  c.trajectory.points[1].positions[0] = std::nan("");
  EXPECT_EQ(fieldOf(validateCommand(c, robot_)), "trajectory.points[1].positions[0]");

  c = good;
  c.trajectory.joint_names[1] = "base_q";
  const Status unknown = validateCommand(c, robot_);
  EXPECT_EQ(fieldOf(unknown), "trajectory.joint_names[1]");
  EXPECT_NE(unknown.error().message.find("unknown joint 'base_q'"), std::string::npos)
      << unknown.error().message;

  c = good;
  c.trajectory.points[1].time_from_start = 0.0;
  EXPECT_EQ(fieldOf(validateCommand(c, robot_)), "trajectory.points[1].time_from_start");

  c = good;
  c.trajectory.joint_names = {"base_x", "base_y", robot_.armJointNames().front()};
  EXPECT_EQ(fieldOf(validateCommand(c, robot_)), "trajectory.joint_names[2]");

  c = good;
  c.kind = static_cast<ActionKind>(7);
  EXPECT_EQ(fieldOf(validateCommand(c, robot_)), "kind");

  c = good;
  c.command_id.clear();
  EXPECT_EQ(fieldOf(validateCommand(c, robot_)), "command_id");

  c = good;
  c.expected_duration_s = -1.0;
  EXPECT_EQ(fieldOf(validateCommand(c, robot_)), "expected_duration_s");

  ExecutionCommand place;
  place.command_id = "p";
  place.kind = ActionKind::kPlace;
  place.object_id = "box";
  place.trajectory.joint_names = robot_.armJointNames();
  place.trajectory.points.push_back({0.0, start_.arm, {}});
  EXPECT_EQ(fieldOf(validateCommand(place, robot_)), "object_target");
  place.object_id.clear();
  EXPECT_EQ(fieldOf(validateCommand(place, robot_)), "object_id");
  place.object_id = "box";
  place.object_target = Eigen::Isometry3d::Identity();
  EXPECT_TRUE(validateCommand(place, robot_));
  place.trajectory.points[0].positions[1] = robot_.armLimits()[1].upper + 0.1;
  const Status limits = validateCommand(place, robot_);
  EXPECT_EQ(fieldOf(limits), "trajectory.points[0].positions[1]");
  EXPECT_NE(limits.error().message.find("outside its limits"), std::string::npos)
      << limits.error().message;
}

TEST_F(ChecksTest, StartMustMatchTheRobot) {
  EXPECT_FALSE(checkStart(moveBase("c", {{1.5, 1.2, 0}, {2.5, 1.2, 0}}), start_, robot_, {}));
  // A heading off by a full turn is the same heading.
  EXPECT_FALSE(checkStart(moveBase("c", {{1.52, 1.2, 2 * std::numbers::pi}, {2.5, 1.2, 0}}), start_,
                          robot_, {}));
  auto off = checkStart(moveBase("c", {{1.8, 1.2, 0}, {2.5, 1.2, 0}}), start_, robot_, {});
  ASSERT_TRUE(off);
  EXPECT_EQ(off->reason.rfind("start:", 0), 0u) << off->reason;
  EXPECT_NE(off->reason.find("base_x"), std::string::npos) << off->reason;
  auto turned = checkStart(moveBase("c", {{1.5, 1.2, 0.2}, {2.5, 1.2, 0}}), start_, robot_, {});
  ASSERT_TRUE(turned);
  EXPECT_NE(turned->reason.find("base_theta"), std::string::npos) << turned->reason;
}

TEST_F(ChecksTest, HeldObjectAndPickTarget) {
  ExecutionCommand place;
  place.kind = ActionKind::kPlace;
  place.object_id = "box";
  EXPECT_FALSE(checkHeld(place, "box"));
  auto empty = checkHeld(place, "");
  ASSERT_TRUE(empty);
  EXPECT_EQ(empty->reason.rfind("held object:", 0), 0u);
  EXPECT_TRUE(checkHeld(place, "can"));
  ExecutionCommand pick = place;
  pick.kind = ActionKind::kPick;
  EXPECT_FALSE(checkHeld(pick, ""));
  EXPECT_TRUE(checkHeld(pick, "can"));
  EXPECT_FALSE(checkHeld(moveBase("m", {{0, 0, 0}}), "box"));

  EXPECT_FALSE(checkPickTarget(pick, world_, 0.05));
  pick.object_target = world_.findObject("box")->pose;
  EXPECT_FALSE(checkPickTarget(pick, world_, 0.05));
  pick.object_target->translation().x() += 0.2;
  auto moved = checkPickTarget(pick, world_, 0.05);
  ASSERT_TRUE(moved);
  EXPECT_EQ(moved->reason.rfind("object_target:", 0), 0u) << moved->reason;
  pick.object_id = "ghost";
  auto ghost = checkPickTarget(pick, world_, 0.05);
  ASSERT_TRUE(ghost);
  EXPECT_EQ(ghost->object_id, "ghost");
  pick.object_id = "wall_south";
  EXPECT_TRUE(checkPickTarget(pick, world_, 0.05));
}

TEST_F(ChecksTest, PathCheckFindsTheFirstObjectOnThePath) {
  PathChecker checker(robot_, {});
  checker.setWorld(world_);
  const std::vector<std::string> none;
  // Free floor ahead of the start.
  const SweptPath clear = makePath(moveBase("c", {{1.5, 1.2, 0}, {3.0, 1.2, 0}}), start_, robot_);
  EXPECT_FALSE(checker.firstContact(clear, 0.0, none));
  // Into the box standing across the corridor's mouth.
  const SweptPath into = makePath(moveBase("c", {{1.5, 1.2, 0}, {5.0, 1.2, 0}}), start_, robot_);
  auto hit = checker.firstContact(into, 0.0, none);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->object_id, "box");
  EXPECT_GT(hit->fraction, 0.5);
  EXPECT_LT(hit->fraction, 1.0);
  // The box allowed (a pick's object): the next thing in the way is not the box.
  auto past = checker.firstContact(into, 0.0, {"box"});
  if (past) {
    EXPECT_NE(past->object_id, "box");
  }

  // A crate appears 0.5 m ahead: on the path from the start, not on what is left after it.
  checker.setWorld(withCrate(world_, "crate", 2.3, 1.2));
  auto crate_hit = checker.firstContact(clear, 0.0, none);
  ASSERT_TRUE(crate_hit);
  EXPECT_EQ(crate_hit->object_id, "crate");
  EXPECT_FALSE(checker.firstContact(clear, 0.95, {}));
  EXPECT_FALSE(checker.firstContact(clear, 0.0, {"crate"}));
  EXPECT_EQ(checker.contactsAt(clear.at(crate_hit->fraction)), std::vector<std::string>{"crate"});
}

// What the planner found touching at the start (its robot is not shrunk; an object just put
// down) is a few mm away from the monitor's shrunk robot: it counts as a start contact, which the
// path may leave; an object a few cm away does not.
TEST_F(ChecksTest, AnObjectJustOutOfReachOfTheShrunkRobotIsAStartContact) {
  PathChecker checker(robot_, {});
  checker.setWorld(withCrate(world_, "crate", 2.3, 1.2));
  // Where the robot driving at the crate first touches it (bisection on the base's x).
  auto at = [&](double x) {
    robot::RobotState s = start_;
    s.base = {x, 1.2, 0.0};
    return s;
  };
  double free_x = 1.5, touching_x = 2.3;
  ASSERT_TRUE(checker.contactsAt(at(free_x)).empty());
  ASSERT_FALSE(checker.contactsAt(at(touching_x)).empty());
  while (touching_x - free_x > 1e-4) {
    const double mid = 0.5 * (free_x + touching_x);
    (checker.contactsAt(at(mid)).empty() ? free_x : touching_x) = mid;
  }
  const std::vector<std::string> crate{"crate"};
  EXPECT_TRUE(checker.contactsAt(at(free_x - 0.005)).empty());
  EXPECT_EQ(checker.startContactsAt(at(free_x - 0.005)), crate);
  EXPECT_EQ(checker.startContactsAt(at(touching_x)), crate);
  EXPECT_TRUE(checker.startContactsAt(at(free_x - 0.03)).empty());
  PathCheckParams exact;
  exact.start_contact_m = 0.0;
  PathChecker strict(robot_, exact);
  strict.setWorld(withCrate(world_, "crate", 2.3, 1.2));
  EXPECT_TRUE(strict.startContactsAt(at(free_x - 0.005)).empty());
}

// The base drives stop-and-turn (as the robot does): straight through the 0.7 m corridor at its
// heading, then the turn to the goal's yaw in the open. A blend of yaw and position would turn
// the 0.6 m base across the corridor and touch its walls.
TEST_F(ChecksTest, ABasePathIsCheckedAsTheRobotDrivesItStopAndTurn) {
  PathChecker checker(robot_, {});
  checker.setWorld(world_);
  const double half_pi = std::numbers::pi / 2;
  const SweptPath through = makePath(moveBase("c", {{1.5, 1.2, 0}, {7.2, 1.2, half_pi}}), start_, robot_);
  EXPECT_NEAR(through.at(0.5).base.theta, 0.0, 1e-9) << "the base turns while driving";
  EXPECT_NEAR(through.at(1.0).base.theta, half_pi, 1e-9);
  EXPECT_NEAR(through.at(1.0).base.x, 7.2, 1e-9);
  const auto hit = checker.firstContact(through, 0.0, {"box"});
  EXPECT_FALSE(hit) << "touches " << hit->object_id << " at " << hit->fraction;
}

TEST_F(ChecksTest, SupportsOfAnObjectOnATable) {
  auto sc = world::loadScenario(configDir() / "scenarios" / "occluded_can.yaml");
  ASSERT_TRUE(sc) << sc.error().toString();
  const world::World w = sc->plannerWorld();
  PathChecker checker(robot_, {});
  checker.setWorld(w);
  const world::Object* can = w.findObject("can");
  ASSERT_NE(can, nullptr);
  EXPECT_EQ(checker.supportsOf(*can, can->pose), std::vector<std::string>{"table_body"});
  // Above the counter, 2 cm up: resting on nothing.
  Eigen::Isometry3d above = can->pose;
  above.translation() = Eigen::Vector3d(0.0, 1.9, 0.70 + 0.06 + 0.02);
  EXPECT_TRUE(checker.supportsOf(*can, above).empty());
  above.translation().z() = 0.70 + 0.06;
  EXPECT_EQ(checker.supportsOf(*can, above), std::vector<std::string>{"counter_body"});
}

TEST_F(ChecksTest, PathProjectionIsMonotone) {
  const SweptPath p =
      makePath(moveBase("c", {{1.5, 1.2, 0}, {2.5, 1.2, 0}, {1.5, 1.2, 0}}), start_, robot_);
  robot::RobotState s = start_;
  s.base.x = 2.0;
  EXPECT_NEAR(p.project(s), 0.25, 1e-9);
  EXPECT_NEAR(p.project(s, 0.5), 0.75, 1e-9);  // on the way back, not rewound
  s.base.x = 2.5;
  EXPECT_NEAR(p.project(s), 0.5, 1e-9);
  EXPECT_NEAR(p.at(0.75).base.x, 2.0, 1e-9);
}

}  // namespace
}  // namespace tamp::execution_monitor
