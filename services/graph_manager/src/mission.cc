// The mission loop: traverse, execute the best branch edge by edge, watch for events after every
// action, and repair by re-joining the branch (online replanning).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <set>
#include <thread>

#include "tamp/core/log.h"
#include "tamp/graph_manager/graph_manager.h"
#include "tamp/graph_manager/drop_settle.h"
#include "state_atoms.h"

namespace tamp::graph_manager {
namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double startDistance(const Trajectory& t, const robot::RobotState& s, ActionKind kind) {
  if (t.empty()) return kInfinity;
  const auto& p = t.points.front().positions;
  if (kind == ActionKind::kMoveBase) {
    if (p.size() < 3) return kInfinity;
    return std::hypot(p[0] - s.base.x, p[1] - s.base.y) + std::abs(std::remainder(p[2] - s.base.theta, 2 * M_PI));
  }
  double d = 0.0;
  for (std::size_t i = 0; i < std::min(p.size(), s.arm.size()); ++i) d = std::max(d, std::abs(p[i] - s.arm[i]));
  return d;
}

ExecutedAction executedFrom(const EdgeCommand& c, const ExecutionReport& rep, const std::string& variant) {
  ExecutedAction a;
  a.command_id = c.command_id;
  a.action = c.action;
  a.variant = variant;
  a.predicted_s = c.expected_s;
  a.predicted_stddev_s = c.expected_stddev_s;
  a.measured_s = rep.measured_s;
  a.outcome = std::string(toString(rep.outcome));
  a.reason = rep.reason;
  a.path = c.trajectory.path();
  return a;
}

EventKind eventOf(const ExecutionReport& rep) {
  if (rep.outcome == ExecOutcome::kBlocked) return EventKind::kActionBlocked;
  if (rep.reason.find("dropped") != std::string::npos) return EventKind::kObjectDropped;
  return EventKind::kActionFailed;
}

}  // namespace

Result<EdgeCommand> GraphManager::command(EdgeId id, EdgeId next, const BranchContext& ctx,
                                          const std::string& command_id) {
  const Edge& e = graph_.edge(id);
  next = armKey(id, next);
  const EdgeMotion* m = nullptr;
  double mean = e.effort_mean_s, sd = e.effort_stddev_s;
  if (e.kind == ActionKind::kMoveArm) {
    auto it = e.motion_by_next.find(next);
    if (it != e.motion_by_next.end()) m = &it->second;
    if (auto ef = e.effort_by_next.find(next); ef != e.effort_by_next.end()) mean = ef->second.first, sd = ef->second.second;
  } else if (e.motion) {
    m = &*e.motion;
  }
  if (!m) return Error(ErrorCode::kInternal, "edge " + e.action + " has no motion");
  EdgeCommand c;
  c.command_id = command_id;
  c.edge_id = "e" + std::to_string(e.id);
  c.action = e.action;
  c.kind = e.kind;
  c.trajectory = m->trajectory;
  c.object_id = m->object_id;
  c.region_id = m->region_id;
  c.object_target = m->object_target;
  c.expected_s = mean;
  c.expected_stddev_s = sd;
  c.world_version = world_version_;
  (void)ctx;
  return c;
}

namespace {
/// The mission's world source, remembering the newest world model version it gave out.
class SeenWorld final : public WorldSource {
 public:
  SeenWorld(WorldSource& s, std::uint64_t& newest) : source_(s), newest_(newest) {}
  world::World world() override {
    const std::uint64_t v = source_.version();  // before the snapshot, which holds at least v
    world::World w = source_.world();
    newest_ = std::max(newest_, v);
    return w;
  }
  Observation robot() override { return source_.robot(); }
  std::uint64_t version() override { return source_.version(); }

 private:
  WorldSource& source_;
  std::uint64_t& newest_;
};
}  // namespace

/// One mission: the state of the loop and its steps.
struct GraphManager::Run {
  Run(GraphManager& g, WorldSource& s, Executor& x, const MissionObserver& o)
      : gm(g), seen(s, g.world_version_), executor(x), observer(o), start_calls(g.logged_.mark()) {
    for (const auto& obj : g.abstraction_.world().objects()) scenario_ids.insert(obj.id);
    gm.interrupted_ = o.abort_requested;  // an abort stops a Traverse too, not only the loop
  }
  ~Run() { gm.interrupted_ = nullptr; }
  Run(const Run&) = delete;
  Run& operator=(const Run&) = delete;

  bool abortRequested() const { return observer.abort_requested && observer.abort_requested(); }

  GraphManager& gm;
  SeenWorld seen;
  WorldSource& source{seen};
  Executor& executor;
  const MissionObserver& observer;
  std::size_t start_calls{0};  ///< the call log's mark at the mission's start
  std::set<std::string> scenario_ids;  ///< the objects of the world at the start (Belief::told_objects unset)
  MissionReport report;
  NodeId current{-1};
  BranchContext ctx;
  std::vector<EdgeId> branch;  ///< from `current` to a goal node
  double branch_total{0.0};
  double done_effort{0.0};
  int attempts{0};  ///< replanning attempts after failures (bounded by max_replans)
  /// The effort estimator's model version when the action in flight was sent (nullopt: unknown).
  std::optional<std::uint64_t> models_before;
  int step{0};
  std::string id_prefix;  ///< "r<n>-" in a resumed mission: its command ids differ from the earlier runs'
  bool first_action{true};
  std::optional<Clock::time_point> event_at;  ///< a replanning waiting for its next command
  std::size_t event_calls{0};                 ///< the call log's mark at that event
  LatencyBreakdown pending;                   ///< that replanning's breakdown so far
  std::set<NodeId> planned_from_scratch;      ///< nodes TP(node, goal) was asked for after a replanning
  struct PendingConditional {
    Clock::time_point at;
    int planner_calls{0};
    int motion_calls{0};
  };
  std::optional<PendingConditional> conditional_at;  ///< a conditional branch waiting for its next command
  /// After a replanning, Traverse proved the branch's first edge(s) best (traverseFirstEdge): the
  /// rest of the branch is chosen by a Traverse from their end while the robot executes them.
  struct Continuation {
    std::vector<EdgeId> proven;  ///< the first edges of `branch`
    NodeId from{-1};             ///< the end of `proven`
    BranchContext ctx;           ///< the branch's context there
    std::size_t replanning{0};   ///< the replanning it follows (report.replanning index), or:
  };
  static constexpr std::size_t kNoReplanning = std::numeric_limits<std::size_t>::max();  ///< the start's
  std::optional<Continuation> continuation;

  MissionReport run();
  /// Takes up the report of the runs before a restart, and the outcome of the command that was
  /// in flight (awaited, not sent again).
  void resumeFrom(const ResumePoint& resume);
  /// The command in flight at the restart, with the outcome the robot reported for it.
  ExecutedAction awaitInFlight(const ResumePoint& resume);

