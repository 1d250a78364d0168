#pragma once
/// @file
/// The graph manager: the mission loop of "Conditional Task and Motion Planning through an
/// Effort-Based Approach" (spec/conditional-tamp-effort-based.tex, Algorithms 1-3).
///
/// ## Design overview
/// 1. `start()`: the live world's symbolic state becomes the root node; `TP(s0, sG)` gives a
///    plan, `RGraph(P)` the first reachability graph (graph.h).
/// 2. `traverse()` (Algorithm 3): depth-first branch-and-bound on predicted effort from the
///    robot's current node to any node where the goal holds.
///    - An edge is priced first by an admissible lower bound (distance at a top speed); a branch
///      whose partial cost plus that bound reaches the best complete cost c* is cut before any
///      motion is planned for it.
///    - Otherwise the edge is evaluated: a lazy motion in the world of the branch (objects moved
///      by earlier edges of the branch are passed as overrides, the held object with its grasp),
///      then its effort from the effort estimator.
///    - A base motion whose pure static-only lazy path crosses movables is not executable as is.
///      For each crossed object o (policy `effort`; policy `infeasible` only when the full-mode
///      path around everything is proven not to exist): `findPossibleActions(o)` (pick and place:
///      the object must be graspable within the payload), a base pose beside o from the grasp
///      service, `findEffectStates(o)`: placements off the swept path from the motion planner,
///      made slots (abstraction.h); then `TP(v, s)` and `TP(s, child)` (and on to the goal),
///      merged with `updateRGraph`. The detour (a full-mode path) stays a parallel edge.
///    - Arm motions towards a pre-grasp configuration are evaluated together with the pick or
///      place that follows (their target is that manipulation's pre-grasp).
///    - A bounded number of edge evaluations and a deadline; deterministic for a seed (the
///      services' own seeds and the order of evaluation are fixed).
/// 3. `runMission()`: executes the best branch edge by edge through an `Executor`, re-planning a
///    motion whose start no longer matches the robot, and re-running `traverse()` from the
///    robot's node after a failed or blocked action (bounded by `max_replans`).
///
/// 4. Policies (params.h): `effort` as above; `infeasible` spawns removal sub-tasks only when the
///    detour is proven impossible; `oracle` (oracle.h, the lower bound of the evaluation) takes
///    its efforts and its knowledge of hidden objects and scripted faults from
///    `ServiceClients::effort()`/`oracle()` (the simulator's truth, at the node), adds a sub-task
///    per subset of up to `oracle_max_objects` blocking objects, cuts no branch on its bound and
///    charges each complete branch the retries its scripted failures will cost.
///
/// The library knows nothing of DDS: the services are reached through `ServiceClients` and the
/// robot through `Executor` (clients.h).

#include <chrono>
#include <functional>
#include <map>
#include <set>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tamp/graph_manager/abstraction.h"
#include "tamp/graph_manager/call_log.h"
#include "tamp/graph_manager/bound.h"
#include "tamp/graph_manager/clients.h"
#include "tamp/graph_manager/contact.h"
#include "tamp/graph_manager/graph.h"
#include "tamp/graph_manager/params.h"
#include "tamp/graph_manager/query_memo.h"

