// The mission loop: traverse, execute the best branch edge by edge, repair after failures.
#include <chrono>
#include <cmath>

#include "tamp/core/log.h"
#include "tamp/graph_manager/graph_manager.h"

namespace tamp::graph_manager {
namespace {


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
  (void)ctx;
  return c;
}

MissionReport GraphManager::runMission(WorldSource& source, Executor& executor, const MissionObserver& observer) {
  MissionReport report;
  auto state = [&](const std::string& s, const std::string& msg) {
    if (observer.on_state) observer.on_state(s, msg);
  };
  auto finish = [&](MissionOutcome o, const std::string& reason) {
    report.status = o;
    report.reason = reason;
    report.counters = counters_;
    report.decisions = decisions_;
    report.planning_time_s = planning_s_;
    report.graph_dot = graph_.toDot({}, root_);
    state(std::string(toString(o)), reason);
    return report;
  };
  Observation robot = source.robot();
  if (!robot.valid) return finish(MissionOutcome::kUnavailable, "no robot state received");
  state("planning", "planning from the robot's state");
  if (Status s = start(source.world(), robot); !s) {
    const auto code = s.error().code;
    return finish(code == ErrorCode::kUnavailable ? MissionOutcome::kUnavailable
                  : code == ErrorCode::kTimeout   ? MissionOutcome::kTimeout
                  : code == ErrorCode::kInvalidArgument ? MissionOutcome::kInputError
                                                        : MissionOutcome::kFailed,
                  s.error().message);
  }
  NodeId current = root_;
  BranchContext ctx = contextOf(robot);
  std::vector<EdgeId> branch;
  double branch_total = 0.0, done_effort = 0.0;
  int failures = 0, step = 0;
  bool first_action = true;
  while (true) {
    if (observer.abort_requested && observer.abort_requested()) return finish(MissionOutcome::kAborted, "aborted by the user");
    if (isGoal(current)) break;
    if (branch.empty()) {
      state(failures ? "replanning" : "planning", "traverse from n" + std::to_string(current));
      TraverseResult t = traverse(current, ctx);
      if (!t.found) return finish(MissionOutcome::kFailed, t.reason);
      branch = t.branch;
      branch_total = done_effort + t.cost_s;
      report.predicted_effort_s = branch_total;
      if (observer.on_graph) observer.on_graph(graph_, branch, current);
    }
    const EdgeId id = branch.front();
    const EdgeId next = branch.size() > 1 ? branch[1] : -1;
    Edge& e = graph_.edge(id);
    // A manipulation follows from the arm motion just executed (its grasp or place pose) and the
    // arm as it is: priced again from there.
    // Not preparable in the world as it is now: a failure like any other, then repair (grasps
    // and placements are asked again: the world model may have changed since).
    auto notPrepared = [&](const std::string& what) {
      e.state = EdgeState::kFailed;
      ExecutedAction a;
      a.action = e.action;
      a.outcome = "not prepared";
      a.reason = "cannot prepare " + what + ": " + e.reason;
      report.actions.push_back(a);
      if (observer.on_action) observer.on_action(a, done_effort, branch_total);
      if (++failures > params_.max_replans) return false;
      ++report.replans;
      grasp_cache_.clear();
      placement_cache_.clear();
      if (e.kind == ActionKind::kMoveArm) {
        e.motion_by_next.erase(armKey(id, next));
        e.effort_by_next.erase(armKey(id, next));
      } else {
        e.motion.reset();
      }
      e.state = EdgeState::kUnevaluated;
      branch.clear();
      return true;
    };
    if (e.kind == ActionKind::kPick || e.kind == ActionKind::kPlace) {
      // A manipulation is never sent deferred: its grasp is planned now or it is a failure.
      if (!std::isfinite(evaluate(id, -1, ctx, 0)) || !e.motion || e.motion->deferred || e.motion->trajectory.empty()) {
        if (e.reason.empty()) e.reason = "no grasp or placement in the world as it is now";
        if (!notPrepared(e.action))
          return finish(MissionOutcome::kFailed, "gave up after " + std::to_string(failures) + " failures; last: " +
                                                     report.actions.back().reason);
        continue;
      }
    }
    // An arm motion into a manipulation is planned again in the world as it is now: the branch
    // priced it in a hypothetical world (objects moved by earlier edges, grasps deferred).
    if (e.kind == ActionKind::kMoveArm && armKey(id, next) >= 0) {
      e.motion_by_next.erase(armKey(id, next));
      e.effort_by_next.erase(armKey(id, next));
      if (!std::isfinite(evaluate(id, next, ctx, 0))) {
        if (!notPrepared(graph_.edge(next).action))
          return finish(MissionOutcome::kFailed, "gave up after " + std::to_string(failures) + " failures; last: " +
                                                     report.actions.back().reason);
        continue;
      }
    }
    // The robot must be where the edge's motion starts; otherwise plan the motion again from it.
    auto cmd = command(id, next, ctx, "m" + std::to_string(step) + "-e" + std::to_string(id));
    if (cmd && e.kind != ActionKind::kPick && e.kind != ActionKind::kPlace &&
        startDistance(cmd->trajectory, ctx.state, e.kind) > params_.start_tolerance) {
      if (e.kind == ActionKind::kMoveBase) {
        e.state = EdgeState::kUnevaluated;
        e.motion.reset();
      } else {
        e.motion_by_next.erase(armKey(id, next));
        e.effort_by_next.erase(armKey(id, next));
      }
      evaluate(id, next, ctx, 0);
      cmd = command(id, next, ctx, "m" + std::to_string(step) + "-e" + std::to_string(id));
    }
    if (!cmd) return finish(MissionOutcome::kFailed, cmd.error().message);
    if (first_action) {
      report.planning_time_to_first_action_s = planning_s_;
      first_action = false;
    }
    e.state = EdgeState::kExecuting;
    state("executing", e.action);
    ExecutionReport rep;
    if (e.motion && !e.motion->transfer.empty() && (e.kind == ActionKind::kPick || e.kind == ActionKind::kPlace)) {
      // The arm motion to the pre-grasp first, as its own move_arm.
      EdgeCommand t = *cmd;
      t.command_id = cmd->command_id + "-arm";
      t.action = "(move_arm to the pre-grasp of " + e.action + ")";
      t.kind = ActionKind::kMoveArm;
      t.trajectory = e.motion->transfer;
      t.object_id.clear();
      t.region_id.clear();
      t.object_target.reset();
      t.expected_s = e.motion->transfer_effort_s;
      t.expected_stddev_s = e.motion->transfer_stddev_s;
      cmd->expected_s -= t.expected_s;
      rep = executor.execute(t, t.expected_s + 4 * t.expected_stddev_s + params_.execution_margin_s);
      ExecutedAction ta;
      ta.command_id = t.command_id;
      ta.action = t.action;
      ta.variant = "transfer";
      ta.predicted_s = t.expected_s;
      ta.predicted_stddev_s = t.expected_stddev_s;
      ta.measured_s = rep.measured_s;
      ta.outcome = std::string(toString(rep.outcome));
      ta.reason = rep.reason;
      report.actions.push_back(ta);
      report.executed_effort_s += rep.measured_s;
      if (observer.on_action) observer.on_action(ta, done_effort, branch_total);
    }
    if (rep.outcome == ExecOutcome::kSucceeded || !(e.motion && !e.motion->transfer.empty())) {
      const double budget = cmd->expected_s + 4 * cmd->expected_stddev_s + params_.execution_margin_s;
      rep = executor.execute(*cmd, budget);
    }
    ++step;
    ExecutedAction a;
    a.command_id = cmd->command_id;
    a.action = e.action;
    a.variant = std::string(toString(e.variant));
    a.predicted_s = cmd->expected_s;
    a.predicted_stddev_s = cmd->expected_stddev_s;
    a.measured_s = rep.measured_s;
    a.outcome = std::string(toString(rep.outcome));
    a.reason = rep.reason;
    a.path = cmd->trajectory.path();
    report.actions.push_back(a);
    report.executed_effort_s += rep.measured_s;
    if (rep.outcome == ExecOutcome::kSucceeded) {
      e.state = EdgeState::kExecuted;
      done_effort += cmd->expected_s;
      if (e.kind == ActionKind::kPlace && cmd->object_target) {
        report.objects_moved.push_back(cmd->object_id);
        if (const world::Object* o = abstraction_.world().findObject(cmd->object_id))
          report.moved_from.emplace_back(o->id, o->pose);
        report.moved_to.emplace_back(cmd->object_id, *cmd->object_target);
      }
      ctx = advance(id, next, ctx);
      const Observation now = source.robot();
      if (now.valid) {
        ctx.state.base = now.robot.base;
        if (now.robot.arm.size() == ctx.state.arm.size()) ctx.state.arm = now.robot.arm;
      }
      if (observer.on_action) observer.on_action(a, done_effort, branch_total);
      current = e.to;
      branch.erase(branch.begin());
      continue;
    }
    if (rep.outcome == ExecOutcome::kUnavailable) return finish(MissionOutcome::kUnavailable, rep.reason);
    e.state = EdgeState::kFailed;
    e.reason = std::string(toString(rep.outcome)) + ": " + rep.reason;
    if (observer.on_action) observer.on_action(a, done_effort, branch_total);
    if (++failures > params_.max_replans)
      return finish(MissionOutcome::kFailed, "gave up after " + std::to_string(failures) + " failed actions; last: " +
                                                 e.action + " " + e.reason);
    ++report.replans;
    // Repair: the robot's node in the graph from what it observes now, then Traverse from it.
    const Observation now = source.robot();
    const world::World live = source.world();
    abstraction_.setWorld(live);
    const HeldGrasp held_before = ctx.held;
    ctx = contextOf(now.valid ? now : robot);
    // Still holding what the branch picked: the grasp is the one it executed. The world model
    // cannot tell (perception filters the held object, whose modelled pose is where it was seen).
    if (!ctx.held.object_id.empty() && ctx.held.object_id == held_before.object_id) ctx.held = held_before;
    std::string armconf = "stow";
    if (auto stow = abstraction_.robot().namedConfiguration("stow");
        stow && ctx.state.arm.size() == stow->size()) {
      double d = 0.0;
      for (std::size_t i = 0; i < stow->size(); ++i) d = std::max(d, std::abs((*stow)[i] - ctx.state.arm[i]));
      if (d > 0.05) armconf = graph_.node(e.from).atoms.empty() ? "stow" : abstraction_.bind(graph_.node(e.from).atoms).armconf;
    }
    auto atoms = abstraction_.dynamicAtoms(live, ctx.state.base, armconf, now.held_object_id);
    graph_.node(e.from).healthy = e.from != current ? graph_.node(e.from).healthy : false;
    current = graph_.addNode(atoms, "observed after " + e.action);
    branch.clear();
  }
  report.status = MissionOutcome::kSucceeded;
  report.counters = counters_;
  report.decisions = decisions_;
  report.planning_time_s = planning_s_;
  report.graph_dot = graph_.toDot({}, current);
  state("succeeded", "goal reached");
  return report;
}

}  // namespace tamp::graph_manager