 private:
  void state(const std::string& s, const std::string& msg) {
    if (observer.on_state) observer.on_state(s, msg);
  }
  MissionReport finish(MissionOutcome o, const std::string& reason);
  void recordPerceived();
  bool planBranch(std::string& why);
  /// Plans the manipulation (and the arm motion into it) in the world as it is now; false when
  /// it cannot be (an event, handled).
  enum class Prepared { kReady, kReplanned, kGaveUp };
  Prepared prepare(EdgeId id, EdgeId next);
  /// The edge cannot be sent (`reason`): reported as "not prepared", its motion forgotten, and
  /// online replanning from where the robot is.
  Prepared notPrepared(EdgeId id, EdgeId next, const std::string& reason);
  /// The command for the edge; its motion planned again when the robot is not where it starts
  /// (an error of kind kNotFound when that fails: not prepared).
  Result<EdgeCommand> commandFor(EdgeId id, EdgeId next);
  ExecutionReport execute(Edge& e, EdgeCommand& cmd);
  /// Sends `cmd` and waits for its outcome; the first of a continuation's proven edges is
  /// executed while Traverse prices the rest of the branch (the graph may grow meanwhile:
  /// edges are looked up again after it).
  ExecutionReport executeAndPrice(const EdgeCommand& cmd, double budget_s);
  void succeeded(EdgeId id, EdgeId next, const EdgeCommand& cmd, const ExecutionReport& rep);
  /// After a succeeded action: what the robot sees that the graph does not expect.
  std::optional<MissionEvent> watch(const Edge& done, const EdgeCommand& cmd, const ExecutionReport& rep);
  /// Online replanning after `ev`; false when the mission must give up (`why` says why).
  bool replan(const MissionEvent& ev, EdgeId failed, std::string& why);
  /// The branch ahead: from the failed edge (or the next one) on.
  std::vector<EdgeId> aheadOf(EdgeId failed) const;
  /// The world as replanning takes it in: the world model, and the graph's own beliefs where it
  /// strays from them within the tolerance (takeInWorld).
  struct Intake {
    world::World perceived;              ///< the world model as it came
    world::World live;                   ///< as the graph plans with it
    std::vector<std::string> fresh;      ///< movables new to the graph
    std::vector<world::Object> changed;  ///< movables seen beyond the tolerance from where expected
    std::vector<world::Object> refused;  ///< the one the event named, taken where it is seen
    bool reshaped{false};                ///< the named object's extent changed
  };
  Intake takeInWorld(const MissionEvent& ev);
  /// What a stop teaches: a margin round the held object, or where the object stopped before
  /// is (contact corrections, applied to `in.live`). True when the stop corrected the world.
  bool learnFromStop(const MissionEvent& ev, const Observation& now, const HeldGrasp& held_before, Intake& in,
                     ReplanRecord& rec);
  /// The failed edge planned again in the world as it is now; a failure unless `stale`.
  void forgetFailedEdge(EdgeId failed, const MissionEvent& ev, bool stale);
  /// A node for where the robot is, sub-tasks from it to the nodes `ahead`, else a plan from it
  /// (false, with `why`, when there is none).
  bool rejoinFromHere(const MissionEvent& ev, EdgeId failed, const std::vector<EdgeId>& ahead, const Intake& in,
                      const Observation& now, ReplanRecord& rec, std::string& why);
  /// Waits (drop_settle_timeout_s at most) until the world model has `object` resting on a support.
  void awaitSettled(const std::string& object);
  /// The robot's state once it reports itself at rest, waiting at most params.rest_wait_s (then
  /// the newest state, moving or not).
  Observation restingRobot();
  /// After an overrun: until the effort estimator has refitted since the action was sent, at most
  /// params.refit_wait_s.
  void awaitRefit();
  void noteCommand();
  /// Conditional planning: before the first action and before each pick, the hand as the robot
  /// reports it against the node's belief. A gripper that holds an object where the node has
  /// the hand empty takes the prebuilt branch (no planner call), else online replanning.
  enum class Hand { kAsBelieved, kSwitched, kGaveUp };
  Hand checkHand(const std::string& before, std::string& why);
  /// The geometry of an object the robot reports held: perception learns it from the points at
  /// the gripper, a few frames after the report; waits up to `held_object_wait_s` for the world
  /// model to have it, then adds it to the graph's world (a warning when it never came).
  void learnHeldObject(const std::string& object);
  /// Where the graph believes a movable object is: where the branch put it, else the world the
  /// graph was last built from; none for an object new to it.
  std::optional<Eigen::Isometry3d> expectedPose(const std::string& id) const {
    if (auto it = ctx.object_poses.find(id); it != ctx.object_poses.end()) return it->second;
    if (const world::Object* o = gm.abstraction_.world().findObject(id)) return o->pose;
    return std::nullopt;
  }
};

void GraphManager::Run::recordPerceived() {
  report.perceived.clear();
  const std::set<std::string>& told = gm.belief_.told_objects ? *gm.belief_.told_objects : scenario_ids;
  const world::World live = source.world();
  for (const auto& o : live.objects())
    if (!told.count(o.id)) report.perceived.push_back(o);
}

MissionReport GraphManager::Run::finish(MissionOutcome o, const std::string& reason) {
  report.status = o;
  report.reason = reason;
  recordPerceived();
  report.counters = gm.counters_;
  report.decisions = gm.decisions_;
  report.planning_time_s = gm.planning_s_;
  report.graph_dot = gm.graph_.toDot({}, current >= 0 ? current : gm.root_);
  state(std::string(toString(o)), reason);
  return report;
}

namespace {
/// Abstraction refinements in a row before a plan is given up (each adds at least one slot).
constexpr int kMaxRefinements = 8;
/// An object's bounding box that changed by more than this in any extent (m) was re-estimated.
constexpr double kReshapedM = 0.02;
}  // namespace