namespace tamp::graph_manager {

/// What the mission must achieve: PDDL atoms over world ids (a base pose goal is a location).
struct MissionGoal {
  std::vector<std::string> atoms;
};

/// The robot as a branch of the search assumes it (the geometric context of a node).
struct BranchContext {
  robot::RobotState state;
  HeldGrasp held;
  std::map<std::string, Eigen::Isometry3d> object_poses;  ///< objects moved by the branch
  std::optional<GraspOption> pending_grasp;   ///< chosen by the move_arm before a pick
  std::optional<Eigen::Isometry3d> pending_place;  ///< object pose chosen before a place
  /// Where the branch's last base motion started: the side the robot comes from to what it does
  /// here (a stand beside an object is sought on that side). None before the branch's first drive.
  std::optional<Pose2D> came_from;
};

/// One alternative at a decision point, with its predicted effort.
struct Alternative {
  std::string description;   ///< "move_base start goal [around]" / "remove box via slot_box_1"
  double effort_s{kInfinity}; ///< best complete branch through it; infinite when none
  bool cut{false};            ///< pruned: only `bound_s` is known
  double bound_s{0.0};
  bool chosen{false};
};

struct Decision {
  std::string node;           ///< "n0"
  std::string what;           ///< the question decided
  std::vector<Alternative> alternatives;
  int traverse{0};            ///< which Traverse made it
};

struct Counters {
  int planner_calls{0};
  int motion_calls{0};
  int placement_calls{0};
  int grasp_calls{0};
  int effort_calls{0};
  int evaluations{0};
  int subtasks{0};
  int memo_hits{0};  ///< motion and grasp questions answered from the memo (query_memo.h), not asked
};

struct TraverseResult {
  bool found{false};
  std::vector<EdgeId> branch;  ///< from the start node to a goal node
  double cost_s{kInfinity};
  double stddev_s{0.0};
  double time_s{0.0};
  int evaluations{0};
  std::string reason;          ///< when not found
  /// traverseFirstEdge: the first this many edges of `branch` are decided (0: the whole branch
  /// is, or nothing is); the rest is the first complete branch found through them, to be priced
  /// again from their end while the robot executes them.
  std::size_t proven_edges{0};
  /// Whether those edges are proven best (every other way on was bounded by the branch's cost),
  /// or only the best found when the Traverse's budget ran out.
  bool proven{false};
};

struct ExecutedAction {
  std::string command_id;
  std::string action;
  std::string variant;
  double predicted_s{0.0};
  double predicted_stddev_s{0.0};
  double measured_s{0.0};
  std::string outcome;
  std::string reason;
  JointPath path;              ///< what the robot was commanded (for the report's picture)
};

enum class MissionOutcome { kSucceeded, kFailed, kAborted, kTimeout, kInputError, kUnavailable };
std::string_view toString(MissionOutcome o);

/// What triggers online replanning (the paper's "On-Line Replanning").
enum class EventKind {
  kActionFailed,   ///< the robot reported a failed action (a missed grasp, a collision)
  kActionBlocked,  ///< the monitor stopped an action: an object in the way
  kObjectDropped,  ///< the held object is no longer held
  kNewObstacle,    ///< a newly perceived object on the remaining branch
  kObjectMoved,    ///< an object the branch acts on is not where the graph expects it
  kOverrun,        ///< an action took longer than predicted + k sigma
  kNotPrepared,    ///< a manipulation has no grasp or placement in the world as it is now
  kHandNotEmpty,   ///< the gripper holds an object where the graph believes it empty, no branch prebuilt
};
std::string_view toString(EventKind k);

struct MissionEvent {
  EventKind kind{EventKind::kActionFailed};
  std::string action;     ///< the action it happened in or after
  std::string object_id;  ///< the object concerned, if any
  std::string detail;
  /// kActionBlocked: the robot itself stopped before contact with `object_id`
  /// (ExecutionReport::stopped_at_contact).
  bool at_contact{false};
};

/// Where the time from an event to the next command went (issue 12's latency), filled when the
/// next command goes out.
struct LatencyBreakdown {
  double repair_s{0.0};    ///< the graph repaired: world taken in, re-join sub-tasks (= planning_s)
  double traverse_s{0.0};  ///< Traverse from the robot's node until the first edge was decided
  double prepare_s{0.0};   ///< the rest: the first edge planned again in the world as it is now
  int evaluations{0};      ///< edge evaluations by that Traverse
  /// The service calls between the event and the next command (all on its critical path).
  std::vector<TimedCall> calls;
  /// Calls made for the branch after the first edge was decided, while the robot executed it.
  int background_calls{0};
  double background_s{0.0};
};

/// One online replanning: the event, how the graph was repaired, what it cost.
struct ReplanRecord {
  MissionEvent event;
  std::string at_node;                ///< the robot's node when it replanned
  /// "re-join" (sub-tasks towards nodes ahead), "re-traverse" (the graph as it is, priced again),
  /// "from scratch" (TP(current, goal): no node ahead could be re-joined).
  std::string how;
  std::vector<std::string> rejoined;  ///< the nodes ahead that a sub-task reached
  double held_padding_m{0.0};         ///< the held object's planning margin from this event on
  /// The object the robot was stopped before, moved by the stop's evidence (correctByContact),
  /// and by how much (m; > 0 towards the robot, < 0 away: ContactCorrection::shift_m); empty / 0
  /// when the estimate already agreed with the stop.
  std::string corrected_object;
  double corrected_m{0.0};
  int planner_calls{0};
  int motion_calls{0};
  double planning_s{0.0};
  double latency_s{-1.0};             ///< from the event to the next command (-1: none followed)
  LatencyBreakdown breakdown;         ///< where `latency_s` went (when a command followed)
};

/// What the planner is told before it observes anything (a scenario's planner view).
struct Belief {
  /// The object in the gripper at the start; unset: what the robot reports. Only "" (empty)
  /// changes the start: the plan assumes the hand empty, and a robot that reports an object in
  /// it takes the conditional branch. A believed object the robot does not report is not held.
  std::optional<std::string> held_object_id;
  /// The objects the scenario told of; unset: those of the world at the mission's start. The
  /// report's `perceived` lists the world model's other objects at the end.
  std::optional<std::set<std::string>> told_objects;
};

/// A contingency known in advance (the paper's "Conditional Planning"): at node `at`, the
/// observation selects the branch from `branch` on instead of the node's own edges. The branch
/// is built before execution starts, over a placeholder item that stands for the object not
/// known yet; the observation binds it, without a planner call.
struct Contingency {
  NodeId at{-1};
  std::string observation;  ///< "gripper not empty"
  std::string placeholder;  ///< the PDDL item standing for the unknown held object
  NodeId branch{-1};        ///< the state of `at` with the placeholder held
  struct Plan {
    std::vector<std::string> actions;
    std::vector<std::vector<std::string>> states;
  };
  std::vector<Plan> plans;  ///< put the object down and re-join the plan ahead; the plan from there on
};

/// A conditional branch taken at run time.
struct ConditionalRecord {
  std::string at_node;      ///< the node the observation was made at
  std::string observation;  ///< what was observed, against what the node believed
  std::string branch_node;  ///< the node it switched to
  bool prebuilt{true};      ///< false: no branch was prebuilt for it (online replanning instead)
  int planner_calls{-1};    ///< from the observation to the next command (-1: none followed)
  int motion_calls{-1};
  double latency_s{-1.0};
};

/// Where a mission taken up by a restarted graph manager stood (from its journal, journal.h).
struct ResumePoint {
  int resumptions{1};                   ///< this is the n-th time the mission is taken up
  std::vector<ExecutedAction> actions;  ///< executed before, with their outcomes
  std::string in_flight;                ///< sent before the restart, no outcome known: awaited
  std::string in_flight_action;
  double in_flight_budget_s{0.0};
};

struct MissionReport {
  MissionOutcome status{MissionOutcome::kFailed};
  std::string reason;
  int resumptions{0};  ///< times a restarted graph manager took the mission up (ResumePoint)
  double executed_effort_s{0.0};
  double predicted_effort_s{0.0};
  double planning_time_s{0.0};
  double planning_time_to_first_action_s{0.0};
  /// The service calls from the mission's start to its first command (where that time went).
  std::vector<TimedCall> first_action_calls;
  int replans{0};
  std::vector<ReplanRecord> replanning;
  std::vector<ConditionalRecord> conditionals;
  Counters counters;
  std::vector<std::string> objects_moved;
  std::vector<Decision> decisions;
  std::vector<ExecutedAction> actions;
  std::vector<std::pair<std::string, Eigen::Isometry3d>> moved_from;  ///< object, pose before
  std::vector<std::pair<std::string, Eigen::Isometry3d>> moved_to;
  /// The objects of the world model at the mission's end that the scenario's view did not have:
  /// what perception found (a crate that blocked a drive, an object that appeared), as it
  /// estimated them, so that a user sees what the decisions were about (tamp run's world.png).
  std::vector<world::Object> perceived;
  std::string graph_dot;
};

/// Progress callbacks for a live display (all optional).
struct MissionObserver {
  std::function<void(const std::string& state, const std::string& message)> on_state;
  std::function<void(const ExecutedAction&, double done_effort_s, double total_effort_s)> on_action;
  std::function<void(const ReachabilityGraph&, const std::vector<EdgeId>& best, NodeId current)> on_graph;
  std::function<bool()> abort_requested;
};

/// Reads the live robot and world.
class WorldSource {
 public:
  virtual ~WorldSource() = default;
  virtual world::World world() = 0;
  virtual Observation robot() = 0;
  /// A world model version that the next world() holds at least (0: unknown). The services are
  /// asked in it, so a planner whose mirror lags behind waits for the world the graph planned in.
  virtual std::uint64_t version() { return 0; }
};

class GraphManager {
 public:
  /// @throws std::invalid_argument when `params` is invalid.
  GraphManager(Abstraction abstraction, std::string domain_pddl, MissionGoal goal, ServiceClients& services,
               GraphManagerParams params);

