#include "dds_clients.h"

#include "tamp/dds/world_sync.h"

#include "tamp/msg_validation/validate.h"

#include <chrono>
#include <future>

#include "tamp/core/log.h"
#include "effort_msgs.h"
#include "tamp/dds/convert.h"

namespace tamp::graph_manager {
namespace {
/// Replies and statuses from other services pass the shared validator too: a malformed one (NaN
/// in a path, an unknown enum value) is an error of that call, logged once per kind.
msgv::RejectLog& replyRejects() {
  static msgv::RejectLog log("graph_manager");
  return log;
}
template <typename Rep>
Result<Rep> checked(Result<Rep> rep, const char* service) {
  if (!rep) return rep;
  if (Status bad = msgv::screen(*rep, service, replyRejects()); !bad.ok()) {
    return Error(ErrorCode::kInvalidArgument,
                 "service '" + std::string(service) + "' sent a malformed reply: " + bad.error().message);
  }
  return rep;
}
}  // namespace

namespace {

using Clock = std::chrono::steady_clock;

/// How many times a motion question is asked while the planner has not received its world.
constexpr int kWorldLagAttempts = 3;

/// Whether a reply says that the planner has not received the world version asked for yet.
template <typename Rep>
bool waitingForWorld(const Result<Rep>& rep) {
  return !rep && rep.error().code == ErrorCode::kNotReady;
}

}  // namespace

template <typename Rep>
Result<Rep> DdsServiceClients::answered(Result<Rep> rep, const char* service) const {
  alive();
  return checked(std::move(rep), service);
}

namespace {

dds::RpcClientOptions rpcOptions() {
  dds::RpcClientOptions o;
  o.attempt_timeout_s = 2.0;
  o.max_attempts = 4;
  return o;
}

TaskStatus fromMsg(msg::PlanStatus s) {
  switch (s) {
    case msg::PlanStatus::PLAN_SOLVED: return TaskStatus::kSolved;
    case msg::PlanStatus::PLAN_UNSOLVABLE: return TaskStatus::kUnsolvable;
    case msg::PlanStatus::PLAN_TIMEOUT: return TaskStatus::kTimeout;
    case msg::PlanStatus::PLAN_INVALID_INPUT: return TaskStatus::kInputError;
    default: return TaskStatus::kFailed;
  }
}

MotionOutcome fromMsg(msg::MotionStatus s) {
  switch (s) {
    case msg::MotionStatus::MOTION_SOLVED: return MotionOutcome::kSolved;
    case msg::MotionStatus::MOTION_NO_PATH: return MotionOutcome::kNoPath;
    case msg::MotionStatus::MOTION_START_IN_COLLISION: return MotionOutcome::kStartInCollision;
    case msg::MotionStatus::MOTION_GOAL_IN_COLLISION: return MotionOutcome::kGoalInCollision;
    case msg::MotionStatus::MOTION_TIMEOUT: return MotionOutcome::kTimeout;
    default: return MotionOutcome::kInvalid;
  }
}

msg::ObjectOverride toMsg(const ObjectOverride& o) {
  msg::ObjectOverride m;
  m.object_id(o.object_id);
  m.removed(o.removed);
  m.pose(dds::toMsg(o.pose));
  return m;
}

}  // namespace

DdsServiceClients::DdsServiceClients(std::shared_ptr<dds::Participant> p, robot::RobotModel robot)
    : robot_(std::move(robot)),
      plan_(p, dds::services::kPlan, rpcOptions()),
      motion_(p, dds::services::kMotion, rpcOptions()),
      placement_(p, dds::services::kPlacement, rpcOptions()),
      grasp_(p, dds::services::kGrasp, rpcOptions()),
      effort_(p, dds::services::kEffort, rpcOptions()) {}

std::string DdsServiceClients::missingServers() const {
  std::string missing;
  auto check = [&missing](bool present, const char* service) {
    if (present) return;
    missing += missing.empty() ? "no server matched for " : ", ";
    missing += service;
  };
  check(plan_.serverPresent(), dds::services::kPlan.name);
  check(motion_.serverPresent(), dds::services::kMotion.name);
  check(placement_.serverPresent(), dds::services::kPlacement.name);
  check(grasp_.serverPresent(), dds::services::kGrasp.name);
  check(effort_.serverPresent(), dds::services::kEffort.name);
  return missing;
}

TaskPlan DdsServiceClients::plan(const TaskQuery& q) {
  const auto t0 = Clock::now();
  msg::PlanRequest req;
  req.domain_pddl(q.domain_pddl);
  req.objects(q.objects);
  req.init(q.init);
  req.goal(q.goal);
  req.search(msg::SearchKind::SEARCH_DEFAULT);
  req.use_costs(true);
  TaskPlan out;
  auto rep = answered(plan_.call(req, dds::CallOptions{q.budget_s, {}}), dds::services::kPlan.name);
  out.time_s = std::chrono::duration<double>(Clock::now() - t0).count();
  if (!rep) {
    out.status = rep.error().code == ErrorCode::kTimeout ? TaskStatus::kTimeout : TaskStatus::kUnavailable;
    out.message = rep.error().message;
    return out;
  }
  out.status = fromMsg(rep->status());
  out.message = rep->header().message();
  out.actions.assign(rep->actions().begin(), rep->actions().end());
  for (const auto& s : rep->states()) out.states.emplace_back(s.atoms().begin(), s.atoms().end());
  return out;
}

MotionAnswer DdsServiceClients::motion(const MotionQuery& q) {
  msg::MotionRequest req;
  req.world_version(q.world_version);
  req.group(q.group == Group::kBase ? msg::PlanningGroup::GROUP_BASE : msg::PlanningGroup::GROUP_ARM);
  req.mode(q.mode == Mode::kLazy ? msg::MotionMode::MOTION_LAZY : msg::MotionMode::MOTION_FULL);
  req.start_base(dds::toMsg(q.start.base));
  std::vector<std::string> names = robot_.armJointNames();
  std::vector<double> values = q.start.arm;
  if (!robot_.gripperJointName().empty()) {
    names.push_back(robot_.gripperJointName());
    values.push_back(q.start.gripper);
  }
  req.start_joint_names(names);
  req.start_joint_positions(values);
  if (q.group == Group::kBase) {
    req.goal_type(msg::GoalType::GOAL_BASE_POSE);
    req.goal_base(dds::toMsg(q.goal_base));
  } else {
    req.goal_type(msg::GoalType::GOAL_CONFIGURATION);
    req.goal_configuration(q.goal_arm);
  }
  req.held_object_id(q.held.object_id);
  if (!q.held.object_id.empty()) {
    req.held_grasp_given(true);
    req.held_link(q.held.link);
    req.held_link_T_object(dds::toMsg(q.held.link_T_object));
    req.held_padding_m(q.held_padding_m);
  }
  req.ignored_objects(q.ignored);
  for (const auto& o : q.overrides) req.object_overrides().push_back(toMsg(o));
  for (const auto& o : q.added) req.added_objects().push_back(dds::toMsg(o, 0));
  req.movable_cost_weight(q.movable_cost_weight);
  req.fixed_objects(q.fixed);
  req.straight_only(q.straight_only);
  MotionAnswer a;
  const auto t0 = Clock::now();
  auto rep = answered(motion_.call(req, dds::CallOptions{q.budget_s, {}}), dds::services::kMotion.name);
  // A planner that has not received the world version the question names answers `unavailable`
  // after waiting for it (its world_wait_s). The world is on its way (a lossy link repairs it, a
  // restarted planner gets it again): asked again a few times before the question counts as failed.
  for (int attempt = 1; attempt < kWorldLagAttempts && waitingForWorld(rep); ++attempt) {
    log::get("graph_manager")->warn("motion: {} (attempt {} of {}): asking again", rep.error().message, attempt, kWorldLagAttempts);
    rep = answered(motion_.call(req, dds::CallOptions{q.budget_s, {}}), dds::services::kMotion.name);
  }
  a.time_s = std::chrono::duration<double>(Clock::now() - t0).count();
  if (!rep) {
    a.status = rep.error().code == ErrorCode::kTimeout ? MotionOutcome::kTimeout : MotionOutcome::kUnavailable;
    a.reason = rep.error().message;
    return a;
  }
  if (rep->header().code() != msg::StatusCode::STATUS_OK) {
    a.status = MotionOutcome::kInvalid;
    a.reason = rep->header().message();
    return a;
  }
  a.status = fromMsg(rep->status());
  a.reason = rep->reason();
  a.world_version = rep->world_version();
  a.path_length = rep->path_length();
  if (a.ok()) {
    auto path = dds::fromMsg(rep->path(), "path");
    auto traj = dds::fromMsg(rep->trajectory(), "trajectory");
    if (!path || !traj) {
      a.status = MotionOutcome::kInvalid;
      a.reason = !path ? path.error().message : traj.error().message;
      return a;
    }
    a.path = *path;
    a.trajectory = *traj;
  }
  for (const auto& b : rep->blocking()) {
    Crossing c;
    c.object_id = b.object_id();
    c.enter_fraction = b.enter_fraction();
    c.exit_fraction = b.exit_fraction();
    c.mass = b.mass();
    c.effort_s = b.effort_s();
    for (const auto& p : b.swept_base()) c.swept_base.push_back(Pose2D{p.x(), p.y(), p.theta()});
    a.blocking.push_back(std::move(c));
  }
  return a;
}

std::vector<MotionAnswer> DdsServiceClients::motions(const std::vector<MotionQuery>& qs) {
  std::vector<std::future<MotionAnswer>> rest;
  for (std::size_t i = 1; i < qs.size(); ++i)
    rest.push_back(std::async(std::launch::async, [this, &q = qs[i]] { return motion(q); }));
  std::vector<MotionAnswer> out;
  out.reserve(qs.size());
  if (!qs.empty()) out.push_back(motion(qs.front()));
  for (auto& f : rest) out.push_back(f.get());
  return out;
}

Result<std::vector<PlacementOption>> DdsServiceClients::placements(const PlacementQuery& q) {
  msg::PlacementRequest req;
  req.object_id(q.object_id);
  req.region_id(q.region_id);
  for (const auto& p : q.keep_clear_path) req.keep_clear_path().push_back(dds::toMsg(p));
  req.keep_clear_radius(q.keep_clear_radius);
  req.max_placements(q.max_placements);
  if (q.base) {
    req.base_given(true);
    req.base_pose(dds::toMsg(*q.base));
  }
  if (q.object_T_tool) {
    req.held_grasp_given(true);
    req.held_object_T_tool(dds::toMsg(*q.object_T_tool));
  }
  req.approach(q.approach_m);
  for (const auto& o : q.overrides) req.object_overrides().push_back(toMsg(o));
  for (const auto& o : q.added) req.added_objects().push_back(dds::toMsg(o, 0));
  req.world_version(q.world_version);
  auto rep = answered(placement_.call(req, dds::CallOptions{q.budget_s, {}}), dds::services::kPlacement.name);
  if (!rep) return rep.error();
  if (rep->header().code() != msg::StatusCode::STATUS_OK)
    return Error(dds::fromMsg(rep->header().code()), rep->header().message());
  std::vector<PlacementOption> out;
  for (const auto& p : rep->placements()) {
    auto pose = dds::fromMsg(p.object_pose(), "object_pose");
    if (!pose) return pose.error();
    PlacementOption o;
    o.object_pose = *pose;
    o.base_pose = Pose2D{p.base_pose().x(), p.base_pose().y(), p.base_pose().theta()};
    o.arm.assign(p.arm_configuration().begin(), p.arm_configuration().end());
    o.pre_arm.assign(p.pre_arm_configuration().begin(), p.pre_arm_configuration().end());
    o.clearance = p.clearance();
    out.push_back(o);
  }
  return out;
}

Result<std::vector<GraspOption>> DdsServiceClients::grasps(const GraspQuery& q) {
  msg::GraspRequest req;
  req.object_id(q.object_id);
  req.base_given(q.base.has_value());
  if (q.base) req.base_pose(dds::toMsg(*q.base));
  req.max_grasps(q.max_grasps);
  for (const auto& o : q.overrides) req.object_overrides().push_back(toMsg(o));
  for (const auto& o : q.added) req.added_objects().push_back(dds::toMsg(o, 0));
  req.world_version(q.world_version);
  auto rep = answered(grasp_.call(req, dds::CallOptions{q.budget_s, {}}), dds::services::kGrasp.name);
  if (!rep) return rep.error();
  if (rep->header().code() != msg::StatusCode::STATUS_OK)
    return Error(dds::fromMsg(rep->header().code()), rep->header().message());
  std::vector<GraspOption> out;
  for (const auto& g : rep->grasps()) {
    auto pose = dds::fromMsg(g.gripper_in_object(), "gripper_in_object");
    if (!pose) return pose.error();
    GraspOption o;
    o.gripper_in_object = *pose;
    o.base_pose = Pose2D{g.base_pose().x(), g.base_pose().y(), g.base_pose().theta()};
    o.pregrasp.assign(g.pregrasp_configuration().begin(), g.pregrasp_configuration().end());
    o.grasp.assign(g.grasp_configuration().begin(), g.grasp_configuration().end());
    o.top = g.type() == msg::GraspType::GRASP_TOP;
    out.push_back(o);
  }
  return out;
}

std::vector<EffortAnswer> DdsServiceClients::effort(const std::vector<EffortQuery>& qs) {
  msg::EffortRequest req;
  for (const auto& q : qs) req.queries().push_back(toEffortMsg(q));
  std::vector<EffortAnswer> out(qs.size());
  auto rep = answered(effort_.call(req, dds::CallOptions{5.0, {}}), dds::services::kEffort.name);
  if (!rep) {
    for (auto& a : out) a.message = rep.error().message;
    return out;
  }
  fillEffortAnswers(rep->estimates(), out);
  return out;
}

std::optional<std::uint64_t> DdsServiceClients::effortModelVersion() {
  // An empty batch: the reply carries the version of the snapshot it would have used.
  auto rep = answered(effort_.call(msg::EffortRequest{}, dds::CallOptions{2.0, {}}), dds::services::kEffort.name);
  if (!rep) return std::nullopt;
  return rep->model_version();
}

// ---- execution ---------------------------------------------------------------------------------------

DdsExecutor::DdsExecutor(std::shared_ptr<dds::Participant> p, std::string mission_id)
    : mission_id_(std::move(mission_id)),
      writer_(p, dds::topics::kExecuteCommand),
      reader_(p, dds::topics::kExecuteStatus, [this](const msg::ExecuteStatus& s, const dds::SampleMeta&) { onStatus(s); }) {}

void DdsExecutor::onStatus(const msg::ExecuteStatus& s) {
  if (!msgv::accept(s, dds::topics::kExecuteStatus.name, replyRejects())) return;
  const auto st = s.state();
  if (st == msg::ExecState::EXEC_SUCCEEDED || st == msg::ExecState::EXEC_FAILED || st == msg::ExecState::EXEC_BLOCKED ||
      st == msg::ExecState::EXEC_CANCELLED) {
    std::lock_guard g(mutex_);
    final_[s.command_id()] = s;
    cv_.notify_all();
  }
}

namespace {
constexpr double kMonitorMatchWaitS = 30.0;
}  // namespace

ExecutionReport DdsExecutor::execute(const EdgeCommand& c, double budget_s) {
  ExecutionReport r;
  // Up to 30 s for the monitor to be matched: with DDS Security on a loaded 2-core machine the
  // authentication handshake of a pair took more than 10 s (MissionTest.Secured..., 2 CI runs).
  if (!writer_.waitForReaders(Termination::after(kMonitorMatchWaitS))) {
    r.outcome = ExecOutcome::kUnavailable;
    r.reason = "no execution monitor on this domain (none matched within " + std::to_string(static_cast<int>(kMonitorMatchWaitS)) + " s)";
    return r;
  }
  const std::string wire = wireId(c.command_id);
  msg::ExecuteCommand m;
  m.command_id(wire);
  m.mission_id(mission_id_);
  m.edge_id(c.edge_id);
  m.pddl_action(c.action);
  m.kind(dds::toMsg(c.kind));
  m.trajectory(dds::toMsg(c.trajectory));
  m.object_id(c.object_id);
  m.region_id(c.region_id);
  if (c.object_target) {
    m.object_target(dds::toMsg(*c.object_target));
    m.object_target_given(true);
  }
  m.expected_duration_s(c.expected_s);
  m.expected_stddev_s(c.expected_stddev_s);
  m.world_version(c.world_version);
  const int matches = writer_.readersEverMatched();
  if (Status s = writer_.write(m); !s) {
    r.outcome = ExecOutcome::kUnavailable;
    r.reason = s.error().message;
    return r;
  }
  std::unique_lock lock(mutex_);
  in_flight_ = m;
  r = finalOf(lock, wire, budget_s, &m, matches);
  in_flight_.reset();
  if (r.outcome == ExecOutcome::kTimeout) {
    lock.unlock();
    msg::ExecuteCommand cancel = m;
    cancel.cancel(true);
    (void)writer_.write(cancel);
  }
  return r;
}

void DdsExecutor::cancelInFlight() {
  std::optional<msg::ExecuteCommand> cancel;
  {
    std::lock_guard g(mutex_);
    cancel = in_flight_;
  }
  if (!cancel) return;
  cancel->cancel(true);
  const Status s = writer_.write(*cancel);
  log::get("graph_manager")->info("'{}' cancelled (the mission is aborted){}", cancel->command_id(),
                                  s ? "" : ": " + s.error().message);
}

ExecutionReport DdsExecutor::await(const std::string& command_id, double budget_s) {
  std::unique_lock lock(mutex_);
  return finalOf(lock, wireId(command_id), budget_s);
}

ExecutionReport DdsExecutor::finalOf(std::unique_lock<std::mutex>& lock, const std::string& wire, double budget_s,
                                     const msg::ExecuteCommand* resend, int matches) {
  ExecutionReport r;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(budget_s));
  const auto done = [&] { return final_.count(wire) > 0; };
  while (!done()) {
    // In slices, so that the worker tells the heartbeat it is waiting, not stuck.
    const auto slice = std::min(deadline, Clock::now() + (resend ? std::chrono::milliseconds(250) : std::chrono::milliseconds(1000)));
    alive();
    if (cv_.wait_until(lock, slice, done)) break;
    if (Clock::now() >= deadline) {
      r.outcome = ExecOutcome::kTimeout;
      r.reason = "no result within " + std::to_string(budget_s) + " s";
      return r;
    }
    // Commands are volatile: a monitor restarted while this one was out never received it. Sent
    // again, it is answered from the monitor's journal or the robot's own results, never executed
    // twice (the monitor and the robot are idempotent on command ids).
    if (const int now = writer_.readersEverMatched(); resend != nullptr && now > matches) {
      matches = now;
      lock.unlock();
      const Status s = writer_.write(*resend);
      log::get("graph_manager")->info("a reader of {} matched while '{}' was out (a restarted execution monitor?): "
                                      "sent again{}", writer_.topicName(), wire, s ? "" : ": " + s.error().message);
      lock.lock();
    }
  }
  const msg::ExecuteStatus s = final_.at(wire);
  final_.erase(wire);
  switch (s.state()) {
    case msg::ExecState::EXEC_SUCCEEDED: r.outcome = ExecOutcome::kSucceeded; break;
    case msg::ExecState::EXEC_BLOCKED: r.outcome = ExecOutcome::kBlocked; break;
    case msg::ExecState::EXEC_CANCELLED: r.outcome = ExecOutcome::kCancelled; break;
    default: r.outcome = ExecOutcome::kFailed; break;
  }
  r.measured_s = s.measured_duration_s() > 0 ? s.measured_duration_s() : s.elapsed_s();
  r.reason = s.reason();
  r.blocking_object_id = s.blocking_object_id();
  r.held_object_id = s.held_object_id();
  r.stopped_at_contact = s.stopped_at_contact();
  return r;
}

