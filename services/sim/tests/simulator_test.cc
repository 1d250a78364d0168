#include "tamp/sim/simulator.h"

#include <cmath>

#include <gtest/gtest.h>

#include "sim_test_util.h"
#include "tamp/collision/scene.h"
#include "tamp/effort_model/records.h"

namespace tamp::sim {
namespace {

using namespace tamp::sim::testing;

/// Distance from (x, y) to the polyline through `poses`.
double distanceToPolyline(double x, double y, const std::vector<Pose2D>& poses) {
  double best = INFINITY;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    const Eigen::Vector2d a(poses[i - 1].x, poses[i - 1].y), b(poses[i].x, poses[i].y), p(x, y);
    const Eigen::Vector2d ab = b - a;
    const double t = ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
    best = std::min(best, (a + t * ab - p).norm());
  }
  return best;
}

/// An independent check: the robot in `s` against every object of `w` (hidden included).
collision::DistanceResult clearance(const world::World& w, const robot::RobotState& s) {
  collision::Scene scene(w);
  scene.setRobot(robotModel().collisionGeometry());
  std::vector<Eigen::Isometry3d> poses;
  robotModel().linkPoses(s, poses);
  scene.setLinkPoses(poses);
  return scene.robotDistance();
}

TEST(SimulatorTest, MoveBaseTakesTheTrueModelTimeAndFollowsThePath) {
  const SimParams params = exactParams();
  Simulator sim(emptyRoom(), robotModel(), upright(), params);
  const std::vector<Pose2D> path{{0, 0, 0}, {2, 0, 0}, {2, 1.5, M_PI / 2}, {0.5, 1.5, M_PI}};
  ASSERT_TRUE(sim.submit(moveBase("drive", path)));
  EXPECT_TRUE(sim.busy());
  double max_speed = 0.0, max_off_path = 0.0, last_t = -1;
  StepEvents all;
  while (sim.busy()) {
    StepEvents e = sim.step(0.02);
    const RobotStateSample s = sim.robotState();
    EXPECT_GT(s.time_s, last_t);
    last_t = s.time_s;
    max_speed = std::max(max_speed, std::hypot(s.joint_velocities[0], s.joint_velocities[1]));
    max_off_path = std::max(max_off_path, distanceToPolyline(s.state.base.x, s.state.base.y, path));
    for (auto& r : e.results) all.results.push_back(r);
    for (auto& r : e.records) all.records.push_back(r);
  }
  ASSERT_EQ(all.results.size(), 1u);
  const ActionResult& r = all.results[0];
  EXPECT_EQ(r.command_id, "drive");
  EXPECT_EQ(r.outcome, Outcome::kSucceeded) << r.reason;
  EXPECT_DOUBLE_EQ(r.progress, 1.0);
  // The duration is the physical model evaluated with the simulator's TRUE parameters.
  ASSERT_EQ(all.records.size(), 1u);
  const double expected = trueTime(all.records[0], params);
  EXPECT_NEAR(r.duration_s, expected, 1e-9);
  // The jerk-limited S-curves take longer than the estimator's trapezoids would with the same limits.
  // ... and not the planner's defaults.
  const auto defaults = effort_model::modelSpec(ActionKind::kMoveBase).defaults();
  EXPECT_GT(std::abs(modelTime(all.records[0], defaults) - r.duration_s), 0.1 * r.duration_s);
  // The robot drove along the commanded polyline, within its true speed limit, and ended there.
  EXPECT_LT(max_off_path, 1e-9);
  EXPECT_LE(max_speed, params.dynamics.base.linear_speed + 1e-6);
  EXPECT_GT(max_speed, 0.9 * params.dynamics.base.linear_speed);
  const RobotStateSample end = sim.robotState();
  EXPECT_NEAR(end.state.base.x, 0.5, 1e-9);
  EXPECT_NEAR(end.state.base.y, 1.5, 1e-9);
  EXPECT_NEAR(std::abs(end.state.base.theta), M_PI, 1e-9);
  EXPECT_FALSE(end.moving);
  // The record is one the estimator accepts.
  const auto& rec = all.records[0];
  EXPECT_TRUE(rec.success);
  EXPECT_EQ(rec.source, "sim");
  EXPECT_EQ(rec.record_id, "drive");
  EXPECT_EQ(rec.action.path.waypoints.size(), 4u);
  EXPECT_TRUE(effort_model::toFeatureRecord(rec, 3600.0, urdfScales()));
}

TEST(SimulatorTest, MoveArmUsesTheTrueJointLimitsAndPayload) {
  const SimParams params = exactParams();
  Simulator sim(emptyRoom(), robotModel(), upright(), params);
  std::vector<double> q0(6, 0.0), q1{0.8, 0.3, -0.4, 1.2, 0.2, -2.0}, q2{0.8, 0.6, -0.8, 1.2, 0.2, -2.0};
  ASSERT_TRUE(sim.submit(armCommand("arm", ActionKind::kMoveArm, {q0, q1, q2})));
  const StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].outcome, Outcome::kSucceeded) << e.results[0].reason;
  EXPECT_NEAR(e.results[0].duration_s, trueTime(e.records[0], params), 1e-9);
  const auto s = sim.robotState().state;
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(s.arm[j], q2[j], 1e-12);
}

