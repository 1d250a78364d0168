#pragma once
/// @file
/// Landmarks and the landmark-count heuristic of LAMA (Richter & Westphal 2010, JAIR 39).
///
/// A landmark is a disjunction of facts (one fact: a simple landmark) that holds in some state of
/// every plan. Two generators fill a `LandmarkGraph`:
///
/// - `zhuGivanLandmarks`: Zhu & Givan's label propagation over the delete relaxation ("Landmark
///   extraction via planning graph propagation", ICAPS 2003 doctoral consortium; Fast Downward's
///   `lm_zg`): every fact reached from the initial state carries the set of facts that every
///   relaxed way of reaching it passes through (the intersection, over its achievers, of the
///   union of their preconditions' labels, plus the fact itself). The labels of the goal facts
///   are causal landmarks of the task; `l' in label(l)` gives the natural order l' -> l. Simple
///   landmarks only.
/// - `rhwLandmarks`: Richter, Helmert & Westphal's back-chaining ("Landmarks revisited", AAAI
///   2008; Fast Downward's `lm_rhw`, the generator of LAMA): from each landmark not true
///   initially, the operators that can achieve it first (applicable in the delete relaxation
///   without it) are collected; the preconditions they all share are landmarks, ordered greedy-
///   necessarily before it, and where each of them has a precondition of one PDDL predicate
///   (and no shared one), the disjunction of those is a landmark (of at most
///   `RhwLandmarkOptions::max_disjunction_size` facts). Fast Downward's domain-transition-graph
///   step needs finite-domain variables, which this task representation does not have; the
///   Zhu-Givan landmarks (a superset of what that step finds in the delete relaxation) are added
///   as simple landmarks instead (`RhwLandmarkOptions::add_zhu_givan`).
///
/// `LandmarkCounter` counts the landmarks a state still needs, path-dependently, in one of two
/// ways (`LandmarkProgression`):
/// - `kAcceptedAfterParents` (LAMA 2008): a landmark is *accepted* on the path once it was true
///   in a state of the path after all its ordered predecessors had been accepted; the value is
///   the number not accepted plus the accepted goal landmarks that are false again.
/// - `kPastAndFuture` (Fast Downward's `LandmarkStatusManager` today, Büchner et al. 2023):
///   a landmark is *past* once it held on the path, and *future* when it was never past, or it
///   is a goal that is false, or it is false and greedy-necessarily ordered before a landmark
///   that is not past ("required again"), or a landmark reasonably ordered before it is not
///   past; a future landmark that held already stays future until an action adds it again. The
///   value is the number of future landmarks.
///
/// Its preferred operators are the applicable operators that add a fact of a landmark that is
/// still needed and false. Values are counts (every landmark counts 1, as in lama-first's
/// `cost_type=one`), never `Heuristic::kDeadEnd` (dead ends are left to h_FF).

#include <bit>
#include <cstdint>
#include <vector>

#include "tamp/symbolic_planner/mutexes.h"
#include "tamp/symbolic_planner/task.h"

namespace tamp::symbolic_planner {

enum class LandmarkOrderKind : uint8_t {
  kReasonable = 0,       ///< `to` is better achieved after `from` (it would have to be undone)
  kNatural = 1,          ///< `from` is true at some time before `to` in every plan
  kGreedyNecessary = 2,  ///< `from` is true right before `to` is first achieved
};

struct LandmarkOrder {
  uint32_t from{0};
  uint32_t to{0};
  LandmarkOrderKind kind{LandmarkOrderKind::kNatural};
};

/// Landmarks (each a sorted set of facts: one = simple, more = disjunctive) and their orders.
struct LandmarkGraph {
  std::vector<std::vector<FactId>> landmarks;
  std::vector<uint8_t> is_goal;  ///< landmark index -> a goal fact (simple landmarks only)
  std::vector<LandmarkOrder> orders;

  bool empty() const { return landmarks.empty(); }
  size_t numDisjunctive() const;
  size_t numOrders(LandmarkOrderKind kind) const;
};

/// The Zhu-Givan landmarks of reaching `goal` (one conjunct, positive facts) from `init`, with
/// natural orders. Empty for disjunctive or negative goals, when a goal fact is relaxed-
/// unreachable, or when the labels would take more than `max_label_entries` fact ids in all
/// (memory bound for very large tasks).
LandmarkGraph zhuGivanLandmarks(const Task& task, const StateBits& init, const Goal& goal,
                                size_t max_label_entries = 50'000'000);

struct RhwLandmarkOptions {
  /// Disjunctive landmarks of at most this many facts (Fast Downward: fewer than 5); 0 or 1 = no
  /// disjunctive landmarks.
  size_t max_disjunction_size{4};
  /// Add the Zhu-Givan landmarks the back-chaining did not find, as simple landmarks (a fact
  /// of a disjunctive landmark makes it simple, as in Fast Downward).
  bool add_zhu_givan{true};
  /// Work bound of the back-chaining (effects and facts visited by its relaxed explorations,
  /// one per landmark): past it, no further landmark is back-chained from; those found stay.
  /// Must be > 0.
  uint64_t max_work{400'000'000};
  /// No disjunctive landmark from first achievers that are all one ground action, split by
  /// grounding into one operator per alternative of its disjunctive precondition: such a
  /// disjunction restates that precondition, and counting it rewards progress towards one
  /// alternative (Fast Downward keeps them; on pathways they cost 3 of 5 instances, see
  /// docs/benchmarks.md, issue 14, sixteenth round).
  bool skip_one_action_disjunctions{true};
  /// Add Hoffmann, Porteous & Sebastia's reasonable orders (`addReasonableOrders`), with h^2
  /// mutexes (`mutexes`), as LAMA-first's `lm_reasonable_orders_hps(lm_rhw())` (measured in
  /// docs/benchmarks.md, issue 14, seventeenth round).
  bool reasonable_orders{true};
  H2MutexOptions mutexes;
  /// Bound of `addReasonableOrders`: interference tests; past it, the orders found stay.
  uint64_t max_interference_tests{20'000'000};