bool GraphManager::Run::planBranch(std::string& why) {
  state(attempts ? "replanning" : "planning", "traverse from n" + std::to_string(current));
  const auto t0 = Clock::now();
  const int evaluations0 = gm.counters_.evaluations;
  // After an event the next command waits for the first edge only (first_edge.cc).
  continuation.reset();
  const bool first_edge = event_at ? gm.params_.replan_first_edge : gm.params_.first_edge_at_start;
  auto search = [&] { return first_edge ? gm.traverseFirstEdge(current, ctx) : gm.traverse(current, ctx); };
  TraverseResult t = search();
  if (abortRequested()) {
    why = t.reason;
    return false;
  }
  // The geometry refuted a region-level reach (a pick from too far on a large region): plan again
  // from the refined state, where those objects are on slots of their own. Each round adds at
  // least one slot, so this ends; the bound keeps it short.
  for (int round = 0; !t.found && round < kMaxRefinements && gm.takeRefinement(); ++round) {
    const NodeId refined = gm.refinedNode(current);
    if (refined == current) break;
    current = refined;
    if (gm.graph_.out(current).empty() && !gm.isGoal(current)) {
      if (!gm.planFrom(current, gm.goal_.atoms, "plan after refining the abstraction")) break;
    }
    t = search();
  }
  if (!t.found && attempts > 0 && planned_from_scratch.insert(current).second) {
    // Every re-joining branch goes through an action that can no longer be done (it failed too
    // often): the goal from here, from scratch, merged into the graph; Traverse again.
    const int planner0 = gm.counters_.planner_calls;
    auto plan = gm.planFrom(current, gm.goal_.atoms, "plan from scratch: no re-joining branch left");
    if (plan) {
      if (!report.replanning.empty()) {
        report.replanning.back().how = "from scratch";
        report.replanning.back().planner_calls += gm.counters_.planner_calls - planner0;
      }
      t = search();
    }
  }
  if (!t.found) {
    why = t.reason;
    return false;
  }
  if (event_at) {
    pending.traverse_s += since(t0);
    pending.evaluations += gm.counters_.evaluations - evaluations0;
  }
  log::get("graph_manager")->debug("traverse from n{}: {} edges, {} proven first, {:.2f} s", current, t.branch.size(),
                                   t.proven_edges, t.cost_s);
  branch = t.branch;
  branch_total = done_effort + t.cost_s;
  report.predicted_effort_s = branch_total;
  if (t.proven_edges > 0 && t.proven_edges < branch.size()) {
    Continuation c;
    c.proven.assign(branch.begin(), branch.begin() + static_cast<std::ptrdiff_t>(t.proven_edges));
    c.from = gm.graph_.edge(c.proven.back()).to;
    c.ctx = gm.advanceAlong(c.proven, ctx);
    c.replanning = event_at && !report.replanning.empty() ? report.replanning.size() - 1 : kNoReplanning;
    continuation = std::move(c);
  }
  if (observer.on_graph) observer.on_graph(gm.graph_, branch, current);
  return true;
}

GraphManager::Run::Prepared GraphManager::Run::prepare(EdgeId id, EdgeId next) {
  // Evaluating may grow the graph (its edge vector): edges are looked up by id after it.
  const ActionKind kind = gm.graph_.edge(id).kind;
  bool ok = true;
  std::string what = gm.graph_.edge(id).action;
  if (kind == ActionKind::kPick || kind == ActionKind::kPlace) {
    // A manipulation is never sent deferred: its grasp is planned now or it is a failure (unless
    // it was planned from where the robot is, in the world as it is: the Traverse after an event
    // plans the first edge so).
    const bool planned = gm.params_.replan_first_edge && gm.plannedIn(id, -1, ctx);
    if (!planned) log::get("graph_manager")->debug("prepare {}: planned in the world as it is now", gm.graph_.edge(id).action);
    const bool priced = planned || std::isfinite(gm.evaluate(id, -1, ctx, 0));
    Edge& m = gm.graph_.edge(id);
    ok = priced && m.motion && !m.motion->deferred && !m.motion->trajectory.empty();
    if (!ok && m.reason.empty()) m.reason = "no grasp or placement in the world as it is now";
  } else if (kind == ActionKind::kMoveArm && gm.armKey(id, next) >= 0) {
    // An arm motion into a manipulation is planned again in the world as it is now: the branch
    // priced it in a hypothetical world (objects moved by earlier edges, grasps deferred).
    // Unless it was planned from where the robot is, in the world as it is (the Traverse after an
    // event plans the first edge so).
    if (!gm.params_.replan_first_edge || !gm.plannedIn(id, next, ctx)) {
      log::get("graph_manager")->debug("prepare {}: the arm motion into it is planned again in the world as it is now",
                                       gm.graph_.edge(next).action);
      Edge& arm = gm.graph_.edge(id);
      arm.motion_by_next.erase(gm.armKey(id, next));
      arm.effort_by_next.erase(gm.armKey(id, next));
    }
    ok = std::isfinite(gm.evaluate(id, next, ctx, 0));
    what = gm.graph_.edge(next).action;
  }
  if (ok) return Prepared::kReady;
  return notPrepared(id, next, "cannot prepare " + what + ": " + gm.graph_.edge(id).reason);
}

GraphManager::Run::Prepared GraphManager::Run::notPrepared(EdgeId id, EdgeId next, const std::string& reason) {
  Edge& e = gm.graph_.edge(id);
  ExecutedAction a;
  a.action = e.action;
  a.outcome = "not prepared";
  a.reason = reason;
  report.actions.push_back(a);
  if (observer.on_action) observer.on_action(a, done_effort, branch_total);
  gm.clearWorldCaches();
  if (e.kind == ActionKind::kMoveArm) {
    e.motion_by_next.erase(gm.armKey(id, next));
    e.effort_by_next.erase(gm.armKey(id, next));
  } else {
    e.motion.reset();
  }
  e.state = EdgeState::kFailed;
  std::string why;
  if (!replan(MissionEvent{EventKind::kNotPrepared, e.action, {}, a.reason}, id, why)) {
    finish(MissionOutcome::kFailed, why);
    return Prepared::kGaveUp;
  }
  return Prepared::kReplanned;
}

Result<EdgeCommand> GraphManager::Run::commandFor(EdgeId id, EdgeId next) {
  const std::string command_id = id_prefix + "m" + std::to_string(step) + "-e" + std::to_string(id);
  auto cmd = gm.command(id, next, ctx, command_id);
  const ActionKind kind = gm.graph_.edge(id).kind;
  const bool manipulation = kind == ActionKind::kPick || kind == ActionKind::kPlace;
  // The robot must be where the edge's motion starts; otherwise plan the motion again from it.
  // An edge without a motion (none kept for the way the branch goes on) is planned now.
  const double off = cmd && !manipulation ? startDistance(cmd->trajectory, ctx.state, kind) : 0.0;
  if (cmd && off <= gm.params_.start_tolerance) return cmd;
  Edge& e = gm.graph_.edge(id);
  if (cmd)
    log::get("graph_manager")->debug("{}: the robot is {:.3f} from where its motion starts: planned again", e.action, off);
  else
    log::get("graph_manager")->warn("{}: {}: planned now", e.action, cmd.error().message);
  if (e.kind == ActionKind::kMoveArm) {
    e.motion_by_next.erase(gm.armKey(id, next));
    e.effort_by_next.erase(gm.armKey(id, next));
  } else {
    e.state = EdgeState::kUnevaluated;
    e.motion.reset();
  }
  if (!std::isfinite(gm.evaluate(id, next, ctx, 0)))
    return Error(ErrorCode::kNotFound,
                 "cannot plan " + e.action + " from where the robot is: " + gm.graph_.edge(id).reason);
  return gm.command(id, next, ctx, command_id);
}

