#pragma once
/// @file
/// Forward state-space searches over a grounded `Task`.
///
/// - `kEhc` (the default): FF's enforced hill-climbing: from the current state, a breadth-first
///   search over helpful actions until a state with a strictly better h_FF is found; on failure
///   (dead end or exhausted plateau), or once it has used its evaluation budget
///   (`ehc_fallback_budget_*`, so that a hill-climbing lost on plateaus leaves the time to the
///   complete search), it falls back to a complete best-first search from the start
///   (`ehc_fallback`, `fallback`: LAMA's lazy search by default, FF's own order: hill-climbing
///   first, then best-first). With `ehc_lazy_beside` (the default) that lazy search starts beside
///   a hill-climbing that has used `ehc_lazy_after` evaluations and the two take turns in one
///   thread; the first plan or proof wins, and a failed hill-climbing leaves the lazy search to go
///   on from where it is (`lazy_plan_preferred`: with LAMA-first's preferred operators). A second
///   lazy search, with LAMA-first's preferred operators (and, `lazy_second_hadd`, its h_FF through
///   h_add's best supporters), joins them once the two have used `lazy_second_after` evaluations
///   (`lazy_beside_both`, the default); where h_FF takes FF's layered graph, a third, the second
///   with h_add's supporters (LAMA-first's), joins with it for `lazy_hadd_lane_budget`
///   evaluations. With
///   `ehc_ff_first` (the default) and a heuristic that has
///   FF-v2.3's variant (`Heuristic::setFFStyle`), a first hill-climbing run uses that variant
///   within a budget of evaluations (it tends to give shorter plans); when it fails or runs
///   out of budget, the search starts again from the initial state with the default heuristic,
///   exactly as without the first run. A run other than the first that proves a state it
///   committed to a dead end (`ehc_h2_restart`) starts again once from the initial state,
///   testing the states it commits to with h^2 from them (`ehc_h2_test_gap_max`), which sees
///   dead ends the delete relaxation does not (Haslum & Geffner 2000; an irreversible move, as
///   in airport, where FF's own path avoids one by its tie-breaking); the first run ends there
///   (`ehc_ff_first_h2_restart`).
/// - `kGbfs`: eager greedy best-first search on h_FF with a second open list for successors through
///   helpful (preferred) operators, alternating with a boost on progress (as Fast Downward's
///   `eager_greedy([ff], preferred=[ff])`). Complete: it proves unsolvability by exhaustion.
/// - `kLazy`: LAMA's first iteration (Richter & Westphal 2010; Fast Downward's `lama-first`):
///   lazy greedy best-first search (successors are evaluated when popped, keyed by the parent's
///   value) alternating over four queues, h_FF and the landmark count (landmarks.h), each with all
///   successors and with the preferred ones (helpful actions of h_FF and landmark achievers),
///   the preferred queues boosted by 1000 on every improvement of either heuristic. Complete.
/// - Anytime phase (`anytime_seconds`, cost tasks only): plan neighbourhood graph search on the
///   first plan (`neighbourhood_time_share`), then LAMA 2011's restarting weighted A*
///   iterations, each bounded by the best cost so far.
/// - `kWAstar` / `kAstar`: (weighted) A* with re-opening on f = g + w*h; with the admissible
///   h_max (the default for these) A* returns cost-optimal plans and weighted A* plans within a
///   factor `weight` of optimal.
///
/// States live in a `StateRegistry` (one contiguous pool, open-addressing hash set of ids): no
/// per-node allocation. Every search checks its `Termination` and a memory budget.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tamp/core/termination.h"
#include "tamp/symbolic_planner/heuristic.h"
#include "tamp/symbolic_planner/landmarks.h"
#include "tamp/symbolic_planner/mutexes.h"
#include "tamp/symbolic_planner/task.h"

