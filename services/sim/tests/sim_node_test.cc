// The simulator's DDS node in-process on an isolated domain: a TrajectoryCommand in, an
// ActionResult, robot states, an execution record and a point cloud out; a malformed command
// answered with a failed result naming the field; an injected fault applied; the oracle served
// (true nominal durations, hidden objects, scripted faults) only when enabled.
#include "sim_node.h"

#include <condition_variable>
#include <cstdlib>
#include <mutex>

#include <gtest/gtest.h>

#include "../../../common/dds/tests/test_util.h"
#include "sim_test_util.h"
#include "tamp/dds/convert.h"

namespace tamp::sim {
namespace {

using namespace tamp::sim::testing;

using dds::testing::Inbox;

TEST(SimNodeTest, ExecutesATrajectoryCommandOverDds) {
  const int domain = dds::testing::isolatedDomain();
  dds::ServiceArgs args;
  args.name = "sim_test";
  args.domain_id = domain;
  SimParams params = exactParams();
  params.sensor.width = 40;
  params.sensor.height = 30;
  world::World w = emptyRoom();
  ASSERT_TRUE(w.addObject(box("hidden_wall", 0.2, 3.0, 1.0, at(2.5, 0.0, 0.5), false, true)));
  SimNode node(args, SimSetup(w, robotModel(), upright()), params);

  auto p = dds::testing::makeParticipant(domain);
  ASSERT_TRUE(p);
  Inbox<msg::ActionResult> results;
  Inbox<msg::RobotState> states;
  Inbox<msg::ExecutionRecord> records;
  Inbox<msg::PointCloudFrame> clouds;
  dds::Reader<msg::ActionResult> rr(p, dds::topics::kActionResult,
                                    [&](const msg::ActionResult& m, const dds::SampleMeta&) { results.push(m); });
  dds::Reader<msg::RobotState> sr(p, dds::topics::kRobotState,
                                  [&](const msg::RobotState& m, const dds::SampleMeta&) { states.push(m); });
  dds::Reader<msg::ExecutionRecord> er(p, dds::topics::kRobotRecords,
                                       [&](const msg::ExecutionRecord& m, const dds::SampleMeta&) { records.push(m); });
  dds::Reader<msg::PointCloudFrame> cr(p, dds::topics::kPointCloud,
                                       [&](const msg::PointCloudFrame& m, const dds::SampleMeta&) { clouds.push(m); });
  dds::Writer<msg::TrajectoryCommand> cw(p, dds::topics::kTrajectoryCommand);
  dds::Writer<msg::FaultInjection> fw(p, dds::topics::kFaultInjection);
  ASSERT_TRUE(cw.waitForReaders(Termination::after(20)));
  ASSERT_TRUE(rr.waitForWriters(Termination::after(20)));
  ASSERT_TRUE(fw.waitForReaders(Termination::after(20)));

  // 1. A malformed command: the third point goes back in time (rejected by the message
  //    conversion, which names the flattened field).
  msg::TrajectoryCommand bad;
  bad.command_id("bad");
  bad.kind(msg::ActionKind::ACTION_MOVE_BASE);
  bad.trajectory(dds::toMsg(moveBase("bad", {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}).trajectory));
  bad.trajectory().times()[2] = 0.5;
  ASSERT_TRUE(cw.write(bad));
  auto r_bad = results.waitFor([](const msg::ActionResult& r) { return r.command_id() == "bad"; });
  ASSERT_TRUE(r_bad);
  EXPECT_EQ(r_bad->outcome(), msg::ActionOutcome::OUTCOME_FAILED);
  EXPECT_NE(r_bad->reason().find("trajectory.times"), std::string::npos) << r_bad->reason();
  // 1b. Well-formed as a message but not as a command: an unknown joint (rejected by the
  //     simulator, which names the joint's field).
  msg::TrajectoryCommand bad2 = bad;
  bad2.command_id("bad2");
  bad2.trajectory(dds::toMsg(moveBase("bad2", {{0, 0, 0}, {1, 0, 0}}).trajectory));
  bad2.trajectory().joint_names()[1] = "base_yy";
  ASSERT_TRUE(cw.write(bad2));
  auto r_bad2 = results.waitFor([](const msg::ActionResult& r) { return r.command_id() == "bad2"; });
  ASSERT_TRUE(r_bad2);
  EXPECT_EQ(r_bad2->outcome(), msg::ActionOutcome::OUTCOME_FAILED);
  EXPECT_NE(r_bad2->reason().find("trajectory.joint_names[1]: unknown joint 'base_yy'"), std::string::npos)
      << r_bad2->reason();

  // 2. A good command into the hidden wall: blocked, with the wall's id.
  msg::TrajectoryCommand go;
  go.command_id("go");
  go.kind(msg::ActionKind::ACTION_MOVE_BASE);
  go.trajectory(dds::toMsg(moveBase("go", {{0, 0, 0}, {4, 0, 0}}).trajectory));
  ASSERT_TRUE(cw.write(go));
  auto r_go = results.waitFor([](const msg::ActionResult& r) { return r.command_id() == "go"; });
  ASSERT_TRUE(r_go);
  EXPECT_EQ(r_go->outcome(), msg::ActionOutcome::OUTCOME_BLOCKED) << r_go->reason();
  EXPECT_EQ(r_go->blocking_object_id(), "hidden_wall");
  EXPECT_GT(r_go->duration_s(), 0.0);
  EXPECT_GT(r_go->progress(), 0.0);
  EXPECT_LT(r_go->progress(), 1.0);
  auto rec = records.waitFor([](const msg::ExecutionRecord& r) { return r.record_id() == "go"; });
  ASSERT_TRUE(rec);
  EXPECT_FALSE(rec->success());
  EXPECT_EQ(rec->kind(), msg::ActionKind::ACTION_MOVE_BASE);
  EXPECT_DOUBLE_EQ(rec->duration_s(), r_go->duration_s());
  EXPECT_EQ(rec->source(), "sim");
  // The robot state stream shows the robot stopped in front of the wall (x ~ 2.4 - 0.3).
  auto st = states.waitFor([](const msg::RobotState& s) { return !s.moving() && s.base().x() > 2.0; });
  ASSERT_TRUE(st);
  EXPECT_NEAR(st->base().x(), 2.1, 0.011);
  EXPECT_EQ(st->joint_names().size(), robotModel().fullJointNames().size());
  EXPECT_EQ(st->joint_positions().size(), st->joint_names().size());
  EXPECT_EQ(st->robot_id(), robotModel().name());
  // A cloud after the action, from the camera, seeing the (hidden) wall ahead.
  auto cloud = clouds.waitFor([&](const msg::PointCloudFrame&) { return true; });
  ASSERT_TRUE(cloud);
  auto frame = dds::fromMsg(*cloud);
  ASSERT_TRUE(frame) << frame.error().toString();
  EXPECT_EQ(frame->width, 40u);
  EXPECT_EQ(frame->height, 30u);

  // 3. An injected fault: a box appears.
  msg::FaultInjection f;
  f.fault_id("surprise");
  f.type(msg::FaultType::FAULT_SPAWN_OBJECT);
  f.object_id("surprise_box");
  msg::ShapeSpec shape;
  shape.type(msg::ShapeType::SHAPE_BOX);
  shape.dimensions({0.3, 0.3, 0.3});
  f.shape(shape);
  f.pose(dds::toMsg(at(-2, 0, 0.15)));
  ASSERT_TRUE(fw.write(f));
  bool appeared = false;
  for (int i = 0; i < 300 && !appeared; ++i) {
    node.loop().withSimulator([&](Simulator& s) { appeared = s.world().findObject("surprise_box") != nullptr; });
    if (!appeared) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_TRUE(appeared);
}

TEST(SimNodeTest, ConversionsRejectMalformedMessages) {
  msg::PointCloudFrame m = dds::toMsg(PointCloudFrame{"cam", 5, Eigen::Isometry3d::Identity(), 2, 2,
                                                 std::vector<float>(12, 1.0f)});
  auto ok = dds::fromMsg(m);
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->xyz.size(), 12u);
  EXPECT_EQ(ok->stamp_ns, 5);
  m.points().pop_back();
  auto bad = dds::fromMsg(m);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().where.field, "points");

