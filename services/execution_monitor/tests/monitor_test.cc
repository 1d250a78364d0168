// The monitor's state machine driven with a fake clock: a valid move ends SUCCEEDED with the
// robot's duration and a held object from a state written after the result; a repeated id is
// never executed again; failed preconditions, a new obstacle on the remaining path, a dropped
// object, an overrun and the robot's own outcomes map to the documented statuses and failures;
// records are forwarded once per id.
#include <gtest/gtest.h>

#include "tamp/execution_monitor/monitor.h"
#include "test_fixtures.h"

namespace tamp::execution_monitor {
namespace {

using namespace testing;

class MonitorTest : public ::testing::Test {
 protected:
  MonitorTest() : monitor_(MonitorParams{}, robotModel()) {}

  RobotObservation observe(double x, std::int64_t stamp, const std::string& held = "") {
    RobotObservation o;
    o.state = corridor().startState();
    o.state.base.x = x;
    o.held_object_id = held;
    o.stamp_ns = stamp;
    return o;
  }
  /// The world and the robot at the start, as the node would feed them.
  void ready(const std::string& held = "") {
    EXPECT_TRUE(monitor_.onWorld(world_, 1, now_).empty());
    EXPECT_TRUE(monitor_.onRobotState(observe(1.5, stamp_, held), now_).empty());
  }
  RobotResult result(const std::string& id, RobotOutcome outcome, double duration) {
    RobotResult r;
    r.command_id = id;
    r.outcome = outcome;
    r.duration_s = duration;
    r.progress = outcome == RobotOutcome::kSucceeded ? 1.0 : 0.5;
    r.stamp_ns = (stamp_ += 10);
    return r;
  }
  static const StatusUpdate* finalOf(const Outputs& out) {
    for (const auto& s : out.statuses) {
      if (isFinal(s.state)) return &s;
    }
    return nullptr;
  }

  ExecutionMonitor monitor_;
  world::World world_ = corridor().plannerWorld();
  double now_ = 100.0;
  std::int64_t stamp_ = 1000;
};

TEST_F(MonitorTest, ValidMoveSucceedsOnceWithTheRobotsDurationAndHeldObject) {
  ready();
  const ExecutionCommand c = moveBase("go", {{1.5, 1.2, 0}, {2.5, 1.2, 0}});
  Outputs out = monitor_.onCommand(c, now_);
  ASSERT_EQ(out.statuses.size(), 2u);
  EXPECT_EQ(out.statuses[0].state, ExecState::kAccepted);
  EXPECT_EQ(out.statuses[1].state, ExecState::kRunning);
  ASSERT_EQ(out.robot.size(), 1u);
  EXPECT_EQ(out.robot[0].type, RobotRequest::Type::kExecute);
  EXPECT_EQ(out.robot[0].command.command_id, "go");
  EXPECT_TRUE(out.failures.empty());

  // Progress from the robot's states, published periodically.
  EXPECT_TRUE(monitor_.onRobotState(observe(2.0, stamp_ += 10), now_ + 1.0).empty());
  out = monitor_.onTick(now_ + 1.0);
  ASSERT_EQ(out.statuses.size(), 1u);
  EXPECT_EQ(out.statuses[0].state, ExecState::kRunning);
  EXPECT_NEAR(out.statuses[0].progress, 0.5, 1e-6);

  // The result alone does not end it: a state written after it must give the held object.
  const std::int64_t before = stamp_;
  EXPECT_TRUE(
      monitor_.onRobotResult(result("go", RobotOutcome::kSucceeded, 3.25), now_ + 2.0).empty());
  EXPECT_TRUE(
      monitor_.onRobotState(observe(2.5, before), now_ + 2.0).empty());  // older than the result
  out = monitor_.onRobotState(observe(2.5, stamp_ + 5, "box"), now_ + 2.1);
  const StatusUpdate* done = finalOf(out);
  ASSERT_NE(done, nullptr);
  EXPECT_EQ(done->state, ExecState::kSucceeded) << done->reason;
  EXPECT_DOUBLE_EQ(done->measured_duration_s, 3.25);
  EXPECT_EQ(done->held_object_id, "box");
  EXPECT_DOUBLE_EQ(done->progress, 1.0);
  EXPECT_TRUE(done->reason.empty()) << done->reason;
  EXPECT_TRUE(out.failures.empty());

  // The same id again: its known status, nothing sent to the robot.
  out = monitor_.onCommand(c, now_ + 3.0);
  EXPECT_TRUE(out.robot.empty());
  ASSERT_EQ(out.statuses.size(), 1u);
  EXPECT_EQ(out.statuses[0].state, ExecState::kSucceeded);
  EXPECT_EQ(monitor_.executedCount(), 1u);
  ExecutionCommand cancel = c;
  cancel.cancel = true;
  out = monitor_.onCommand(cancel, now_ + 3.0);
  EXPECT_TRUE(out.robot.empty());
  EXPECT_EQ(out.statuses.at(0).state, ExecState::kSucceeded);
}

TEST_F(MonitorTest, PreconditionsFailBeforeTheRobotMoves) {
  ready();
  // The start is 1 m ahead of the robot.
  Outputs out = monitor_.onCommand(moveBase("far", {{2.5, 1.2, 0}, {3.0, 1.2, 0}}), now_);
  const StatusUpdate* f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->state, ExecState::kFailed);
  EXPECT_EQ(f->reason.rfind("start:", 0), 0u) << f->reason;
  EXPECT_NE(f->reason.find("base_x"), std::string::npos) << f->reason;
  EXPECT_TRUE(out.robot.empty());
  ASSERT_EQ(out.failures.size(), 1u);
  EXPECT_EQ(out.failures[0].type, FailureType::kPrecondition);

