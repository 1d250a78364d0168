#pragma once
/// @file
/// The symbolic planner: an FF-style planner (Hoffmann & Nebel, "The FF Planning System: Fast
/// Plan Generation Through Heuristic Search", JAIR 14, 2001) for the task-planning calls
/// `TP(v, s, A)` of the conditional TAMP system.
///
/// ## Design overview
/// 1. **Parsing** (`pddl.h`): PDDL domains/problems of FF's ADL subset plus `:action-costs` into a
///    lifted AST; every error names file:line:column.
/// 2. **Grounding** (`grounding.h`): relaxed reachability by a semi-naive join over the positive
///    preconditions (static atoms and equality evaluated exactly), then ground operators with
///    quantifiers expanded, disjunctions split (DNF) and negation compiled into complement facts
///    (as FF does). The result is a compact integer `Task` (`task.h`) with bitset states.
///    Before the heuristic tables are built, a backward relevance analysis for the goal
///    (`relevance.h`) drops the facts and operators no goal needs and merges operators that are
///    the same on the rest (`Query::prune_irrelevant`).
/// 3. **Heuristics** (`heuristic.h`): counter-based relaxed exploration; h_FF with FF's helpful
///    actions, h_add, h_max (admissible).
/// 4. **Search** (`search.h`): FF's enforced hill-climbing on helpful actions, falling back to
///    complete greedy best-first search with a preferred-operator queue; (weighted) A* with h_max
///    when optimal or bounded-suboptimal plans are asked for. All take a `Termination`.
/// 5. **Checking** (`validator.h`): an independent replay of plans on the lifted semantics.
///
/// ## Calls from the graph manager
/// The graph manager asks many queries on one domain and object set from arbitrary states.
/// `PlanningSession` grounds once and reuses the grounding: relaxed reachability from the union of
/// every initial state seen is complete for any query whose atoms it contains (R is monotone and
/// idempotent); a query with new atoms extends the fixpoint; a query that drops static facts gets
/// a task without the operators needing them. Objects can be added (the session re-grounds).
/// `Planner` serves self-contained `PlanRequest`s (domain + problem as text or files, or objects +
/// init + goal) with a small cache of sessions keyed by domain text and object set: this is what
/// the DDS node maps its messages to (plain value types only, no DDS here).

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/termination.h"
#include "tamp/symbolic_planner/grounding.h"
#include "tamp/symbolic_planner/pddl.h"
#include "tamp/symbolic_planner/relevance.h"
#include "tamp/symbolic_planner/search.h"
#include "tamp/symbolic_planner/validator.h"

