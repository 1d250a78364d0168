// Traverse (Algorithm 3): the mission's task planning (TP from any node) and the branch-and-bound
// search on predicted effort. Edge pricing is in evaluate.cc, sub-task spawning in subtasks.cc.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include "tamp/core/log.h"
#include "tamp/graph_manager/graph_manager.h"
#include "tamp/world/scenario.h"

namespace tamp::graph_manager {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }


}  // namespace

std::string_view toString(TaskStatus s) {
  switch (s) {
    case TaskStatus::kSolved: return "solved";
    case TaskStatus::kUnsolvable: return "unsolvable";
    case TaskStatus::kFailed: return "failed";
    case TaskStatus::kTimeout: return "timeout";
    case TaskStatus::kInputError: return "input error";
    case TaskStatus::kUnavailable: return "unavailable";
  }
  return "?";
}
std::string_view toString(MotionOutcome s) {
  switch (s) {
    case MotionOutcome::kSolved: return "solved";
    case MotionOutcome::kNoPath: return "no path";
    case MotionOutcome::kStartInCollision: return "start in collision";
    case MotionOutcome::kGoalInCollision: return "goal in collision";
    case MotionOutcome::kTimeout: return "timeout";
    case MotionOutcome::kInvalid: return "invalid request";
    case MotionOutcome::kUnavailable: return "unavailable";
  }
  return "?";
}
std::string_view toString(ExecOutcome o) {
  switch (o) {
    case ExecOutcome::kSucceeded: return "succeeded";
    case ExecOutcome::kFailed: return "failed";
    case ExecOutcome::kBlocked: return "blocked";
    case ExecOutcome::kCancelled: return "cancelled";
    case ExecOutcome::kTimeout: return "timeout";
    case ExecOutcome::kUnavailable: return "unavailable";
  }
  return "?";
}
std::string_view toString(MissionOutcome o) {
  switch (o) {
    case MissionOutcome::kSucceeded: return "succeeded";
    case MissionOutcome::kFailed: return "failed";
    case MissionOutcome::kAborted: return "aborted";
    case MissionOutcome::kTimeout: return "timeout";
    case MissionOutcome::kInputError: return "input_error";
    case MissionOutcome::kUnavailable: return "unavailable";
  }
  return "?";
}

GraphManager::GraphManager(Abstraction abstraction, std::string domain_pddl, MissionGoal goal,
                           ServiceClients& services, GraphManagerParams params)
    : abstraction_(std::move(abstraction)),
      domain_(std::move(domain_pddl)),
      goal_(std::move(goal)),
      logged_(services),
      services_(logged_),
      params_(params),
      // Invalid params are refused just below, with their own message.
      drive_bound_(params.lower_bound_base_speed > 0.0 ? params.lower_bound_base_speed : 1.0) {
  if (auto why = params_.invalidReason()) throw std::invalid_argument("GraphManagerParams: " + *why);
  domain_pushes_ = pushesIn(domain_);
}

bool GraphManager::isGoal(NodeId n) const {
  const auto& atoms = graph_.node(n).atoms;
  for (const auto& g : goal_.atoms) {
    const auto t = atomTokens(g);
    if (!t.empty() && t[0] == "not") {
      std::string inner = "(";
      for (std::size_t i = 1; i < t.size(); ++i) inner += (i > 1 ? " " : "") + t[i];
      inner += ")";
      if (std::binary_search(atoms.begin(), atoms.end(), inner)) return false;
    } else {
      std::string norm = "(";
      for (std::size_t i = 0; i < t.size(); ++i) norm += (i ? " " : "") + t[i];
      norm += ")";
      if (!std::binary_search(atoms.begin(), atoms.end(), norm)) return false;
    }
  }
  return true;
}

std::vector<std::string> GraphManager::withStatics(const std::vector<std::string>& dynamic) const {
  std::vector<std::string> all = abstraction_.staticAtoms();
  all.insert(all.end(), dynamic.begin(), dynamic.end());
  return all;
}