  /// Builds the root node from the live state and the first plan. Errors: kInvalidArgument (goal
  /// names unknown symbols), kNotFound (the planner proves the goal unreachable: the message says
  /// so), kTimeout, kUnavailable.
  /// An arm out of its driving configuration (stowed_tolerance_rad) gets a configuration symbol
  /// of its own (Abstraction::addObservedArmconf), which a plan can only leave.
  Status start(const world::World& live, const Observation& robot);
  /// Algorithm 3 from `from` with the robot in `context`.
  TraverseResult traverse(NodeId from, const BranchContext& context);
  /// Algorithm 3 until the branch's first edge is decided (first_edge.cc): below the first edge
  /// of the first complete branch nothing more is explored, every other way on from `from` is,
  /// against that branch's cost. When the best branch goes through that edge, `proven_edges`
  /// says so and `traverse(end of those edges)` chooses the rest as `traverse(from)` would;
  /// otherwise this is `traverse(from)`. The first edge is an arm motion with the manipulation
  /// it prepares, or one edge (firstEdgeOf).
  TraverseResult traverseFirstEdge(NodeId from, const BranchContext& context);
  /// The edges decided together at the start of `branch`: an arm motion into a manipulation
  /// with that manipulation, else the first edge (empty for an empty branch).
  std::vector<EdgeId> firstEdgeOf(const std::vector<EdgeId>& branch) const;
  /// `advance` along `edges` (each arm motion with the edge after it) from `ctx`.
  BranchContext advanceAlong(const std::vector<EdgeId>& edges, const BranchContext& ctx) const;
  /// What a motion planned in `ctx` depends on: the base and arm, the held object, the grasp or
  /// placement prepared, the branch's moved objects and every object of the world as last taken
  /// in (first_edge.cc).
  std::string contextKey(const BranchContext& ctx) const;
  /// Whether edge `id` (an arm motion into the manipulation `next`, or a pick or place) was
  /// planned in `ctx` (contextKey), feasible, with its grasp or placement prepared: then it need
  /// not be planned again before it is sent. Base motions: false (commandFor checks their start).
  bool plannedIn(EdgeId id, EdgeId next, const BranchContext& ctx) const;
  /// What the planner is told before it observes (default: what the robot reports at the start).
  void setBelief(Belief b) { belief_ = std::move(b); }
  /// The whole mission: start, traverse, execute, repair.
  MissionReport runMission(WorldSource& source, Executor& executor, const MissionObserver& observer = {});
  /// The mission taken up again after a restart: the command in flight is awaited (never sent
  /// again), the graph is built from the live state, commands are numbered apart from the
  /// earlier runs' ("r<n>-m<step>-..."), and the report goes on from the actions before.
  MissionReport resumeMission(const ResumePoint& resume, WorldSource& source, Executor& executor,
                              const MissionObserver& observer = {});

