#include "tamp/execution_monitor/monitor.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "tamp/core/format.h"

namespace tamp::execution_monitor {

// ---- types -------------------------------------------------------------------------------------

std::string_view toString(ExecState s) {
  switch (s) {
    case ExecState::kAccepted:
      return "accepted";
    case ExecState::kRunning:
      return "running";
    case ExecState::kSucceeded:
      return "succeeded";
    case ExecState::kFailed:
      return "failed";
    case ExecState::kBlocked:
      return "blocked";
    case ExecState::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

bool isFinal(ExecState s) {
  return s == ExecState::kSucceeded || s == ExecState::kFailed || s == ExecState::kBlocked ||
         s == ExecState::kCancelled;
}

std::string_view toString(FailureType t) {
  switch (t) {
    case FailureType::kBlocked:
      return "blocked";
    case FailureType::kObjectDropped:
      return "object_dropped";
    case FailureType::kActionFailed:
      return "action_failed";
    case FailureType::kNewObstacle:
      return "new_obstacle";
    case FailureType::kTimeout:
      return "timeout";
    case FailureType::kPrecondition:
      return "precondition";
  }
  return "unknown";
}

void Outputs::append(Outputs other) {
  for (auto& s : other.statuses) statuses.push_back(std::move(s));
  for (auto& f : other.failures) failures.push_back(std::move(f));
  for (auto& r : other.robot) robot.push_back(std::move(r));
}

// ---- records -----------------------------------------------------------------------------------

void RecordForwarder::addCommand(const ExecutionCommand& c) {
  commands_[c.command_id] =
      RecordAnnotation{c.command_id, c.mission_id, c.expected_duration_s, c.expected_stddev_s};
}

std::optional<RecordAnnotation> RecordForwarder::onRecord(const std::string& record_id,
                                                          const std::string& command_id) {
  if (record_id.empty() || forwarded_.count(record_id)) return std::nullopt;
  auto it = commands_.find(record_id);
  if (it == commands_.end() && !command_id.empty()) it = commands_.find(command_id);
  if (it == commands_.end() && !forward_unmatched_) return std::nullopt;
  forwarded_.insert(record_id);
  if (it == commands_.end()) return RecordAnnotation{};
  return it->second;
}

// ---- the monitor -------------------------------------------------------------------------------

namespace {

/// Progress along the path (fraction) that counts as the robot still moving (TimeoutParams).
constexpr double kProgressStep = 0.01;

enum class Phase { kWaiting, kRunning, kStopping, kFinishing };
enum class Verdict { kNone, kCancelRequested, kNewObstacle, kTimeout, kDropped };

struct Active {
  ExecutionCommand cmd;
  Phase phase{Phase::kWaiting};
  double wait_deadline{0.0};
  double started{0.0};
  SweptPath path;
  std::vector<std::string> ignore;  // allowed contacts + objects touching the robot at the start
  std::map<std::string, Eigen::Vector3d> validated;  // objects at validation and their positions
  std::string held_at_start;
  double progress{0.0};
  double progress_mark{0.0};  ///< the progress when it last advanced by kProgressStep
  double progress_at{0.0};    ///< when that was
  double last_status{0.0};
  double timeout_limit{0.0};
  std::string note;  // added to the reason of the final status (e.g. an older world version)
  Verdict verdict{Verdict::kNone};
  std::string verdict_object;
  std::string verdict_reason;
  double stop_deadline{0.0};
  std::optional<RobotResult> result;
  double finish_deadline{0.0};
  bool rejoined{false};  // sent by a previous run of the monitor: not validated or watched again
};

bool carries(const Active& a) {
  return !a.held_at_start.empty() &&
         (a.cmd.kind == ActionKind::kMoveBase || a.cmd.kind == ActionKind::kMoveArm);
}

std::string pct(double f) { return formatNumber(100.0 * f, 3) + " %"; }

std::string baseText(const Pose2D& b) {
  return "(" + formatNumber(b.x, 3) + ", " + formatNumber(b.y, 3) + ", " +
         formatNumber(b.theta, 3) + ")";
}

}  // namespace

struct ExecutionMonitor::Impl {
  MonitorParams params;
  robot::RobotModel robot;
  PathChecker checker;
  RecordForwarder records;
  std::map<std::string, StatusUpdate> known;
  std::map<std::string, RobotResult> robot_history;  // results of ids the monitor did not send
  std::set<std::string> sent_before;  // ids a previous run sent to the robot (its journal)
  std::deque<ExecutionCommand> queue;
  std::optional<Active> active;
  std::optional<RobotObservation> state;
  std::optional<world::World> world;
  std::uint64_t world_version{0};
  std::int64_t min_state_stamp{0};  // a start needs a state no older than the last result
  std::size_t executed{0};

  Impl(MonitorParams p, robot::RobotModel r)
      : params(std::move(p)),
        robot(std::move(r)),
        checker(robot, params.path_check),
        records(params.forward_unmatched_records) {}

  Pose2D base() const { return state ? state->state.base : Pose2D{}; }

  void emit(Outputs& out, StatusUpdate s) {
    known[s.command_id] = s;
    out.statuses.push_back(std::move(s));
  }

  StatusUpdate finalStatus(const std::string& id, ExecState st, std::string reason) const {
    StatusUpdate s;
    s.command_id = id;
    s.state = st;
    s.reason = std::move(reason);
    if (state) s.held_object_id = state->held_object_id;
    return s;
  }

  /// A command that ends before the robot was commanded.
  void failBeforeStart(Outputs& out, const ExecutionCommand& c, const CheckFailure& f) {
    StatusUpdate s = finalStatus(c.command_id, ExecState::kFailed, f.reason);
    if (f.reason.rfind("path:", 0) == 0) s.blocking_object_id = f.object_id;
    emit(out, s);
    out.failures.push_back(
        FailureReport{c.command_id, FailureType::kPrecondition, f.object_id, base(), f.reason});
  }

  void stop(Outputs& out, Verdict v, std::string object, std::string reason, double now) {
    Active& a = *active;
    a.verdict = v;
    a.verdict_object = std::move(object);
    a.verdict_reason = std::move(reason);
    a.phase = Phase::kStopping;
    a.stop_deadline = now + params.result_wait_s;
    RobotRequest r;
    r.type = RobotRequest::Type::kCancel;
    r.command = a.cmd;
    out.robot.push_back(std::move(r));
    StatusUpdate s;
    s.command_id = a.cmd.command_id;
    s.state = ExecState::kRunning;
    s.progress = a.progress;
    s.elapsed_s = now - a.started;
    s.reason = "stopping: " + a.verdict_reason;
    emit(out, s);
  }

  /// Starts the head of the queue when its inputs are there (validating it first).
  void tryStart(Outputs& out, double now) {
    for (;;) {
      if (!active) {
        if (queue.empty()) return;
        active = Active{};
        active->cmd = std::move(queue.front());
        queue.pop_front();
        active->wait_deadline = now + params.input_wait_s;
      }
      Active& a = *active;
      if (a.phase != Phase::kWaiting) return;
      const ExecutionCommand& c = a.cmd;
      if (sent_before.count(c.command_id)) {
        rejoin(out, now);
        return;
      }
      const bool have_state = state && state->stamp_ns >= min_state_stamp;
      const bool have_world = world.has_value() && world_version > 0;
      const bool world_current = have_world && world_version >= c.world_version;
      if (!(have_state && world_current) && now < a.wait_deadline) return;
      std::optional<CheckFailure> failure;
      if (!have_state) {
        failure = CheckFailure{
            state ? "robot state: none since the previous action's result within " +
                        formatNumber(params.input_wait_s) + " s"
                  : "robot state: none received within " + formatNumber(params.input_wait_s) + " s",
            ""};
      } else if (!have_world) {
        failure = CheckFailure{
            "world model: none received within " + formatNumber(params.input_wait_s) + " s", ""};
      }
      if (!world_current && have_world) {
        a.note = "validated against world version " + std::to_string(world_version) +
                 ", older than the command's " + std::to_string(c.world_version);
      }
      if (!failure) failure = validate(a);
      if (failure) {
        failBeforeStart(out, c, *failure);
        active.reset();
        continue;  // the next queued command
      }
      ++executed;
      sendToRobot(out, now);
      return;
    }
  }

  /// The head was sent to the robot by a previous run of the monitor: it is not validated again
  /// (the robot may have moved with it); it is sent again, which the robot, idempotent on
  /// command ids, answers by joining the running action or by its recorded result.
  void rejoin(Outputs& out, double now) {
    Active& a = *active;
    a.rejoined = true;
    a.note = "sent before a restart of the monitor: joined, not executed again";
    sendToRobot(out, now);
  }

  /// The active command goes to the robot now: recorded, running, its timeout set from its
  /// predicted duration, and reported running.
  void sendToRobot(Outputs& out, double now) {
    Active& a = *active;
    const ExecutionCommand& c = a.cmd;
    records.addCommand(c);
    RobotRequest r;
    r.type = RobotRequest::Type::kExecute;
    r.command = c;
    out.robot.push_back(std::move(r));
    a.phase = Phase::kRunning;
    a.started = now;
    a.last_status = now;
    a.progress_at = now;
    a.progress_mark = a.progress;
    const double expected =
        c.expected_duration_s > 0.0 ? c.expected_duration_s : c.trajectory.duration();
    a.timeout_limit =
        expected + params.timeout.stddevs * c.expected_stddev_s + params.timeout.margin_s;
    StatusUpdate s;
    s.command_id = c.command_id;
    s.state = ExecState::kRunning;
    s.reason = a.note;
    emit(out, s);
  }

  /// The checks just before the start (the robot state and world are there).
  std::optional<CheckFailure> validate(Active& a) {
    const ExecutionCommand& c = a.cmd;
    if (auto f = checkStart(c, state->state, robot, params.start_tolerance)) return f;
    if (auto f = checkHeld(c, state->held_object_id)) return f;
    if (auto f = checkPickTarget(c, *world, params.object_tolerance_m)) return f;
    checker.setWorld(*world);
    a.path = makePath(c, state->state, robot);
    a.held_at_start = state->held_object_id;
    a.ignore = allowedContacts(c, state->held_object_id);
    for (const auto& id : checker.startContactsAt(state->state)) a.ignore.push_back(id);
    // The manipulated object's support: where it rests (pick) or will rest (place).
    if (const world::Object* o = world->findObject(c.object_id); o && c.kind == ActionKind::kPick) {
      for (const auto& id : checker.supportsOf(*o, o->pose)) a.ignore.push_back(id);
    } else if (o && c.kind == ActionKind::kPlace && c.object_target) {
      for (const auto& id : checker.supportsOf(*o, *c.object_target)) a.ignore.push_back(id);
    }
    for (const auto& o : world->objects()) a.validated[o.id] = o.pose.translation();
    if (auto hit = checker.firstContact(a.path, 0.0, a.ignore)) {
      const robot::RobotState at = a.path.at(hit->fraction);
      return CheckFailure{"path: the robot would touch '" + hit->object_id +
                              "' of the world model at " + pct(hit->fraction) +
                              " of the trajectory (base at " + baseText(at.base) + ")",
                          hit->object_id};
    }
    return std::nullopt;
  }

  void finalize(Outputs& out, double now) {
    Active& a = *active;
    const ExecutionCommand& c = a.cmd;
    const std::optional<RobotResult>& r = a.result;
    const bool fresh_state = state && r && state->stamp_ns >= r->stamp_ns;
    StatusUpdate s;
    s.command_id = c.command_id;
    s.elapsed_s = now - a.started;
    s.measured_duration_s = r ? r->duration_s : now - a.started;
    s.held_object_id = state ? state->held_object_id : "";
    s.progress = r ? r->progress : a.progress;
    std::optional<FailureReport> failure;
    auto fail = [&](FailureType t, const std::string& object, const std::string& why) {
      failure = FailureReport{c.command_id, t, object, base(), why};
    };
    const bool robot_succeeded = r && r->outcome == RobotOutcome::kSucceeded;
    switch (a.verdict) {
      case Verdict::kDropped:
        s.state = ExecState::kFailed;
        s.reason = a.verdict_reason;
        fail(FailureType::kObjectDropped, a.verdict_object, s.reason);
        break;
      case Verdict::kCancelRequested:
        s.state = robot_succeeded ? ExecState::kSucceeded : ExecState::kCancelled;
        if (!robot_succeeded) s.reason = a.verdict_reason;
        break;
      case Verdict::kNewObstacle:
        if (robot_succeeded) {
          s.state = ExecState::kSucceeded;
        } else {
          s.state = ExecState::kBlocked;
          s.reason = a.verdict_reason;
          s.blocking_object_id = a.verdict_object;
          fail(FailureType::kNewObstacle, a.verdict_object, s.reason);
        }
        break;
      case Verdict::kTimeout:
        if (robot_succeeded) {
          s.state = ExecState::kSucceeded;
        } else {
          s.state = ExecState::kFailed;
          s.reason = a.verdict_reason;
          fail(FailureType::kTimeout, "", s.reason);
        }
        break;
      case Verdict::kNone:
        switch (r->outcome) {
          case RobotOutcome::kSucceeded:
            s.state = ExecState::kSucceeded;
            break;
          case RobotOutcome::kBlocked:
            s.state = ExecState::kBlocked;
            s.blocking_object_id = r->blocking_object_id;
            s.stopped_at_contact = true;
            s.reason = "blocked: the robot stopped before '" + r->blocking_object_id + "'" +
                       (r->reason.empty() ? "" : ": " + r->reason);
            fail(FailureType::kBlocked, r->blocking_object_id, s.reason);
            break;
          case RobotOutcome::kFailed:
            s.state = ExecState::kFailed;
            s.reason = "action failed: " +
                       (r->reason.empty() ? std::string("no reason given") : r->reason);
            fail(FailureType::kActionFailed, c.object_id, s.reason);
            break;
          case RobotOutcome::kCancelled:
            s.state = ExecState::kCancelled;
            s.reason = "cancelled by the robot" + (r->reason.empty() ? "" : ": " + r->reason);
            fail(FailureType::kActionFailed, "", s.reason);
            break;
        }
        break;
    }
    // A carried object must still be held when a move that "succeeded" ends.
    if (s.state == ExecState::kSucceeded && carries(a) && fresh_state &&
        state->held_object_id != a.held_at_start) {
      s.state = ExecState::kFailed;
      s.reason = "object dropped: '" + a.held_at_start + "' is no longer held at the end of the " +
                 std::string(toString(c.kind));
      fail(FailureType::kObjectDropped, a.held_at_start, s.reason);
    }
    if (s.state == ExecState::kSucceeded) s.progress = 1.0;
    auto note = [&](const std::string& n) { s.reason += (s.reason.empty() ? "" : "; ") + n; };
    if (!a.note.empty()) note(a.note);
    if (!r) {
      note("no result from the robot within " + formatNumber(params.result_wait_s) +
           " s of the cancel: measured_duration_s is the monitor's elapsed time");
    } else if (!fresh_state) {
      note("no robot state after the result within " + formatNumber(params.state_wait_s) +
           " s: held_object_id is from an older state");
    }
    if (failure) failure->description = s.reason;
    emit(out, s);
    if (failure) out.failures.push_back(*failure);
    min_state_stamp = r ? r->stamp_ns : (state ? state->stamp_ns + 1 : 0);
    active.reset();
    tryStart(out, now);
  }

  void enterFinishing(Outputs& out, const RobotResult& r, double now) {
    Active& a = *active;
    a.result = r;
    a.phase = Phase::kFinishing;
    a.finish_deadline = now + params.state_wait_s;
    if (state && state->stamp_ns >= r.stamp_ns) finalize(out, now);
  }

  void checkRemainingPath(Outputs& out, double now) {
    Active& a = *active;
    if (a.phase != Phase::kRunning || a.rejoined || !world || !state) return;
    checker.setWorld(*world);
    std::vector<std::string> ignore = a.ignore;
    for (const auto& id : checker.contactsAt(state->state)) ignore.push_back(id);
    // Known objects that stayed put were checked at the start: only new or moved ones count.
    for (const auto& o : world->objects()) {
      const auto it = a.validated.find(o.id);
      if (it != a.validated.end() &&
          (o.pose.translation() - it->second).norm() <= params.moved_tolerance_m) {
        ignore.push_back(o.id);
      }
    }
    if (auto hit = checker.firstContact(a.path, a.progress, ignore)) {
      const robot::RobotState at = a.path.at(hit->fraction);
      stop(out, Verdict::kNewObstacle, hit->object_id,
           "new obstacle: '" + hit->object_id +
               "' of the world model is on the remaining path at " + pct(hit->fraction) +
               " of the trajectory (base at " + baseText(at.base) + "; robot at " +
               pct(a.progress) + ")",
           now);
    }
  }
};

ExecutionMonitor::ExecutionMonitor(MonitorParams params, robot::RobotModel robot) {
  if (Status s = params.validate(); !s)
    throw std::invalid_argument("ExecutionMonitor: " + s.error().message);
  impl_ = std::make_unique<Impl>(std::move(params), std::move(robot));
}

ExecutionMonitor::~ExecutionMonitor() = default;

Outputs ExecutionMonitor::onCommand(const ExecutionCommand& c, double now) {
  Impl& m = *impl_;
  Outputs out;
  const auto known = m.known.find(c.command_id);
  if (c.cancel) {
    if (m.active && m.active->cmd.command_id == c.command_id) {
      Active& a = *m.active;
      if (a.phase == Phase::kWaiting) {
        m.emit(out,
               m.finalStatus(c.command_id, ExecState::kCancelled, "cancelled before it started"));
        m.active.reset();
      } else if (a.phase == Phase::kRunning) {
        m.stop(out, Verdict::kCancelRequested, "", "cancelled by the sender", now);
      } else {
        out.statuses.push_back(known->second);  // stopping or finishing already: status as is
      }
    } else if (auto q = std::find_if(
                   m.queue.begin(), m.queue.end(),
                   [&](const ExecutionCommand& x) { return x.command_id == c.command_id; });
               q != m.queue.end()) {
      m.queue.erase(q);
      m.emit(out,
             m.finalStatus(c.command_id, ExecState::kCancelled, "cancelled before it started"));
    } else if (known != m.known.end()) {
      out.statuses.push_back(known->second);
    } else {
      m.emit(out, m.finalStatus(c.command_id, ExecState::kCancelled,
                                "cancelled before it was received"));
    }
    m.tryStart(out, now);
    return out;
  }
  if (known != m.known.end()) {
    out.statuses.push_back(known->second);  // idempotent: never executed twice
    return out;
  }
  if (const auto h = m.robot_history.find(c.command_id); h != m.robot_history.end()) {
    // The robot executed this id before this monitor knew it (a restart): not again.
    const RobotResult& r = h->second;
    static constexpr ExecState kMap[] = {ExecState::kSucceeded, ExecState::kBlocked,
                                         ExecState::kFailed, ExecState::kCancelled};
    StatusUpdate s = m.finalStatus(
        c.command_id, kMap[static_cast<int>(r.outcome)],
        "executed before (the robot's result)" + (r.reason.empty() ? "" : ": " + r.reason));
    s.measured_duration_s = r.duration_s;
    s.blocking_object_id = r.blocking_object_id;
    s.progress = r.progress;
    if (!(m.state && m.state->stamp_ns >= r.stamp_ns)) s.held_object_id.clear();
    m.emit(out, s);
    return out;
  }
  if (Status v = validateCommand(c, m.robot); !v) {
    m.emit(out, m.finalStatus(c.command_id, ExecState::kFailed,
                              "malformed command: " + v.error().message));
    return out;
  }
  m.queue.push_back(c);
  StatusUpdate s;
  s.command_id = c.command_id;
  s.state = ExecState::kAccepted;
  m.emit(out, s);
  m.tryStart(out, now);
  return out;
}

Outputs ExecutionMonitor::onMalformedCommand(const std::string& command_id, const Error& error,
                                             double) {
  Impl& m = *impl_;
  Outputs out;
  if (const auto known = m.known.find(command_id); known != m.known.end()) {
    out.statuses.push_back(known->second);
    return out;
  }
  // Name the field even when the converter's message does not start with it.
  const std::string& field = error.where.field;
  const bool named = field.empty() || error.message.rfind(field, 0) == 0;
  m.emit(out, m.finalStatus(
                  command_id, ExecState::kFailed,
                  "malformed command: " + (named ? error.message : field + ": " + error.message)));
  return out;
}

Outputs ExecutionMonitor::onRobotState(const RobotObservation& obs, double now) {
  Impl& m = *impl_;
  Outputs out;
  m.state = obs;
  if (!m.active) return out;
  Active& a = *m.active;
  switch (a.phase) {
    case Phase::kWaiting:
      m.tryStart(out, now);
      break;
    case Phase::kRunning:
      if (a.rejoined) break;  // no path of its own to follow
      a.progress = a.path.project(obs.state, a.progress);
      if (a.progress >= a.progress_mark + kProgressStep) {
        a.progress_mark = a.progress;
        a.progress_at = now;
      }
      if (carries(a) && obs.held_object_id != a.held_at_start) {
        m.stop(
            out, Verdict::kDropped, a.held_at_start,
            "object dropped: '" + a.held_at_start + "' is no longer held during the " +
                std::string(toString(a.cmd.kind)) +
                (obs.held_object_id.empty() ? ""
                                            : " (the gripper holds '" + obs.held_object_id + "')"),
            now);
      }
      break;
    case Phase::kStopping:
      break;
    case Phase::kFinishing:
      if (obs.stamp_ns >= a.result->stamp_ns) m.finalize(out, now);
      break;
  }
  return out;
}

Outputs ExecutionMonitor::onWorld(const world::World& w, std::uint64_t published_version,
                                  double now) {
  Impl& m = *impl_;
  Outputs out;
  m.world = w;
  m.world_version = published_version;
  if (!m.active) return out;
  if (m.active->phase == Phase::kWaiting) {
    m.tryStart(out, now);
  } else if (m.active->phase == Phase::kRunning) {
    m.checkRemainingPath(out, now);
  }
  return out;
}

Outputs ExecutionMonitor::onRobotResult(const RobotResult& r, double now) {
  Impl& m = *impl_;
  Outputs out;
  if (m.active && m.active->cmd.command_id == r.command_id &&
      (m.active->phase == Phase::kRunning || m.active->phase == Phase::kStopping)) {
    m.enterFinishing(out, r, now);
  } else if (!m.known.count(r.command_id)) {
    m.robot_history[r.command_id] = r;
  }
  return out;
}

Outputs ExecutionMonitor::onTick(double now) {
  Impl& m = *impl_;
  Outputs out;
  if (!m.active) {
    m.tryStart(out, now);
    return out;
  }
  Active& a = *m.active;
  switch (a.phase) {
    case Phase::kWaiting:
      m.tryStart(out, now);
      break;
    case Phase::kRunning: {
      const double elapsed = now - a.started;
      const double still_s = now - a.progress_at;
      const bool stalled = a.rejoined || still_s > m.params.timeout.stall_s;
      if (elapsed > a.timeout_limit && (stalled || elapsed > m.params.timeout.max_factor * a.timeout_limit)) {
        m.stop(out, Verdict::kTimeout, "",
               "timeout: " + formatNumber(elapsed, 3) + " s elapsed, more than the expected " +
                   formatNumber(a.cmd.expected_duration_s, 3) + " s + " +
                   formatNumber(m.params.timeout.stddevs) + " x " +
                   formatNumber(a.cmd.expected_stddev_s, 3) + " s + " +
                   formatNumber(m.params.timeout.margin_s) + " s" +
                   (stalled ? ", no progress for " + formatNumber(still_s, 3) + " s"
                            : ", " + formatNumber(m.params.timeout.max_factor) + " times that while moving"),
               now);
      } else if (now - a.last_status >= m.params.status_period_s) {
        a.last_status = now;
        StatusUpdate s;
        s.command_id = a.cmd.command_id;
        s.state = ExecState::kRunning;
        s.progress = a.progress;
        s.elapsed_s = elapsed;
        s.reason = a.note;
        m.emit(out, s);
      }
      break;
    }
    case Phase::kStopping:
      if (now > a.stop_deadline) m.finalize(out, now);
      break;
    case Phase::kFinishing:
      if (now > a.finish_deadline) m.finalize(out, now);
      break;
  }
  return out;
}

void ExecutionMonitor::resume(const std::vector<std::string>& sent_ids) {
  for (const auto& id : sent_ids) {
    if (!impl_->known.count(id)) impl_->sent_before.insert(id);
  }
}

std::optional<RecordAnnotation> ExecutionMonitor::onRobotRecord(const std::string& record_id,
                                                                const std::string& command_id) {
  return impl_->records.onRecord(record_id, command_id);
}

std::optional<StatusUpdate> ExecutionMonitor::status(const std::string& id) const {
  const auto it = impl_->known.find(id);
  if (it == impl_->known.end()) return std::nullopt;
  return it->second;
}

std::string ExecutionMonitor::activeCommandId() const {
  return impl_->active ? impl_->active->cmd.command_id : std::string();
}
std::size_t ExecutionMonitor::executedCount() const { return impl_->executed; }
std::size_t ExecutionMonitor::queuedCount() const {
  return impl_->queue.size() + (impl_->active ? 1 : 0);
}
const robot::RobotModel& ExecutionMonitor::robot() const { return impl_->robot; }
const MonitorParams& ExecutionMonitor::params() const { return impl_->params; }

}  // namespace tamp::execution_monitor