TEST(SimulatorTest, DurationNoiseIsLogNormalAroundTheModel) {
  SimParams params = exactParams();
  params.duration_noise = 0.05;
  params.seed = 11;
  Simulator sim(emptyRoom(), robotModel(), upright(), params);
  std::vector<double> logs;
  for (int i = 0; i < 60; ++i) {
    const double x = i % 2 == 0 ? 1.0 : 0.0;
    const double from = 1.0 - x;
    ASSERT_TRUE(sim.submit(moveBase("m" + std::to_string(i), {{from, 0, 0}, {x, 0, 0}})))
        << "action " << i;
    const StepEvents e = runToEnd(sim, 0.5);
    ASSERT_EQ(e.records.size(), 1u);
    logs.push_back(std::log(e.records[0].duration_s /
                            trueTime(e.records[0], params)));
  }
  double mean = 0, var = 0;
  for (double l : logs) mean += l / logs.size();
  for (double l : logs) var += (l - mean) * (l - mean) / (logs.size() - 1);
  EXPECT_LT(std::abs(mean), 3 * 0.05 / std::sqrt(60.0));
  EXPECT_NEAR(std::sqrt(var), 0.05, 0.015);
  // Different actions got different factors.
  EXPECT_NE(logs[0], logs[2]);
}

TEST(SimulatorTest, StopsBeforeAHiddenObstacleAndReportsIt) {
  world::World w = emptyRoom();
  // A crate the planner does not know about, 2 m ahead.
  ASSERT_TRUE(w.addObject(box("hidden_crate", 0.4, 0.6, 0.5, at(2.0, 0.0, 0.25), false, true)));
  ASSERT_EQ(w.plannerView().findObject("hidden_crate"), nullptr);
  SimParams params = exactParams();
  Simulator sim(w, robotModel(), upright(), params);
  ASSERT_TRUE(sim.submit(moveBase("go", {{0, 0, 0}, {4, 0, 0}})));
  const StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  const ActionResult& r = e.results[0];
  EXPECT_EQ(r.outcome, Outcome::kBlocked);
  EXPECT_EQ(r.blocking_object_id, "hidden_crate");
  EXPECT_NE(r.reason.find("hidden_crate"), std::string::npos);
  EXPECT_GT(r.progress, 0.2);
  EXPECT_LT(r.progress, 0.8);
  // Stopped short: not touching, and less than one check step (1 cm) from contact. The base
  // front is 0.3 m ahead of base_link; the crate's face is at x = 1.8.
  const RobotStateSample s = sim.robotState();
  const auto d = clearance(sim.world(), s.state);
  EXPECT_EQ(d.object, "hidden_crate");
  EXPECT_GT(d.distance, 0.0);
  EXPECT_LE(d.distance, params.max_step_m + 1e-6);
  EXPECT_NEAR(s.state.base.x, 1.5, params.max_step_m + 1e-6);
  EXPECT_NEAR(s.state.base.y, 0.0, 1e-12);
  EXPECT_FALSE(s.moving);
  // The record says the action did not complete; its duration is the time to the stop.
  ASSERT_EQ(e.records.size(), 1u);
  EXPECT_FALSE(e.records[0].success);
  EXPECT_NEAR(e.records[0].duration_s, r.duration_s, 1e-12);
  EXPECT_LT(r.duration_s, trueTime(e.records[0], params));
  // Backing away drives in reverse, without turning: turning in place 1 cm from the crate would
  // sweep the base's corners (0.39 m from its centre) into it.
  ASSERT_TRUE(sim.submit(moveBase("back", {{s.state.base.x, 0, 0}, {0.5, 0, 0}})));
  const StepEvents back = runToEnd(sim);
  ASSERT_EQ(back.results.size(), 1u);
  EXPECT_EQ(back.results[0].outcome, Outcome::kSucceeded) << back.results[0].reason;
  EXPECT_NEAR(sim.robotState().state.base.x, 0.5, 1e-9);
  EXPECT_NEAR(sim.robotState().state.base.theta, 0.0, 1e-9);
}