  const ReachabilityGraph& graph() const { return graph_; }
  const Abstraction& abstraction() const { return abstraction_; }
  const Counters& counters() const { return counters_; }
  /// Every service call of this graph manager, timed (the replanning latency's breakdown).
  const LoggedServiceClients& callLog() const { return logged_; }
  NodeId root() const { return root_; }
  bool isGoal(NodeId n) const;
  const std::vector<Decision>& decisions() const { return decisions_; }

  // ---- pieces (public for tests) ----
  /// TP from the node's state to `goal` literals; adds the plan to the graph. Returns its edges.
  Result<std::vector<EdgeId>> planFrom(NodeId from, const std::vector<std::string>& goal, const std::string& origin);
  /// Evaluates edge `e` in `ctx` (and `next` for arm motions into a manipulation). Returns the
  /// edge's effort, or infinity when it cannot be executed as is.
  double evaluate(EdgeId e, EdgeId next, const BranchContext& ctx, int depth);
  /// The context after executing `e` (with `next`) from `ctx`.
  BranchContext advance(EdgeId e, EdgeId next, const BranchContext& ctx) const;
  /// The command that executes edge `e` from context `ctx`.
  Result<EdgeCommand> command(EdgeId e, EdgeId next, const BranchContext& ctx, const std::string& command_id);
  BranchContext contextOf(const Observation& robot) const;

  // ---- conditional planning (conditional.cc) ----
  /// Prebuilds the "gripper not empty" branches along `plan` (from the start node): at its start
  /// and before each pick, where the hand is believed empty, at most `max_contingencies`. Each
  /// puts the unknown object down and re-joins the plan ahead. Returns how many were built.
  int buildContingencies(const std::vector<EdgeId>& plan);
  const std::vector<Contingency>& contingencies() const { return contingencies_; }
  /// The prebuilt branch at `at` bound to the observed `object`: its node, or none when no branch
  /// was prebuilt there. No planner call.
  std::optional<NodeId> takeContingency(NodeId at, const std::string& object);

  // ---- online replanning (replan.cc) ----
  /// Sub-tasks from `current` that re-join the nodes the branch `ahead` (its remaining edges)
  /// passes through, the first `max_rejoin_targets` reachable ones: TP(current, state of the
  /// node). Atoms of `current` about `new_objects` (unknown to the nodes ahead) are carried
  /// along: the branch from the re-joined node on is copied into states that include them.
  /// Returns the re-joined nodes (empty: no re-join exists).
  std::vector<NodeId> rejoin(NodeId current, const std::vector<EdgeId>& ahead,
                             const std::vector<std::string>& new_objects, const std::string& origin);
  /// Forgets the motions of unexecuted edges that pass near `objects` (their footprints grown
  /// by the robot's radius): they are planned again in the world as it is now. Returns how many.
  int invalidateNear(const std::vector<world::Object>& objects);
  /// Raises the held object's planning margin by a step (up to its maximum) after the robot was
  /// stopped before `blocker` (known where it is) while holding `held`, and forgets the motions planned
  /// with an object in the hand. False when the margin was already at its maximum.
  bool widenHeldMargin(const std::string& held, const std::string& blocker);
  /// After the robot, holding nothing that touched, was stopped before movable `object` at
  /// `stop`: the object is moved in `live` (and kept there for the mission's questions, see
  /// `corrections_`) to touch the robot's body, when `live` has it farther off (contact.h; call
  /// after applyContactCorrections, so that a second stop corrects the first correction).
  /// `perceived`: the world model as it came. The correction, or none.
  std::optional<ContactCorrection> correctByContact(const world::World& perceived, world::World& live,
                                                    const std::string& object, const robot::RobotState& stop);
  /// The contact corrections still standing applied to `live`; those whose object the world
  /// model (`perceived`) has seen move since, or lost, are dropped.
  void applyContactCorrections(const world::World& perceived, world::World& live);
  /// The object held in node `n`'s state, or "".
  std::string heldAt(NodeId n) const;
  /// Prices every evaluated, unexecuted motion again (the effort models may have been refitted).
  void reprice();
  /// The key of an arm edge's motion: the manipulation `next` it prepares, or -1 (stow, none).
  EdgeId armKey(EdgeId arm, EdgeId next) const;

