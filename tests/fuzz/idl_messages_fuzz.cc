// libFuzzer target: the IDL messages as a service receives them. The first byte picks a message
// type, the rest is its CDR payload (encapsulation header included) as it would arrive on the
// wire; whatever deserialises goes through the shared validator (tamp::msgv), which must return
// ok or an error naming a field, never crash, throw or read out of bounds. An accepted message
// is checked once more: validation of it must be deterministic.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "tamp/msg/effortPubSubTypes.h"
#include "tamp/msg/executionPubSubTypes.h"
#include "tamp/msg/missionPubSubTypes.h"
#include "tamp/msg/motionPubSubTypes.h"
#include "tamp/msg/planningPubSubTypes.h"
#include "tamp/msg/robotPubSubTypes.h"
#include "tamp/msg/worldPubSubTypes.h"
#include "tamp/msg_validation/validate.h"

namespace {

using eprosima::fastrtps::rtps::SerializedPayload_t;
namespace msg = tamp::msg;

template <typename T, typename PubSub>
void one(const uint8_t* data, size_t size) {
  PubSub type;
  SerializedPayload_t payload(static_cast<uint32_t>(size));
  if (size > 0) std::memcpy(payload.data, data, size);
  payload.length = static_cast<uint32_t>(size);
  T m;
  bool ok = false;
  try {
    ok = type.deserialize(&payload, &m);
  } catch (const std::exception&) {
    return;  // fastcdr refuses some malformed payloads by throwing (e.g. a bad string length)
  }
  if (!ok) return;
  const tamp::Status first = tamp::msgv::validate(m);
  const tamp::Status again = tamp::msgv::validate(m);
  if (first.ok() != again.ok()) __builtin_trap();
  if (!first.ok() && first.error().where.field.empty()) __builtin_trap();  // names the field
}

using Fn = void (*)(const uint8_t*, size_t);
#define TAMP_FUZZ_TYPE(Name) &one<msg::Name, msg::Name##PubSubType>
const Fn kTypes[] = {
    TAMP_FUZZ_TYPE(PlanRequest),      TAMP_FUZZ_TYPE(MotionRequest),       TAMP_FUZZ_TYPE(PlacementRequest),
    TAMP_FUZZ_TYPE(GraspRequest),     TAMP_FUZZ_TYPE(EffortRequest),       TAMP_FUZZ_TYPE(PlanReply),
    TAMP_FUZZ_TYPE(MotionReply),      TAMP_FUZZ_TYPE(PlacementReply),      TAMP_FUZZ_TYPE(GraspReply),
    TAMP_FUZZ_TYPE(EffortReply),      TAMP_FUZZ_TYPE(MissionCommand),      TAMP_FUZZ_TYPE(ExecuteCommand),
    TAMP_FUZZ_TYPE(ExecuteStatus),    TAMP_FUZZ_TYPE(TrajectoryCommand),   TAMP_FUZZ_TYPE(ActionResult),
    TAMP_FUZZ_TYPE(FailureEvent),     TAMP_FUZZ_TYPE(FaultInjection),      TAMP_FUZZ_TYPE(ExecutionRecord),
    TAMP_FUZZ_TYPE(EffortModelSnapshot), TAMP_FUZZ_TYPE(RobotState),       TAMP_FUZZ_TYPE(PointCloudFrame),
    TAMP_FUZZ_TYPE(WorldObject),      TAMP_FUZZ_TYPE(WorldMeta),           TAMP_FUZZ_TYPE(WorldEvent),
    TAMP_FUZZ_TYPE(RecordAck),
};
#undef TAMP_FUZZ_TYPE
constexpr size_t kTypeCount = sizeof(kTypes) / sizeof(kTypes[0]);

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  kTypes[data[0] % kTypeCount](data + 1, size - 1);
  return 0;
}

#ifdef TAMP_FUZZ_REPLAY
// Seeds: one valid, filled-in message of each type, serialised as on the wire (the replay's
// mutations and libFuzzer start from real layouts, not from noise).
namespace {

template <typename T, typename PubSub>
void writeSeed(const std::filesystem::path& dir, size_t index, const char* name, T m) {
  PubSub type;
  SerializedPayload_t payload(type.getSerializedSizeProvider(&m)());
  if (!type.serialize(&m, &payload)) return;
  std::ofstream out(dir / (std::to_string(index) + "_" + name + ".cdr"), std::ios::binary);
  const char tag = static_cast<char>(index);
  out.write(&tag, 1);
  out.write(reinterpret_cast<const char*>(payload.data), payload.length);
}

msg::Pose3D unitPose() {
  msg::Pose3D p;
  p.position().x(1.0);
  p.orientation().w(1.0);
  return p;
}
void header(msg::RequestHeader& h) {
  h.request_id("client#1");
  h.client_id("client");
  h.budget_s(5.0);
  h.attempt(1);
}

}  // namespace