BranchContext GraphManager::contextOf(const Observation& robot) const {
  BranchContext c;
  c.state = robot.robot;
  if (!robot.held_object_id.empty()) {
    c.held.object_id = robot.held_object_id;
    c.held.link = abstraction_.robot().options().tool_link;
    if (const auto& h = abstraction_.world().held(); h && h->object_id == robot.held_object_id) {
      c.held.link = h->link;
      c.held.link_T_object = h->link_T_object;
    } else if (const world::Object* o = abstraction_.world().findObject(robot.held_object_id)) {
      c.held.link_T_object = abstraction_.robot().toolPoseInWorld(robot.robot).inverse() * o->pose;
    }
  }
  return c;
}

// ---- task planning ---------------------------------------------------------------------------------

Result<std::vector<EdgeId>> GraphManager::planFrom(NodeId from, const std::vector<std::string>& goal,
                                                   const std::string& origin) {
  TaskQuery q;
  q.domain_pddl = domain_;
  q.objects = abstraction_.objects();
  q.init = withStatics(graph_.node(from).atoms);
  q.goal = goal;
  q.budget_s = params_.plan_budget_s;
  ++counters_.planner_calls;
  TaskPlan p = services_.plan(q);
  if (p.status != TaskStatus::kSolved) {
    const ErrorCode code = p.status == TaskStatus::kUnsolvable  ? ErrorCode::kNotFound
                           : p.status == TaskStatus::kTimeout    ? ErrorCode::kTimeout
                           : p.status == TaskStatus::kInputError ? ErrorCode::kInvalidArgument
                           : p.status == TaskStatus::kUnavailable ? ErrorCode::kUnavailable
                                                                  : ErrorCode::kInternal;
    return Error(code, "task planner (" + std::string(toString(p.status)) + "): " + p.message);
  }
  if (p.states.size() != p.actions.size() + 1)
    return Error(ErrorCode::kInternal, "task planner: the plan's states do not match its actions");
  // The planner's states may omit atoms it found static; apply its changes to the node's atoms.
  std::vector<std::vector<std::string>> states{graph_.node(from).atoms};
  for (std::size_t i = 0; i < p.actions.size(); ++i) {
    std::set<std::string> prev(p.states[i].begin(), p.states[i].end());
    std::set<std::string> next(p.states[i + 1].begin(), p.states[i + 1].end());
    std::set<std::string> cur(states.back().begin(), states.back().end());
    for (const auto& a : prev)
      if (!next.count(a)) cur.erase(a);
    for (const auto& a : next)
      if (!prev.count(a)) cur.insert(a);
    states.emplace_back(cur.begin(), cur.end());
  }
  return graph_.addPlan(p.actions, states, origin);
}

bool GraphManager::armStowed(const std::vector<double>& arm) const {
  // `stow` binds to the folded arm, or to `carry` while holding: both are driving configurations.
  for (const char* name : {"stow", "carry"}) {
    const auto q = abstraction_.robot().namedConfiguration(name);
    if (!q || q->size() != arm.size()) continue;
    double d = 0.0;
    for (std::size_t i = 0; i < q->size(); ++i) d = std::max(d, std::abs((*q)[i] - arm[i]));
    if (d <= params_.stowed_tolerance_rad) return true;
  }
  return false;
}

Status GraphManager::start(const world::World& live, const Observation& robot) {
  const auto t0 = Clock::now();
  abstraction_.setWorld(live);
  // The arm as the robot reports it: stowed, or out (a mission taken up after a restart, a robot
  // handed over mid-task): then a symbol of its own, which a plan can only leave.
  const std::string armconf =
      !robot.valid || armStowed(robot.robot.arm) ? std::string("stow") : abstraction_.addObservedArmconf("arm_observed");
  auto atoms = abstraction_.dynamicAtoms(live, robot.robot.base, armconf, robot.held_object_id);
  root_ = graph_.addNode(atoms, "start");
  auto plan = planFrom(root_, goal_.atoms, "plan 0");
  if (!plan) {
    planning_s_ += since(t0);
    if (plan.error().code == ErrorCode::kNotFound)
      return Error(ErrorCode::kNotFound, "the goal is unreachable: " + plan.error().message);
    return plan.error();
  }
  // The contingencies known in advance, in the graph before execution starts.
  (void)buildContingencies(*plan);
  planning_s_ += since(t0);
  return Status::Ok();
}

