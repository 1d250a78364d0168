#pragma once
/// @file
/// Parameters of the graph manager (validated; `config/services/graph_manager.yaml`).

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "tamp/core/error.h"

namespace tamp::graph_manager {

/// When moving an object is considered (the paper's claim is measured by comparing the two).
enum class Policy {
  kEffort,      ///< revise whenever a cheaper branch exists: removal and detour are both priced
  kInfeasible,  ///< consider moving an object only when full mode proves there is no way around
  /// The lower bound (evaluation only): efforts are the simulator's true nominal durations, the
  /// hidden objects are known at planning time, scripted action failures are priced as the
  /// retry they cost, and remove-or-avoid is evaluated exhaustively: every subset of up to
  /// `oracle_max_objects` blocking objects removed, the rest gone round, no branch-and-bound cut.
  kOracle,
};
std::string_view toString(Policy p);  ///< "effort", "infeasible", "oracle"
std::optional<Policy> policyFromString(std::string_view s);

struct GraphManagerParams {
  Policy policy{Policy::kEffort};
  std::uint32_t seed{1};
  int max_evaluations{120};        ///< edge evaluations per Traverse (the paper's MaxAttempts); >= 1
  double traverse_budget_s{30.0};  ///< deadline of one Traverse; > 0
  int max_replans{4};              ///< failed executions tolerated before the mission fails; >= 0
  int max_subtask_depth{1};        ///< nested sub-tasks (a removal inside a removal branch); >= 0
  int max_blocking_objects{2};     ///< blocking objects of one edge given sub-tasks; >= 1
  /// Policy `oracle`: the largest set of an edge's blocking objects removed together in one
  /// sub-task (every subset up to this size is planned and priced; the objects not in a subset
  /// are gone round); also the blocking objects per edge considered. 2^n - 1 sub-tasks for n
  /// objects, so keep it small; >= 1, <= 4.
  int oracle_max_objects{3};
  int placements_per_object{2};    ///< findEffectStates: sampled placements kept per object; >= 1
  /// Pushes (an object too heavy or too wide to grasp, within the robot's push limit, when the
  /// domain has a `push` action): straight pushes along the object's footprint axes, by the
  /// shortest multiple of `push_step_m` up to `push_max_m` that clears the blocked path, from a
  /// base pose `push_gap_m` short of contact; at most `pushes_per_object` kept per object.
  double push_step_m{0.25};        ///< > 0
  double push_max_m{3.0};          ///< >= push_step_m
  double push_gap_m{0.03};         ///< >= 0
  /// After a push the base backs off straight, leaving the object: as far as a turn in place
  /// sweeps past its front (from the robot's footprint) plus this margin; >= 0 and below
  /// push_step_m + push_gap_m.
  double push_backoff_m{0.15};
  int pushes_per_object{2};        ///< >= 0 (0: never push)
  /// Budget of the full-mode motion that checks one push or its back-off; > 0. Only a straight
  /// motion is kept, which the planner finds at once when it is free (the slowest solved in the
  /// Moghaddam worlds took 0.19 s); a push that is not free otherwise costs motion_budget_s.
  double push_budget_s{1.0};
  double keep_clear_margin_m{0.10};  ///< placements keep this much more than the robot's radius off the path
  /// A held object is planned grown by a margin that starts at 0 and rises by this step each
  /// time the robot is stopped before touching an object whose place it knew while holding (where it sits
  /// in the hand is known only as well as the grasp went), up to held_padding_max_m. >= 0
  /// (0: never grown); the maximum is at most 0.25 m.
  double held_padding_step_m{0.03};
  double held_padding_max_m{0.09};
  /// Stopped before a movable object with nothing in the hand that could have touched it: the
  /// object's estimate is moved to touch the robot's body where it stopped (contact.h), when it
  /// stood at most this far off (m, in [0, 0.5]; 0: never). Farther, the stop is no evidence
  /// about that estimate.
  double contact_correction_max_m{0.15};
  /// Before reading where the robot stopped: wait at most this long (s, >= 0) for a robot state
  /// that says it is at rest (the last state sent while it still moved is up to a state period
  /// behind the stop).
  double rest_wait_s{1.0};
  double lower_bound_base_speed{1.5};  ///< m/s, above the robot's top speed (admissible bound); > 0
  /// Bound a base motion by the effort model's time of one straight drive of its length (bound.cc),
  /// not only by the distance at lower_bound_base_speed.
  bool model_bounds{true};
  /// Cut a branch on its cost plus the drive bound from where it stands to the goal's location.
  bool goal_bound{true};
  double approach_m{0.10};         ///< pick/place: gripper approach and retreat along z (m); > 0
  double plan_budget_s{5.0};       ///< per task-planner call; > 0
  double motion_budget_s{8.0};     ///< per motion call; > 0
  double execution_margin_s{30.0}; ///< execution budget = prediction + k sigma + this; > 0
  double start_tolerance{0.02};    ///< re-plan a motion whose start is farther from the robot; > 0
  /// An arm whose joints are all within this of `stow` is stowed; otherwise, at the start of a
  /// mission and after an event, it is out (a configuration symbol of its own or the node's); > 0
  double stowed_tolerance_rad{0.05};
  /// A lazy path crossing movables is replaced by a clear effort-aware one at most this much
  /// longer (the objects are then beside the way, not in it); >= 1.
  double clear_path_stretch{1.25};
  /// Motion queries known together go out together (ServiceClients::motions: the motion node's
  /// planner pool answers them side by side): a lazy base path with its effort-aware alternative
  /// (asked speculatively, used only when the first crosses a movable), a push with its back-off.
  bool concurrent_motions{true};
  /// Answer a motion or grasp question asked again in the same world from memory (QueryMemo).
  /// Off by default: with it on, occluded_can failed 4 of 8 runs on a base path into the counter
  /// (0 of 2 off), not diagnosed (docs/benchmarks.md, sixth session).
  bool memoise_answers{false};
  /// A base path longer than this many times the straight line from a start facing away is
  /// planned again after a turn in place towards the goal; >= 1.
  double turn_first_ratio{1.5};
  /// Online replanning: an action that takes longer than its prediction plus this many standard
  /// deviations is an event (the plan ahead is priced again from the refitted models); > 0.
  double overrun_sigma{3.0};
  /// After an overrun, how long the graph manager waits for the effort estimator to refit from
  /// that action's record (the estimator refits a surprising record at once) before it prices the
  /// plan ahead again; without the wait the prices are asked before the refit. s, >= 0 (0: no
  /// wait).
  double refit_wait_s{1.0};
  /// Online replanning: re-join sub-tasks tried towards the next this many nodes of the branch
  /// ahead (the first reachable ones are kept, Traverse chooses among them); >= 1.
  int max_rejoin_targets{2};
  /// Online replanning: the next command goes out once Traverse has proven the branch's first
  /// edge best (traverseFirstEdge), the rest of the branch is priced while the robot executes
  /// it, and an arm motion planned from where the robot is, in the world as it is, is not
  /// planned again before it is sent. false: the whole branch is priced before the command.
  /// (Off from the third to the eleventh session for a stow motion stopped before the box in
  /// namo_corridor_slippery; the cause was arm paths clipping objects between checked states,
  /// fixed by the swept check, docs/benchmarks.md.)
  bool replan_first_edge{true};
  /// The mission's first command too (and every Traverse not after an event) goes out once its
  /// first edge is proven best, the rest priced while the robot executes it, as
  /// `replan_first_edge` does after an event (issue 11: time to the first command; on since
  /// session 33: namo_big_crossing's first command 4.3 s median against 7.3 s, 6 paired seeds,
  /// docs/evaluation.md). false: the whole branch is priced before the first command.
  bool first_edge_at_start{true};
  /// Conditional planning: the nodes of the first plan given a prebuilt "the gripper is not
  /// empty" branch before execution starts (the start and the states before each pick, in plan
  /// order); each costs up to `max_rejoin_targets` planner calls at the start; >= 0 (0: none).
  int max_contingencies{3};
  /// Conditional planning: how long to wait for the world model to know an object the robot
  /// reports in its gripper (perception learns it from the points at the gripper) before
  /// planning how to put it down; s, > 0.
  double held_object_wait_s{5.0};
  /// An action that failed or was blocked this many times in a mission is not tried again: the
  /// edge is infeasible and Traverse looks for another branch (going round, another placement,
  /// another grasp). A repeat of the same failure from the same state teaches nothing; >= 1.
  int max_action_failures{2};
  /// An object of the world model that moved this far from where the graph expects it is an
  /// event (m); > 0. Above perception's error on a partly hidden object: with the arm over a thin
  /// box, the estimate strays about 0.09 m (namo_corridor, measured), and a false event replaces
  /// a good prior with that estimate.
  double moved_object_tolerance_m{0.15};
  /// After a drop, the world is taken in once the world model has the dropped object resting on a
  /// support (its bottom within 5 cm of the support below), or after this long (s); >= 0. The
  /// robot reports the empty hand before perception has seen where the object fell: a re-pick
  /// planned on the estimate of a falling object sends the gripper into it.
  double drop_settle_timeout_s{2.0};
  /// After a drop, the object must rest unchanged in the world model this long (s, >= 0) before
  /// a re-pick is planned from it (DropSettleWatch): the first frames after a drop could move the
  /// fall estimate, or call it gone before perception sees where the object really fell. 0 since
  /// session 26: perception's fall estimate starts where the gripper let go (session 25), and in
  /// 10 transport_drop runs it never moved within the 0.3 s window that was the default, which
  /// was then most of the drop's replanning latency (docs/benchmarks.md).
  double drop_confirm_s{0.0};
  /// A restarted graph manager takes up an unfinished mission of its journal only when the
  /// journal was written at most this long ago (s, > 0): a deployment started again hours later
  /// must not set the robot moving on an old mission. An older one is closed as aborted.
  double resume_max_age_s{120.0};

  /// Empty when valid; else the field and why.
  std::optional<std::string> invalidReason() const;
};

/// Reads `config/services/graph_manager.yaml`; errors name file:line:column and the field.
Result<GraphManagerParams> loadParams(const std::filesystem::path& file);
Result<GraphManagerParams> parseParams(const std::string& yaml_text, const std::string& name);

}  // namespace tamp::graph_manager