TEST(SimulatorTest, AnArmSweepingIntoAnObjectStopsBeforeContact) {
  world::World w = emptyRoom();
  // A shelf board in front of the robot at 0.9-1.0 m: the base passes under it, the arm
  // pitching forward hits it.
  ASSERT_TRUE(w.addObject(box("shelf", 0.3, 0.8, 0.1, at(0.75, 0.0, 0.95))));
  SimParams params = exactParams();
  Simulator sim(w, robotModel(), upright(), params);
  ASSERT_TRUE(sim.submit(armCommand("pitch", ActionKind::kMoveArm, {std::vector<double>(6, 0.0),
                                                                     {0, 1.5, 0, 0, 0, 0}})));
  const StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].outcome, Outcome::kBlocked);
  EXPECT_EQ(e.results[0].blocking_object_id, "shelf");
  const auto s = sim.robotState().state;
  EXPECT_GT(s.arm[1], 0.2);
  EXPECT_LT(s.arm[1], 1.5);
  const auto d = clearance(sim.world(), s);
  EXPECT_GT(d.distance, 0.0);
  EXPECT_LE(d.distance, params.max_step_m + 1e-6);
}

TEST(SimulatorTest, ScriptedFaultsFireAtTheirTimeAndStep) {
  world::World w = emptyRoom();
  Fault spawn;
  spawn.id = "box_appears";
  spawn.type = FaultType::kSpawnObject;
  spawn.trigger.time_s = 1.0;
  spawn.object = box("dropped_box", 0.4, 0.4, 0.4, at(3.0, 0.0, 0.2));
  Fault fail;
  fail.id = "motor_fault";
  fail.type = FaultType::kFailAction;
  fail.trigger.step = 1;
  fail.trigger.fraction = 0.5;
  fail.reason = "wheel motor overcurrent";
  SimParams params = exactParams();
  Simulator sim(w, robotModel(), upright(), params, {spawn, fail});
  // Step 0: drive to x = 5; the box appears at t = 1 s on the way and blocks it.
  ASSERT_TRUE(sim.submit(moveBase("s0", {{0, 0, 0}, {5, 0, 0}})));
  StepEvents e = runToEnd(sim, 0.3);
  ASSERT_EQ(e.faults.size(), 1u);
  EXPECT_EQ(e.faults[0].fault_id, "box_appears");
  EXPECT_NEAR(e.faults[0].time_s, 1.0, 1e-12);  // not rounded to the 0.3 s step
  EXPECT_TRUE(e.world_changed);
  ASSERT_NE(sim.world().findObject("dropped_box"), nullptr);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].outcome, Outcome::kBlocked);
  EXPECT_EQ(e.results[0].blocking_object_id, "dropped_box");
  const double x_stop = sim.robotState().state.base.x;
  EXPECT_NEAR(x_stop, 3.0 - 0.2 - 0.3, params.max_step_m + 1e-6);
  // Step 1: an arm motion (clear of the box); it fails half-way through.
  const std::vector<double> goal{0.8, 0.3, -0.4, 1.2, 0.2, -2.0};
  ASSERT_TRUE(sim.submit(armCommand("s1", ActionKind::kMoveArm, {std::vector<double>(6, 0.0), goal})));
  const double planned = sim.remainingActionTime();
  e = runToEnd(sim, 0.3);
  ASSERT_EQ(e.faults.size(), 1u);
  EXPECT_EQ(e.faults[0].fault_id, "motor_fault");
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].outcome, Outcome::kFailed);
  EXPECT_NE(e.results[0].reason.find("wheel motor overcurrent"), std::string::npos);
  EXPECT_NEAR(e.results[0].progress, 0.5, 1e-9);
  EXPECT_NEAR(e.results[0].duration_s, 0.5 * planned, 1e-9);
  EXPECT_FALSE(e.records[0].success);
  // The arm stopped where it was, between start and goal.
  const auto arm = sim.robotState().state.arm;
  EXPECT_LT(arm[5], -0.1);
  EXPECT_GT(arm[5], -1.9);
  EXPECT_FALSE(sim.robotState().moving);
}