  // ---- abstraction refinement (refine.cc) ----
  /// `(reaches l over_r)` says that the arm reaches some of region r from l, not every object on
  /// it: on a large region (a hall floor) a plan may pick an object from a base pose too far from
  /// it. When the grasp service refutes such a pick, the object gets a slot of its own at its pose
  /// (reached only where inverse kinematics says so): a lazy refinement of the abstraction, made
  /// only where the geometry disagrees with it. True when a slot was added.
  bool refineSupport(const std::string& object, const std::string& region, const BranchContext& ctx);
  /// The node of `n`'s state with the refined objects on their slots (`n` itself when none
  /// applies). Planning from it sees the object-level reach facts.
  NodeId refinedNode(NodeId n);
  /// Whether a refinement happened since the last call (and clears it).
  bool takeRefinement();
  /// A base pose beside `o` from which the arm grasps it, in the branch's world (the objects it
  /// moved where it put them); none when no base pose reaches it. Tried in order
  /// (standCandidates): poses of `approach` (the base poses of the branch's way in, `entry` the
  /// first that touches `o`) back from `entry`; poses facing `o` from the side of `entry` (the
  /// branch's base when `entry` is on the object); then the grasp service's own samples, the one
  /// nearest to `entry`.
  std::optional<GraspOption> standBeside(const world::Object& o, const Pose2D& entry, const BranchContext& ctx,
                                         const std::vector<Pose2D>& approach = {});
  /// The base poses standBeside asks the grasp service about, nearest to `o` first; at most
  /// kStandSteps of each kind, kStandStep_m apart. A pose keeps the base clear of `o` by
  /// `keep_clear_margin_m` (its radius on the way in, whatever its heading; its front when facing
  /// `o`) and `o` within the arm's reach sphere: they follow the robot's description, not a
  /// robot's numbers.
  std::vector<Pose2D> standCandidates(const world::Object& o, const Pose2D& entry, const std::vector<Pose2D>& approach,
                                      const BranchContext& ctx) const;
  static constexpr std::size_t kStandSteps = 3;
  static constexpr double kStandStep_m = 0.10;