// ---- branch-and-bound ----------------------------------------------------------------------------------

struct GraphManager::Search {
  Search(GraphManager& g, Clock::time_point start)
      : gm(g), t0(start), exhaustive(g.params_.policy == Policy::kOracle) {}
  GraphManager& gm;
  Clock::time_point t0;
  /// Policy oracle: no branch is cut on its bound (every branch within the evaluation budget is
  /// priced in full), and each complete branch pays what the scripted failures will cost it.
  bool exhaustive{false};
  std::vector<BranchStep> steps;  ///< parallel to `branch`: what the robot executes
  double best{kInfinity};
  double best_sd2{0.0};
  std::vector<EdgeId> best_branch;
  std::map<EdgeId, double> best_through;
  std::map<EdgeId, double> cut_bound;
  int evaluations{0};
  int completions{0};  ///< complete branches found (however costly)
  bool exhausted{false};
  bool interrupted{false};  ///< stopped by GraphManager::interrupted_ (an abort)
  std::vector<EdgeId> branch;
  std::vector<double> branch_sd2;
  /// traverseFirstEdge: below the first edge (with the manipulation an arm motion prepares) of
  /// the best complete branch so far, nothing more is explored; every other way on from the
  /// start is, against that branch's cost (first_edge.cc).
  bool first_edge_only{false};
  std::vector<EdgeId> first_edge;
  /// First edges that were settled (their subtree explored no further) and then lost to a better
  /// branch through another first edge: tried again from the start against the new best, since
  /// what was left unexplored below them may beat it.
  std::set<EdgeId> revisit;

  bool settled() const {
    return first_edge_only && !first_edge.empty() && branch.size() >= first_edge.size() &&
           std::equal(first_edge.begin(), first_edge.end(), branch.begin());
  }

  /// A manipulation with a transfer arm motion sends the robot two commands.
  static BranchStep stepOf(const Edge& e, double effort_s) {
    const bool transfer = e.motion && !e.motion->transfer.empty();
    return BranchStep{e.kind, effort_s, transfer ? 2 : 1};
  }

  bool outOfBudget() {
    if (evaluations >= gm.params_.max_evaluations || since(t0) > gm.params_.traverse_budget_s) {
      exhausted = true;
      return true;
    }
    if (gm.interrupted_ && gm.interrupted_()) {
      exhausted = interrupted = true;
      return true;
    }
    return false;
  }

  bool onBranch(NodeId n) const {
    for (EdgeId e : branch)
      if (gm.graph_.edge(e).from == n) return true;
    return false;
  }

  double known(EdgeId id) const {
    const Edge& e = gm.graph_.edge(id);
    if (e.state == EdgeState::kInfeasible || e.state == EdgeState::kLazy) return kInfinity;
    if (e.kind == ActionKind::kMoveArm) return 0.0;  // priced with the manipulation that follows
    if (e.kind != ActionKind::kMoveBase) return 0.0;
    return e.state == EdgeState::kUnevaluated ? e.lower_bound_s : e.effort_mean_s;
  }