  msg::TrajectoryCommand c;
  c.command_id("c");
  c.kind(msg::ActionKind::ACTION_PLACE);
  c.trajectory(dds::toMsg(armCommand("c", ActionKind::kPlace, {std::vector<double>(6, 0.0)}).trajectory));
  auto place = fromMsg(c);  // place with a zero quaternion target: rejected, field named
  ASSERT_FALSE(place);
  EXPECT_EQ(place.error().where.field.rfind("object_target", 0), 0u) << place.error().toString();
  c.trajectory().positions().pop_back();
  auto short_traj = fromMsg(c);
  ASSERT_FALSE(short_traj);
  EXPECT_EQ(short_traj.error().where.field, "trajectory.positions");

  msg::FaultInjection f;
  f.type(msg::FaultType::FAULT_SPAWN_OBJECT);
  f.object_id("BAD ID");
  msg::ShapeSpec shape;
  shape.type(msg::ShapeType::SHAPE_SPHERE);
  shape.dimensions({0.1});
  f.shape(shape);
  f.pose(dds::toMsg(Eigen::Isometry3d::Identity()));
  auto fault = fromMsg(f);
  ASSERT_FALSE(fault);
  EXPECT_EQ(fault.error().where.field, "object");
}

}  // namespace
}  // namespace tamp::sim