void GraphManager::Run::noteCommand() {
  if (first_action) {
    report.planning_time_to_first_action_s = gm.planning_s_;
    report.first_action_calls = gm.logged_.since(start_calls);
    const CallSummary sum = CallSummary::of(report.first_action_calls);
    log::get("graph_manager")
        ->info("first command after {:.3f} s of planning: {} calls {:.3f} s (motion {} {:.3f} s, grasp {} {:.3f} s, "
               "placement {} {:.3f} s, plan {} {:.3f} s, effort {} {:.3f} s)",
               gm.planning_s_, sum.calls(), sum.seconds(), sum.motion.calls, sum.motion.s, sum.grasp.calls, sum.grasp.s,
               sum.placement.calls, sum.placement.s, sum.plan.calls, sum.plan.s, sum.effort.calls, sum.effort.s);
    first_action = false;
  }
  if (event_at && !report.replanning.empty()) {
    ReplanRecord& r = report.replanning.back();
    r.latency_s = since(*event_at);
    r.breakdown = pending;
    r.breakdown.repair_s = r.planning_s;
    r.breakdown.prepare_s = std::max(0.0, r.latency_s - r.planning_s - pending.traverse_s);
    r.breakdown.calls = gm.logged_.since(event_calls);
    const CallSummary sum = CallSummary::of(r.breakdown.calls);
    log::get("graph_manager")
        ->info("replanning latency {:.3f} s: repair {:.3f} s, traverse {:.3f} s ({} evaluations), prepare {:.3f} s; "
               "{} calls {:.3f} s (motion {} {:.3f} s, grasp {} {:.3f} s, placement {} {:.3f} s, plan {} {:.3f} s, "
               "effort {} {:.3f} s)",
               r.latency_s, r.breakdown.repair_s, r.breakdown.traverse_s, r.breakdown.evaluations, r.breakdown.prepare_s,
               sum.calls(), sum.seconds(), sum.motion.calls, sum.motion.s, sum.grasp.calls, sum.grasp.s,
               sum.placement.calls, sum.placement.s, sum.plan.calls, sum.plan.s, sum.effort.calls, sum.effort.s);
  }
  event_at.reset();
  if (conditional_at && !report.conditionals.empty()) {
    ConditionalRecord& c = report.conditionals.back();
    c.latency_s = since(conditional_at->at);
    c.planner_calls = gm.counters_.planner_calls - conditional_at->planner_calls;
    c.motion_calls = gm.counters_.motion_calls - conditional_at->motion_calls;
  }
  conditional_at.reset();
}

void GraphManager::Run::learnHeldObject(const std::string& object) {
  if (gm.abstraction_.world().findObject(object) != nullptr) return;
  const auto deadline = Clock::now() + std::chrono::duration<double>(gm.params_.held_object_wait_s);
  world::World live = source.world();
  while (live.findObject(object) == nullptr && Clock::now() < deadline &&
         !abortRequested()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    live = source.world();
  }
  const world::Object* o = live.findObject(object);
  if (o == nullptr) {
    log::get("graph_manager")->warn("the world model does not know '{}' after {} s", object, gm.params_.held_object_wait_s);
    return;
  }
  world::World w = gm.abstraction_.world();
  (void)w.addObject(*o);
  gm.abstraction_.setWorld(w);
}

GraphManager::Run::Hand GraphManager::Run::checkHand(const std::string& before, std::string& why) {
  const Observation now = source.robot();
  const std::vector<std::string>& believed = gm.graph_.node(current).atoms;
  if (!now.valid || now.held_object_id.empty() ||
      !std::binary_search(believed.begin(), believed.end(), std::string("(hand-empty)")))
    return Hand::kAsBelieved;
  const std::string& object = now.held_object_id;
  learnHeldObject(object);
  const std::string observation = "the gripper holds '" + object + "', the node believes it empty";
  ConditionalRecord rec;
  rec.at_node = "n" + std::to_string(current);
  rec.observation = observation;
  // The prebuilt branch, unless the node places that object elsewhere (then its atoms about it
  // are wrong too, and only replanning can say where things are).
  bool named = false;
  for (const auto& a : believed) named = named || detail::mentions(a, {object});
  const auto branch_node = named ? std::nullopt : gm.takeContingency(current, object);
  if (!branch_node) {
    rec.prebuilt = false;
    report.conditionals.push_back(rec);
    log::get("graph_manager")->info("{} at {}: no prebuilt branch, online replanning", observation, rec.at_node);
    if (!replan(MissionEvent{EventKind::kHandNotEmpty, before, object, observation}, -1, why)) return Hand::kGaveUp;
    return Hand::kSwitched;
  }
  Decision d;
  d.node = rec.at_node;
  d.what = "observation: " + observation;
  d.traverse = gm.traverse_count_;
  Alternative empty;
  empty.description = "the hand empty: on with " + before;
  Alternative holding;
  holding.description = "the gripper not empty: put '" + object + "' down first (prebuilt branch n" +
                        std::to_string(*branch_node) + ")";
  holding.chosen = true;
  d.alternatives = {empty, holding};
  gm.decisions_.push_back(d);
  rec.branch_node = "n" + std::to_string(*branch_node);
  report.conditionals.push_back(rec);
  conditional_at = PendingConditional{Clock::now(), gm.counters_.planner_calls, gm.counters_.motion_calls};
  log::get("graph_manager")->info("{} at {}: the prebuilt branch from {}", observation, rec.at_node, rec.branch_node);
  current = *branch_node;
  ctx = gm.contextOf(now);
  branch.clear();
  return Hand::kSwitched;
}