  void complete(double branch_cost) {
    ++completions;
    const double cost = branch_cost + gm.oraclePenalty(steps);
    if (first_edge_only && !branch.empty() && (first_edge.empty() || cost < best)) {
      // The first edge to settle is the best branch's: a better branch through another first
      // edge takes over, and the one it replaces is explored again below (revisit).
      std::vector<EdgeId> f = gm.firstEdgeOf(branch);
      if (!first_edge.empty() && f != first_edge) {
        // The same arm motion into another manipulation: the arm edge is tried again too (the
        // manipulation settled before is explored again below it, the new one stays settled).
        revisit.insert(first_edge.front());
        if (f.front() != first_edge.front()) revisit.erase(f.front());
      }
      first_edge = std::move(f);
    }
    if (cost < best) {
      best = cost;
      best_branch = branch;
      best_sd2 = 0.0;
      for (double s : branch_sd2) best_sd2 += s;
    }
    for (EdgeId e : branch) {
      auto [it, fresh] = best_through.emplace(e, cost);
      if (!fresh) it->second = std::min(it->second, cost);
    }
  }

  /// Edges on a branch that was cut on its bound (at it or below): a way on that was priced, not
  /// one that failed.
  std::set<EdgeId> bounded;

  void cut(EdgeId e, double bound) {
    gm.graph_.edge(e).cut = true;
    cut_bound[e] = bound;
    bounded.insert(e);
    bounded.insert(branch.begin(), branch.end());
  }

  /// Whether no branch through `e` reached the goal or was cut on its bound: it failed.
  bool failedThrough(EdgeId e) const { return !best_through.count(e) && !bounded.count(e); }

  /// Records an edge's state when its try ends (however the loop body leaves).
  struct TriedMark {
    GraphManager& gm;
    std::map<EdgeId, EdgeState>& tried;
    EdgeId id;
    TriedMark(GraphManager& g, std::map<EdgeId, EdgeState>& t, EdgeId e) : gm(g), tried(t), id(e) {
      tried[id] = gm.graph_.edge(id).state;
    }
    ~TriedMark() { tried[id] = gm.graph_.edge(id).state; }
    TriedMark(const TriedMark&) = delete;
    TriedMark& operator=(const TriedMark&) = delete;
  };

  void dfs(NodeId v, const BranchContext& ctx, double cost, int depth) {
    if (gm.isGoal(v)) {
      complete(cost);
      return;
    }
    // Each out-edge with its state when it was last tried: an edge priced again since (policy
    // infeasible prices a blocked edge again round what the robot cannot move, once the way
    // round everything is proven impossible) is tried again.
    std::map<EdgeId, EdgeState> tried;
    const int completed_before = completions;
    while (!settled() && !outOfBudget()) {
      // The untried out-edge with the least known or bounded effort (out(v) grows with sub-tasks).
      EdgeId pick = -1;
      double pick_cost = kInfinity;
      for (EdgeId e : gm.graph_.out(v)) {
        if (auto t = tried.find(e); t != tried.end() && t->second == gm.graph_.edge(e).state) continue;
        Edge& x = gm.graph_.edge(e);
        if (x.state == EdgeState::kUnevaluated && x.lower_bound_s == 0.0) x.lower_bound_s = gm.lowerBound(x);
        const double k = known(e);
        if (pick < 0 || k < pick_cost) pick = e, pick_cost = k;
      }
      if (pick < 0 && branch.empty() && !revisit.empty()) {
        // At the start: first edges that lost their place to a better branch are tried again
        // (their subtree was cut short while they were settled), now against the better cost.
        for (EdgeId e : revisit) tried.erase(e);
        revisit.clear();
        continue;
      }
      if (pick < 0) {
        // Every way on was tried and none reached the goal: an object whose every removal failed
        // at its first step is gone round instead (the edges it blocked are planned again, and
        // tried again when changed). Not when a way on reached it: the rescue costs motions (on
        // namo_moghaddam_07, 7 s more before the first command, and the oracle's budget).
        auto dead = [&](EdgeId x) { return tried.count(x) && failedThrough(x); };
        if (completions == completed_before && gm.fixUnremovable(v, ctx, dead)) continue;
        return;
      }
      TriedMark mark{gm, tried, pick};
      Edge& e = gm.graph_.edge(pick);
      if (e.to == v || onBranch(e.to)) continue;
      if (!std::isfinite(pick_cost)) continue;
      if (!exhaustive && cost + pick_cost + gm.toGoalBound(e.to) >= best) {
        cut(pick, cost + pick_cost + gm.toGoalBound(e.to));
        continue;
      }
      if (e.kind == ActionKind::kMoveArm) {
        expandArm(pick, ctx, cost, depth);
        continue;
      }
      ++evaluations;
      const int sub_depth = depth + (e.origin.rfind("sub-task", 0) == 0 ? 1 : 0);
      const double c = gm.evaluate(pick, -1, ctx, sub_depth);
      // Evaluating may grow the graph (variants, sub-tasks): the edge is looked up again.
      Edge& done = gm.graph_.edge(pick);
      if (!std::isfinite(c)) continue;
      if (!exhaustive && cost + c + gm.toGoalBound(done.to) >= best) {
        cut(pick, cost + c + gm.toGoalBound(done.to));
        continue;
      }
      branch.push_back(pick);
      branch_sd2.push_back(done.effort_stddev_s * done.effort_stddev_s);
      steps.push_back(stepOf(done, c));
      const NodeId to = done.to;
      dfs(to, gm.advance(pick, -1, ctx), cost + c, depth);
      branch.pop_back();
      branch_sd2.pop_back();
      steps.pop_back();
    }
  }