  // An object of the world model on the path.
  world_ = withCrate(world_, "crate", 2.3, 1.2);
  monitor_.onWorld(world_, 2, now_);
  out = monitor_.onCommand(moveBase("blocked", {{1.5, 1.2, 0}, {3.0, 1.2, 0}}), now_);
  f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->state, ExecState::kFailed);
  EXPECT_EQ(f->reason.rfind("path:", 0), 0u) << f->reason;
  EXPECT_EQ(f->blocking_object_id, "crate");
  ASSERT_EQ(out.failures.size(), 1u);
  EXPECT_EQ(out.failures[0].object_id, "crate");
  EXPECT_TRUE(out.robot.empty());

  // A place with an empty hand.
  ExecutionCommand place;
  place.command_id = "place";
  place.kind = ActionKind::kPlace;
  place.object_id = "box";
  place.object_target = Eigen::Isometry3d::Identity();
  place.trajectory.joint_names = robotModel().armJointNames();
  place.trajectory.points.push_back({0.0, corridor().startState().arm, {}});
  out = monitor_.onCommand(place, now_);
  f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->reason.rfind("held object:", 0), 0u) << f->reason;
  EXPECT_EQ(monitor_.executedCount(), 0u);
}

TEST_F(MonitorTest, MalformedCommandsFailNamingTheFieldAndStayKnown) {
  ready();
  ExecutionCommand c = moveBase("nan", {{1.5, 1.2, 0}, {2.5, 1.2, 0}});
  c.trajectory.points[1].positions[1] = std::nan("");
  Outputs out = monitor_.onCommand(c, now_);
  const StatusUpdate* f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->state, ExecState::kFailed);
  EXPECT_NE(f->reason.find("trajectory.points[1].positions[1]"), std::string::npos) << f->reason;
  // Corrected but with the same id: not executed (idempotent on command_id).
  c.trajectory.points[1].positions[1] = 1.2;
  out = monitor_.onCommand(c, now_);
  EXPECT_TRUE(out.robot.empty());
  EXPECT_EQ(out.statuses.at(0).state, ExecState::kFailed);

  out = monitor_.onMalformedCommand(
      "bad_kind", Error(ErrorCode::kInvalidArgument, "kind: unknown action kind 9"), now_);
  f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->reason, "malformed command: kind: unknown action kind 9");
  // A converter message without the field gets it in front.
  out = monitor_.onMalformedCommand("bad_value",
                                    Error(ErrorCode::kInvalidArgument, "non-finite value",
                                          SourceLocation{"", 0, 0, "trajectory.positions"}),
                                    now_);
  f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->reason, "malformed command: trajectory.positions: non-finite value");
  EXPECT_EQ(monitor_.executedCount(), 0u);
}