ExecutionReport GraphManager::Run::execute(Edge& e, EdgeCommand& cmd) {
  e.state = EdgeState::kExecuting;
  state("executing", e.action);
  noteCommand();
  ExecutionReport rep;
  const bool transfer = e.motion && !e.motion->transfer.empty() &&
                        (e.kind == ActionKind::kPick || e.kind == ActionKind::kPlace);
  if (transfer) {
    // The arm motion to the pre-grasp first, as its own move_arm.
    EdgeCommand t = cmd;
    t.command_id = cmd.command_id + "-arm";
    t.action = "(move_arm to the pre-grasp of " + e.action + ")";
    t.kind = ActionKind::kMoveArm;
    t.trajectory = e.motion->transfer;
    t.object_id.clear();
    t.region_id.clear();
    t.object_target.reset();
    t.expected_s = e.motion->transfer_effort_s;
    t.expected_stddev_s = e.motion->transfer_stddev_s;
    cmd.expected_s -= t.expected_s;
    rep = executor.execute(t, t.expected_s + 4 * t.expected_stddev_s + gm.params_.execution_margin_s);
    ExecutedAction ta = executedFrom(t, rep, "transfer");
    ta.path = {};
    report.actions.push_back(ta);
    report.executed_effort_s += rep.measured_s;
    if (observer.on_action) observer.on_action(ta, done_effort, branch_total);
    if (rep.outcome != ExecOutcome::kSucceeded) return rep;
  }
  const double budget = cmd.expected_s + 4 * cmd.expected_stddev_s + gm.params_.execution_margin_s;
  return executeAndPrice(cmd, budget);
}

ExecutionReport GraphManager::Run::executeAndPrice(const EdgeCommand& cmd, double budget_s) {
  if (!continuation || branch.empty() || branch.front() != continuation->proven.front())
    return executor.execute(cmd, budget_s);
  const Continuation c = std::move(*continuation);
  continuation.reset();
  const std::size_t calls0 = gm.logged_.mark();
  // The executor on its own thread (it only waits for the robot); the graph stays on this one.
  auto running = std::async(std::launch::async, [this, &cmd, budget_s] { return executor.execute(cmd, budget_s); });
  const TraverseResult rest = gm.traverse(c.from, c.ctx);
  ExecutionReport rep = running.get();
  const CallSummary calls = CallSummary::of(gm.logged_.since(calls0));
  if (c.replanning < report.replanning.size()) {
    report.replanning[c.replanning].breakdown.background_calls += calls.calls();
    report.replanning[c.replanning].breakdown.background_s += calls.seconds();
  }
  double proven_s = 0.0;
  for (std::size_t i = 0; i < c.proven.size(); ++i) {
    const Edge& e = gm.graph_.edge(c.proven[i]);
    const EdgeId key = gm.armKey(c.proven[i], i + 1 < c.proven.size() ? c.proven[i + 1] : -1);
    const auto it = e.effort_by_next.find(key);
    proven_s += e.kind == ActionKind::kMoveArm && it != e.effort_by_next.end() ? it->second.first : e.effort_mean_s;
  }
  // Without a way on from there, the next Traverse (from the robot's node then) says why.
  branch = c.proven;
  if (rest.found) {
    branch.insert(branch.end(), rest.branch.begin(), rest.branch.end());
    branch_total = done_effort + proven_s + rest.cost_s;
    report.predicted_effort_s = branch_total;
  }
  log::get("graph_manager")->info("the rest of the branch from n{} priced during {}: {} edges, {:.1f} s ({} calls, {:.3f} s)",
                                  c.from, cmd.action, rest.branch.size(), rest.cost_s, calls.calls(), calls.seconds());
  if (observer.on_graph) observer.on_graph(gm.graph_, branch, current);
  return rep;
}

void GraphManager::Run::succeeded(EdgeId id, EdgeId next, const EdgeCommand& cmd, const ExecutionReport& rep) {
  (void)rep;
  Edge& e = gm.graph_.edge(id);
  e.state = EdgeState::kExecuted;
  done_effort += cmd.expected_s;
  if ((e.kind == ActionKind::kPlace || isPush(e)) && cmd.object_target) {
    report.objects_moved.push_back(cmd.object_id);
    if (const world::Object* o = gm.abstraction_.world().findObject(cmd.object_id))
      report.moved_from.emplace_back(o->id, o->pose);
    report.moved_to.emplace_back(cmd.object_id, *cmd.object_target);
  }
  // Picked, placed or pushed: the object is where the action took it; a stop's evidence of where
  // it stood before is over.
  if (!cmd.object_id.empty()) gm.corrections_.erase(cmd.object_id);
  ctx = gm.advance(id, next, ctx);
  const Observation now = source.robot();
  if (now.valid) {
    ctx.state.base = now.robot.base;
    if (now.robot.arm.size() == ctx.state.arm.size()) ctx.state.arm = now.robot.arm;
  }
  current = e.to;
  branch.erase(branch.begin());
}

std::optional<MissionEvent> GraphManager::Run::watch(const Edge& done, const EdgeCommand& cmd,
                                                     const ExecutionReport& rep) {
  // The hand: what the branch holds now must be what the robot holds.
  const Observation now = source.robot();
  if (now.valid && now.held_object_id != ctx.held.object_id && !ctx.held.object_id.empty())
    return MissionEvent{EventKind::kObjectDropped, done.action, ctx.held.object_id,
                        "'" + ctx.held.object_id + "' is no longer held after " + done.action};
  // The world: objects new to the graph on the way ahead, objects it acts on moved.
  const world::World live = source.world();
  std::vector<std::string> acted;
  for (EdgeId id : branch) {
    const Edge& e = gm.graph_.edge(id);
    if ((e.kind == ActionKind::kPick || e.kind == ActionKind::kPlace) && e.tokens.size() > 1) acted.push_back(e.tokens[1]);
  }
  for (const auto& o : live.objects()) {
    if (o.kind != world::ObjectKind::kMovable || o.id == ctx.held.object_id) continue;
    const world::Object* known = gm.abstraction_.world().findObject(o.id);
    if (!known) {
      // New: an event when it stands near a base motion or an object the branch acts on.
      bool relevant = false;
      const double r = gm.abstraction_.robot().baseRadius() + gm.params_.keep_clear_margin_m;
      for (EdgeId id : branch) {
        const Edge& e = gm.graph_.edge(id);
        if (e.kind == ActionKind::kMoveBase && e.motion) {
          const auto& p = e.motion->trajectory.empty() ? e.motion->lazy_path : e.motion->trajectory.path();
          const int ix = p.indexOf("base_x"), iy = p.indexOf("base_y");
          if (ix < 0 || iy < 0) continue;
          for (const auto& w : p.waypoints)
            if (std::hypot(w[static_cast<std::size_t>(ix)] - o.pose.translation().x(),
                           w[static_cast<std::size_t>(iy)] - o.pose.translation().y()) < r + 0.5)
              relevant = true;
        }
      }
      for (const auto& a : acted)
        if (const world::Object* t = live.findObject(a);
            t && (t->pose.translation().head<2>() - o.pose.translation().head<2>()).norm() < 0.4)
          relevant = true;
      if (relevant)
        return MissionEvent{EventKind::kNewObstacle, done.action, o.id, "'" + o.id + "' perceived on the way ahead"};
      continue;
    }
    if (std::find(acted.begin(), acted.end(), o.id) == acted.end()) continue;
    const double moved = (expectedPose(o.id)->translation().head<2>() - o.pose.translation().head<2>()).norm();
    if (moved > gm.params_.moved_object_tolerance_m)
      return MissionEvent{EventKind::kObjectMoved, done.action, o.id,
                          "'" + o.id + "' is " + std::to_string(moved) + " m from where the graph expects it"};
  }
  // The clock: an action far over its prediction prices the plan ahead again.
  const double limit = cmd.expected_s + gm.params_.overrun_sigma * std::max(cmd.expected_stddev_s, 0.05 * cmd.expected_s);
  if (rep.outcome == ExecOutcome::kSucceeded && std::isfinite(cmd.expected_s) && rep.measured_s > limit)
    return MissionEvent{EventKind::kOverrun, done.action, {},
                        "took " + std::to_string(rep.measured_s) + " s, predicted " + std::to_string(cmd.expected_s) + " s"};
  return std::nullopt;
}