 private:
  struct Search;
  struct Run;
  /// Branch-and-bound from `from`; `first_edge_only`: traverseFirstEdge's search.
  TraverseResult search(NodeId from, const BranchContext& context, bool first_edge_only);
  /// The held object's mass in the node's state (0 when the hand is empty).
  double heldMassAt(NodeId n) const;
  /// Whether the arm is in a driving configuration (`stow` or `carry`, within
  /// stowed_tolerance_rad): what the symbol `stow` stands for.
  bool armStowed(const std::vector<double>& arm) const;
  /// What an edge without a motion costs at least (bound.cc): a base motion, the drive bound of
  /// its locations' distance; anything else 0.
  double lowerBound(const Edge& e) const;
  /// Asks the effort estimator for the drive times drive_bound_ interpolates; without a usable
  /// answer (or with params_.model_bounds off) the distance bound stays.
  void calibrateBounds();
  /// Before a Traverse: calibrates the bounds again when the estimator's model version changed
  /// since the last calibration (a faster robot lowers them; stale bounds would not be admissible).
  void boundsForCurrentModels();
  /// What the rest of any branch from node `v` costs at least: the drive from v's location to the
  /// goal's (0 when the goal names none, or params_.goal_bound is off).
  double toGoalBound(NodeId v);
  /// Removal sub-tasks for the objects `e`'s lazy path crosses; returns how many of them it
  /// found the robot cannot move at all (added to fixed_objects_).
  int spawnSubtasks(EdgeId e, const BranchContext& ctx, int depth);
  /// `e` priced again (its lazy path now goes round fixed_objects_ where it can); the sub-tasks
  /// spawned for its earlier path stay alternatives.
  double evaluateBaseAgain(EdgeId e, const BranchContext& ctx, int depth);
  /// Policy infeasible: whether the full-mode variant of the direct edge `e` was proven to have
  /// no path (only then may objects be moved).
  bool aroundProvenImpossible(const Edge& e) const;
  /// The support (region or slot) of `object` in node `v`'s state (its world region if none).
  std::string supportAt(NodeId v, const std::string& object) const;
  /// findPossibleActions by pick and place: a base pose beside `o` from which the arm grasps it,
  /// and findEffectStates, placements that clear `swept` by `radius`; their slots (empty, and
  /// `why`, when the robot cannot grasp `o` or nothing fits). `support`: what `o` stands on in the
  /// branch's state (the region or slot the base pose is then known to reach).
  std::vector<std::string> placeSlots(const world::Object& o, const std::string& support, const Crossing& crossing,
                                      const BranchContext& ctx,
                                      const std::vector<Pose2D>& swept, double radius, std::string& why);
  /// One sub-task from `v`: TP(v, `moved`), then TP(that, `progress`) (what the blocked action
  /// achieved; skipped when empty), then TP(that, goal), each merged into the graph.
  /// Returns the sub-task's first edge from `v` (-1 when the planner found none).
  EdgeId addSubtask(NodeId v, const std::vector<std::string>& moved, const std::vector<std::string>& progress,
                    const std::string& origin);
  /// One object's removal sub-tasks spawned from a node in one branch world (objectsKey): the edge
  /// its lazy path blocked, and the sub-tasks' first edges from the node.
  struct Removal {
    NodeId from{-1};
    std::string world;
    std::string object;
    EdgeId blocked{-1};
    int depth{0};
    std::vector<EdgeId> firsts;
  };
  /// Traverse calls it when every way on from `v` was tried and none reached the goal.
  /// Every removal whose sub-tasks all failed at their first edge from `v` (`dead`: tried, and no
  /// branch through it reached the goal or was cut on its bound), in ctx's world: its object is
  /// fixed in that world (a push whose stand lies behind other objects, a placement out of reach),
  /// and the edges it blocked are planned again round it (evaluateBaseAgain); the failed removals
  /// stay alternatives. Whether any edge was planned again. namo_moghaddam_07's world failed with
  /// "no branch" so: its lazy path crossed two boxes whose push stands no drive reached, and
  /// nothing made the next lazy path go round them.
  bool fixUnremovable(NodeId v, const BranchContext& ctx, const std::function<bool(EdgeId)>& dead);
  std::vector<Removal> removals_;
  // ---- policy oracle (oracle.cc) ----
  /// Blocking objects of one edge given removal sub-tasks under the current policy.
  int blockingObjectsConsidered() const;
  /// Policy oracle: sub-tasks that remove every subset of 2 to `oracle_max_objects` of the
  /// objects in `slots` (object, its first slot) together, from `v`, then achieve what the
  /// blocked edge `v -> child` achieved, then the goal. Single objects are spawnSubtasks' own.
  void spawnSubsetSubtasks(NodeId v, NodeId child, const std::vector<std::pair<std::string, std::string>>& slots);
  /// Policy oracle: asks the simulator's truth again (before each Traverse: the fault schedule
  /// is counted in the simulator's accepted commands). Keeps the last answer on failure.
  void refreshOracle();
  /// Policy oracle: what the scripted failures cost `steps` (0 for the other policies).
  double oraclePenalty(const std::vector<BranchStep>& steps) const;
  /// Policy oracle: the hidden objects in the graph's world as the oracle told them (perception
  /// has not found them, so the services' world model lacks them): every motion, grasp and
  /// placement question carries them (`MotionQuery::added`). Empty for the other policies.
  std::vector<world::Object> unseenObjects() const;
  std::optional<OracleKnowledge> oracle_;
  double evaluateBase(Edge& e, const BranchContext& ctx, int depth);
  // ---- pushes (push.cc) ----
  /// Whether the domain has the `push` action and its `push-to` facts.
  bool domainPushes() const;
  /// Why `o` cannot be pushed ("" when it can): the domain, the robot's push limit, the floor.
  std::string whyNotPushable(const world::Object& o) const;
  /// The full-mode base motion of a push: from `from` to `to`, `object` (at `object_pose`)
  /// carried ahead of the base, in the branch's world.
  MotionQuery pushQuery(const std::string& object, const Eigen::Isometry3d& object_pose, const Pose2D& from,
                        const Pose2D& to, const BranchContext& ctx) const;
  /// Whether the answer is a straight drive from `from` to `to` (what a push can execute).
  static bool straightPush(const MotionAnswer& a, const Pose2D& from, const Pose2D& to);
  /// A push's base motion: straight from `from` to `apex` with the object (at `pose`) carried
  /// ahead, then straight back to `to`, the object left at `target`; none (and `why`) when
  /// either part is not a collision-free straight drive in the branch's world.
  /// How far the base backs off after a push: `push_backoff_m` beyond the distance a turn in
  /// place sweeps past its front (its circumradius minus its front's reach), so that the base can
  /// turn away from the object it pushed with that much to spare (perception's estimate of a pushed
  /// object lags; with a fixed 0.15 m the next turn swept into it, and the monitor stopped it).
  double pushBackoff() const;
  /// Where a push that is not free was blocked: where the base stands to push (so at every
  /// distance along its direction), or further on (a shorter push may be free).
  enum class PushBlock { kNone, kAtStart, kFurtherOn };
  /// Memoised per world (push_cache_): spawnPushes checks a push that evaluatePush prices later.
  std::optional<MotionAnswer> pushMotion(const std::string& object, const Eigen::Isometry3d& pose,
                                         const Eigen::Isometry3d& target, const Pose2D& from, const Pose2D& apex,
                                         const Pose2D& to, const BranchContext& ctx, std::string& why,
                                         PushBlock* block = nullptr);
  /// pushMotion's two motion calls, uncached.
  std::optional<MotionAnswer> planPushMotion(const std::string& object, const Eigen::Isometry3d& pose,
                                             const Eigen::Isometry3d& target, const Pose2D& from, const Pose2D& apex,
                                             const Pose2D& to, const BranchContext& ctx, std::string& why,
                                             PushBlock& block);
  /// Where a push of an object (at `pose`) along `n` by a distance starts, peaks and ends, and
  /// where it leaves the object.
  struct PushGeometry {
    Pose2D from, apex, to;
    Eigen::Isometry3d target{Eigen::Isometry3d::Identity()};
  };
  PushGeometry pushGeometry(const world::Object& o, const Eigen::Isometry3d& pose, const Eigen::Vector2d& n,
                            double distance) const;
  /// The push's slot and locations, added to the abstraction when its motion is free in the
  /// branch's world; none otherwise (and, in `block`, where it was blocked).
  std::optional<std::string> addPushIfFree(const world::Object& o, const std::string& support,
                                           const Eigen::Isometry3d& pose, const Eigen::Vector2d& n, double distance,
                                           const BranchContext& ctx, PushBlock* block = nullptr);
  /// The pushes of `o` along `n` (multiples of push_step_m up to `max_distance`) after which a
  /// lazy path pricing crossings dearly, from the pushed base to `way_end`, goes round `o` and
  /// crosses no movable outside `crossed` (the blocked way's): pushes that do not take the object
  /// off the way but open a way round it. Shortest first, but one push step further first when
  /// that opens too (room to spare); empty when no distance opens a way.
  std::vector<double> openingPushDistances(const world::Object& o, const Eigen::Isometry3d& pose,
                                           const Eigen::Vector2d& n, double max_distance, const Pose2D& way_end,
                                           const std::vector<std::string>& crossed, const BranchContext& ctx);
  /// The first of openingPushDistances whose push is free, added as addPushIfFree does; `tried`
  /// counts the pushes checked.
  std::optional<std::string> addOpeningPush(const world::Object& o, const std::string& support,
                                            const Eigen::Isometry3d& pose, const Eigen::Vector2d& n,
                                            double max_distance, const Pose2D& way_end,
                                            const std::vector<std::string>& crossed, const BranchContext& ctx,
                                            int& tried);
  /// findPossibleActions for an object the robot cannot grasp: pushes of `o` (on `support`)
  /// that clear `swept` by `keep_clear`, each checked collision-free; then, while fewer than
  /// pushes_per_object are free, pushes that open a way round `o` (openingPushDistances): forwards
  /// along the way, and shorter ones in the directions whose clearing push runs into something
  /// beyond the way. Their slots (empty, and `why`, when none).
  std::vector<std::string> spawnPushes(const world::Object& o, const std::string& support, const BranchContext& ctx,
                                       const std::vector<Pose2D>& swept, const std::vector<std::string>& crossed,
                                       double keep_clear, std::string& why);
  double evaluatePush(Edge& e, const BranchContext& ctx);
  MotionAnswer planBase(const MotionQuery& q);
  MotionAnswer lazyOrFull(const MotionQuery& q);
  double evaluateArm(Edge& e, EdgeId next, const BranchContext& ctx);
  double evaluateManipulation(Edge& e, const BranchContext& ctx);
  double priceDeferredPick(Edge& e, const world::Object& o, const BranchContext& ctx);
  std::optional<EdgeMotion> armTarget(const Edge& arm_edge, EdgeId next, const BranchContext& ctx,
                                      std::vector<double>& target, std::string& why, int alternative = 0);
  std::pair<double, double> price(const EffortQuery& q);
  /// Effort of a base or arm path in the branch's context (the held object's mass).
  std::pair<double, double> pricePath(ActionKind kind, const JointPath& path, const BranchContext& ctx);
  /// A collision-free arm motion from the context's state to `target` in the branch's world.
  MotionAnswer armMotion(const BranchContext& ctx, const std::vector<double>& target);
  /// A place of the held `object` on `region` (a slot's pose, else a sampled placement the arm
  /// reaches from the context's base): pre-place and place configurations, the object pose.
  std::optional<std::pair<GraspOption, Eigen::Isometry3d>> preparePlace(const std::string& object,
                                                                       const std::string& region,
                                                                       const BranchContext& ctx, std::string& why,
                                                                       int skip = 0);
  /// preparePlace on a region: the `skip`-th placement the motion planner found reachable,
  /// with collision-free configurations, from the context's base in the branch's world.
  std::optional<std::pair<GraspOption, Eigen::Isometry3d>> sampledPlace(const std::string& object,
                                                                       const std::string& region,
                                                                       const BranchContext& ctx, std::string& why,
                                                                       int skip);
  /// True when `object` at `pose` would stand in front of another movable object on `region` as seen from
  /// the context's base (world::occludes), the others where the branch has them.
  bool occludesFromBase(const std::string& object, const std::string& region, const Eigen::Isometry3d& pose,
                        const BranchContext& ctx) const;
  /// The branch's moved objects as overrides of the live world (`except` left out).
  static std::vector<ObjectOverride> overridesOf(const BranchContext& ctx, const std::string& except = {});
  /// A cache key for queries in the branch's world from its base pose.
  static std::string worldKey(const BranchContext& ctx);
  /// The branch's object poses and held object, without the base pose (for queries whose start
  /// is given, not the branch's base).
  static std::string objectsKey(const BranchContext& ctx);
  /// Forgets what was computed in the world before it changed (grasps, placements, pushes, the
  /// memo of motion and grasp answers).
  void clearWorldCaches();
  /// The motion and grasp services, through `memo_` (ask.cc): counted in `counters_` when asked.
  MotionAnswer askMotion(const MotionQuery& q);
  /// `q` with the mission's margin around a held object (not one pushed by the base), and the
  /// contact corrections of objects the query does not place itself.
  MotionQuery withHeldMargin(MotionQuery q) const;
  /// The contact corrections (`corrections_`) as overrides, added to `overrides` for the objects
  /// they do not already name, except `skip` (ignored or held by the query).
  void addCorrections(std::vector<ObjectOverride>& overrides, const std::vector<std::string>& skip = {}) const;
  /// Independent motion queries at once (ServiceClients::motions), those not in the memo.
  std::vector<MotionAnswer> askMotions(const std::vector<MotionQuery>& qs);
  /// Grasps and placements asked in the world model version the graph plans in (as motions).
  Result<std::vector<GraspOption>> askGrasps(GraspQuery q);
  Result<std::vector<PlacementOption>> askPlacements(PlacementQuery q);
  MotionQuery baseQuery(const Edge& e, const BranchContext& ctx) const;
  std::vector<std::string> withStatics(const std::vector<std::string>& dynamic) const;
  void recordDecisions(NodeId from, const std::map<EdgeId, double>& best_through, const std::vector<EdgeId>& branch,
                       double best_cost, int traverse_index, const std::map<EdgeId, double>& cut_bounds);