TEST(SimulatorTest, WorldChangesDuringAnActionReplanTheStop) {
  world::World w = emptyRoom();
  ASSERT_TRUE(w.addObject(box("far_crate", 0.4, 0.4, 0.4, at(5.0, 0.0, 0.2), false, true)));
  Simulator sim(w, robotModel(), upright(), exactParams());
  ASSERT_TRUE(sim.submit(moveBase("go", {{0, 0, 0}, {8, 0, 0}})));
  // Blocked by the far crate (at x = 5 - 0.2 - 0.3 = 4.5); a box appears nearer on the way.
  (void)sim.step(1.0);
  Fault spawn;
  spawn.id = "near";
  spawn.type = FaultType::kSpawnObject;
  spawn.object = box("near_box", 0.4, 0.4, 0.4, at(2.5, 0.0, 0.2));
  ASSERT_TRUE(sim.inject(spawn));
  StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].blocking_object_id, "near_box");
  EXPECT_NEAR(sim.robotState().state.base.x, 2.0, 0.011);
  // Removing what blocks a running action lets it go on to the next obstacle.
  ASSERT_TRUE(sim.submit(moveBase("turn", {{2.0, 0, 0}, {2.0, 0, M_PI / 2}})));
  ASSERT_EQ(runToEnd(sim).results.at(0).outcome, Outcome::kBlocked) << "the base corners hit the box";
  Fault remove;
  remove.id = "gone";
  remove.type = FaultType::kRemoveObject;
  remove.object_id = "near_box";
  ASSERT_TRUE(sim.inject(remove));
  (void)sim.step(0.0);
  const double x = sim.robotState().state.base.x;
  const double theta = sim.robotState().state.base.theta;
  ASSERT_TRUE(sim.submit(moveBase("on", {{x, 0, theta}, {x, 0, 0}, {8, 0, 0}})));
  Fault remove_far;
  remove_far.id = "gone_far";
  remove_far.type = FaultType::kRemoveObject;
  remove_far.object_id = "far_crate";
  (void)sim.step(2.0);
  ASSERT_TRUE(sim.inject(remove_far));
  e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].outcome, Outcome::kSucceeded) << e.results[0].reason;
  EXPECT_NEAR(sim.robotState().state.base.x, 8.0, 1e-9);
}