namespace tamp::symbolic_planner {

/// What came of a planning call; maps to the `tamp plan` exit codes (0, 10, 20, 30).
enum class PlanStatus {
  kSolved,        ///< `plan` holds a valid plan
  kUnsolvable,    ///< proven: no plan exists
  kFailed,        ///< an incomplete search gave up (nothing proven)
  kTimeout,       ///< the deadline passed
  kCancelled,     ///< a stop was requested
  kOutOfMemory,   ///< the memory budget was exhausted
  kInputError,    ///< malformed or unsupported input; `message` names file:line:column
  kInternalError  ///< a bug (e.g. a plan the checker rejects); `message` says what
};
std::string toString(PlanStatus s);

/// A ground atom by names, e.g. {"on", {"can", "table"}}.
struct AtomSpec {
  std::string predicate;
  std::vector<std::string> args;
};

/// An object with its type (a type name of the domain, "object" when untyped).
struct ObjectSpec {
  std::string name;
  std::string type{"object"};
};

struct PlanStatistics {
  double parse_seconds{0.0};
  double ground_seconds{0.0};   ///< exploration + task construction (0 when cached)
  double search_seconds{0.0};
  double check_seconds{0.0};    ///< the independent replay of the plan (PlanRequest::check_plan)
  bool grounding_reused{false};
  size_t facts{0};
  size_t operators{0};
  uint64_t expanded{0};
  uint64_t generated{0};
  uint64_t evaluated{0};
  int64_t initial_h{0};
  bool ehc_failed{false};
  bool ehc_ff_failed{false};  ///< the first EHC run (FF-v2.3 heuristic variant) failed; see SearchOptions
  bool ehc_second_ran{false};  ///< the default EHC also ran after the first run's long plan; see SearchOptions
  bool ehc_second_won{false};  ///< ... and its plan was the cheaper one
  uint64_t ehc_retries{0};  ///< plateaus searched again without helpful-action pruning (every run)
  uint64_t ehc_retries_abandoned{0};  ///< ... given up at SearchOptions::ehc_retry_budget_share
  uint64_t ehc_h2_restarts{0};        ///< hill-climbing runs started again after a proven dead end
  uint64_t ehc_h2_tests{0};           ///< ... h^2 tests of states to commit to in them
  uint64_t ehc_h2_dead_ends{0};       ///< ... that found the state a dead end
  uint64_t ehc_fallbacks{0};  ///< complete searches the hill-climbing fell back to
  uint64_t ehc_fallbacks_in_agenda{0};  ///< ... started inside a goal-agenda entry that is not the last
  bool lazy_beside_started{false};  ///< the lazy search ran beside the hill-climbing; see SearchOptions
  bool lazy_beside_won{false};      ///< ... and gave the answer while the hill-climbing ran
  uint64_t anytime_iterations{0};    ///< SearchOptions::anytime_seconds: iterations run
  uint64_t anytime_improvements{0};  ///< ... that found a cheaper plan
  uint64_t neighbourhood_runs{0};          ///< plan neighbourhood searches of the anytime phase
  uint64_t neighbourhood_improvements{0};  ///< ... that found a cheaper plan
  uint64_t neighbourhood_states{0};        ///< states of the largest of them
  double neighbourhood_seconds{0.0};       ///< ... and their time
  bool unit_first_failed{false};  ///< the unit-cost first run failed; see SearchOptions::unit_cost_first
  bool unit_beside{false};  ///< the unit-cost run went on beside the cost + 1 run (SearchOptions::unit_beside_time_share)
  uint64_t landmarks{0};  ///< landmarks of the lazy search's landmark count (0: not used)
  uint64_t landmarks_disjunctive{0};  ///< ... of which disjunctive
  uint64_t landmark_gn_orders{0};     ///< ... greedy-necessary orders between them
  uint64_t landmark_reasonable_orders{0};  ///< ... reasonable orders between them
  /// Relevance analysis (relevance.h) of this query, when it ran (`relevance_ran`); `facts` and
  /// `operators` above are the searched task's, pruned when `pruned`.
  bool relevance_ran{false};
  bool pruned{false};
  RelevanceStats relevance;
};

/// A self-contained request (maps 1:1 to the plan-request message).
struct PlanRequest {
  std::string domain_text;   ///< PDDL domain; when empty, `domain_path` is read
  std::string domain_path;
  std::string problem_text;  ///< PDDL problem; when both text and path are empty, the problem is
  std::string problem_path;  ///<   built from `objects`, `init` and `goal` below
  std::vector<ObjectSpec> objects;
  std::vector<AtomSpec> init;
  std::string goal;          ///< a PDDL goal formula, e.g. "(and (holding can))"
  /// Static function values for action costs, e.g. {"road-length", {"a","b"}} -> 7.
  std::vector<std::pair<AtomSpec, double>> function_values;
  bool use_costs{true};      ///< with objects/init/goal: minimise total-cost (like :metric)
  SearchOptions search;
  double timeout_seconds{60.0};  ///< on top of the caller's Termination; <= 0: none
  bool check_plan{true};     ///< replay the plan with the independent checker before replying
  /// With `check_plan`: fill PlanReply::states from the replay. A caller that wants only the
  /// plan (`tamp plan`) sets it false and saves a copy of every true atom per step.
  bool return_states{true};
  bool prune_irrelevant{true};  ///< see Query::prune_irrelevant
};

/// The answer (maps 1:1 to the plan-reply message).
struct PlanReply {
  PlanStatus status{PlanStatus::kInternalError};
  std::vector<PlanStep> plan;
  Cost cost{0};          ///< total-cost of the plan (its length without a metric)
  std::string message;   ///< for errors: what and where; empty on success
  PlanStatistics stats;
  /// When solved, checked (`check_plan`) and asked for (`return_states`): every true ground atom
  /// of each state along the plan, from the independent replay (states[0] the initial state,
  /// states[i + 1] after step i).
  std::vector<std::vector<std::string>> states;
};

/// A query on a session: an initial state and a goal.
struct Query {
  std::vector<AtomId> init;          ///< every true atom (closed world); ids from atomId()
  /// Goal as literals (conjunction) ...
  std::vector<AtomLiteral> goal_literals;
  /// ... or as a formula (used when set; any formula of the supported fragment).
  std::optional<pddl::Formula> goal_formula;
  SearchOptions search;
  /// Search a task pruned to what is relevant to the goal (relevance.h) when the session has no
  /// heuristic tables for its grounded task yet: the first query on a task (a one-shot request)
  /// is pruned for its goal, and later queries with the same goal reuse that pruned task and its
  /// tables; queries with other goals search the whole task (its tables built once), so that a
  /// session's many queries keep their latency.
  bool prune_irrelevant{true};
};

/// One domain and object set; grounding cached across queries. Not thread-safe (one per thread,
/// or guard it).
class PlanningSession {
 public:
  /// `problem` provides the objects and static function values; its init seeds the grounding
  /// and is the default initial state, its goal the default goal.
  static Result<std::unique_ptr<PlanningSession>> create(pddl::Domain domain, pddl::Problem problem,
                                                         bool use_costs, GroundingLimits limits = {});
  /// Parses domain and problem text (names are used in error messages).
  static Result<std::unique_ptr<PlanningSession>> fromText(const std::string& domain_text,
                                                           const std::string& problem_text,
                                                           const std::string& domain_name = "<domain>",
                                                           const std::string& problem_name = "<problem>");