  Abstraction abstraction_;
  std::string domain_;
  bool domain_pushes_{false};  ///< the domain has `push` and `push-to` (pushesIn, at construction)
  MissionGoal goal_;
  LoggedServiceClients logged_;  ///< wraps the services given; declared before `services_`
  ServiceClients& services_;
  GraphManagerParams params_;
  ReachabilityGraph graph_;
  NodeId root_{-1};
  Counters counters_;
  std::vector<Decision> decisions_;
  int traverse_count_{0};
  /// Set by a running mission (its observer's abort_requested): a Traverse stops at its next
  /// step when it answers true, as when its budget runs out.
  std::function<bool()> interrupted_;
  double planning_s_{0.0};
  DriveBound drive_bound_;  ///< what a base motion costs at least (calibrateBounds)
  std::map<NodeId, double> to_goal_bound_;  ///< toGoalBound's answers for the current calibration
  bool bounds_calibrated_{false};
  std::optional<std::uint64_t> bound_version_;  ///< the model version drive_bound_ was asked under
  /// The margin a held object is planned with (params_.held_padding_step_m per static contact
  /// the robot was stopped before while holding; see Run::replan).
  double held_padding_m_{0.0};
  /// Objects the robot was stopped before where the world model did not have them
  /// (correctByContact): where the stop puts them, and where the world model had them then. The
  /// motion planner and the grasp and placement services plan with the world model, so every
  /// question carries these as overrides; the world model seeing the object elsewhere (by more
  /// than `kCorrectionHoldM`) ends one.
  struct ContactCorrected {
    Eigen::Isometry3d pose;
    Eigen::Isometry3d seen;
  };
  std::map<std::string, ContactCorrected> corrections_;
  /// The newest world model version the mission took from its WorldSource (0: unknown): motion
  /// questions and commands carry it, so no service answers from an older world than the graph's.
  std::uint64_t world_version_{0};
  QueryMemo memo_;
  std::map<std::string, std::vector<GraspOption>> grasp_cache_;
  /// Placements of a held object from a base pose in a world (sampledPlace): asked for a few
  /// at first, more only when every one kept was tried (each sample costs IK solves).
  struct PlacementCacheEntry {
    std::vector<PlacementOption> kept;  ///< the motion planner's answer minus those that occlude
    std::uint32_t asked{0};             ///< max_placements of the last request
    bool exhausted{false};              ///< the last request returned fewer than asked: no more
    std::string why;                    ///< the last request's error, if any
  };
  std::map<std::string, PlacementCacheEntry> placement_cache_;
  /// pushMotion's answers (or why not) per push and branch world.
  struct PushCacheEntry {
    std::optional<MotionAnswer> answer;
    std::string why;
    PushBlock block{PushBlock::kNone};
  };
  std::map<std::string, PushCacheEntry> push_cache_;
  /// Movables the robot can neither carry nor push in this world (found by spawnSubtasks): base
  /// lazy paths go round them where a way exists (MotionQuery::fixed). Cleared with the world.
  /// In every branch when it follows from the object itself (no grasp or above the payload, and
  /// above the push limit); otherwise (no placement or push free where the objects stand) only
  /// in branches whose objects stand as where it was found (`fixed_in_world_`, by objectsKey):
  /// a push blocked by a neighbour may be free once the neighbour is moved. namo_moghaddam_07
  /// failed so: a box whose push another box blocked at the start was fixed in every branch,
  /// also in the one that had pushed the other box away, the only way to the goal.
  std::set<std::string> fixed_objects_;
  std::map<std::string, std::set<std::string>> fixed_in_world_;
  /// The movables fixed in the branch world of `ctx` (both kinds, sorted).
  std::vector<std::string> fixedIn(const BranchContext& ctx) const;
  /// Movables a removal (a placement or a push) was found for in this world: never fixed, though
  /// the way another path crosses them may have none.
  std::set<std::string> removable_objects_;
  /// Failed executions in this mission: per move edge, and per manipulation of an object ("pick
  /// box"), whichever edge carried it (a grasp that misses from one stand misses from the next).
  int failuresOf(const Edge& e) const;
  void noteFailure(Edge& e);
  std::map<std::string, int> manipulation_failures_;
  bool refined_{false};  ///< refineSupport added a slot since takeRefinement()
  Belief belief_;
  std::vector<Contingency> contingencies_;
  /// Copies the edges `ahead[first..]`, which leave `target`, into states that also hold
  /// `carried` (the frame assumption); returns the copy of `target`. `record` gets the copy.
  NodeId carryAhead(NodeId target, const std::vector<EdgeId>& ahead, std::size_t first,
                    const std::vector<std::string>& carried, const std::string& origin,
                    Contingency::Plan* record = nullptr);
};

}  // namespace tamp::graph_manager