extern "C" int TampFuzzWriteSeeds(const char* dir_name) {
  const std::filesystem::path dir(dir_name);
  std::filesystem::create_directories(dir);
  msg::JointTrajectory traj;
  traj.joint_names({"x", "y", "theta"});
  traj.times({0.0, 1.0});
  traj.positions({0, 0, 0, 1, 0, 0.5});
  msg::JointPath path;
  path.joint_names({"x", "y", "theta"});
  path.values({0, 0, 0, 1, 0, 0.5});
  {
    msg::PlanRequest m;
    header(m.header());
    m.domain_path("config/pddl/mobile_manipulation.pddl");
    m.objects({"can - item", "table - region", "start - location"});
    m.init({"(robot-at start)", "(hand-empty)", "(arm-at stow)"});
    m.goal({"(holding can)"});
    writeSeed<msg::PlanRequest, msg::PlanRequestPubSubType>(dir, 0, "PlanRequest", m);
  }
  {
    msg::MotionRequest m;
    header(m.header());
    m.group(msg::GROUP_ARM);
    m.goal_type(msg::GOAL_END_EFFECTOR_POSE);
    m.start_joint_names({"arm_joint_1", "arm_joint_2"});
    m.start_joint_positions({0.1, -0.2});
    m.goal_end_effector(unitPose());
    msg::ObjectOverride o;
    o.object_id("box");
    o.pose(unitPose());
    m.object_overrides({o});
    m.ignored_objects({"can"});
    writeSeed<msg::MotionRequest, msg::MotionRequestPubSubType>(dir, 1, "MotionRequest", m);
  }
  {
    msg::PlacementRequest m;
    header(m.header());
    m.object_id("can");
    m.region_id("table");
    m.keep_clear_path({msg::Pose2D(), msg::Pose2D()});
    m.max_placements(4);
    writeSeed<msg::PlacementRequest, msg::PlacementRequestPubSubType>(dir, 2, "PlacementRequest", m);
  }
  {
    msg::GraspRequest m;
    header(m.header());
    m.object_id("can");
    m.max_grasps(4);
    writeSeed<msg::GraspRequest, msg::GraspRequestPubSubType>(dir, 3, "GraspRequest", m);
  }
  {
    msg::EffortRequest m;
    header(m.header());
    msg::EffortQuery q;
    q.path(path);
    msg::EffortQuery pick;
    pick.kind(msg::ACTION_PICK);
    pick.object_mass(0.3);
    pick.approach_m(0.1);
    pick.retreat_m(0.1);
    m.queries({q, pick});
    writeSeed<msg::EffortRequest, msg::EffortRequestPubSubType>(dir, 4, "EffortRequest", m);
  }
  {
    msg::PlanReply m;
    m.actions({"(move_base start table_front)"});
    msg::PlanState st;
    st.atoms({"(robot-at start)"});
    m.states({st, st});
    writeSeed<msg::PlanReply, msg::PlanReplyPubSubType>(dir, 5, "PlanReply", m);
  }
  {
    msg::MotionReply m;
    m.path(path);
    m.trajectory(traj);
    msg::BlockingObject b;
    b.object_id("box");
    b.exit_fraction(0.5);
    b.swept_base({msg::Pose2D()});
    m.blocking({b});
    writeSeed<msg::MotionReply, msg::MotionReplyPubSubType>(dir, 6, "MotionReply", m);
  }
  {
    msg::PlacementReply m;
    msg::Placement p;
    p.object_pose(unitPose());
    p.arm_configuration({0, 1, 2});
    m.placements({p});
    writeSeed<msg::PlacementReply, msg::PlacementReplyPubSubType>(dir, 7, "PlacementReply", m);
  }
  {
    msg::GraspReply m;
    msg::Grasp g;
    g.gripper_in_object(unitPose());
    g.pregrasp_configuration({0, 1});
    g.grasp_configuration({0, 1});
    m.grasps({g});
    writeSeed<msg::GraspReply, msg::GraspReplyPubSubType>(dir, 8, "GraspReply", m);
  }
  {
    msg::EffortReply m;
    msg::EffortEstimate e;
    e.mean_s(1.0);
    e.stddev_s(0.1);
    m.estimates({e});
    writeSeed<msg::EffortReply, msg::EffortReplyPubSubType>(dir, 9, "EffortReply", m);
  }
  {
    msg::MissionCommand m;
    m.mission_id("m1");
    m.scenario_path("config/scenarios/occluded_can.yaml");
    m.goal({"(holding can)"});
    writeSeed<msg::MissionCommand, msg::MissionCommandPubSubType>(dir, 10, "MissionCommand", m);
  }
  {
    msg::ExecuteCommand m;
    m.command_id("c1");
    m.mission_id("m1");
    m.kind(msg::ACTION_PICK);
    m.object_id("can");
    m.trajectory(traj);
    m.object_target(unitPose());
    m.object_target_given(true);
    m.expected_duration_s(2.0);
    writeSeed<msg::ExecuteCommand, msg::ExecuteCommandPubSubType>(dir, 11, "ExecuteCommand", m);
  }
  {
    msg::ExecuteStatus m;
    m.command_id("c1");
    m.state(msg::EXEC_SUCCEEDED);
    m.progress(1.0);
    writeSeed<msg::ExecuteStatus, msg::ExecuteStatusPubSubType>(dir, 12, "ExecuteStatus", m);
  }
  {
    msg::TrajectoryCommand m;
    m.command_id("t1");
    m.trajectory(traj);
    writeSeed<msg::TrajectoryCommand, msg::TrajectoryCommandPubSubType>(dir, 13, "TrajectoryCommand", m);
  }
  {
    msg::ActionResult m;
    m.command_id("t1");
    m.outcome(msg::OUTCOME_BLOCKED);
    m.blocking_object_id("box");
    m.duration_s(1.5);
    writeSeed<msg::ActionResult, msg::ActionResultPubSubType>(dir, 14, "ActionResult", m);
  }
  {
    msg::FailureEvent m;
    m.command_id("c1");
    m.object_id("box");
    writeSeed<msg::FailureEvent, msg::FailureEventPubSubType>(dir, 15, "FailureEvent", m);
  }
  {
    msg::FaultInjection m;
    m.fault_id("f1");
    m.type(msg::FAULT_SPAWN_OBJECT);
    m.object_id("crate");
    m.shape().dimensions({0.2, 0.2, 0.2});
    m.pose(unitPose());
    writeSeed<msg::FaultInjection, msg::FaultInjectionPubSubType>(dir, 16, "FaultInjection", m);
  }
  {
    msg::ExecutionRecord m;
    m.record_id("r1");
    m.path(path);
    m.duration_s(3.0);
    m.success(true);
    m.source("sim");
    writeSeed<msg::ExecutionRecord, msg::ExecutionRecordPubSubType>(dir, 17, "ExecutionRecord", m);
  }
  {
    msg::EffortModelSnapshot m;
    m.model_id("effort");
    msg::ActionTimeModel a;
    a.parameter_names({"v", "a"});
    a.values({0.5, 0.5});
    a.log_covariance({0.1, 0, 0, 0.1});
    m.models({a});
    writeSeed<msg::EffortModelSnapshot, msg::EffortModelSnapshotPubSubType>(dir, 18, "EffortModelSnapshot", m);
  }
  {
    msg::RobotState m;
    m.robot_id("robot");
    m.joint_names({"a", "b"});
    m.joint_positions({0.1, 0.2});
    m.joint_velocities({0, 0});
    writeSeed<msg::RobotState, msg::RobotStatePubSubType>(dir, 19, "RobotState", m);
  }
  {
    msg::PointCloudFrame m;
    m.sensor_id("cam");
    m.sensor_pose(unitPose());
    m.width(2);
    m.height(1);
    m.points({0.f, 0.f, 1.f, 0.5f, 0.5f, 1.f});
    writeSeed<msg::PointCloudFrame, msg::PointCloudFramePubSubType>(dir, 20, "PointCloudFrame", m);
  }
  {
    msg::WorldObject m;
    m.id("can");
    m.kind(msg::OBJECT_MOVABLE);
    m.shape().type(msg::SHAPE_CYLINDER);
    m.shape().dimensions({0.03, 0.12});
    m.pose(unitPose());
    m.mass(0.3);
    m.confidence(1.0);
    writeSeed<msg::WorldObject, msg::WorldObjectPubSubType>(dir, 21, "WorldObject", m);
  }
  {
    msg::WorldMeta m;
    m.world_id("world");
    msg::Region r;
    r.id("table");
    msg::Point2 a, b, c;
    b.x(1);
    c.y(1);
    r.polygon({a, b, c});
    msg::NamedLocation l;
    l.id("start");
    m.regions({r});
    m.locations({l});
    m.bounds({0, 0, 1, 1});
    m.object_ids({"can"});
    m.object_versions({1});
    writeSeed<msg::WorldMeta, msg::WorldMetaPubSubType>(dir, 22, "WorldMeta", m);
  }
  {
    msg::WorldEvent m;
    m.object_id("can");
    writeSeed<msg::WorldEvent, msg::WorldEventPubSubType>(dir, 23, "WorldEvent", m);
  }
  {
    msg::RecordAck m;
    m.record_id("r1");
    m.estimator("effort_estimator");
    m.stored(true);
    writeSeed<msg::RecordAck, msg::RecordAckPubSubType>(dir, 24, "RecordAck", m);
  }
  return 0;
}
#endif  // TAMP_FUZZ_REPLAY
