// The simulator's checkpoint file (node/checkpoint.h): read back exactly, and a broken one refused
// naming the file, the line and the field.
#include "checkpoint.h"

#include <gtest/gtest.h>

#include "sim_test_util.h"

namespace tamp::sim {
namespace {

using namespace tamp::sim::testing;

SimSnapshot sampleSnapshot() {
  SimSnapshot s;
  s.time_s = 12.345678901234;
  s.epoch_s = 1796333902.4864765;
  s.robot = upright(Pose2D{1.25, -0.5, 0.3});
  s.robot.arm[1] = 0.123456789012345;
  s.held = world::HeldObject{"carried", robotModel().options().tool_link,
                             Eigen::Isometry3d(Eigen::Translation3d(0.01, 0.0, 0.05)) *
                                 Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ())};
  world::Object carried = box("carried", 0.05, 0.05, 0.1, at(1.5, -0.5, 1.0, 0.4), true);
  carried.graspable = true;
  carried.region = "";
  world::Object wall = box("hidden_wall", 0.2, 3.0, 1.0, at(6.0, 0.0, 0.5), false, true);
  world::Object crate = box("crate", 0.3, 0.3, 0.3, at(2.0, 1.0, 0.15, -0.7), true, true);
  crate.region = "floor";
  s.objects = {carried, crate, wall};
  s.fired_faults = {"fault_0", "fault_2"};
  s.pending_faults = {"fault_2"};
  ActionResult done{"m1-e1", Outcome::kBlocked, 4.5,
                    0.625,   "crate",           "stopped before contact with 'crate'"};
  s.log.push_back(ActionLogEntry{"m1-e1", ActionKind::kMoveBase, 0, 0.5, done});
  s.log.push_back(ActionLogEntry{"id with spaces", ActionKind::kPick, 1, 7.25, std::nullopt});
  s.names = {{"seen_box_1", "carried"}};
  return s;
}

TEST(SimCheckpointTest, ReadsBackExactly) {
  const SimSnapshot s = sampleSnapshot();
  auto back = parseCheckpoint(formatCheckpoint(s), "sim.checkpoint");
  ASSERT_TRUE(back) << back.error().toString();
  EXPECT_EQ(back->time_s, s.time_s);
  EXPECT_EQ(back->epoch_s, s.epoch_s);
  EXPECT_EQ(back->robot.base.x, s.robot.base.x);
  EXPECT_EQ(back->robot.base.y, s.robot.base.y);
  EXPECT_EQ(back->robot.base.theta, s.robot.base.theta);
  EXPECT_EQ(back->robot.arm, s.robot.arm);
  EXPECT_EQ(back->robot.gripper, s.robot.gripper);
  ASSERT_TRUE(back->held.has_value());
  EXPECT_EQ(*back->held, *s.held);
  ASSERT_EQ(back->objects.size(), s.objects.size());
  for (std::size_t i = 0; i < s.objects.size(); ++i) {
    EXPECT_EQ(back->objects[i], s.objects[i]) << s.objects[i].id;  // kind and hidden included
  }
  EXPECT_EQ(back->fired_faults, s.fired_faults);
  EXPECT_EQ(back->pending_faults, s.pending_faults);
  ASSERT_EQ(back->log.size(), 2u);
  EXPECT_EQ(back->log[0].command_id, "m1-e1");
  EXPECT_EQ(back->log[0].kind, ActionKind::kMoveBase);
  EXPECT_EQ(back->log[0].step, 0);
  EXPECT_EQ(back->log[0].start_s, 0.5);
  ASSERT_TRUE(back->log[0].result.has_value());
  EXPECT_EQ(back->log[0].result->outcome, Outcome::kBlocked);
  EXPECT_EQ(back->log[0].result->duration_s, 4.5);
  EXPECT_EQ(back->log[0].result->progress, 0.625);
  EXPECT_EQ(back->log[0].result->blocking_object_id, "crate");
  EXPECT_EQ(back->log[0].result->reason, "stopped before contact with 'crate'");
  EXPECT_EQ(back->log[1].command_id, "id with spaces");
  EXPECT_EQ(back->log[1].kind, ActionKind::kPick);
  EXPECT_FALSE(back->log[1].result.has_value());
  EXPECT_EQ(back->names, s.names);
}

TEST(SimCheckpointTest, ABrokenCheckpointIsRefusedNamingTheFileLineAndField) {
  const std::string good = formatCheckpoint(sampleSnapshot());
  // Replaces the line starting with `prefix` by `replacement`.
  const auto edited = [&](const std::string& prefix, const std::string& replacement) {
    std::string text = good;
    const std::size_t at = text.find("\n" + prefix) + 1;
    const std::size_t end = text.find('\n', at);
    return text.replace(at, end - at, replacement);
  };
  struct Case {
    std::string text;
    int line;
    std::string field;
  };
  const std::vector<Case> cases{
      {"tamp-perception-checkpoint 1\n", 1, "header"},
      {edited("robot ", "robot 1.0 2.0 0.1 0.0 0.5 nan 0.2"), 4, "robot.arm[1]"},
      {edited("robot ", "robot 1.0 2.0"), 4, "robot"},
      {edited("time ", "time -3"), 2, "time"},
      {edited("epoch ", "epoch 0"), 3, "epoch"},
      {edited("held ", "held carried tool 1 0 0"), 5, "held"},
      {edited("object ", "object visible 0a0b"), 6, "object"},
      {edited("object ", "object wobbly 00"), 6, "object.hidden"},
      {edited("action ", "action 0 0.5 move_base 6d31 exploded 1 1 - -"), 12, "action.outcome"},
      {edited("action ", "action 0 0.5 fly 6d31 running"), 12, "action.kind"},
      {good + "teleport 1 2 3\n", 15, "record"},
      {edited("name ", "name seen_box_1"), 14, "name"},
      {good + "name seen_box_1 crate\n", 15, "name"},
      {"tamp-sim-checkpoint 1\ntime 1.0\nepoch 5.0\n", 4, "robot"},
      {"tamp-sim-checkpoint 1\ntime 1.0\n", 3, "epoch"},
  };
  for (const Case& c : cases) {
    auto r = parseCheckpoint(c.text, "/run/sim.checkpoint");
    ASSERT_FALSE(r) << c.field;
    EXPECT_EQ(r.error().code, ErrorCode::kParseError);
    EXPECT_EQ(r.error().where.file, "/run/sim.checkpoint");
    EXPECT_EQ(r.error().where.line, c.line) << c.field << ": " << r.error().toString();
    EXPECT_EQ(r.error().where.field, c.field) << r.error().toString();
    EXPECT_NE(r.error().toString().find("/run/sim.checkpoint"), std::string::npos);
  }
}

}  // namespace
}  // namespace tamp::sim