  /// A move_arm edge: priced per manipulation that follows it (its target is their pre-grasp).
  void expandArm(EdgeId arm, const BranchContext& ctx, double cost, int depth) {
    // Copies: evaluating may grow the graph's edge vector.
    const Edge a = gm.graph_.edge(arm);
    std::vector<EdgeId> nexts;
    for (EdgeId f : gm.graph_.out(a.to))
      if (gm.graph_.edge(f).kind == ActionKind::kPick || gm.graph_.edge(f).kind == ActionKind::kPlace) nexts.push_back(f);
    if (nexts.empty() || (a.tokens.size() > 3 && a.tokens[3] == "stow")) nexts = {-1};
    for (EdgeId f : nexts) {
      if (settled() || outOfBudget()) return;
      ++evaluations;
      const double c = gm.evaluate(arm, f, ctx, depth);
      if (!std::isfinite(c)) continue;
      const double to_goal = gm.toGoalBound(a.to);  // an arm motion leaves the base where it is
      if (!exhaustive && cost + c + to_goal >= best) {
        cut(arm, cost + c + to_goal);
        continue;
      }
      const auto sd = gm.graph_.edge(arm).effort_by_next[f].second;
      branch.push_back(arm);
      branch_sd2.push_back(sd * sd);
      steps.push_back(BranchStep{ActionKind::kMoveArm, c, 1});
      const BranchContext next_ctx = gm.advance(arm, f, ctx);
      if (f < 0) {
        dfs(a.to, next_ctx, cost + c, depth);
      } else {
        // Evaluate the manipulation right away (it needs the prepared grasp or placement).
        const Edge& fe = gm.graph_.edge(f);
        ++evaluations;
        const double cf = gm.evaluate(f, -1, next_ctx, depth);
        const double after = std::isfinite(cf) ? cost + c + cf + gm.toGoalBound(fe.to) : kInfinity;
        if (std::isfinite(cf) && !exhaustive && after >= best) bounded.insert(branch.begin(), branch.end());
        if (std::isfinite(cf) && (exhaustive || after < best) && !onBranch(fe.to)) {
          branch.push_back(f);
          branch_sd2.push_back(fe.effort_stddev_s * fe.effort_stddev_s);
          steps.push_back(stepOf(fe, cf));
          dfs(fe.to, gm.advance(f, -1, next_ctx), cost + c + cf, depth);
          branch.pop_back();
          branch_sd2.pop_back();
          steps.pop_back();
        }
      }
      branch.pop_back();
      branch_sd2.pop_back();
      steps.pop_back();
    }
  }
};

TraverseResult GraphManager::traverse(NodeId from, const BranchContext& context) {
  return search(from, context, false);
}

