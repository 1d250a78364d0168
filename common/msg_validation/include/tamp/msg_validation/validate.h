#pragma once
/// @file
/// Structural validation of every IDL message a service receives, before the node converts it:
/// the one place that decides what a malformed message is (issue 13, "bad input at every
/// boundary"). A validator checks what holds whatever the receiver's state:
///   - every double the receiver reads is finite (NaN and inf poses, joints, durations);
///   - enums are in range (CDR carries any 32-bit value);
///   - ids the receiver needs are non-empty and of bounded length;
///   - sequences are within `Limits` and parallel sequences agree (values per joint, names per
///     version, points per width x height);
///   - quaternions the receiver uses are non-zero (it normalises them).
/// Checks that need the receiver's state (an object id unknown to this world, a joint unknown to
/// this robot) stay in the node, after this pass; they name the field the same way.
///
/// Validators return the first problem as a value: kInvalidArgument with `where.field` the full
/// path and the message "<path>: <what>", e.g. "MotionRequest.start_joint_positions[3]: NaN".
/// They never throw and never allocate more than the message's size.
///
///   if (Status s = msgv::validate(req); !s.ok()) { reply INVALID_ARGUMENT with s.error().message }
///   if (!msgv::accept(sample, topic, rejects_)) return;   // streams: log (rate-limited) and drop
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <string_view>

#include "tamp/core/error.h"
#include "tamp/msg/common.h"
#include "tamp/msg/effort.h"
#include "tamp/msg/execution.h"
#include "tamp/msg/mission.h"
#include "tamp/msg/motion.h"
#include "tamp/msg/oracle.h"
#include "tamp/msg/planning.h"
#include "tamp/msg/robot.h"
#include "tamp/msg/world.h"

namespace tamp::msgv {

/// Size bounds. Defaults are far above what the shipped services send (a mission's largest
/// messages: a 640x480 cloud, plan requests of a few hundred atoms, trajectories of a few
/// thousand points) and far below what would exhaust memory in a receiver that copies them.
struct Limits {
  std::size_t max_id_length{256};           ///< ids, names, joint names (bytes)
  std::size_t max_text_length{16u << 20};   ///< free text: reasons, PDDL, reports (bytes)
  std::size_t max_joints{64};               ///< joint names per path/trajectory/state
  std::size_t max_waypoints{200000};        ///< points of a path or trajectory
  std::size_t max_items{100000};            ///< objects, atoms, queries, overrides, regions, ...
  std::size_t max_polygon_vertices{10000};  ///< per region / prism
  std::size_t max_cloud_points{8u << 20};   ///< points (triplets) of one cloud frame
  std::size_t max_octree_bytes{64u << 20};  ///< occupancy map payload
};

// Requests served by the services.
Status validate(const msg::PlanRequest& m, const Limits& limits = {});
Status validate(const msg::MotionRequest& m, const Limits& limits = {});
Status validate(const msg::PlacementRequest& m, const Limits& limits = {});
Status validate(const msg::GraspRequest& m, const Limits& limits = {});
Status validate(const msg::EffortRequest& m, const Limits& limits = {});
/// EffortRequest in two parts, for a server that answers the good queries of a batch: the
/// header and the number of queries, then each query (named "EffortRequest.queries[i]...").
Status validateEnvelope(const msg::EffortRequest& m, const Limits& limits = {});
Status validateQuery(const msg::EffortQuery& q, std::size_t index, const Limits& limits = {});
/// OracleRequest's header and the number of queries; each query then with validateQuery.
Status validateEnvelope(const msg::OracleRequest& m, const Limits& limits = {});
// Replies the graph manager reads.
Status validate(const msg::PlanReply& m, const Limits& limits = {});
Status validate(const msg::MotionReply& m, const Limits& limits = {});
Status validate(const msg::PlacementReply& m, const Limits& limits = {});
Status validate(const msg::GraspReply& m, const Limits& limits = {});
Status validate(const msg::EffortReply& m, const Limits& limits = {});
Status validate(const msg::OracleReply& m, const Limits& limits = {});
// Streams and commands.
Status validate(const msg::MissionCommand& m, const Limits& limits = {});
Status validate(const msg::ExecuteCommand& m, const Limits& limits = {});
Status validate(const msg::ExecuteStatus& m, const Limits& limits = {});
Status validate(const msg::TrajectoryCommand& m, const Limits& limits = {});
Status validate(const msg::ActionResult& m, const Limits& limits = {});
Status validate(const msg::FailureEvent& m, const Limits& limits = {});
Status validate(const msg::FaultInjection& m, const Limits& limits = {});
Status validate(const msg::ExecutionRecord& m, const Limits& limits = {});
Status validate(const msg::RecordAck& m, const Limits& limits = {});
Status validate(const msg::EffortModelSnapshot& m, const Limits& limits = {});
Status validate(const msg::RobotState& m, const Limits& limits = {});
Status validate(const msg::PointCloudFrame& m, const Limits& limits = {});
Status validate(const msg::WorldObject& m, const Limits& limits = {});
Status validate(const msg::WorldMeta& m, const Limits& limits = {});
Status validate(const msg::WorldEvent& m, const Limits& limits = {});

/// Logs rejected messages without flooding: the first rejection of each kind (topic and field
/// path with indices removed, e.g. "tamp/robot/state RobotState.joint_positions[]") at warn at
/// once, later ones of that kind counted and summarised at most once per `period`. Thread-safe.
class RejectLog {
 public:
  explicit RejectLog(std::string component, std::chrono::steady_clock::duration period = std::chrono::seconds(10));
  /// Records (and maybe logs) that a message on `topic` was rejected for `why`.
  void reject(std::string_view topic, const Error& why);
  /// Rejections so far, all kinds.
  std::uint64_t count() const;
  /// Log lines written so far (for tests of the rate limit).
  std::uint64_t linesLogged() const;

 private:
  struct Kind {
    std::uint64_t count{0};
    std::uint64_t unlogged{0};
    std::chrono::steady_clock::time_point last_logged{};
  };
  std::string component_;
  std::chrono::steady_clock::duration period_;
  mutable std::mutex mutex_;
  std::map<std::string, Kind> kinds_;
  std::uint64_t count_{0};
  std::uint64_t lines_{0};
};

/// The field path of an error with every "[n]" made "[]": one kind per field, whatever the index.
std::string kindOf(const Error& why);

/// Validates `m`; on failure records it in `log` (as a message on `topic`) and returns false.
template <typename T>
bool accept(const T& m, std::string_view topic, RejectLog& log, const Limits& limits = {}) {
  Status s = validate(m, limits);
  if (s.ok()) return true;
  log.reject(topic, s.error());
  return false;
}

/// Validates `m`; on failure records it in `log` and returns the error (for a request: reply with
/// it, STATUS_INVALID_ARGUMENT and its message).
template <typename T>
Status screen(const T& m, std::string_view topic, RejectLog& log, const Limits& limits = {}) {
  Status s = validate(m, limits);
  if (!s.ok()) log.reject(topic, s.error());
  return s;
}

}  // namespace tamp::msgv