namespace tamp::symbolic_planner {

/// The landmark generator of the lazy search's landmark count (landmarks.h).
enum class LandmarkGenerator { kZhuGivan, kRhw };

enum class SearchAlgorithm { kEhc, kGbfs, kLazy, kWAstar, kAstar };

/// Parses "ehc", "gbfs", "lazy", "wastar", "astar"; nullopt otherwise.
std::optional<SearchAlgorithm> parseSearchAlgorithm(const std::string& name);
std::string toString(SearchAlgorithm a);

struct SearchOptions {
  SearchAlgorithm algorithm{SearchAlgorithm::kEhc};
  /// Heuristic; nullopt = h_FF for ehc/gbfs, h_max for wastar/astar (admissible).
  std::optional<HeuristicKind> heuristic;
  /// How action costs enter the heuristic; nullopt = unit for ehc/gbfs on unit-cost tasks,
  /// cost+1 for ehc/gbfs on tasks with costs, the real cost for wastar/astar.
  std::optional<CostType> cost_type;
  double weight{5.0};           ///< wastar only; must be >= 1
  bool ehc_fallback{true};      ///< ehc: complete best-first search when hill-climbing fails
  /// ehc: the complete search to fall back to: kLazy (LAMA's lazy GBFS) or kGbfs (eager).
  SearchAlgorithm fallback{SearchAlgorithm::kLazy};
  bool goal_agenda{true};       ///< ehc: FF's goal agenda (achieve ordered goal subsets in turn)
  /// ehc: when the breadth-first search over helpful actions exhausts a plateau, search it again
  /// with all applicable actions before falling back (FF gives up at once).
  bool ehc_full_retry{true};
  /// ehc: that search again may use at most this share of the hill-climbing's fallback budget
  /// (`ehc_fallback_budget_*`) in evaluations; past it, hill-climbing counts as failed and the
  /// complete search starts (a plateau too large without pruning is where hill-climbing
  /// wanders). 0 = unbounded; must be in [0, 1]. Unbounded when the fallback budget is.
  double ehc_retry_budget_share{0.1};
  /// ehc: when a better state is found, evaluate the remaining successors of the same node and
  /// continue from the best (FF continues from the first).
  bool ehc_best_sibling{true};
  /// ehc: first try hill-climbing with the heuristic's FF-v2.3 variant (see above), allowed
  /// `ehc_ff_budget_per_h` evaluations per unit of the initial state's h (0 disables the first run).
  bool ehc_ff_first{true};
  uint64_t ehc_ff_budget_per_h{300};
  /// ehc: that first run continues from the first better state, as FF does, whatever
  /// `ehc_best_sibling` says (which then applies to the default run only): 2-6x fewer
  /// evaluations on many domains, but the first run then fails on maintenance-4, which only the
  /// first run with the best sibling solves (docs/benchmarks.md, issue 14, fifth round): off.
  bool ehc_ff_first_improvement{false};
  /// ehc: give up (kFailed, no fallback) after this many evaluations per unit of the initial
  /// state's h (at least 2 units; with the goal agenda, h of the first entry); 0 = unlimited.
  uint64_t ehc_eval_budget_per_h{0};
  /// ehc: fall back to the complete search (as on a failure) once hill-climbing has used
  /// `ehc_fallback_budget_min + ehc_fallback_budget_per_h * h(init)` evaluations (h of the first
  /// goal-agenda entry), so that a hill-climbing lost on plateaus leaves the time to the complete
  /// search, but never more than `ehc_fallback_budget_max`; 0 = unlimited (FF). The defaults keep
  /// every hill-climbing that succeeds on the IPC sets of docs/benchmarks.md within budget (the
  /// largest need: maintenance-20, 138k evaluations at h 201; tpp-24, 41k at h 8) and stop those
  /// that wander (psr-small; visitall, whose h of 300-2500 made the uncapped budget cost most
  /// of the time limit).
  uint64_t ehc_fallback_budget_per_h{500};
  uint64_t ehc_fallback_budget_min{50000};
  uint64_t ehc_fallback_budget_max{200000};
  /// ehc: evaluations already spent towards that budget (set by `search()` for the default
  /// hill-climbing after a failed first run with the FF-v2.3 variant, so both share one budget).
  uint64_t ehc_fallback_budget_spent{0};
  /// ehc: give up (kFailed, no fallback) after this many evaluations in all; 0 = unlimited.
  uint64_t ehc_eval_budget{0};
  /// ehc with `ehc_ff_first`: when the first run's plan has at least `ehc_second_trigger_ratio`
  /// times as many actions as the initial h (the hill-climbing wandered, typically across goal
  /// agenda entries that undo each other, as in blocksworld), the default EHC also runs, without
  /// fallback and allowed `ehc_second_budget_per_step` evaluations per action of the first plan,
  /// but at most `ehc_second_budget_factor` times the first run's evaluations, and the cheaper of
  /// the two plans is returned (the first on ties). 0 disables the second run.
  uint64_t ehc_second_budget_per_step{300};
  uint64_t ehc_second_budget_factor{16};
  double ehc_second_trigger_ratio{2.0};
  /// ehc with the lazy fallback: once the hill-climbing (all its runs before the first plan) has
  /// used `ehc_lazy_after` evaluations, the fallback's lazy search starts beside it, and the two
  /// take turns of `ehc_lazy_turn_ehc` / `ehc_lazy_turn_lazy` evaluations in the same thread (the
  /// lazy search is a coroutine the hill-climbing resumes), so the same evaluations and plans in
  /// every run. The first plan or proof of either is the answer; when the hill-climbing gives up,
  /// the lazy search goes on alone from where it is. The lazy search has its own states and
  /// heuristic, so the memory budget holds for each of the two. A hill-climbing that needs fewer
  /// evaluations (a TAMP query: about 30) never meets the lazy search. false: the lazy search
  /// only after the hill-climbing has failed (FF's order).
  bool ehc_lazy_beside{true};
  /// ehc: when a hill-climbing run (not the first, see `ehc_ff_first_h2_restart`) proves that a
  /// state it committed to is a dead end (h_FF finds the goal unreachable from it, or its plateau
  /// searched again without pruning holds everything reachable from it), the run starts again
  /// from the initial state, once, and from then on tests the states it commits to with h^2 from
  /// them (mutexes.h; when, `ehc_h2_test_gap_max`): a state
  /// from which h^2 finds a goal fact or pair unreachable is a dead end the delete relaxation
  /// does not see (airport: an aircraft that cannot turn round), skipped as h_FF's dead ends are.
  /// The restarted run shares the run's budgets. false: a proven dead end ends the run (FF).
  bool ehc_h2_restart{true};
  /// ehc: test committed states with h^2 from the start of every hill-climbing run (the
  /// restart's mode; set for the default run by `search()` after a first run that restarted).
  bool ehc_h2_commits{false};
  /// ehc_h2_restart for the first run (FF-v2.3's variant) too; false: its proven dead end ends it
  /// and the default run takes over (on airport-30 the first run's restart found about 80 dead
  /// ends with h^2 and failed all the same).
  bool ehc_ff_first_h2_restart{false};
  /// ehc, while testing with h^2: 0 tests every state before committing to it (the twenty-first
  /// round's test). n > 0: the gap starts at 1 (every state tested before it is taken) and
  /// doubles after each test that finds no dead end, up to n, and falls back to 1 after one; at
  /// a gap above 1 states are taken untested, and the last one is tested once the states taken
  /// since the last one found alive reach the gap, when a plateau is met (helpful actions find
  /// no better state) and before the goal of a goal-agenda entry is taken. h^2 dead ends are monotone along a path (what is reachable from a state is reachable
  /// from its predecessors, so h^2 from it reaches a subset of what it reaches from them): when
  /// the last state is dead, bisection over the untested states finds the first dead one, and
  /// the run goes back to the state before it, with it and the states after it marked dead.
  uint32_t ehc_h2_test_gap_max{16};
  /// The bounds of one h^2 test of a committed state (over them: not a dead end).
  H2MutexOptions ehc_h2_mutexes{20'000, 200'000'000};
  /// The h^2 tests of one hill-climbing run stop (states are committed to untested) once they
  /// have done this many words of work in all (about 3 x 10^8 a second here); 0 = unbounded.
  /// airport-30's restart: 500 tests, 3.1 x 10^9 words, 10 s.
  uint64_t ehc_h2_work_budget{4'000'000'000};
  /// ehc_lazy_beside: its lazy search (beside the hill-climbing, and alone once it gives up) prefers
  /// LAMA-first's operators: the relaxed plan's own applicable first-layer operators
  /// (`Heuristic::setRelaxedPlanPreferred`) and none of the landmark count's, in a heuristic of
  /// its own; the hill-climbing, `kLazy` and the anytime phase keep theirs (FF's helpful actions
  /// and the achievers of the landmarks still needed). Off by default (docs/benchmarks.md, issue
  /// 14, thirtieth round): on it solves hiking-16 / -20, transport-18, trucks-18 and
  /// scanalyzer-30 in 30 s (FF's helpful actions on hiking are hundreds of drives, the relaxed
  /// plan's a few), but loses depots-6 and -20 (0.3 / 0.4 s with the default; out of time at
  /// 60 s; LAMA-first itself needs 41 s on depots-6).
  bool lazy_plan_preferred{false};
  /// ehc_lazy_beside with `lazy_plan_preferred` off: a second lazy search beside the hill-climbing,
  /// with LAMA-first's preferred operators (in a heuristic of its own, counting the landmarks of
  /// the first's graph); once it has joined (`lazy_second_after`), after each turn of the
  /// hill-climbing both lazy searches take one (each a third of the evaluations; a half each once
  /// the hill-climbing gives up), and the first final answer of either is the answer. The two
  /// kinds of preferred operators split the domains (docs/benchmarks.md, issue 14, thirtieth and
  /// thirty-first rounds): the default's keep depots-6 / -20 and citycar-6, LAMA-first's solve
  /// hiking-16 / -20 (FF's helpful actions on hiking are hundreds of drives, the relaxed plan's a
  /// few).
  bool lazy_beside_both{true};
  /// lazy_beside_both: the second lazy search joins once the hill-climbing and the first lazy
  /// search have used this many evaluations since the first started (or once the first ends
  /// without an answer); 0: both start together. A search that ends sooner (airport-30: about
  /// 3 400 after the first started; transport-30: about 44 000 in all) pays nothing or little
  /// for the second; one that needs hundreds of thousands (hiking-16) loses a few
  /// seconds (docs/benchmarks.md, issue 14, thirty-first round: 8 000, 16 000 and 32 000).
  uint64_t lazy_second_after{32'000};
  /// lazy_beside_both: the second lazy search's h_FF takes its relaxed plan through h_add's best
  /// supporters (`HeuristicKind::kFFHadd`, Fast Downward's `ff()`), also where the operators
  /// cost the same and the default h_FF takes FF's layered graph: with it, that search is
  /// LAMA-first's (its preferred operators, no landmark achievers among them, its h_FF). Only
  /// with the default heuristic (h_FF); the hill-climbing and the first lazy search keep theirs.
  /// Off by default (docs/benchmarks.md, issue 14, thirty-second round): on, it solves blocks-80
  /// and pathways-18 and hiking-16 / -20 faster, but loses trucks-18 and airport-40's time, which
  /// the layered graph's second search gives. On tasks whose operators differ in cost (cost + 1)
  /// h_FF is h_add's already: no change there.
  bool lazy_second_hadd{false};
  /// lazy_beside_both with `lazy_second_hadd` off, the default heuristic (h_FF) and operators that
  /// cost the same (where h_FF takes FF's layered graph): a third lazy search joins with the
  /// second, the same but for its h_FF, through h_add's best supporters (LAMA-first's lazy search
  /// but for its turns), and takes its turns until it has used this many evaluations; then it is
  /// dropped and its states freed. The two h_FF split the domains in that search (the
  /// thirty-second round: h_add's solves blocks-80 and pathways-18 within thousands of its
  /// evaluations, the layered graph's trucks-18 after millions), so the third gets a small
  /// budget that costs the second little where it needs millions (docs/benchmarks.md, issue 14,
  /// thirty-third round: blocks-80 needs more than 25 000 and at most 50 000; trucks-18's
  /// second search then runs beside 50 000 more evaluations). 0: no third lazy search.
  uint64_t lazy_hadd_lane_budget{50'000};
  uint64_t ehc_lazy_after{4000};
  uint64_t ehc_lazy_turn_ehc{100};
  uint64_t ehc_lazy_turn_lazy{100};
  bool preferred_operators{true};  ///< gbfs/lazy: use the helpful-action open list(s)
  /// lazy: alternate h_FF with LAMA's landmark-count heuristic (landmarks.h), four queues.
  bool landmarks{true};
  /// lazy: the landmarks it counts: kZhuGivan (fact landmarks, counted with
  /// kAcceptedAfterParents) or kRhw (RHW's, with disjunctive landmarks and greedy-necessary
  /// orders, counted with kPastAndFuture, as LAMA in Fast Downward today).
  LandmarkGenerator landmark_generator{LandmarkGenerator::kRhw};
  RhwLandmarkOptions rhw;  ///< kRhw's options
  /// ehc/gbfs/lazy: drop redundant actions from the plan found (greedy action elimination).
  bool eliminate_redundant_actions{true};
  int preferred_boost{1000};    ///< gbfs/lazy: preferred-queue priority boost on progress
  size_t memory_limit_mb{4096};  ///< search data (states + nodes); 0 = unlimited
  /// ehc/gbfs/lazy on tasks whose operators differ in cost: after the first plan, improve it for
  /// up to this many seconds (and never past the caller's deadline) with LAMA 2011's anytime
  /// iterations: the lazy greedy search with landmarks (`kLazy`), then lazy weighted A*
  /// (w = 5, 3, 2, 1, then 1 again) on g + w * h with the search's
  /// heuristic, re-opening, preferred operators, every path costing at least the best plan so far
  /// pruned. 0 (the default) = return the first plan: a TAMP query keeps its latency; `tamp plan`
  /// sets 5 s.
  double anytime_seconds{0.0};
  /// With the anytime phase on a task whose operators differ in cost (and no explicit
  /// `cost_type`): search for the first plan with unit costs (as LAMA 2011's first iteration;
  /// it is found faster and often cheaper than with cost + 1), within `unit_first_time_share`
  /// of the time left (when there is a deadline) and the memory budget. When that run runs out
  /// of its share of the time, out of memory, or gives up (ehc without fallback), the
  /// first plan is searched for again from the start with `cost_type`'s default (cost + 1) and
  /// the time left; the anytime iterations always use cost + 1. false: cost + 1 at once.
  bool unit_cost_first{true};
  double unit_first_time_share{0.1};  ///< must be in (0, 1]
  /// unit_cost_first with a deadline: when the unit-cost run has not answered within its
  /// `unit_first_time_share`, it is not dropped: the cost + 1 run starts from the start beside
  /// it, and the two take turns of `unit_beside_turn` evaluations each (the unit-cost run on a
  /// thread of its own, but never running at the same time as the caller's: the same
  /// evaluations in every run but for where its time share ends), until the unit-cost run has
  /// used this share of the time left in all (its first share included); then it is stopped
  /// and its states freed, and the cost + 1 run goes on alone. The first plan or proof of either
  /// is the answer. A unit-cost run that needs more than its first share (transport-18) gets up to
  /// this share, a cost + 1 run that needs most of the time (citycar-6) loses what the unit-cost
  /// run uses beside it. At most `unit_first_time_share` (0, the default until the thirty-fifth
  /// round): the unit-cost run ends at its first share and the cost + 1 run starts after it.
  /// In turns alone (thirty-third round): at 0.3, transport-18 is solved (23.4 s of 29), but
  /// citycar-6's first plan comes after at least 54 s of its 59 (the unit-cost run takes 17.7 s
  /// of it, in vain) and citycar-11 takes 31.7 s instead of 21. The default, 0.6, is this
  /// share with `unit_beside_stall_share` 0.5 and `unit_progress_alone` (docs/benchmarks.md,
  /// issue 14, thirty-fifth round). Must be in [0, 1].
  double unit_beside_time_share{0.6};
  uint64_t unit_beside_turn{1000};  ///< must be > 0
  /// unit_beside_time_share: the unit-cost run goes on beside the cost + 1 run only while it makes
  /// progress: it is stopped (at the end of its first share, or at a turn) once it has made none
  /// in the last `unit_beside_stall_share` of its evaluations (progress: a hill-climbing step to
  /// a better state, or a landmark count below every one before in its lazy searches). 0: no
  /// such stop (its time share alone). Measured in docs/benchmarks.md, issue 14, thirty-fourth
  /// round: transport-18's unit-cost run lowers its landmark count every few hundred
  /// evaluations; citycar-6's and -11's reach their lowest within their first second. At 0.5
  /// (with `unit_beside_time_share` 0.6) in turns it solves transport-18 and keeps citycar's
  /// time, but loses transport-30 (its first plan comes late already); so does 0.75 (thirty-fifth
  /// round). The default, 0.5, with `unit_progress_alone`. Must be in [0, 1].
  double unit_beside_stall_share{0.5};
  /// unit_beside_time_share with unit_beside_stall_share: the unit-cost run that is still making
  /// progress at the end of its first share goes on **alone** (the cost + 1 run not yet started),
  /// in steps of `unit_beside_turn` evaluations, until it answers, makes no progress in the last
  /// `unit_beside_stall_share` of its evaluations, or has used `unit_beside_time_share` of the
  /// time left; then it is stopped and the cost + 1 run starts from the start, alone, with the
  /// time left. Unlike the turns, a unit-cost run that answers gets all its time at once, and the
  /// cost + 1 run, when it starts, all the rest (transport-30 needs 11-14 s of the one or about
  /// 23 s of the other in its 29 s: in turns neither answers; docs/benchmarks.md, issue 14,
  /// thirty-fifth round: transport 5 of 5, transport-18 and -30 in 14-16 s, nothing lost on the
  /// cost domains of pddl-more and pddl-adl; the unit-cost run went on alone only on transport-18
  /// and -30, sokoban-30 and tetris-4 (1.0-1.3 s more there); citycar's and pegsol-30's are
  /// stalled at the end of their first share, as before). The default; false: in turns.
  bool unit_progress_alone{true};
  /// Anytime phase: before the weighted iterations, plan neighbourhood graph search (Nakhost and
  /// Mueller, ICAPS 2010) on the first plan, for up to this share of the phase's time: the plan's
  /// states and the states reached from them breadth-first, up to a number of states that
  /// doubles from `neighbourhood_first_states` while no cheaper plan is found; the cheapest path
  /// through those states (uniform-cost, no heuristic) replaces the plan when it is cheaper. A
  /// neighbourhood that holds every reachable state proves its plan optimal and ends the phase.
  /// 0 = none (LAMA 2011's iterations only); must be in [0, 1].
  double neighbourhood_time_share{0.5};
  size_t neighbourhood_first_states{1024};  ///< must be > 0
  /// When a neighbourhood found nothing cheaper, the doubled one grows from it (its
  /// breadth-first search goes on where it stopped) instead of being built again from the plan:
  /// the same states, in the same order, so the same plans. Only the breadth-first part is
  /// saved (2-42 % of a search on citycar, parcprinter, sokoban; the uniform-cost search through
  /// the states is the rest and is done again): 20-50 % of the neighbourhood search's time on
  /// parcprinter-12 and pegsol-12 / -18.
  /// false = rebuilt at each doubling (the twenty-fifth round's search; kept for the tests that
  /// compare the two).
  bool neighbourhood_grow{true};

  /// @throws std::invalid_argument naming the bad field (weight < 1, ...).
  void validate() const;
};

enum class SearchStatus {
  kSolved,       ///< plan found
  kUnsolvable,   ///< proven: no plan exists (relaxed dead end or exhausted complete search)
  kFailed,       ///< an incomplete search (ehc without fallback) gave up; nothing is proven
  kTimeout,      ///< deadline passed
  kCancelled,    ///< stop requested
  kOutOfMemory,  ///< memory budget exhausted
};
std::string toString(SearchStatus s);

struct SearchStatistics {
  uint64_t expanded{0};
  uint64_t generated{0};
  uint64_t evaluated{0};
  uint64_t reopened{0};
  uint64_t registered_states{0};
  Cost initial_h{0};
  bool ehc_failed{false};  ///< ehc fell back to the complete search (failure or budget)
  /// ehc: the first run with the FF-v2.3 heuristic variant failed (or ran out of budget) and the
  /// search started again; its evaluations are included in `evaluated`.
  bool ehc_ff_failed{false};
  /// ehc: the default EHC also ran after the FF-v2.3-variant run solved the task (see
  /// `ehc_second_budget_per_step`); `ehc_second_won`: its plan was cheaper and was returned.
  bool ehc_second_ran{false};
  bool ehc_second_won{false};
  uint64_t ehc_retries{0};  ///< plateaus searched again without helpful-action pruning
  uint64_t ehc_retries_abandoned{0};  ///< ... given up at `ehc_retry_budget_share`
  /// ehc: complete searches the hill-climbing fell back to (`ehc_fallback`), and how many of
  /// them started inside a goal-agenda entry that is not the last.
  uint64_t ehc_fallbacks{0};
  uint64_t ehc_fallbacks_in_agenda{0};
  /// `ehc_lazy_beside`: the lazy search started beside the hill-climbing; `lazy_beside_won`: it
  /// gave the answer while the hill-climbing was still running.
  /// `ehc_h2_restart`: hill-climbing runs started again after a proven dead end; h^2 tests of
  /// committed states, and how many found the state a dead end.
  uint64_t ehc_h2_restarts{0};
  uint64_t ehc_h2_tests{0};
  uint64_t ehc_h2_dead_ends{0};
  bool lazy_beside_started{false};
  bool lazy_beside_won{false};
  uint64_t landmarks{0};    ///< lazy: number of landmarks found (0: landmark count not used)
  uint64_t landmarks_disjunctive{0};  ///< ... of which disjunctive
  uint64_t landmark_gn_orders{0};     ///< ... greedy-necessary orders between them
  uint64_t landmark_reasonable_orders{0};  ///< ... reasonable orders between them
  uint64_t eliminated_actions{0};  ///< removed by action elimination
  uint64_t anytime_iterations{0};    ///< weighted A* iterations of the anytime phase
  uint64_t anytime_improvements{0};  ///< ... that found a cheaper plan
  /// A weighted A* iteration exhausted its bounded space, or a plan neighbourhood held every
  /// reachable state: no cheaper plan exists.
  bool anytime_proved_optimal{false};
  uint64_t neighbourhood_runs{0};          ///< plan neighbourhood searches of the anytime phase
  uint64_t neighbourhood_improvements{0};  ///< ... that found a cheaper plan
  uint64_t neighbourhood_states{0};        ///< states of the largest neighbourhood searched
  double neighbourhood_seconds{0.0};       ///< time of the plan neighbourhood searches
  /// `unit_cost_first`: the unit-cost run ran out of its time share or memory, or gave up, and the
  /// first plan came from the cost + 1 run; its effort is included in the counters above.
  bool unit_first_failed{false};
  /// `unit_beside_time_share`: the unit-cost run went on beside the cost + 1 run (whichever answered).
  bool unit_beside{false};
  double seconds{0.0};
};

struct SearchResult {
  SearchStatus status{SearchStatus::kFailed};
  std::vector<OpId> plan;
  Cost cost{0};  ///< sum of operator costs (plan length on unit-cost tasks)
  SearchStatistics stats;
};

/// Searches from `init` (task.numWords() words) to `goal`.
/// @throws std::invalid_argument when options are invalid or `init` has the wrong size.
SearchResult search(const Task& task, const StateBits& init, const Goal& goal, const SearchOptions& options,
                    const Termination& term);

/// Same, with a caller-owned heuristic (already built for `task`; its goal is set here). Lets a
/// session reuse heuristic tables across queries.
SearchResult search(const Task& task, const StateBits& init, const Goal& goal, const SearchOptions& options,
                    Heuristic& heuristic, const Termination& term);

}  // namespace tamp::symbolic_planner