TEST_F(MonitorTest, NewObstacleOnTheRemainingPathCancelsAndBlocks) {
  ready();
  monitor_.onCommand(moveBase("go", {{1.5, 1.2, 0}, {3.5, 1.2, 0}}), now_);
  monitor_.onRobotState(observe(2.0, stamp_ += 10), now_ + 1.0);
  // Something appears behind the robot: not on what is left of the path.
  EXPECT_TRUE(monitor_.onWorld(withCrate(world_, "behind", 0.6, 1.2), 2, now_ + 1.1).empty());
  // A known object that moved: within the tolerance it is not re-checked, beyond it, it is.
  {
    ExecutionMonitor m(MonitorParams{}, robotModel());
    world::World w = withCrate(world_, "known", 3.6, 1.9);  // beside the end of the path
    m.onWorld(w, 1, now_);
    m.onRobotState(observe(1.5, stamp_), now_);
    ASSERT_EQ(m.onCommand(moveBase("k", {{1.5, 1.2, 0}, {3.5, 1.2, 0}}), now_).robot.size(), 1u);
    world::World jitter = world_;
    ASSERT_TRUE(
        jitter.addObject(crate("known", 3.6, 1.9 - 0.5 * MonitorParams{}.moved_tolerance_m)));
    EXPECT_TRUE(m.onWorld(jitter, 2, now_ + 0.1).robot.empty());
    world::World moved = world_;
    ASSERT_TRUE(moved.addObject(crate("known", 3.6, 1.3)));  // into the path
    const Outputs o = m.onWorld(moved, 3, now_ + 0.2);
    ASSERT_EQ(o.robot.size(), 1u);
    EXPECT_EQ(o.robot[0].type, RobotRequest::Type::kCancel);
  }
  // Something appears ahead of it: cancel, then BLOCKED once the robot has stopped.
  Outputs out = monitor_.onWorld(withCrate(world_, "crate", 3.0, 1.2), 3, now_ + 1.2);
  ASSERT_EQ(out.robot.size(), 1u);
  EXPECT_EQ(out.robot[0].type, RobotRequest::Type::kCancel);
  EXPECT_EQ(out.robot[0].command.command_id, "go");
  EXPECT_EQ(finalOf(out), nullptr);
  EXPECT_TRUE(
      monitor_.onRobotResult(result("go", RobotOutcome::kCancelled, 1.4), now_ + 1.3).empty());
  out = monitor_.onRobotState(observe(2.1, stamp_ + 1), now_ + 1.35);
  const StatusUpdate* f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->state, ExecState::kBlocked) << f->reason;
  EXPECT_EQ(f->blocking_object_id, "crate");
  EXPECT_FALSE(f->stopped_at_contact) << "stopped by the monitor on a prediction, not at contact";
  EXPECT_DOUBLE_EQ(f->measured_duration_s, 1.4);
  ASSERT_EQ(out.failures.size(), 1u);
  EXPECT_EQ(out.failures[0].type, FailureType::kNewObstacle);
  EXPECT_EQ(out.failures[0].object_id, "crate");
}

TEST_F(MonitorTest, DroppedObjectAndOverrunCancel) {
  ready("box");
  monitor_.onCommand(moveBase("carry", {{1.5, 1.2, 0}, {2.5, 1.2, 0}}), now_);
  Outputs out = monitor_.onRobotState(observe(1.8, stamp_ += 10, ""), now_ + 0.5);
  ASSERT_EQ(out.robot.size(), 1u);
  EXPECT_EQ(out.robot[0].type, RobotRequest::Type::kCancel);
  monitor_.onRobotResult(result("carry", RobotOutcome::kCancelled, 0.6), now_ + 0.6);
  out = monitor_.onRobotState(observe(1.8, stamp_ + 1, ""), now_ + 0.7);
  const StatusUpdate* f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->state, ExecState::kFailed);
  EXPECT_EQ(f->held_object_id, "");
  ASSERT_EQ(out.failures.size(), 1u);
  EXPECT_EQ(out.failures[0].type, FailureType::kObjectDropped);
  EXPECT_EQ(out.failures[0].object_id, "box");

  // Overrun: expected 4 s + 3 x 0.5 s + 5 s; the robot never answers the cancel either.
  now_ += 10.0;
  monitor_.onCommand(moveBase("slow", {{1.8, 1.2, 0}, {2.5, 1.2, 0}}), now_);
  EXPECT_EQ(monitor_.activeCommandId(), "slow");
  EXPECT_TRUE(monitor_.onTick(now_ + 10.4).robot.empty());
  out = monitor_.onTick(now_ + 10.6);
  ASSERT_EQ(out.robot.size(), 1u);
  EXPECT_EQ(out.robot[0].type, RobotRequest::Type::kCancel);
  out = monitor_.onTick(now_ + 10.6 + MonitorParams{}.result_wait_s + 0.1);
  f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->state, ExecState::kFailed);
  EXPECT_EQ(f->reason.rfind("timeout:", 0), 0u) << f->reason;
  EXPECT_NE(f->reason.find("no result from the robot"), std::string::npos) << f->reason;
  ASSERT_EQ(out.failures.size(), 1u);
  EXPECT_EQ(out.failures[0].type, FailureType::kTimeout);
}

