#pragma once
/// @file
/// The registry of every topic and request/reply service: name, IDL type, QoS class. Writers and
/// readers take a `TopicSpec<T>`, so a topic's type and QoS cannot disagree between processes.
/// Names follow `tamp/<area>/<what>`; a service `S` uses the topics `S/request` and `S/reply`.

#include "tamp/dds/endpoint.h"
#include "tamp/msg/diagnosticsPubSubTypes.h"
#include "tamp/msg/effortPubSubTypes.h"
#include "tamp/msg/executionPubSubTypes.h"
#include "tamp/msg/heartbeatPubSubTypes.h"
#include "tamp/msg/missionPubSubTypes.h"
#include "tamp/msg/motionPubSubTypes.h"
#include "tamp/msg/oraclePubSubTypes.h"
#include "tamp/msg/planningPubSubTypes.h"
#include "tamp/msg/robotPubSubTypes.h"
#include "tamp/msg/worldPubSubTypes.h"

#define TAMP_DDS_TYPE(Name)                          \
  template <>                                        \
  struct TypeSupport<::tamp::msg::Name> {            \
    using type = ::tamp::msg::Name##PubSubType;      \
  };

namespace tamp::dds {

TAMP_DDS_TYPE(Heartbeat)
TAMP_DDS_TYPE(RobotState)
TAMP_DDS_TYPE(PointCloudFrame)
TAMP_DDS_TYPE(WorldObject)
TAMP_DDS_TYPE(WorldMeta)
TAMP_DDS_TYPE(OccupancyMap)
TAMP_DDS_TYPE(WorldEvent)
TAMP_DDS_TYPE(PlanRequest)
TAMP_DDS_TYPE(PlanReply)
TAMP_DDS_TYPE(MotionRequest)
TAMP_DDS_TYPE(MotionReply)
TAMP_DDS_TYPE(PlacementRequest)
TAMP_DDS_TYPE(PlacementReply)
TAMP_DDS_TYPE(GraspRequest)
TAMP_DDS_TYPE(GraspReply)
TAMP_DDS_TYPE(EffortRequest)
TAMP_DDS_TYPE(EffortReply)
TAMP_DDS_TYPE(EffortModelSnapshot)
TAMP_DDS_TYPE(ExecutionRecord)
TAMP_DDS_TYPE(RecordAck)
TAMP_DDS_TYPE(ExecuteCommand)
TAMP_DDS_TYPE(ExecuteStatus)
TAMP_DDS_TYPE(TrajectoryCommand)
TAMP_DDS_TYPE(ActionResult)
TAMP_DDS_TYPE(FailureEvent)
TAMP_DDS_TYPE(FaultInjection)
TAMP_DDS_TYPE(MissionCommand)
TAMP_DDS_TYPE(MissionStatus)
TAMP_DDS_TYPE(GraphSnapshot)
TAMP_DDS_TYPE(EchoRequest)
TAMP_DDS_TYPE(EchoReply)
TAMP_DDS_TYPE(OracleRequest)
TAMP_DDS_TYPE(OracleReply)

/// A request/reply service: two topics and the request's payload limit.
template <typename Req, typename Rep>
struct ServiceSpec {
  const char* name;                    ///< topics "<name>/request" and "<name>/reply"
  uint32_t max_request_bytes{16u << 20};
};

namespace topics {
// Liveness
inline constexpr TopicSpec<msg::Heartbeat> kHeartbeat{"tamp/heartbeat", QosClass::kHeartbeat};
// Robot and sensors
inline constexpr TopicSpec<msg::RobotState> kRobotState{"tamp/robot/state", QosClass::kStream};
inline constexpr TopicSpec<msg::PointCloudFrame> kPointCloud{"tamp/sensor/cloud", QosClass::kBulk};
inline constexpr TopicSpec<msg::TrajectoryCommand> kTrajectoryCommand{"tamp/robot/trajectory", QosClass::kCommand};
// Results are events (TRANSIENT_LOCAL): a reader's match is not the writer's -- a result written
// right after the reader saw the writer may precede the writer seeing the reader, and a VOLATILE
// result would then be lost (SimNodeTest caught it, 2 runs in 6 at load 2). Readers filter by
// command id.
inline constexpr TopicSpec<msg::ActionResult> kActionResult{"tamp/robot/result", QosClass::kEvent};
inline constexpr TopicSpec<msg::FaultInjection> kFaultInjection{"tamp/sim/fault", QosClass::kCommand};
// World model (perception)
inline constexpr TopicSpec<msg::WorldObject> kWorldObjects{"tamp/world/objects", QosClass::kState};
inline constexpr TopicSpec<msg::WorldMeta> kWorldMeta{"tamp/world/meta", QosClass::kState};
inline constexpr TopicSpec<msg::OccupancyMap> kOccupancy{"tamp/world/octomap", QosClass::kState};
inline constexpr TopicSpec<msg::WorldEvent> kWorldEvents{"tamp/world/events", QosClass::kEvent};
// Effort
inline constexpr TopicSpec<msg::EffortModelSnapshot> kEffortModel{"tamp/effort/model", QosClass::kState};
// The robot driver's (simulator's) raw measurement of each finished action; the execution
// monitor adds the prediction and the command it executed and forwards it on kExecutionRecords.
inline constexpr TopicSpec<msg::ExecutionRecord> kRobotRecords{"tamp/robot/record", QosClass::kEvent};
inline constexpr TopicSpec<msg::ExecutionRecord> kExecutionRecords{"tamp/execution/record", QosClass::kEvent};
// The estimator acknowledges each record it holds (stored now or before); the monitor resends a
// record until then. VOLATILE: a lost acknowledgement costs a resend, which is acknowledged again.
inline constexpr TopicSpec<msg::RecordAck> kRecordAcks{"tamp/execution/record_ack", QosClass::kCommand};
// Execution
inline constexpr TopicSpec<msg::ExecuteCommand> kExecuteCommand{"tamp/execute/command", QosClass::kCommand};
inline constexpr TopicSpec<msg::ExecuteStatus> kExecuteStatus{"tamp/execute/status", QosClass::kEvent};  // as results
inline constexpr TopicSpec<msg::FailureEvent> kFailureEvents{"tamp/execute/failure", QosClass::kEvent};
// Mission
inline constexpr TopicSpec<msg::MissionCommand> kMissionCommand{"tamp/mission/command", QosClass::kCommand};
inline constexpr TopicSpec<msg::MissionStatus> kMissionStatus{"tamp/mission/status", QosClass::kState};
inline constexpr TopicSpec<msg::GraphSnapshot> kGraph{"tamp/mission/graph", QosClass::kState};
}  // namespace topics

namespace services {
inline constexpr ServiceSpec<msg::PlanRequest, msg::PlanReply> kPlan{"tamp/symbolic_planner/plan"};
inline constexpr ServiceSpec<msg::MotionRequest, msg::MotionReply> kMotion{"tamp/motion_planner/motion"};
inline constexpr ServiceSpec<msg::PlacementRequest, msg::PlacementReply> kPlacement{"tamp/motion_planner/placement"};
inline constexpr ServiceSpec<msg::GraspRequest, msg::GraspReply> kGrasp{"tamp/motion_planner/grasp"};
inline constexpr ServiceSpec<msg::EffortRequest, msg::EffortReply> kEffort{"tamp/effort_estimator/estimate"};
/// The simulator's truth for the `oracle` policy (evaluation only: served when $TAMP_ORACLE=1).
inline constexpr ServiceSpec<msg::OracleRequest, msg::OracleReply> kOracle{"tamp/sim/oracle"};
/// Every node answers echo requests on "tamp/<node name>/echo" (see echoService()).
}  // namespace services

}  // namespace tamp::dds

#undef TAMP_DDS_TYPE