TEST(SimulatorTest, InjectedFaultsFireAtTheNextStep) {
  Simulator sim(emptyRoom(), robotModel(), upright(), exactParams());
  // A spawned object, a removal, and a failure of the next action.
  Fault spawn;
  spawn.id = "f1";
  spawn.type = FaultType::kSpawnObject;
  spawn.object = box("pallet", 1, 1, 0.2, at(-3, 0, 0.1));
  ASSERT_TRUE(sim.inject(spawn));
  EXPECT_EQ(sim.inject(spawn).ok(), true) << "queued twice: the second fails when it fires";
  StepEvents e = sim.step(0.1);
  ASSERT_EQ(e.faults.size(), 2u);
  EXPECT_NE(sim.world().findObject("pallet"), nullptr);
  EXPECT_NE(e.faults[1].description.find("failed"), std::string::npos);
  Fault bad = spawn;
  EXPECT_FALSE(sim.inject(bad)) << "the id is taken now";
  Fault remove;
  remove.id = "f2";
  remove.type = FaultType::kRemoveObject;
  remove.object_id = "nothing_here";
  EXPECT_EQ(sim.inject(remove).error().code, ErrorCode::kNotFound);
  remove.object_id = "pallet";
  ASSERT_TRUE(sim.inject(remove));
  Fault fail;
  fail.id = "f3";
  fail.type = FaultType::kFailAction;
  fail.trigger.fraction = 0.25;
  ASSERT_TRUE(sim.inject(fail));
  e = sim.step(0.1);
  EXPECT_EQ(sim.world().findObject("pallet"), nullptr);
  ASSERT_TRUE(sim.submit(moveBase("doomed", {{0, 0, 0}, {2, 0, 0}})));
  e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].outcome, Outcome::kFailed);
  EXPECT_NEAR(e.results[0].progress, 0.25, 1e-9);
  // The one after it is fine.
  ASSERT_TRUE(sim.submit(moveBase("fine", {{sim.robotState().state.base.x, 0, 0}, {2, 0, 0}})));
  e = runToEnd(sim);
  EXPECT_EQ(e.results.at(0).outcome, Outcome::kSucceeded);
}

TEST(SimulatorTest, CancelStopsTheRobotWhereItIs) {
  Simulator sim(emptyRoom(), robotModel(), upright(), exactParams());
  ASSERT_TRUE(sim.submit(moveBase("long", {{0, 0, 0}, {6, 0, 0}})));
  (void)sim.step(4.0);
  EXPECT_EQ(sim.cancel("other").error().code, ErrorCode::kNotFound);
  ASSERT_TRUE(sim.cancel("long"));
  const StepEvents e = sim.step(0.1);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].outcome, Outcome::kCancelled);
  EXPECT_NEAR(e.results[0].duration_s, 4.0, 1e-9);
  const double x = sim.robotState().state.base.x;
  (void)sim.step(5.0);
  EXPECT_EQ(sim.robotState().state.base.x, x);
  EXPECT_GT(x, 0.3);
  EXPECT_LT(x, 6.0);
}

struct BadCommand {
  std::string name;
  ActionCommand command;
  std::string field;    // expected Error::where.field
  std::string message;  // expected in the message
};

std::vector<BadCommand> badCommands() {
  std::vector<BadCommand> c;
  auto good = [] { return moveBase("c", {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}); };
  {
    auto x = good();
    x.trajectory.joint_names[1] = "base_why";
    c.push_back({"unknown_joint", x, "trajectory.joint_names[1]", "unknown joint 'base_why'"});
  }
  {
    auto x = good();
    x.trajectory.joint_names[2] = "base_x";
    c.push_back({"duplicate_joint", x, "trajectory.joint_names[2]", "duplicate joint 'base_x'"});
  }
  {
    auto x = good();
    x.trajectory.points[1].positions[0] = std::nan("");
    c.push_back({"nan", x, "trajectory.points[1].positions[0]", "base_x is not finite"});
  }
  {
    auto x = good();
    x.trajectory.points[2].time_from_start = 0.5;
    c.push_back({"non_monotonic", x, "trajectory.points[2].time_from_start", "times must increase strictly"});
  }
  {
    auto x = good();
    x.trajectory.points[1].time_from_start = INFINITY;
    c.push_back({"infinite_time", x, "trajectory.points[1].time_from_start", "must be finite"});
  }
  {
    auto x = good();
    x.trajectory.points[2].positions.pop_back();
    c.push_back({"short_point", x, "trajectory.points[2].positions", "has 2 values for 3 joints"});
  }
  {
    auto x = good();
    x.trajectory.points[0].positions[0] = 0.5;
    c.push_back({"start_away", x, "trajectory.points[0].positions[0]", "but the robot is at 0"});
  }
  {
    auto x = good();
    x.trajectory.points.clear();
    c.push_back({"no_points", x, "trajectory.points", "no points"});
  }
  {
    auto x = good();
    x.command_id.clear();
    c.push_back({"no_id", x, "command_id", "must not be empty"});
  }
  {
    auto x = armCommand("a", ActionKind::kMoveArm, {std::vector<double>(6, 0.0), {0, 2.5, 0, 0, 0, 0}});
    c.push_back({"arm_limit", x, "trajectory.points[1].positions[1]", "outside its limits [-2, 2]"});
  }
  {
    auto x = armCommand("a", ActionKind::kMoveArm, {std::vector<double>(6, 0.0)});
    x.trajectory.joint_names[0] = "base_x";
    c.push_back({"base_in_arm", x, "trajectory.joint_names[0]", "cannot move the base joint 'base_x'"});
  }
  {
    auto x = good();
    x.trajectory.joint_names[2] = "arm_joint_1";
    c.push_back({"arm_in_base", x, "trajectory.joint_names[2]", "move_base moves base_x, base_y and base_theta only"});
  }
  {
    auto x = armCommand("p", ActionKind::kPlace, {std::vector<double>(6, 0.0)});
    x.object_id = "can";
    c.push_back({"place_without_pose", x, "object_pose", "place needs the pose"});
  }
  {
    auto x = armCommand("p", ActionKind::kPick, {std::vector<double>(6, 0.0)});
    x.object_id = "Not An Id";
    c.push_back({"bad_object_id", x, "object_id", "needs a valid object id"});
  }
  {
    auto x = good();
    x.trajectory.points[1].velocities = {1.0};
    c.push_back({"velocity_size", x, "trajectory.points[1].velocities", "has 1 values for 3 joints"});
  }
  return c;
}