// Past its limit (expected 4 s + 3 x 0.5 s + 5 s = 10.5 s) a robot that is slower than predicted
// but still moving along its path is let finish; it is stopped once it makes no progress for
// stall_s (5 s), or at max_factor (3) times the limit while moving.
TEST_F(MonitorTest, ASlowButMovingRobotIsNotStoppedAtTheLimitOnlyWhenItStallsOrCrawlsTooLong) {
  ready();
  monitor_.onCommand(moveBase("slow", {{1.5, 1.2, 0}, {2.5, 1.2, 0}}), now_);
  ASSERT_EQ(monitor_.activeCommandId(), "slow");
  // 2 cm every second: past the limit, no cancel while it moves.
  double x = 1.5, t = now_;
  for (int k = 0; k < 14; ++k) {
    t += 1.0;
    x += 0.02;
    Outputs out = monitor_.onRobotState(observe(x, stamp_ += 10), t);
    out = monitor_.onTick(t + 0.01);
    ASSERT_TRUE(out.robot.empty()) << "stopped while moving at t = " << t - now_;
  }
  ASSERT_GT(t - now_, 10.5);
  // It stops moving: past the limit and still for more than 5 s, it is stopped as overrun.
  Outputs out = monitor_.onTick(t + 4.9);
  EXPECT_TRUE(out.robot.empty());
  out = monitor_.onTick(t + 5.2);
  ASSERT_EQ(out.robot.size(), 1u);
  EXPECT_EQ(out.robot[0].type, RobotRequest::Type::kCancel);
  monitor_.onRobotResult(result("slow", RobotOutcome::kCancelled, t + 5.3 - now_), t + 5.3);
  out = monitor_.onRobotState(observe(x, stamp_ += 10), t + 5.4);
  const StatusUpdate* f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_NE(f->reason.find("no progress for"), std::string::npos) << f->reason;

  // Crawling on: stopped at 3 x 10.5 s although it still moves.
  now_ = t + 10.0;
  monitor_.onCommand(moveBase("crawl", {{x, 1.2, 0}, {x + 1.0, 1.2, 0}}), now_);
  ASSERT_EQ(monitor_.activeCommandId(), "crawl");
  const double x0 = x;
  bool stopped = false;
  for (double dt = 1.0; dt < 40.0 && !stopped; dt += 1.0) {
    x = x0 + 0.015 * dt;
    (void)monitor_.onRobotState(observe(x, stamp_ += 10), now_ + dt);
    out = monitor_.onTick(now_ + dt + 0.01);
    if (!out.robot.empty()) {
      stopped = true;
      EXPECT_GT(dt, 3 * 10.5 - 1.0);
      EXPECT_LT(dt, 3 * 10.5 + 1.5);
    }
  }
  EXPECT_TRUE(stopped);
}