  const pddl::Domain& domain() const { return domain_; }
  const pddl::Problem& problem() const { return problem_; }

  /// Atom id for the current object set (invalidated by addObjects(); see generation()).
  Result<AtomId> atomId(const AtomSpec& atom);
  Result<std::vector<AtomId>> atomIds(const std::vector<AtomSpec>& atoms);
  /// The problem's own initial atoms as ids.
  Result<std::vector<AtomId>> problemInit();

  /// Adds objects (e.g. newly sampled placements); the grounding is rebuilt lazily on the next
  /// query from the union of initial states seen so far. Errors: unknown type, duplicate name
  /// with a different type.
  Status addObjects(const std::vector<ObjectSpec>& objects);
  /// Incremented whenever atom ids are invalidated.
  uint64_t generation() const { return generation_; }

  /// Plans from `q.init` to the goal. Never throws for bad input (returns kInputError); throws
  /// std::invalid_argument only for invalid options (misuse).
  PlanReply solve(const Query& q, const Termination& term);

  /// The grounded task currently cached (null before the first query).
  std::shared_ptr<const Task> task() const { return task_; }
  const GroundingStats& groundingStats() const;

 private:
  PlanningSession() = default;
  Status ensureGrounder();
  pddl::Domain domain_;
  pddl::Problem problem_;
  bool use_costs_{false};
  GroundingLimits limits_;
  std::unique_ptr<Grounder> grounder_;
  std::vector<AtomId> seed_ids_;  ///< atoms that extended the seeds (carried over by addObjects)
  std::shared_ptr<const Task> task_;
  std::vector<AtomId> task_statics_;
  std::vector<AtomId> task_negated_;
  struct HeuristicCache {
    HeuristicKind kind;
    CostType cost_type;
    std::unique_ptr<Heuristic> h;
  };
  std::vector<HeuristicCache> heuristics_;
  /// The task pruned for the first goal queried on `task_` (Query::prune_irrelevant), with its
  /// own heuristic tables; `prune_tried_` once that goal was analysed.
  bool prune_tried_{false};
  PrunedTask pruned_;
  Goal pruned_for_;
  std::vector<HeuristicCache> pruned_heuristics_;
  uint64_t generation_{0};
};

/// Serves self-contained requests, reusing groundings across requests with the same domain
/// text and object set (LRU of `cache_size` sessions). Thread-safe (one request at a time).
class Planner {
 public:
  explicit Planner(size_t cache_size = 4) : cache_size_(cache_size) {}
  PlanReply solve(const PlanRequest& request, const Termination& term);

 private:
  struct Entry {
    std::string key;
    std::unique_ptr<PlanningSession> session;
  };
  std::mutex mutex_;
  std::vector<Entry> cache_;  ///< most recently used last
  size_t cache_size_;
};

/// One-shot convenience: `Planner{0}.solve(request, term)` without caching.
PlanReply plan(const PlanRequest& request, const Termination& term);

/// Formats a plan in IPC format: one "(action args)" per line, then "; cost = N".
std::string formatPlan(const std::vector<PlanStep>& plan, Cost cost);

}  // namespace tamp::symbolic_planner