TEST(SimulatorTest, RejectsMalformedCommandsNamingTheField) {
  Simulator sim(emptyRoom(), robotModel(), upright(), exactParams());
  for (const BadCommand& b : badCommands()) {
    SCOPED_TRACE(b.name);
    const Status s = sim.submit(b.command);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().code, ErrorCode::kInvalidArgument);
    EXPECT_EQ(s.error().where.field, b.field) << s.error().message;
    EXPECT_NE(s.error().message.find(b.message), std::string::npos) << s.error().message;
    EXPECT_FALSE(sim.busy());
  }
  // Nothing moved, nothing recorded.
  const StepEvents e = sim.step(1.0);
  EXPECT_TRUE(e.results.empty());
  EXPECT_TRUE(e.records.empty());
  EXPECT_EQ(sim.robotState().state.base, Pose2D{});
  EXPECT_EQ(sim.actionCount(), 0);
  // A second command while one runs is refused.
  ASSERT_TRUE(sim.submit(moveBase("first", {{0, 0, 0}, {1, 0, 0}})));
  const Status busy = sim.submit(moveBase("second", {{0, 0, 0}, {1, 0, 0}}));
  ASSERT_FALSE(busy);
  EXPECT_EQ(busy.error().code, ErrorCode::kUnavailable);
  EXPECT_THROW((void)sim.step(-1.0), std::invalid_argument);
}

}  // namespace
}  // namespace tamp::sim