TEST_F(MonitorTest, RobotOutcomesMapToStatusesAndFailures) {
  ready();
  struct Case {
    RobotOutcome outcome;
    ExecState state;
    std::optional<FailureType> failure;
  };
  const Case cases[] = {
      {RobotOutcome::kBlocked, ExecState::kBlocked, FailureType::kBlocked},
      {RobotOutcome::kFailed, ExecState::kFailed, FailureType::kActionFailed},
      {RobotOutcome::kCancelled, ExecState::kCancelled, FailureType::kActionFailed},
      {RobotOutcome::kSucceeded, ExecState::kSucceeded, std::nullopt}};
  int i = 0;
  for (const Case& c : cases) {
    const std::string id = "c" + std::to_string(i++);
    Outputs out = monitor_.onCommand(moveBase(id, {{1.5, 1.2, 0}, {1.5, 1.2, 0.5}}), now_);
    ASSERT_EQ(out.robot.size(), 1u) << id;
    RobotResult r = result(id, c.outcome, 1.0);
    r.blocking_object_id = c.outcome == RobotOutcome::kBlocked ? "hidden_wall" : "";
    monitor_.onRobotResult(r, now_);
    out = monitor_.onRobotState(observe(1.5, stamp_ + 1), now_);
    const StatusUpdate* f = finalOf(out);
    ASSERT_NE(f, nullptr) << id;
    EXPECT_EQ(f->state, c.state) << id;
    if (c.failure) {
      ASSERT_EQ(out.failures.size(), 1u) << id;
      EXPECT_EQ(out.failures[0].type, *c.failure) << id;
    } else {
      EXPECT_TRUE(out.failures.empty()) << id;
    }
    // Only the robot's own stop before an object is a stop at contact.
    EXPECT_EQ(f->stopped_at_contact, c.outcome == RobotOutcome::kBlocked) << id;
    if (c.outcome == RobotOutcome::kBlocked) {
      EXPECT_EQ(f->blocking_object_id, "hidden_wall");
    }
  }
}

TEST_F(MonitorTest, QueueCancelAndMissingInputs) {
  // No world model: the command waits, then fails naming it.
  EXPECT_TRUE(monitor_.onRobotState(observe(1.5, stamp_), now_).empty());
  Outputs out = monitor_.onCommand(moveBase("early", {{1.5, 1.2, 0}, {2.0, 1.2, 0}}), now_);
  EXPECT_EQ(finalOf(out), nullptr);
  out = monitor_.onTick(now_ + MonitorParams{}.input_wait_s + 0.1);
  const StatusUpdate* f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->reason.rfind("world model:", 0), 0u) << f->reason;

  // A second command queues behind the first and is cancelled before it starts; the first is
  // cancelled while it runs.
  now_ += 5.0;
  monitor_.onWorld(world_, 1, now_);
  monitor_.onCommand(moveBase("first", {{1.5, 1.2, 0}, {2.0, 1.2, 0}}), now_);
  out = monitor_.onCommand(moveBase("second", {{2.0, 1.2, 0}, {2.5, 1.2, 0}}), now_);
  ASSERT_EQ(out.statuses.size(), 1u);
  EXPECT_EQ(out.statuses[0].state, ExecState::kAccepted);
  ExecutionCommand cancel;
  cancel.command_id = "second";
  cancel.cancel = true;
  out = monitor_.onCommand(cancel, now_);
  EXPECT_EQ(out.statuses.at(0).state, ExecState::kCancelled);
  EXPECT_TRUE(out.robot.empty());
  cancel.command_id = "first";
  out = monitor_.onCommand(cancel, now_);
  ASSERT_EQ(out.robot.size(), 1u);
  EXPECT_EQ(out.robot[0].type, RobotRequest::Type::kCancel);
  monitor_.onRobotResult(result("first", RobotOutcome::kCancelled, 0.3), now_);
  out = monitor_.onRobotState(observe(1.6, stamp_ + 1), now_);
  f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->state, ExecState::kCancelled);
  EXPECT_TRUE(out.failures.empty());
  EXPECT_EQ(monitor_.executedCount(), 1u);
}

TEST_F(MonitorTest, AnIdTheRobotAlreadyExecutedIsNotExecutedAgain) {
  ready();
  monitor_.onRobotResult(result("before_restart", RobotOutcome::kSucceeded, 2.0), now_);
  monitor_.onRobotState(observe(1.5, stamp_ + 1), now_);
  Outputs out =
      monitor_.onCommand(moveBase("before_restart", {{1.5, 1.2, 0}, {2.0, 1.2, 0}}), now_);
  EXPECT_TRUE(out.robot.empty());
  const StatusUpdate* f = finalOf(out);
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->state, ExecState::kSucceeded);
  EXPECT_DOUBLE_EQ(f->measured_duration_s, 2.0);
}