// ---- world ---------------------------------------------------------------------------------------------

DdsWorldSource::DdsWorldSource(std::shared_ptr<dds::Participant> p, robot::RobotModel robot)
    : robot_(std::move(robot)),
      mirror_(p),
      state_(p, dds::topics::kRobotState, [this](const msg::RobotState& s, const dds::SampleMeta&) {
        std::lock_guard g(mutex_);
        last_ = s;
      }) {}

Observation DdsWorldSource::robot() {
  alive();
  Observation o;
  std::optional<msg::RobotState> s;
  {
    std::lock_guard g(mutex_);
    s = last_;
  }
  if (!s) return o;
  auto st = robot_.fromJointValues(std::vector<std::string>(s->joint_names().begin(), s->joint_names().end()),
                                   std::vector<double>(s->joint_positions().begin(), s->joint_positions().end()),
                                   robot_.defaultState());
  if (!st) return o;
  o.robot = *st;
  o.robot.base = Pose2D{s->base().x(), s->base().y(), s->base().theta()};
  o.held_object_id = s->held_object_id();
  o.moving = s->moving();
  o.valid = true;
  return o;
}

Status DdsWorldSource::waitReady(const Termination& until) {
  std::string missing = missingInputs();
  while (!missing.empty() && !until()) {
    alive();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    missing = missingInputs();
  }
  if (missing.empty()) return Status::Ok();
  return Error(ErrorCode::kUnavailable, missing);
}

std::string DdsWorldSource::missingInputs() const {
  bool state = false;
  {
    std::lock_guard g(mutex_);
    state = last_.has_value();
  }
  const bool world = mirror_.publishedVersion() > 0;
  std::string missing;
  if (!world) missing = "no complete world model (" + std::string(dds::topics::kWorldMeta.name) + " and its objects, from perception)";
  if (!state) {
    if (!missing.empty()) missing += " and ";
    missing += "no robot state (" + std::string(dds::topics::kRobotState.name) + " from the robot)";
  }
  return missing;
}

}  // namespace tamp::graph_manager
