// Contract tests of the message validators: for every message type a service receives, a valid
// message passes, and each kind of damage (NaN/inf, unknown enum value, empty required id,
// huge sequence, mismatched parallel sequences) is refused with the full field path.
#include "tamp/msg_validation/validate.h"

#include <cmath>
#include <limits>
#include <thread>

#include <gtest/gtest.h>

namespace tamp::msgv {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

template <typename T>
std::string why(const T& m, const Limits& l = {}) {
  Status s = validate(m, l);
  return s.ok() ? "(ok)" : s.error().message;
}

void fillHeader(msg::RequestHeader& h) {
  h.request_id("c#1");
  h.client_id("c");
  h.budget_s(5.0);
}
msg::Pose3D identity() {
  msg::Pose3D p;
  p.orientation().w(1.0);
  return p;
}

msg::MotionRequest validMotion() {
  msg::MotionRequest m;
  fillHeader(m.header());
  m.group(msg::GROUP_ARM);
  m.goal_type(msg::GOAL_CONFIGURATION);
  m.start_joint_names({"j1", "j2", "j3", "j4"});
  m.start_joint_positions({0.0, 0.1, 0.2, 0.3});
  m.goal_configuration({0.0, 0.0, 0.0, 0.0});
  return m;
}

TEST(MsgValidation, MotionRequest) {
  EXPECT_EQ(why(validMotion()), "(ok)");
  auto m = validMotion();
  m.start_joint_positions()[3] = kNaN;
  EXPECT_EQ(why(m), "MotionRequest.start_joint_positions[3]: NaN");
  m = validMotion();
  m.start_base().theta(kInf);
  EXPECT_EQ(why(m), "MotionRequest.start_base.theta: inf");
  m = validMotion();
  m.group(static_cast<msg::PlanningGroup>(7));
  EXPECT_EQ(why(m), "MotionRequest.group: unknown value 7 (0..2)");
  m = validMotion();
  m.start_joint_positions().pop_back();
  EXPECT_EQ(why(m), "MotionRequest.start_joint_positions: 3 values for 4 start_joint_names");
  m = validMotion();
  m.held_padding_m(0.5);
  EXPECT_EQ(why(m).rfind("MotionRequest.held_padding_m: must be in [", 0), 0u) << why(m);
  m.held_padding_m(kNaN);
  EXPECT_EQ(why(m), "MotionRequest.held_padding_m: NaN");
  m = validMotion();
  m.header().request_id("");
  EXPECT_EQ(why(m), "MotionRequest.header.request_id: empty (an id is required)");
  m = validMotion();
  m.header().budget_s(kNaN);
  EXPECT_EQ(why(m), "MotionRequest.header.budget_s: NaN");
  // The end-effector goal is read only for GOAL_END_EFFECTOR_POSE: then a zero quaternion is bad.
  m = validMotion();
  EXPECT_EQ(why(m), "(ok)");  // default goal_end_effector: all zero, unused
  m.goal_type(msg::GOAL_END_EFFECTOR_POSE);
  EXPECT_EQ(why(m), "MotionRequest.goal_end_effector.orientation: zero quaternion");
  m.goal_end_effector(identity());
  m.goal_end_effector().position().z(kNaN);
  EXPECT_EQ(why(m), "MotionRequest.goal_end_effector.position.z: NaN");
  m = validMotion();
  m.object_overrides().resize(2);
  m.object_overrides()[0].object_id("box");
  m.object_overrides()[0].removed(true);
  EXPECT_EQ(why(m), "MotionRequest.object_overrides[1].object_id: empty (an id is required)");
  m.object_overrides()[1].object_id("can");
  EXPECT_EQ(why(m), "MotionRequest.object_overrides[1].pose.orientation: zero quaternion");
  // Added objects (the oracle's hidden ones) are whole objects: id, shape and pose checked.
  m = validMotion();
  m.added_objects().resize(1);
  m.added_objects()[0].id("crate");
  m.added_objects()[0].shape().type(msg::SHAPE_BOX);
  m.added_objects()[0].shape().dimensions({0.4, 0.4, 0.4});
  m.added_objects()[0].pose(identity());
  EXPECT_EQ(why(m), "(ok)");
  m.added_objects()[0].pose().position().y(kNaN);
  EXPECT_EQ(why(m), "MotionRequest.added_objects[0].pose.position.y: NaN");
  msg::GraspRequest g;
  fillHeader(g.header());
  g.object_id("crate");
  g.added_objects(m.added_objects());
  EXPECT_EQ(why(g), "GraspRequest.added_objects[0].pose.position.y: NaN");
  m = validMotion();
  m.ignored_objects(std::vector<std::string>(200001, "x"));
  EXPECT_EQ(why(m), "MotionRequest.ignored_objects: 200001 elements (limit 100000)");
  m = validMotion();
  m.fixed_objects({"can", ""});
  EXPECT_EQ(why(m), "MotionRequest.fixed_objects[1]: empty (an id is required)");
  m = validMotion();
  m.movable_cost_weight(-1);
  EXPECT_EQ(why(m), "MotionRequest.movable_cost_weight: must be >= 0, got -1.000000");
  m = validMotion();
  m.start_joint_names()[1] = std::string(300, 'j');
  EXPECT_EQ(why(m), "MotionRequest.start_joint_names[1]: id of 300 bytes (limit 256)");
}

TEST(MsgValidation, TheErrorCarriesTheFieldPath) {
  auto m = validMotion();
  m.start_joint_positions()[3] = kNaN;
  Status s = validate(m);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(s.error().where.field, "MotionRequest.start_joint_positions[3]");
  EXPECT_EQ(kindOf(s.error()), "MotionRequest.start_joint_positions[]");
}

TEST(MsgValidation, PlanRequest) {
  msg::PlanRequest m;
  fillHeader(m.header());
  m.domain_path("mm.pddl");
  m.objects({"can - item"});
  m.init({"(hand-empty)"});
  m.goal({"(holding can)"});
  EXPECT_EQ(why(m), "(ok)");
  m.goal()[0] = "";
  EXPECT_EQ(why(m), "PlanRequest.goal[0]: empty string");
  m.goal().clear();
  EXPECT_EQ(why(m), "PlanRequest.goal: empty, and no problem_pddl");
  m.goal({"(holding can)"});
  m.domain_path("");
  EXPECT_EQ(why(m), "PlanRequest.domain_pddl: empty, and no domain_path");
  m.domain_path("mm.pddl");
  m.search(static_cast<msg::SearchKind>(99));
  EXPECT_EQ(why(m), "PlanRequest.search: unknown value 99 (0..4)");
  m.search(msg::SEARCH_WASTAR);
  m.weight(kNaN);
  EXPECT_EQ(why(m), "PlanRequest.weight: NaN");
  m.weight(0);
  Limits small;
  small.max_items = 2;
  m.init({"(a)", "(b)", "(c)"});
  EXPECT_EQ(why(m, small), "PlanRequest.init: 3 elements (limit 2)");
}

TEST(MsgValidation, PlacementGraspAndEffortRequests) {
  msg::PlacementRequest p;
  fillHeader(p.header());
  p.object_id("can");
  p.region_id("table");
  p.keep_clear_path({msg::Pose2D()});
  EXPECT_EQ(why(p), "(ok)");
  p.keep_clear_path()[0].y(kNaN);
  EXPECT_EQ(why(p), "PlacementRequest.keep_clear_path[0].y: NaN");
  p.keep_clear_path().clear();
  p.region_id("");
  EXPECT_EQ(why(p), "PlacementRequest.region_id: empty (an id is required)");

  msg::GraspRequest g;
  fillHeader(g.header());
  EXPECT_EQ(why(g), "GraspRequest.object_id: empty (an id is required)");
  g.object_id("can");
  EXPECT_EQ(why(g), "(ok)");
  g.max_grasps(4000000000u);
  EXPECT_EQ(why(g), "GraspRequest.max_grasps: 4000000000 (limit 100000)");

  msg::EffortRequest e;
  fillHeader(e.header());
  e.queries().resize(2);
  e.queries()[1].path().joint_names({"x", "y"});
  e.queries()[1].path().values({0, 0, 1, 1});
  EXPECT_EQ(why(e), "(ok)");
  e.queries()[1].path().values({0, 0, 1});
  EXPECT_EQ(why(e), "EffortRequest.queries[1].path.values: 3 values are not a multiple of 2 joints");
  e.queries()[1].path().values({0, 0, 1, kNaN});
  EXPECT_EQ(why(e), "EffortRequest.queries[1].path.values[3]: NaN");
  e.queries()[1].path().values({0, 0, 1, 1});
  e.queries()[0].object_mass(-2);
  EXPECT_EQ(why(e), "EffortRequest.queries[0].object_mass: must be >= 0, got -2.000000");
}

TEST(MsgValidation, CommandsAndResults) {
  msg::ExecuteCommand c;
  c.command_id("c1");
  c.kind(msg::ACTION_MOVE_BASE);
  c.trajectory().joint_names({"x", "y", "theta"});
  c.trajectory().times({0, 1});
  c.trajectory().positions({0, 0, 0, 1, 0, 0});
  EXPECT_EQ(why(c), "(ok)");
  c.trajectory().times({1, 0});
  EXPECT_EQ(why(c), "ExecuteCommand.trajectory.times[1]: decreasing (0.000000 after 1.000000)");
  c.trajectory().times({0, 1});
  c.trajectory().positions({0, 0, 0, 1, 0});
  EXPECT_EQ(why(c), "ExecuteCommand.trajectory.positions: expected 6 values (2 points x 3 joints), got 5");
  c.trajectory().positions({0, 0, 0, 1, 0, 0});
  c.kind(msg::ACTION_PICK);
  EXPECT_EQ(why(c), "ExecuteCommand.object_id: empty (an id is required)");
  c.object_id("can");
  c.object_target_given(true);
  EXPECT_EQ(why(c), "ExecuteCommand.object_target.orientation: zero quaternion");
  c.object_target(identity());
  c.expected_duration_s(kInf);
  EXPECT_EQ(why(c), "ExecuteCommand.expected_duration_s: inf");
  msg::ExecuteCommand cancel;
  cancel.command_id("c1");
  cancel.cancel(true);
  cancel.kind(static_cast<msg::ActionKind>(12));  // a cancel is read for its id only
  EXPECT_EQ(why(cancel), "(ok)");

  msg::TrajectoryCommand t;
  EXPECT_EQ(why(t), "TrajectoryCommand.command_id: empty (an id is required)");
  t.command_id("t1");
  t.kind(static_cast<msg::ActionKind>(4));
  EXPECT_EQ(why(t), "TrajectoryCommand.kind: unknown value 4 (0..3)");

  msg::ActionResult r;
  r.command_id("t1");
  r.outcome(msg::OUTCOME_BLOCKED);
  EXPECT_EQ(why(r), "ActionResult.blocking_object_id: empty (an id is required)");
  r.blocking_object_id("box");
  r.duration_s(-1);
  EXPECT_EQ(why(r), "ActionResult.duration_s: must be >= 0, got -1.000000");

  msg::MissionCommand mc;
  mc.mission_id("m1");
  EXPECT_EQ(why(mc), "MissionCommand.scenario_path: empty (a mission needs a scenario)");
  mc.abort(true);
  EXPECT_EQ(why(mc), "(ok)");
  mc.abort(false);
  mc.scenario_path("config/scenarios/occluded_can.yaml");
  mc.policy(static_cast<msg::EffortPolicy>(3));
  EXPECT_EQ(why(mc), "MissionCommand.policy: unknown value 3 (0..2)");

  msg::FaultInjection f;
  f.type(msg::FAULT_SPAWN_OBJECT);
  EXPECT_EQ(why(f), "FaultInjection.object_id: empty (an id is required)");
  f.object_id("crate");
  f.shape().dimensions({0.1, -0.2, 0.3});
  EXPECT_EQ(why(f), "FaultInjection.shape.dimensions[1]: negative (-0.200000)");
  f.shape().dimensions({0.1, 0.2, 0.3});
  f.pose(identity());
  EXPECT_EQ(why(f), "(ok)");
}

TEST(MsgValidation, StatesCloudsRecordsAndModels) {
  msg::RobotState s;
  s.joint_names({"a", "b"});
  s.joint_positions({0, 1});
  EXPECT_EQ(why(s), "(ok)");
  s.joint_positions({0, kNaN});
  EXPECT_EQ(why(s), "RobotState.joint_positions[1]: NaN");
  s.joint_positions({0});
  EXPECT_EQ(why(s), "RobotState.joint_positions: 1 values for 2 joint_names");
  s.joint_positions({0, 1});
  s.base().x(-kInf);
  EXPECT_EQ(why(s), "RobotState.base.x: -inf");

  msg::PointCloudFrame pc;
  pc.sensor_id("cam");
  pc.sensor_pose(identity());
  pc.width(2);
  pc.height(1);
  pc.points({0, 0, 1, NAN, NAN, NAN});  // NaN triplet: no return
  EXPECT_EQ(why(pc), "(ok)");
  pc.points()[2] = INFINITY;
  EXPECT_EQ(why(pc), "PointCloudFrame.points[2]: inf");
  pc.points({0, 0, 1, 0});
  EXPECT_EQ(why(pc), "PointCloudFrame.points: 4 values are not x, y, z triplets");
  pc.points({0, 0, 1});
  EXPECT_EQ(why(pc), "PointCloudFrame.width: width x height = 2 x 1 does not match 1 points");

  msg::ExecutionRecord rec;
  EXPECT_EQ(why(rec), "(ok)");
  rec.record_id(std::string(1000, 'r'));
  EXPECT_EQ(why(rec), "ExecutionRecord.record_id: id of 1000 bytes (limit 256)");
  rec.record_id("r1");
  rec.duration_s(kNaN);
  EXPECT_EQ(why(rec), "ExecutionRecord.duration_s: NaN");

  msg::RecordAck ack;
  ack.record_id("r1");
  EXPECT_EQ(why(ack), "(ok)");
  ack.record_id("");
  EXPECT_NE(why(ack).find("RecordAck.record_id"), std::string::npos) << why(ack);

  msg::EffortModelSnapshot snap;
  snap.model_id("effort");
  snap.models().resize(1);
  snap.models()[0].parameter_names({"v", "a"});
  snap.models()[0].values({0.5, 0.5});
  snap.models()[0].log_covariance({1, 0, 0, 1});
  EXPECT_EQ(why(snap), "(ok)");
  snap.models()[0].log_covariance({1, 0, 0});
  EXPECT_EQ(why(snap), "EffortModelSnapshot.models[0].log_covariance: expected 0 or 4 values (n x n), got 3");
}

TEST(MsgValidation, WorldModel) {
  msg::WorldObject o;
  o.id("can");
  o.shape().type(msg::SHAPE_CYLINDER);
  o.shape().dimensions({0.03, 0.12});
  o.pose(identity());
  o.confidence(1.0);
  EXPECT_EQ(why(o), "(ok)");
  o.confidence(1.5);
  EXPECT_EQ(why(o), "WorldObject.confidence: must be in [0.000000, 1.000000], got 1.500000");
  o.confidence(1.0);
  o.shape().type(static_cast<msg::ShapeType>(9));
  EXPECT_EQ(why(o), "WorldObject.shape.type: unknown value 9 (0..3)");
  o.shape().type(msg::SHAPE_CYLINDER);
  o.pose().orientation().w(0);
  EXPECT_EQ(why(o), "WorldObject.pose.orientation: zero quaternion");

  msg::WorldMeta w;
  w.world_id("world");
  w.regions().resize(1);
  w.regions()[0].id("table");
  w.regions()[0].polygon({msg::Point2(), msg::Point2(), msg::Point2()});
  w.locations().resize(1);
  w.locations()[0].id("start");
  w.object_ids({"can"});
  w.object_versions({1});
  EXPECT_EQ(why(w), "(ok)");
  w.regions()[0].polygon()[2].x(kNaN);
  EXPECT_EQ(why(w), "WorldMeta.regions[0].polygon[2].x: NaN");
  w.regions()[0].polygon()[2].x(0);
  w.locations()[0].id("");
  EXPECT_EQ(why(w), "WorldMeta.locations[0].id: empty (an id is required)");
  w.locations()[0].id("start");
  w.object_versions({});
  EXPECT_EQ(why(w), "WorldMeta.object_versions: 0 versions for 1 object_ids");
  w.object_versions({1});
  w.bounds({0, 0, 1});
  EXPECT_EQ(why(w), "WorldMeta.bounds: 3 values (expected 0 or 4: xmin, ymin, xmax, ymax)");
}

TEST(MsgValidation, RepliesTheGraphManagerReads) {
  msg::MotionReply m;
  m.path().joint_names({"x"});
  m.path().values({0, 1});
  EXPECT_EQ(why(m), "(ok)");
  m.blocking().resize(1);
  m.blocking()[0].object_id("box");
  m.blocking()[0].enter_fraction(1.5);
  EXPECT_EQ(why(m), "MotionReply.blocking[0].enter_fraction: must be in [0.000000, 1.000000], got 1.500000");
  msg::EffortReply e;
  e.estimates().resize(1);
  e.estimates()[0].mean_s(kNaN);
  EXPECT_EQ(why(e), "EffortReply.estimates[0].mean_s: NaN");
  e.estimates()[0].code(msg::STATUS_INFEASIBLE);  // an estimate that failed carries no number
  EXPECT_EQ(why(e), "(ok)");
  msg::PlanReply p;
  p.status(static_cast<msg::PlanStatus>(6));
  EXPECT_EQ(why(p), "PlanReply.status: unknown value 6 (0..5)");
  msg::GraspReply g;
  g.grasps().resize(1);
  EXPECT_EQ(why(g), "GraspReply.grasps[0].gripper_in_object.orientation: zero quaternion");
  msg::PlacementReply pl;
  pl.placements().resize(1);
  pl.placements()[0].object_pose(identity());
  pl.placements()[0].clearance(kNaN);
  EXPECT_EQ(why(pl), "PlacementReply.placements[0].clearance: NaN");
  msg::ExecuteStatus st;
  st.command_id("c");
  st.state(static_cast<msg::ExecState>(6));
  EXPECT_EQ(why(st), "ExecuteStatus.state: unknown value 6 (0..5)");
}

TEST(RejectLog, LogsTheFirstOfEachKindAndThenAtMostOncePerPeriod) {
  RejectLog log("msg_validation_test", std::chrono::milliseconds(200));
  auto m = validMotion();
  for (int i = 0; i < 4; ++i) {
    m.start_joint_positions()[static_cast<std::size_t>(i)] = kNaN;
    log.reject("tamp/motion_planner/motion/request", validate(m).error());
  }
  EXPECT_EQ(log.count(), 4U);
  EXPECT_EQ(log.linesLogged(), 1U) << "one kind: one line, whatever the index";
  auto other = validMotion();
  other.start_base().x(kNaN);
  log.reject("tamp/motion_planner/motion/request", validate(other).error());
  EXPECT_EQ(log.linesLogged(), 2U) << "a new kind is logged at once";
  std::this_thread::sleep_for(std::chrono::milliseconds(250));
  log.reject("tamp/motion_planner/motion/request", validate(m).error());
  EXPECT_EQ(log.linesLogged(), 3U) << "after the period, one summary line";
  EXPECT_FALSE(accept(m, "t", log));
  EXPECT_TRUE(accept(validMotion(), "t", log));
  EXPECT_EQ(log.count(), 7U);  // 4 + 1 + 1 + the refused accept()
}

}  // namespace
}  // namespace tamp::msgv