namespace tamp::sim {
namespace {

using namespace tamp::sim::testing;

TEST(SimulatorTest, ARepeatedCommandIdIsNeverExecutedAgain) {
  Simulator sim(emptyRoom(), robotModel(), upright(), exactParams());
  const ActionCommand drive = moveBase("drive", {{0, 0, 0}, {1, 0, 0}});
  ASSERT_TRUE(sim.submit(drive));
  (void)sim.step(0.1);
  const double mid = sim.robotState().state.base.x;
  // While it runs: the repeat joins it (no restart from the start, no second action).
  ASSERT_TRUE(sim.submit(drive));
  EXPECT_EQ(sim.actionCount(), 1);
  const StepEvents first = runToEnd(sim);
  ASSERT_EQ(first.results.size(), 1u);
  EXPECT_EQ(first.results[0].outcome, Outcome::kSucceeded) << first.results[0].reason;
  EXPECT_GT(sim.robotState().state.base.x, mid);
  // After it ended: the repeat (whose start is now away from the robot) gets the recorded result
  // again, not a rejection, and the robot does not move; no second record.
  const double end_x = sim.robotState().state.base.x;
  ASSERT_TRUE(sim.submit(drive));
  EXPECT_FALSE(sim.busy());
  const StepEvents again = sim.step(0.05);
  ASSERT_EQ(again.results.size(), 1u);
  EXPECT_EQ(again.results[0].command_id, "drive");
  EXPECT_EQ(again.results[0].outcome, Outcome::kSucceeded);
  EXPECT_DOUBLE_EQ(again.results[0].duration_s, first.results[0].duration_s);
  EXPECT_TRUE(again.records.empty());
  EXPECT_DOUBLE_EQ(sim.robotState().state.base.x, end_x);
  ASSERT_EQ(sim.actionLog().size(), 1u);
  EXPECT_EQ(sim.actionLog()[0].command_id, "drive");
  ASSERT_TRUE(sim.actionLog()[0].result.has_value());
  EXPECT_EQ(sim.actionLog()[0].result->outcome, Outcome::kSucceeded);
  // A new id is executed (from where the robot is).
  ASSERT_TRUE(sim.submit(moveBase("back", {{end_x, 0, 0}, {0, 0, 0}})));
  EXPECT_EQ(sim.actionCount(), 2);
  EXPECT_EQ(sim.actionLog().size(), 2u);
}

TEST(SimulatorTest, ARejectedCommandIsNotLoggedAsExecuted) {
  Simulator sim(emptyRoom(), robotModel(), upright(), exactParams());
  // Starts away from the robot: rejected, not executed, so not in the action log.
  EXPECT_FALSE(sim.submit(moveBase("far", {{3, 0, 0}, {4, 0, 0}})));
  EXPECT_TRUE(sim.actionLog().empty());
  EXPECT_FALSE(sim.busy());
}

}  // namespace
}  // namespace tamp::sim

namespace tamp::sim {
namespace {

using namespace tamp::sim::testing;

/// The empty room with a hidden static wall and a movable box held in the gripper.
world::World roomWithHeldBox() {
  world::World w = emptyRoom();
  EXPECT_TRUE(w.addObject(box("hidden_wall", 0.2, 3.0, 1.0, at(6.0, 0.0, 0.5), false, true)));
  world::Object held = box("carried", 0.05, 0.05, 0.1, at(0.5, 0.0, 1.0), true);
  held.graspable = true;
  EXPECT_TRUE(w.addObject(held));
  EXPECT_TRUE(w.setHeld(world::HeldObject{"carried", robotModel().options().tool_link,
                                          Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.05))}));
  return w;
}