namespace tamp::sim {
namespace {

using namespace tamp::sim::testing;

/// $TAMP_ORACLE set for one scope (the node reads it when it is built).
struct OracleEnv {
  explicit OracleEnv(bool on) {
    if (on) setenv("TAMP_ORACLE", "1", 1);
    else unsetenv("TAMP_ORACLE");
  }
  ~OracleEnv() { unsetenv("TAMP_ORACLE"); }
};

// The oracle's durations are the simulator's true nominal ones: equal to Simulator::
// nominalDuration of the same command (another code path: the command's planned timeline) and,
// with noise and stalls off, to what the robot then takes. It also reveals the hidden objects
// (with their true kind) and the scripted faults.
// `tamp run --realtime-factor` reaches the simulator as $TAMP_SIM_REALTIME_FACTOR; a value that is
// not a number >= 0 stops the node from starting, with the variable named.
TEST(SimNodeTest, ABadRealtimeFactorFromTheEnvironmentIsRefused) {
  for (const char* bad : {"abc", "-1", "2x", "nan"}) {
    setenv("TAMP_SIM_REALTIME_FACTOR", bad, 1);
    dds::ServiceArgs args;
    args.name = "sim_rt_test";
    args.domain_id = dds::testing::isolatedDomain();
    auto node = SimNode::create(args);
    unsetenv("TAMP_SIM_REALTIME_FACTOR");
    ASSERT_FALSE(node) << bad;
    EXPECT_NE(node.error().message.find("TAMP_SIM_REALTIME_FACTOR"), std::string::npos) << node.error().message;
    EXPECT_NE(node.error().message.find(bad), std::string::npos) << node.error().message;
  }
}

TEST(SimNodeOracleTest, DurationsAreTheSimulatorsNominalOnesAndTheTruthIsRevealed) {
  const OracleEnv env(true);
  const int domain = dds::testing::isolatedDomain();
  dds::ServiceArgs args;
  args.name = "sim_oracle_test";
  args.domain_id = domain;
  SimParams params = exactParams();
  params.dynamics.base.latency_s = 0.25;  // something other than the defaults' zero, if any
  world::World w = emptyRoom();
  ASSERT_TRUE(w.addObject(box("crate", 0.4, 0.4, 0.4, at(3.0, 2.0, 0.2), true, true)));
  Fault fail;
  fail.id = "pick_slips";
  fail.type = FaultType::kFailAction;
  fail.trigger.step = 2;
  fail.action = ActionKind::kPick;
  SimNode node(args, SimSetup(w, robotModel(), upright(), {fail}), params);

  auto p = dds::testing::makeParticipant(domain);
  ASSERT_TRUE(p);
  dds::RpcClient<msg::OracleRequest, msg::OracleReply> oracle(p, dds::services::kOracle);
  ASSERT_TRUE(oracle.waitForServer(Termination::after(20)));

  const auto drive = moveBase("drive", {{0, 0, 0}, {1.5, 0, 0}, {1.5, 1.0, 1.0}});
  const auto arm = armCommand("arm", ActionKind::kMoveArm,
                              {std::vector<double>(robotModel().armDof(), 0.0),
                               std::vector<double>(robotModel().armDof(), 0.4)});
  msg::OracleRequest req;
  msg::EffortQuery qb;
  qb.kind(msg::ActionKind::ACTION_MOVE_BASE);
  qb.path(dds::toMsg(drive.trajectory.path()));
  msg::EffortQuery qa;
  qa.kind(msg::ActionKind::ACTION_MOVE_ARM);
  qa.path(dds::toMsg(arm.trajectory.path()));
  qa.object_mass(3.0);
  msg::EffortQuery qp;
  qp.kind(msg::ActionKind::ACTION_PICK);
  qp.approach_m(0.1);
  qp.retreat_m(0.1);
  qp.object_mass(2.0);
  msg::EffortQuery qbad = qb;
  qbad.object_mass(-1.0);
  req.queries({qb, qa, qp, qbad});
  req.want_truth(true);
  auto rep = oracle.call(req, dds::CallOptions{10.0, {}});
  ASSERT_TRUE(rep) << rep.error().toString();
  ASSERT_EQ(rep->header().code(), msg::STATUS_OK) << rep->header().message();
  ASSERT_EQ(rep->durations().size(), 4u);

  // move_base: against the simulator's own timeline of the command from where the robot stands.
  Result<double> planned = Error(ErrorCode::kInternal, "not run");
  node.loop().withSimulator([&](Simulator& s) { planned = s.nominalDuration(drive); });
  ASSERT_TRUE(planned) << planned.error().toString();
  ASSERT_EQ(rep->durations()[0].code(), msg::STATUS_OK) << rep->durations()[0].message();
  EXPECT_NEAR(rep->durations()[0].mean_s(), *planned, 1e-9);
  EXPECT_EQ(rep->durations()[0].stddev_s(), 0.0);  // exactParams: no execution noise
  // move_arm with a load and pick: the dynamics' nominal duration with the node's parameters.
  const auto speeds = armSpeedLimits(robotModel());
  NominalQuery na;
  na.kind = ActionKind::kMoveArm;
  na.path = arm.trajectory.path();
  na.object_mass_kg = 3.0;
  NominalQuery np;
  np.kind = ActionKind::kPick;
  np.approach_m = np.retreat_m = 0.1;
  np.object_mass_kg = 2.0;
  EXPECT_NEAR(rep->durations()[1].mean_s(), *nominalDuration(params.dynamics, speeds, na), 1e-9);
  EXPECT_NEAR(rep->durations()[2].mean_s(), *nominalDuration(params.dynamics, speeds, np), 1e-9);
  // A malformed query is refused alone, naming its field.
  EXPECT_EQ(rep->durations()[3].code(), msg::STATUS_INVALID_ARGUMENT);
  EXPECT_NE(rep->durations()[3].message().find("queries[3].object_mass"), std::string::npos)
      << rep->durations()[3].message();

  // The truth: the hidden crate as the movable object it is, the scripted failure.
  ASSERT_EQ(rep->hidden_objects().size(), 1u);
  EXPECT_EQ(rep->hidden_objects()[0].id(), "crate");
  EXPECT_EQ(rep->hidden_objects()[0].kind(), msg::OBJECT_MOVABLE);
  ASSERT_EQ(rep->faults().size(), 1u);
  EXPECT_EQ(rep->faults()[0].fault_id(), "pick_slips");
  EXPECT_EQ(rep->faults()[0].type(), msg::FaultType::FAULT_FAIL_NEXT_ACTION);
  EXPECT_FALSE(rep->faults()[0].at_time());
  EXPECT_EQ(rep->faults()[0].step(), 2);
  EXPECT_FALSE(rep->faults()[0].any_action());
  EXPECT_EQ(rep->faults()[0].action(), msg::ActionKind::ACTION_PICK);
  EXPECT_EQ(rep->action_count(), 0);

  // Executed (noise and stalls off), the drive takes exactly what the oracle said.
  ASSERT_TRUE(node.loop().submit(drive));
  double measured = -1.0;
  while (measured < 0.0) {
    node.loop().withSimulator([&](Simulator& s) {
      const auto& log = s.actionLog();
      if (!log.empty() && log.back().result) measured = log.back().result->duration_s;
    });
    if (measured < 0.0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_NEAR(measured, rep->durations()[0].mean_s(), 1e-6);
}

// An object a scripted fault will put down is part of the truth before it appears: where it will.
TEST(SimNodeOracleTest, AnObjectAScriptedFaultWillPutDownIsToldWhereItWillAppear) {
  const OracleEnv env(true);
  const int domain = dds::testing::isolatedDomain();
  dds::ServiceArgs args;
  args.name = "sim_oracle_spawn_test";
  args.domain_id = domain;
  Fault spawn;
  spawn.id = "someone_leaves_a_box";
  spawn.type = FaultType::kSpawnObject;
  spawn.trigger.time_s = 1e6;  // not during this test
  spawn.object = box("parcel", 0.3, 0.3, 0.3, at(2.5, 1.0, 0.15), true, false);
  SimNode node(args, SimSetup(emptyRoom(), robotModel(), upright(), {spawn}), exactParams());
  auto p = dds::testing::makeParticipant(domain);
  ASSERT_TRUE(p);
  dds::RpcClient<msg::OracleRequest, msg::OracleReply> oracle(p, dds::services::kOracle);
  ASSERT_TRUE(oracle.waitForServer(Termination::after(20)));
  msg::OracleRequest req;
  req.want_truth(true);
  auto rep = oracle.call(req, dds::CallOptions{10.0, {}});
  ASSERT_TRUE(rep) << rep.error().toString();
  ASSERT_EQ(rep->header().code(), msg::STATUS_OK) << rep->header().message();
  bool in_world = true;
  node.loop().withSimulator([&](Simulator& s) { in_world = s.world().findObject("parcel") != nullptr; });
  EXPECT_FALSE(in_world);  // not there yet
  ASSERT_EQ(rep->hidden_objects().size(), 1u);
  EXPECT_EQ(rep->hidden_objects()[0].id(), "parcel");
  EXPECT_EQ(rep->hidden_objects()[0].kind(), msg::OBJECT_MOVABLE);
  EXPECT_NEAR(rep->hidden_objects()[0].pose().position().x(), 2.5, 1e-9);
  ASSERT_EQ(rep->faults().size(), 1u);
  EXPECT_EQ(rep->faults()[0].type(), msg::FaultType::FAULT_SPAWN_OBJECT);
  EXPECT_EQ(rep->faults()[0].object_id(), "parcel");
}

// A normal deployment does not expose the truth: without $TAMP_ORACLE no oracle is served
// (judged after the node's other request/reply service, echo, is matched).
TEST(SimNodeOracleTest, NoOracleIsServedUnlessEnabled) {
  const OracleEnv env(false);
  const int domain = dds::testing::isolatedDomain();
  dds::ServiceArgs args;
  args.name = "sim_no_oracle_test";
  args.domain_id = domain;
  SimNode node(args, SimSetup(emptyRoom(), robotModel(), upright()), exactParams());
  auto p = dds::testing::makeParticipant(domain);
  ASSERT_TRUE(p);
  dds::RpcClient<msg::EchoRequest, msg::EchoReply> echo(p, dds::echoService("sim_no_oracle_test"));
  ASSERT_TRUE(echo.waitForServer(Termination::after(20)));
  dds::RpcClient<msg::OracleRequest, msg::OracleReply> oracle(p, dds::services::kOracle);
  EXPECT_FALSE(oracle.waitForServer(Termination::after(2)));
  msg::OracleRequest req;
  req.want_truth(true);
  auto rep = oracle.call(req, dds::CallOptions{1.0, {}});
  EXPECT_FALSE(rep);
}

}  // namespace
}  // namespace tamp::sim