TEST_F(MonitorTest, AnIdSentBeforeARestartIsJoinedNotValidatedOrExecutedAsNew) {
  // The previous run sent "half" to the robot; the robot is half-way (x = 2.0, away from the
  // trajectory's start 1.5, so validation would fail it) when the command comes again.
  monitor_.resume({"half"});
  EXPECT_TRUE(monitor_.onWorld(world_, 1, now_).empty());
  EXPECT_TRUE(monitor_.onRobotState(observe(2.0, stamp_), now_).empty());
  Outputs out = monitor_.onCommand(moveBase("half", {{1.5, 1.2, 0}, {2.5, 1.2, 0}}), now_);
  // Re-sent to the (idempotent) robot to join it; not a precondition failure.
  ASSERT_EQ(out.robot.size(), 1u);
  EXPECT_EQ(out.robot[0].type, RobotRequest::Type::kExecute);
  EXPECT_TRUE(out.failures.empty());
  EXPECT_EQ(finalOf(out), nullptr);
  EXPECT_EQ(monitor_.executedCount(), 0u);
  EXPECT_EQ(monitor_.activeCommandId(), "half");
  // Its outcome is the robot's.
  EXPECT_TRUE(
      monitor_.onRobotResult(result("half", RobotOutcome::kSucceeded, 4.0), now_ + 1.0).empty());
  out = monitor_.onRobotState(observe(2.5, stamp_ + 5), now_ + 1.1);
  const StatusUpdate* done = finalOf(out);
  ASSERT_NE(done, nullptr);
  EXPECT_EQ(done->state, ExecState::kSucceeded) << done->reason;
  EXPECT_DOUBLE_EQ(done->measured_duration_s, 4.0);
  // A repeat now gets the recorded status; a new id is validated as usual (and fails: the
  // robot is not at its start).
  out = monitor_.onCommand(moveBase("half", {{1.5, 1.2, 0}, {2.5, 1.2, 0}}), now_ + 2.0);
  EXPECT_TRUE(out.robot.empty());
  ASSERT_EQ(out.statuses.size(), 1u);
  EXPECT_EQ(out.statuses[0].state, ExecState::kSucceeded);
  out = monitor_.onCommand(moveBase("fresh", {{1.5, 1.2, 0}, {2.0, 1.2, 0}}), now_ + 2.0);
  EXPECT_TRUE(out.robot.empty());
  ASSERT_NE(finalOf(out), nullptr);
  EXPECT_EQ(finalOf(out)->state, ExecState::kFailed);
}

TEST_F(MonitorTest, ResumeIgnoresIdsWithAKnownOutcome) {
  ready();
  const ExecutionCommand c = moveBase("go", {{1.5, 1.2, 0}, {2.5, 1.2, 0}});
  (void)monitor_.onCommand(c, now_);
  (void)monitor_.onRobotResult(result("go", RobotOutcome::kSucceeded, 1.0), now_ + 1.0);
  ASSERT_NE(finalOf(monitor_.onRobotState(observe(2.5, stamp_ + 5), now_ + 1.1)), nullptr);
  monitor_.resume({"go"});
  const Outputs out = monitor_.onCommand(c, now_ + 2.0);
  EXPECT_TRUE(out.robot.empty());
  EXPECT_EQ(out.statuses.at(0).state, ExecState::kSucceeded);
}

TEST(RecordForwarderTest, ForwardsEachRecordIdOnceWithItsCommand) {
  RecordForwarder fw;
  ExecutionCommand c = moveBase("go", {{0, 0, 0}});
  c.expected_duration_s = 4.5;
  c.expected_stddev_s = 0.3;
  fw.addCommand(c);
  auto a = fw.onRecord("go", "");
  ASSERT_TRUE(a);
  EXPECT_EQ(a->command_id, "go");
  EXPECT_EQ(a->mission_id, "m1");
  EXPECT_DOUBLE_EQ(a->predicted_s, 4.5);
  EXPECT_DOUBLE_EQ(a->predicted_stddev_s, 0.3);
  EXPECT_FALSE(fw.onRecord("go", ""));
  auto by_field = fw.onRecord("rec-7", "go");  // a driver with its own record ids
  ASSERT_TRUE(by_field);
  EXPECT_EQ(by_field->command_id, "go");
  auto stranger = fw.onRecord("direct", "");
  ASSERT_TRUE(stranger);
  EXPECT_TRUE(stranger->command_id.empty());
  EXPECT_FALSE(fw.onRecord("", ""));
  EXPECT_EQ(fw.forwarded(), 3u);

  RecordForwarder strict(false);
  EXPECT_FALSE(strict.onRecord("direct", ""));
}

}  // namespace
}  // namespace tamp::execution_monitor