TEST(SimulatorResumeTest, ARestartedSimulatorResumesTheWorldAndNeverExecutesTheInFlightIdAgain) {
  // The driver's process: a 2 m drive, "killed" half-way (its snapshot is all that is left).
  Simulator before(roomWithHeldBox(), robotModel(), upright(), exactParams());
  const ActionCommand drive = moveBase("drive", {{0, 0, 0}, {2, 0, 0}});
  ASSERT_TRUE(before.submit(drive));
  for (int i = 0; i < 40; ++i) (void)before.step(0.05);
  ASSERT_TRUE(before.busy());
  const SimSnapshot snap = before.snapshot();
  const double mid = snap.robot.base.x;
  ASSERT_GT(mid, 0.2);
  ASSERT_LT(mid, 1.8);
  ASSERT_EQ(snap.log.size(), 1u);
  EXPECT_FALSE(snap.log[0].result.has_value());

  // The restarted driver: built from the scenario, then resumed.
  Simulator after(roomWithHeldBox(), robotModel(), upright(), exactParams());
  ASSERT_TRUE(after.resume(snap));
  EXPECT_DOUBLE_EQ(after.time(), snap.time_s);
  EXPECT_DOUBLE_EQ(after.epoch(), before.epoch());  // stamps go on, not back
  EXPECT_DOUBLE_EQ(after.robotState().state.base.x, mid);
  EXPECT_EQ(after.robotState().held_object_id, "carried");
  EXPECT_TRUE(after.world().object("hidden_wall").hidden);
  // The held object is at the gripper where the robot stands, not where the scenario had it.
  EXPECT_NEAR(after.world().object("carried").pose.translation().x(),
              before.world().object("carried").pose.translation().x(), 1e-9);
  EXPECT_FALSE(after.busy());
  // The interrupted command ends, failed with the reason, at the first step; no record.
  const StepEvents first = after.step(0.05);
  ASSERT_EQ(first.results.size(), 1u);
  EXPECT_EQ(first.results[0].command_id, "drive");
  EXPECT_EQ(first.results[0].outcome, Outcome::kFailed);
  EXPECT_NE(first.results[0].reason.find(kRestartedMidAction), std::string::npos) << first.results[0].reason;
  EXPECT_TRUE(first.records.empty());
  // The sender repeats the id (a restarted monitor): the same failure, the robot does not move.
  ASSERT_TRUE(after.submit(drive));
  EXPECT_FALSE(after.busy());
  const StepEvents again = after.step(0.5);
  ASSERT_EQ(again.results.size(), 1u);
  EXPECT_EQ(again.results[0].outcome, Outcome::kFailed);
  EXPECT_DOUBLE_EQ(after.robotState().state.base.x, mid);
  EXPECT_EQ(after.actionCount(), 1);
  ASSERT_EQ(after.actionLog().size(), 1u);
  ASSERT_TRUE(after.actionLog()[0].result.has_value());
  EXPECT_EQ(after.actionLog()[0].result->outcome, Outcome::kFailed);
  // A new command from where the robot really is runs.
  ASSERT_TRUE(after.submit(moveBase("rest", {{mid, 0, 0}, {2, 0, 0}})));
  const StepEvents rest = runToEnd(after);
  ASSERT_EQ(rest.results.size(), 1u);
  EXPECT_EQ(rest.results[0].outcome, Outcome::kSucceeded) << rest.results[0].reason;
  EXPECT_NEAR(after.robotState().state.base.x, 2.0, 1e-6);
  EXPECT_EQ(after.actionLog()[1].step, 1);
}

TEST(SimulatorResumeTest, ASnapshotThatDoesNotFitIsRefusedNamingTheField) {
  Simulator source(roomWithHeldBox(), robotModel(), upright(), exactParams());
  const SimSnapshot good = source.snapshot();
  const auto refused = [&](SimSnapshot s, const std::string& field) {
    Simulator sim(roomWithHeldBox(), robotModel(), upright(), exactParams());
    const Status st = sim.resume(s);
    EXPECT_FALSE(st.ok()) << field;
    if (!st.ok()) {
      EXPECT_EQ(st.error().code, ErrorCode::kInvalidArgument);
      EXPECT_NE(st.error().message.find(field), std::string::npos) << st.error().message;
    }
    EXPECT_DOUBLE_EQ(sim.robotState().state.base.x, 0.0);  // nothing changed
  };
  SimSnapshot s = good;
  s.robot.arm.pop_back();
  refused(s, "robot.arm");
  s = good;
  s.epoch_s = 0.0;
  refused(s, "epoch_s");
  s = good;
  s.held->link = "base_link";
  refused(s, "held");
  s = good;
  s.objects.push_back(s.objects.front());
  refused(s, "objects[" + s.objects.front().id + "]");
  s = good;
  s.fired_faults.push_back("fault_9");
  refused(s, "fired_faults[0]");
  s = good;
  s.log.push_back(ActionLogEntry{"a", ActionKind::kMoveBase, 0, 0.0, ActionResult{"a", Outcome::kSucceeded, 1.0, 1.0, "", ""}});
  s.log.push_back(ActionLogEntry{"a", ActionKind::kMoveBase, 1, 0.0, std::nullopt});
  refused(s, "log[1].command_id");
  // Resuming after commands were accepted is misuse.
  Simulator busy(roomWithHeldBox(), robotModel(), upright(), exactParams());
  ASSERT_TRUE(busy.submit(moveBase("drive", {{0, 0, 0}, {1, 0, 0}})));
  EXPECT_THROW((void)busy.resume(good), std::logic_error);
}

}  // namespace
}  // namespace tamp::sim
