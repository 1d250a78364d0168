#pragma once
/// @file
/// The execution monitor (Conditional TAMP through an effort-based approach,
/// spec/conditional-tamp-effort-based.tex, section 4: executing the chosen branch, observing
/// the conditions it relies on, and reporting the unexpected events that trigger online
/// replanning; measured durations feed the effort estimator).
///
/// Design overview
/// - **A state machine without DDS or clock.** `ExecutionMonitor` is driven by events (a command,
///   a robot state sample, a world model, a robot result, a tick) with the monitor's time `now`
///   (seconds, any monotonic origin) and returns the `Outputs` to publish: status updates,
///   failure reports and requests to the robot. The node (node/) only converts messages, feeds
///   events in and publishes what comes out; unit tests drive the same machine with a fake
///   clock.
/// - **Idempotent on command_id.** Every id ever seen is remembered with its latest status; a
///   command with a known id is never executed again: its known status is re-published. A robot
///   result seen for an id the monitor did not send (e.g. from before a restart, through the
///   results' transient-local history) makes that id known too. Across a restart of the monitor,
///   `resume()` takes the ids its previous run sent to the robot (the node's `SentJournal`): such
///   an id, commanded again, is not validated again (the robot may be half-way through it) but
///   sent again to the robot, which is idempotent on command ids too (the simulator joins the
///   running action or re-sends its recorded result): the outcome comes from the robot, nothing
///   is executed twice.
/// - **One action at a time, in order.** Commands are queued (EXEC_ACCEPTED); the head starts
///   once a robot state and a world model of at least the command's world version are there
///   (waiting at most `input_wait_s`; then the latest world model is used, and with none the
///   command fails).
/// - **Validation just before the start**, against the latest world model and robot state:
///   the command's form (`validateCommand`, on arrival), the trajectory's start
///   (`checkStart`), the held object (`checkHeld`), a pick's object (`checkPickTarget`) and the
///   whole path (`PathChecker`; the picked / placed and held objects, the support the object rests
///   or will rest on, and objects already touching the robot, are allowed contacts). A failure is a
///   final EXEC_FAILED whose reason names what failed, with a FailureReport kPrecondition; the
///   robot is not commanded.
/// - **Watching while it runs.** On every world model: the remaining path (from the robot's
///   progress) against the objects perceived since the start or moved by more than
///   `moved_tolerance_m` (one on it: cancel the robot, final EXEC_BLOCKED with its id,
///   kNewObstacle). On every robot state: progress, and the held object still held while a
///   move_base / move_arm carries it (else cancel, EXEC_FAILED, kObjectDropped). On every tick:
///   an overrun beyond expected + k stddev + margin (cancel, EXEC_FAILED, kTimeout), and
///   EXEC_RUNNING with progress every `status_period_s`.
/// - **Outcome.** The robot's result is mapped (blocked: EXEC_BLOCKED + kBlocked, failed:
///   EXEC_FAILED + kActionFailed, cancelled by the robot: EXEC_CANCELLED + kActionFailed); after
///   a cancel of its own the monitor's verdict stands unless the robot finished the action first
///   (a drop always stands). The final status carries the robot's measured duration and the
///   held object from a robot state written no earlier than the result (waiting at most
///   `state_wait_s` for it; the reason says when none came).
/// - **Execution records.** `RecordForwarder` matches the robot's raw records to the commands
///   it executed (record_id or command_id equal to the command's id), adds the prediction and
///   the mission, and forwards each record id exactly once.
///
/// Thread safety: none; the node serialises the calls.

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/execution_monitor/checks.h"
#include "tamp/execution_monitor/params.h"
#include "tamp/execution_monitor/types.h"
#include "tamp/robot/robot_model.h"
#include "tamp/world/world.h"

namespace tamp::execution_monitor {

/// What the monitor adds to a robot record before forwarding it.
struct RecordAnnotation {
  std::string command_id;  ///< "" for a record of a command the monitor did not send
  std::string mission_id;
  double predicted_s{0.0};
  double predicted_stddev_s{0.0};
};

/// Matches the robot's execution records to the commands sent and forwards each once.
class RecordForwarder {
 public:
  explicit RecordForwarder(bool forward_unmatched = true) : forward_unmatched_(forward_unmatched) {}
  /// Remembers a command sent to the robot (before it is sent).
  void addCommand(const ExecutionCommand& command);
  /// The annotation for a record with `record_id` (and the robot's `command_id` field, often
  /// empty), or nullopt when it must not be forwarded: an empty or already forwarded record id,
  /// or a record of no known command when unmatched records are not forwarded.
  std::optional<RecordAnnotation> onRecord(const std::string& record_id,
                                           const std::string& command_id);
  std::size_t forwarded() const { return forwarded_.size(); }

 private:
  bool forward_unmatched_;
  std::map<std::string, RecordAnnotation> commands_;
  std::set<std::string> forwarded_;
};

class ExecutionMonitor {
 public:
  /// Throws std::invalid_argument when `params` are invalid (the message names the field).
  ExecutionMonitor(MonitorParams params, robot::RobotModel robot);
  ~ExecutionMonitor();
  ExecutionMonitor(const ExecutionMonitor&) = delete;
  ExecutionMonitor& operator=(const ExecutionMonitor&) = delete;

  /// A command (or a cancel, `command.cancel`). New ids are validated (a malformed one gets a
  /// final EXEC_FAILED naming the field) and queued (EXEC_ACCEPTED); known ids get their known
  /// status again. A cancel of a queued command ends it (EXEC_CANCELLED), of the running one
  /// cancels the robot (the final status follows its result), of an unknown id records the id as
  /// cancelled (never executed later).
  Outputs onCommand(const ExecutionCommand& command, double now);
  /// A command that could not even be read (the node's conversion failed): a final EXEC_FAILED
  /// with `error`'s message, and the id is known from now on.
  Outputs onMalformedCommand(const std::string& command_id, const Error& error, double now);
  Outputs onRobotState(const RobotObservation& observation, double now);
  /// The latest world model and the version its publisher holds completely.
  Outputs onWorld(const world::World& world, std::uint64_t published_version, double now);
  Outputs onRobotResult(const RobotResult& result, double now);
  /// Deadlines, timeouts and periodic progress; call every few tens of milliseconds.
  Outputs onTick(double now);

  /// Ids a previous run of the monitor sent to the robot (its journal); call before the first
  /// command. Such an id, commanded again, is re-sent to the robot without validation (the robot
  /// joins or reports it) instead of being executed as new.
  void resume(const std::vector<std::string>& sent_ids);

  /// Annotation of a robot record (see RecordForwarder).
  std::optional<RecordAnnotation> onRobotRecord(const std::string& record_id,
                                                const std::string& command_id);

  /// The latest status of `command_id`, if known.
  std::optional<StatusUpdate> status(const std::string& command_id) const;
  /// The running command's id, or "".
  std::string activeCommandId() const;
  /// Commands sent to the robot so far.
  std::size_t executedCount() const;
  std::size_t queuedCount() const;
  const robot::RobotModel& robot() const;
  const MonitorParams& params() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tamp::execution_monitor