  /// @throws std::invalid_argument naming the bad field.
  void validate() const;
};

/// The RHW landmarks of reaching `goal` from `init` (see the file comment); empty where
/// `zhuGivanLandmarks` is (disjunctive or negative goals, a relaxed-unreachable goal).
/// `term` stops the h^2 table of the reasonable orders (the graph is then returned without
/// them: a caller whose deadline passed is about to stop anyway).
/// @throws std::invalid_argument when `options` are invalid.
LandmarkGraph rhwLandmarks(const Task& task, const StateBits& init, const Goal& goal,
                           const RhwLandmarkOptions& options, const Termination& term = Termination());

/// Hoffmann, Porteous & Sebastia's reasonable orders ("Ordered landmarks in planning", JAIR 22,
/// 2004) as Fast Downward approximates them (`LandmarkFactoryReasonableOrdersHPS`): A ->r B
/// ("B is better achieved after A") between simple landmarks, B not true in `init`, when A
/// *interferes* with B (achieving A after B would delete B): a and b are mutex, or every operator
/// adding a also adds a fact mutex with b or deletes b, or a greedy-necessary predecessor of A is
/// mutex with b (every fact of it, when disjunctive). Candidates A: every landmark when B is a
/// goal; otherwise the natural or greedy-necessary predecessors of B's greedy-necessary
/// successors and their ancestors. An order against a stronger one the other way is not added;
/// a reasonable one the other way is replaced. At most `max_tests` interference tests.
/// @returns the number of reasonable orders added.
size_t addReasonableOrders(const Task& task, const StateBits& init, const MutexTable& mutexes,
                           LandmarkGraph& graph, uint64_t max_tests = 20'000'000);

enum class LandmarkProgression { kAcceptedAfterParents, kPastAndFuture };

class LandmarkCounter {
 public:
  /// Counts the landmarks of `graph`. kAcceptedAfterParents needs simple landmarks only.
  /// @throws std::invalid_argument for a disjunctive landmark with kAcceptedAfterParents, or an
  /// order naming no landmark.
  LandmarkCounter(const Task& task, LandmarkGraph graph, LandmarkProgression progression);
  /// Zhu-Givan landmarks with kAcceptedAfterParents (the landmark count before RHW).
  LandmarkCounter(const Task& task, const StateBits& init, const Goal& goal,
                  size_t max_label_entries = 50'000'000);

  bool enabled() const { return !graph_.empty(); }
  size_t numLandmarks() const { return graph_.landmarks.size(); }
  const LandmarkGraph& graph() const { return graph_; }
  /// Words of a landmark status (per state): the accepted set, or the past then the future set.
  size_t words() const {
    return progression_ == LandmarkProgression::kPastAndFuture ? 2 * lm_words_ : lm_words_;
  }

  /// Status of the initial state `state` into `out` (words() words).
  void initial(const uint64_t* state, uint64_t* out) const;
  /// Status of `state`, reached from `parent_state` whose status is `parent`, into `out`.
  void progress(const uint64_t* parent_state, const uint64_t* parent, const uint64_t* state,
                uint64_t* out) const;
  /// The heuristic value of `state` with status `status`.
  Cost value(const uint64_t* state, const uint64_t* status) const;
  /// Appends the preferred operators of `state` (see above) to `out`.
  void preferred(const uint64_t* state, const uint64_t* status, std::vector<OpId>& out) const;
  /// The same operators as `preferred`, each once, in the order of `applicable`, which must be
  /// every operator applicable in `state` (`Task::applicableOps`): marks the facts of the
  /// landmarks in question and tests the applicable operators' effects, instead of testing every
  /// adder of those facts for applicability (on hiking-16, 28 000 operators, the adders of a
  /// landmark `at_person` are thousands, the applicable operators a few hundred).
  void preferredAmong(const uint64_t* state, const uint64_t* status,
                      const std::vector<OpId>& applicable, std::vector<OpId>& out) const;

 private:
  bool holds(uint32_t l, const uint64_t* state) const;
  bool parentsAccepted(uint32_t l, const uint64_t* accepted) const;

  const Task& task_;
  LandmarkGraph graph_;
  LandmarkProgression progression_;
  size_t lm_words_{0};
  // CSR over landmarks: natural and greedy-necessary predecessors (accepted-after-parents),
  // greedy-necessary successors and reasonable predecessors (past and future).
  std::vector<uint32_t> parents_begin_, parents_;
  std::vector<uint32_t> gn_children_begin_, gn_children_;
  std::vector<uint32_t> reasonable_parents_begin_, reasonable_parents_;
  mutable std::vector<uint64_t> now_;        ///< scratch of progress(): the landmarks that hold
  mutable std::vector<uint32_t> fact_mark_;  ///< scratch of preferredAmong(): epoch per fact
  mutable uint32_t fact_epoch_{0};
};

}  // namespace tamp::symbolic_planner