TraverseResult GraphManager::search(NodeId from, const BranchContext& context, bool first_edge_only) {
  const auto t0 = Clock::now();
  ++traverse_count_;
  if (params_.policy == Policy::kOracle) refreshOracle();
  TraverseResult r;
  if (graph_.out(from).empty() && !isGoal(from)) {
    auto plan = planFrom(from, goal_.atoms, "plan " + std::to_string(traverse_count_));
    if (!plan) {
      r.reason = plan.error().message;
      r.time_s = since(t0);
      planning_s_ += r.time_s;
      return r;
    }
  }
  boundsForCurrentModels();
  Search s(*this, t0);
  s.first_edge_only = first_edge_only;
  s.dfs(from, context, 0.0, 0);
  r.evaluations = s.evaluations;
  r.time_s = since(t0);
  planning_s_ += r.time_s;
  if (s.interrupted) {  // an abort: whatever was found is not to be executed
    r.reason = "interrupted: the mission is being aborted";
    return r;
  }
  if (s.best_branch.empty() && !isGoal(from)) {
    std::string why;
    for (const Edge& e : graph_.edges())
      if (!e.reason.empty()) why += (why.empty() ? "" : "; ") + e.action + ": " + e.reason;
    r.reason = std::string(s.exhausted ? "no branch reaches the goal within the evaluation budget"
                                       : "no branch reaches the goal") +
               (why.empty() ? "" : " (" + why + ")");
    return r;
  }
  r.found = true;
  r.branch = s.best_branch;
  // The first edge is proven best when the best branch found goes through it and every other way
  // on was explored within the budget; with the budget spent it is only the best so far
  // (first_edge.cc).
  if (first_edge_only && !s.first_edge.empty() && r.branch.size() >= s.first_edge.size() &&
      std::equal(s.first_edge.begin(), s.first_edge.end(), r.branch.begin())) {
    r.proven_edges = s.first_edge.size();
    r.proven = !s.exhausted;
  }
  r.cost_s = s.best;
  r.stddev_s = std::sqrt(s.best_sd2);
  // Below a proven first edge nothing was explored: only its decisions are recorded (the rest of
  // the branch is decided, and recorded, by the Traverse that continues from there).
  const std::vector<EdgeId> decided = first_edge_only ? std::vector<EdgeId>(r.branch.begin(),
                                                                            r.branch.begin() + static_cast<std::ptrdiff_t>(r.proven_edges))
                                                      : r.branch;
  recordDecisions(from, s.best_through, decided, r.cost_s, traverse_count_, s.cut_bound);
  return r;
}

void GraphManager::recordDecisions(NodeId from, const std::map<EdgeId, double>& best_through,
                                   const std::vector<EdgeId>& branch, double best_cost, int traverse_index,
                                   const std::map<EdgeId, double>& cut_bounds) {
  (void)best_cost;
  std::vector<NodeId> nodes{from};
  for (EdgeId e : branch) nodes.push_back(graph_.edge(e).to);
  for (std::size_t i = 0; i < branch.size(); ++i) {
    const NodeId n = nodes[i];
    std::vector<Alternative> alts;
    for (EdgeId e : graph_.out(n)) {
      const Edge& x = graph_.edge(e);
      if (x.state == EdgeState::kLazy) continue;  // a placeholder: its sub-tasks and detour are the options
      Alternative a;
      a.description = x.action + (x.variant == Variant::kAround ? " [around]" : "") + " <" + x.origin + ">";
      if (auto it = best_through.find(e); it != best_through.end()) a.effort_s = it->second;
      if (auto it = cut_bounds.find(e); it != cut_bounds.end() && !std::isfinite(a.effort_s)) {
        a.cut = true;
        a.bound_s = it->second;
      }
      a.chosen = e == branch[i];
      alts.push_back(a);
    }
    if (alts.size() < 2) continue;
    Decision d;
    d.node = "n" + std::to_string(n);
    d.what = "how to go on from " + d.node;
    d.alternatives = alts;
    d.traverse = traverse_index;
    decisions_.push_back(std::move(d));
  }
}

}  // namespace tamp::graph_manager