void GraphManager::Run::awaitRefit() {
  // The overrunning action's record reaches the estimator beside its result, and a record that
  // far off its estimate is refitted at once: prices asked before that refit are the old ones.
  if (!models_before || !(gm.params_.refit_wait_s > 0)) return;
  const auto t0 = Clock::now();
  const auto deadline = t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(gm.params_.refit_wait_s));
  while (true) {
    const std::optional<std::uint64_t> now = gm.services_.effortModelVersion();
    if (now && *now > *models_before) {
      log::get("graph_manager")->info("effort models refitted ({} -> {}) {:.3f} s after the overrun", *models_before, *now,
                                      since(t0));
      return;
    }
    if (!now || Clock::now() >= deadline) {
      log::get("graph_manager")->info("no refit of the effort models {:.3f} s after the overrun: pricing with the models as they are",
                                      since(t0));
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

Observation GraphManager::Run::restingRobot() {
  const auto t0 = Clock::now();
  Observation o = source.robot();
  while (o.valid && o.moving && since(t0) < gm.params_.rest_wait_s && !abortRequested()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    o = source.robot();
  }
  if (o.moving) log::get("graph_manager")->warn("the robot still reports itself moving {:.1f} s after it was stopped", since(t0));
  return o;
}

void GraphManager::Run::awaitSettled(const std::string& object) {
  const auto t0 = Clock::now();
  DropSettleWatch watch(object, gm.params_.drop_confirm_s);
  while (true) {
    if (watch.settled(source.world(), since(t0))) {
      const Eigen::Vector3d& p = *watch.restingAt();
      log::get("graph_manager")->info("'{}' rests at ({:.2f}, {:.2f}, {:.2f}) {:.3f} s after the drop{}", object, p.x(), p.y(),
                                      p.z(), since(t0),
                                      watch.restarts() > 0 ? " (its estimate vanished or moved " +
                                                                 std::to_string(watch.restarts()) + " time(s) first)"
                                                           : std::string());
      return;
    }
    if (since(t0) >= gm.params_.drop_settle_timeout_s) {
      log::get("graph_manager")->warn("'{}' not seen resting on a support {:.1f} s after the drop: planning from the world model as it is",
                                      object, gm.params_.drop_settle_timeout_s);
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

std::vector<EdgeId> GraphManager::Run::aheadOf(EdgeId failed) const {
  if (failed < 0) return branch;
  std::vector<EdgeId> ahead;
  auto it = std::find(branch.begin(), branch.end(), failed);
  ahead.assign(it == branch.end() ? branch.begin() : it, branch.end());
  if (it == branch.end()) ahead.insert(ahead.begin(), failed);
  return ahead;
}

GraphManager::Run::Intake GraphManager::Run::takeInWorld(const MissionEvent& ev) {
  // What the world is now: perception's objects, but where the graph knows an object to be (its
  // prior, or where the mission put it) within the tolerance, that pose: a partial view strays
  // further than a place does, and a stray estimate would unbind the slot. The exception: the
  // object that a refused or stopped motion named. The monitor judges a motion by the world
  // model, so planning again where the graph believes that object is would be refused again (a
  // pushed chair whose estimate lags 11 cm behind its slot); it is taken where perception sees it.
  Intake in;
  in.perceived = source.world();
  in.live = in.perceived;
  const bool names_object = ev.kind == EventKind::kActionFailed || ev.kind == EventKind::kActionBlocked;
  for (const auto& o : in.live.objects()) {
    if (o.kind != world::ObjectKind::kMovable) continue;
    const auto expected = expectedPose(o.id);
    if (!expected) in.fresh.push_back(o.id);
    if (!expected || (expected->translation() - o.pose.translation()).norm() > gm.params_.moved_object_tolerance_m)
      in.changed.push_back(o);
    else if (names_object && o.id == ev.object_id)
      in.refused.push_back(o);
    else
      (void)in.live.setObjectPose(o.id, *expected);
  }
  // The named object's extent changed since the graph last took the world in (an estimate grown,
  // shrunk or turned: a new object seen from more sides): the world changed under the plan as
  // much as when it moved.
  in.reshaped = names_object && !ev.object_id.empty() && [&] {
    const world::Object* before = gm.abstraction_.world().findObject(ev.object_id);
    const world::Object* after = in.live.findObject(ev.object_id);
    if (!before || !after) return false;
    const Eigen::Vector3d a = before->aabb().max - before->aabb().min, b = after->aabb().max - after->aabb().min;
    return (a - b).cwiseAbs().maxCoeff() > kReshapedM;
  }();
  return in;
}

bool GraphManager::Run::learnFromStop(const MissionEvent& ev, const Observation& now, const HeldGrasp& held_before,
                                      Intake& in, ReplanRecord& rec) {
  // Stopped before an object the plan knew where it is (a wall, or a movable where the graph
  // expects it) while holding one: the plan cleared it with the held object where the graph
  // believes it sits in the hand, and the robot did not. Held objects are planned with a
  // margin from now on.
  if (ev.kind == EventKind::kActionBlocked && !held_before.object_id.empty()) {
    const world::Object* blocker = in.live.findObject(ev.object_id);
    auto named = [&](const world::Object& o) { return o.id == ev.object_id; };
    const bool known = blocker && std::find(in.fresh.begin(), in.fresh.end(), ev.object_id) == in.fresh.end() &&
                       std::none_of(in.changed.begin(), in.changed.end(), named);
    if (known) gm.widenHeldMargin(held_before.object_id, ev.object_id);
  }
  rec.held_padding_m = gm.held_padding_m_;
  // A command refused because of a corrected object: the monitor checks commands against the
  // world model, which still has it where it was seen; planning round the correction again would
  // be refused again. The world model's estimate wins.
  if (ev.kind == EventKind::kActionFailed && gm.corrections_.erase(ev.object_id) > 0)
    log::get("graph_manager")->info("'{}': a command was refused with the world model's estimate of it; its contact correction ends",
                                    ev.object_id);
  gm.applyContactCorrections(in.perceived, in.live);
  // The robot stopped itself before a movable with nothing in the hand (not the monitor on a
  // prediction): the robot's body at the stop is where the object begins (contact.h). Planning
  // round the estimate again would drive into it again.
  bool corrected = false;
  if (ev.at_contact && held_before.object_id.empty() && now.valid && !ev.object_id.empty()) {
    if (auto c = gm.correctByContact(in.perceived, in.live, ev.object_id, now.robot)) {
      corrected = true;
      rec.corrected_object = ev.object_id;
      rec.corrected_m = c->shift_m;
    }
  }
  if (!gm.corrections_.empty()) gm.abstraction_.setWorld(in.live);
  return corrected;
}

void GraphManager::Run::forgetFailedEdge(EdgeId failed, const MissionEvent& ev, bool stale) {
  // Planned again in the world as it is now, unless it failed too often (then infeasible).
  Edge& f = gm.graph_.edge(failed);
  if (stale)
    log::get("graph_manager")
        ->info("{}: not counted as a failure: '{}' changed in the world model since it was planned", f.action,
               ev.object_id);
  else
    gm.noteFailure(f);
  f.state = EdgeState::kUnevaluated;
  f.motion.reset();
  f.motion_by_next.clear();
  f.effort_by_next.clear();
  f.subtasks_spawned = false;
}

bool GraphManager::Run::rejoinFromHere(const MissionEvent& ev, EdgeId failed, const std::vector<EdgeId>& ahead,
                                       const Intake& in, const Observation& now, ReplanRecord& rec, std::string& why) {
  // The arm out of its driving configuration: where the node before the event had it.
  std::string armconf = "stow";
  const NodeId was = failed >= 0 ? gm.graph_.edge(failed).from : current;
  if (!gm.armStowed(ctx.state.arm) && !gm.graph_.node(was).atoms.empty()) {
    armconf = gm.abstraction_.bind(gm.graph_.node(was).atoms).armconf;
    // The node had the arm stowed and the robot has it out (a move_arm out of stow that ended,
    // or stopped part-way, without its result reaching the graph): a symbol of its own, which a
    // plan can only leave; a base motion with the arm out would be refused.
    if (armconf == "stow") armconf = gm.abstraction_.addObservedArmconf("arm_observed");
  }
  const auto atoms = gm.abstraction_.dynamicAtoms(in.live, ctx.state.base, armconf, now.valid ? now.held_object_id : "");
  current = gm.graph_.addNode(atoms, "observed after " + ev.action);
  const auto joined = gm.rejoin(current, ahead, in.fresh, "re-join after " + std::string(toString(ev.kind)));
  for (NodeId n : joined) rec.rejoined.push_back("n" + std::to_string(n));
  rec.how = "re-join";
  if (!joined.empty()) return true;
  rec.how = "from scratch";
  if (gm.graph_.out(current).empty() && !gm.isGoal(current)) {
    auto plan = gm.planFrom(current, gm.goal_.atoms, "plan after " + std::string(toString(ev.kind)));
    if (!plan) {
      why = "replanning after " + std::string(toString(ev.kind)) + " (" + ev.detail + "): " + plan.error().message;
      return false;
    }
  }
  return true;
}

bool GraphManager::Run::replan(const MissionEvent& ev, EdgeId failed, std::string& why) {
  const auto t0 = Clock::now();
  const std::size_t calls0 = gm.logged_.mark();
  const double planning0 = gm.planning_s_;
  const int planner0 = gm.counters_.planner_calls, motion0 = gm.counters_.motion_calls;
  const bool failure = ev.kind != EventKind::kOverrun;
  if (failure && ++attempts > gm.params_.max_replans) {
    why = "gave up after " + std::to_string(attempts) + " replanning attempts; last: " + ev.action + ": " + ev.detail;
    return false;
  }
  ++report.replans;
  ReplanRecord rec;
  rec.event = ev;
  const std::vector<EdgeId> ahead = aheadOf(failed);
  if (ev.kind == EventKind::kObjectDropped) awaitSettled(!ev.object_id.empty() ? ev.object_id : ctx.held.object_id);
  // Stopped before an object: where it stopped is evidence (learnFromStop), so the state must be the stop's.
  const Observation now = ev.at_contact ? restingRobot() : source.robot();
  Intake in = takeInWorld(ev);
  gm.abstraction_.setWorld(in.live);
  gm.clearWorldCaches();
  const HeldGrasp held_before = ctx.held;
  if (now.valid) ctx = gm.contextOf(now);
  // Still holding what the branch picked: the grasp is the one it executed. The world model
  // cannot tell (perception filters the held object, whose modelled pose is where it was seen).
  if (!ctx.held.object_id.empty() && ctx.held.object_id == held_before.object_id) ctx.held = held_before;
  const bool corrected = learnFromStop(ev, now, held_before, in, rec);
  // Failed, refused or stopped because of an object the graph did not know, or knew elsewhere or
  // smaller (the world model changed since the edge was planned, e.g. a new object's estimate
  // still growing onto the path), or where the stop corrected it: the world changed under the
  // plan, the action did not fail, so it is not counted towards max_action_failures (max_replans
  // still bounds the attempts).
  auto named = [&](const world::Object& o) { return o.id == ev.object_id; };
  const bool names_object = ev.kind == EventKind::kActionFailed || ev.kind == EventKind::kActionBlocked;
  const bool stale = names_object && !ev.object_id.empty() &&
                     (in.reshaped || corrected || std::find(in.fresh.begin(), in.fresh.end(), ev.object_id) != in.fresh.end() ||
                      std::any_of(in.changed.begin(), in.changed.end(), named));
  std::vector<world::Object> near = in.changed;
  near.insert(near.end(), in.refused.begin(), in.refused.end());
  gm.invalidateNear(near);
  if (failed >= 0) forgetFailedEdge(failed, ev, stale);
  if (ev.kind == EventKind::kOverrun) {
    awaitRefit();
    gm.reprice();
    rec.how = "re-traverse";
  } else if (!rejoinFromHere(ev, failed, ahead, in, now, rec, why)) {
    return false;
  }
  rec.at_node = "n" + std::to_string(current);
  rec.planner_calls = gm.counters_.planner_calls - planner0;
  rec.motion_calls = gm.counters_.motion_calls - motion0;
  gm.planning_s_ = planning0 + since(t0);
  rec.planning_s = since(t0);
  log::get("graph_manager")->info("replanning after {} ({}): {} at {}", toString(ev.kind), ev.detail, rec.how, rec.at_node);
  report.replanning.push_back(rec);
  event_at = t0;
  event_calls = calls0;
  pending = LatencyBreakdown{};
  branch.clear();
  return true;
}

MissionReport GraphManager::Run::run() {
  Observation robot = source.robot();
  if (!robot.valid) return finish(MissionOutcome::kUnavailable, "no robot state received");
  state("planning", "planning from the robot's state");
  // Told the hand is empty, the planner plans so, and the first observation of the hand selects
  // the conditional branch if the robot holds something. Told it holds an object, what the robot
  // reports wins at the start (an object dropped before the mission began is simply not held).
  Observation believed = robot;
  if (gm.belief_.held_object_id && gm.belief_.held_object_id->empty()) believed.held_object_id.clear();
  if (Status s = gm.start(source.world(), believed); !s) {
    const auto code = s.error().code;
    return finish(code == ErrorCode::kUnavailable       ? MissionOutcome::kUnavailable
                  : code == ErrorCode::kTimeout         ? MissionOutcome::kTimeout
                  : code == ErrorCode::kInvalidArgument ? MissionOutcome::kInputError
                                                        : MissionOutcome::kFailed,
                  s.error().message);
  }
  current = gm.root_;
  ctx = gm.contextOf(believed);
  while (true) {
    if (abortRequested()) return finish(MissionOutcome::kAborted, "aborted by the user");
    if (gm.isGoal(current)) break;
    std::string why;
    // The hand before the first action (before any motion is planned) and before each pick.
    const bool at_start = first_action && report.conditionals.empty();
    const bool before_pick = !branch.empty() && gm.graph_.edge(branch.front()).kind == ActionKind::kPick;
    if (at_start || before_pick) {
      const Hand h = checkHand(at_start ? std::string("the start") : gm.graph_.edge(branch.front()).action, why);
      if (h == Hand::kGaveUp) return finish(MissionOutcome::kFailed, why);
      if (h == Hand::kSwitched) continue;
    }
    if (branch.empty() && !planBranch(why)) {
      if (abortRequested()) return finish(MissionOutcome::kAborted, "aborted by the user");
      return finish(MissionOutcome::kFailed, why);
    }
    const EdgeId id = branch.front();
    const EdgeId next = branch.size() > 1 ? branch[1] : -1;
    const Prepared p = prepare(id, next);
    if (p == Prepared::kGaveUp) return report;
    if (p == Prepared::kReplanned) continue;
    auto cmd = commandFor(id, next);
    if (!cmd && cmd.error().code == ErrorCode::kNotFound) {
      if (notPrepared(id, next, cmd.error().message) == Prepared::kGaveUp) return report;
      continue;
    }
    if (!cmd) return finish(MissionOutcome::kFailed, cmd.error().message);
    models_before = gm.services_.effortModelVersion();
    const ExecutionReport rep = execute(gm.graph_.edge(id), *cmd);
    Edge& e = gm.graph_.edge(id);  // after: pricing during the execution may have grown the graph
    ++step;
    ExecutedAction a = executedFrom(*cmd, rep, std::string(toString(e.variant)));
    report.actions.push_back(a);
    report.executed_effort_s += rep.measured_s;
    if (rep.outcome == ExecOutcome::kSucceeded) {
      succeeded(id, next, *cmd, rep);
      if (observer.on_action) observer.on_action(a, done_effort, branch_total);
      if (gm.isGoal(current)) break;
      // An overrun: the time models were refitted from this action, the graph is priced again.
      if (auto ev = watch(e, *cmd, rep); ev && !replan(*ev, -1, why)) return finish(MissionOutcome::kFailed, why);
      continue;
    }
    if (rep.outcome == ExecOutcome::kUnavailable) return finish(MissionOutcome::kUnavailable, rep.reason);
    if (abortRequested()) return finish(MissionOutcome::kAborted, "aborted by the user");  // stopped mid-action
    e.state = EdgeState::kFailed;
    e.reason = std::string(toString(rep.outcome)) + ": " + rep.reason;
    if (observer.on_action) observer.on_action(a, done_effort, branch_total);
    MissionEvent ev{eventOf(rep), e.action, rep.blocking_object_id, e.reason, rep.stopped_at_contact};
    if (!replan(ev, id, why)) return finish(MissionOutcome::kFailed, why);
  }
  report.status = MissionOutcome::kSucceeded;
  recordPerceived();
  report.counters = gm.counters_;
  report.decisions = gm.decisions_;
  report.planning_time_s = gm.planning_s_;
  report.graph_dot = gm.graph_.toDot({}, current);
  state("succeeded", "goal reached");
  return report;
}

void GraphManager::Run::resumeFrom(const ResumePoint& resume) {
  report.resumptions = resume.resumptions;
  id_prefix = "r" + std::to_string(resume.resumptions) + "-";
  auto take = [&](const ExecutedAction& a) {
    report.actions.push_back(a);
    report.executed_effort_s += a.measured_s;
    const auto tokens = atomTokens(a.action);
    if (a.outcome == "succeeded" && tokens.size() > 1 && (tokens[0] == "place" || tokens[0] == "push")) report.objects_moved.push_back(tokens[1]);
  };
  for (const auto& a : resume.actions) take(a);
  if (!resume.in_flight.empty()) take(awaitInFlight(resume));
  // An arm left out by the last action gets a symbol of its own (start()), not the pre-grasp the
  // action named: a new graph chooses its own grasp, and the motion from the old pre-grasp to the
  // new one, close to the object, was stopped by the robot twice in a trial; from `stow` the
  // approach is the one every mission makes.
}

ExecutedAction GraphManager::Run::awaitInFlight(const ResumePoint& resume) {
  state("planning", "waiting for the outcome of " + resume.in_flight + ", sent before the restart");
  const ExecutionReport rep = executor.await(resume.in_flight, resume.in_flight_budget_s);
  ExecutedAction a;
  a.command_id = resume.in_flight;
  a.action = resume.in_flight_action;
  a.measured_s = rep.measured_s;
  a.outcome = std::string(toString(rep.outcome));
  a.reason = rep.outcome == ExecOutcome::kTimeout ? "no outcome after the restart: " + rep.reason : rep.reason;
  log::get("graph_manager")->info("resumed: {} {} {}", a.command_id, a.action, a.outcome);
  return a;
}

MissionReport GraphManager::runMission(WorldSource& source, Executor& executor, const MissionObserver& observer) {
  Run r(*this, source, executor, observer);
  return r.run();
}

MissionReport GraphManager::resumeMission(const ResumePoint& resume, WorldSource& source, Executor& executor,
                                          const MissionObserver& observer) {
  Run r(*this, source, executor, observer);
  r.resumeFrom(resume);
  return r.run();
}

}  // namespace tamp::graph_manager
