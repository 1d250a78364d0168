#pragma once
/// @file
/// Backward relevance analysis of a grounded task for one goal (issue 14, twenty-third round).
///
/// Grounding keeps every operator reachable from the initial state (forward, relaxed); many of
/// them can never help to reach the goal. As Fast Downward's translator drops the variables that
/// are no ancestors of a goal in the causal graph (Helmert 2006, "The Fast Downward planning
/// system", Sec. 5.2), this analysis keeps:
/// - the *relevant* facts: every goal fact, the preconditions of relevant operators and the
///   conditions of their kept conditional effects, to a fixpoint;
/// - the *relevant* operators: those with an effect that adds a relevant fact or deletes a fact
///   a goal needs false (`GoalConjunct::neg`); of each, the effects on kept facts (an effect that
///   touches no kept fact is dropped);
/// - of operators that are the same on the kept facts (same precondition, effects, conditions),
///   one, the cheapest (the first on ties).
///
/// Every plan of the pruned task is a plan of the task: kept facts change under the pruned
/// operators exactly as under the originals (their preconditions and conditions are kept facts).
/// The converse (every plan of the task, its irrelevant operators left out, is one of the pruned
/// task) holds when leaving operators out can only keep kept facts *true* longer: an operator left
/// out adds no relevant fact, but it may delete one, and a kept conditional effect whose condition
/// then holds where it did not could delete a relevant fact or add one a goal needs false. The
/// analysis checks for that (the closure of the facts that may be true longer) and, when it
/// cannot rule it out, prunes nothing; so pruning never makes a solvable task unsolvable (and a
/// relaxed dead end of the pruned task is one of the task). STRIPS tasks are always safe.
///
/// A fact with a complement that a kept operator recomputes (`Operator::needs_fixup`) keeps its
/// complement too.

#include <cstdint>
#include <memory>
#include <vector>

#include "tamp/core/termination.h"
#include "tamp/symbolic_planner/task.h"

namespace tamp::symbolic_planner {

/// What the analysis found (also when it pruned nothing).
struct RelevanceStats {
  size_t facts_before{0}, facts_after{0};
  size_t ops_before{0};
  size_t ops_relevant{0};   ///< operators with an effect on a relevant fact
  size_t ops_after{0};      ///< ... after merging operators that are the same on the kept facts
  size_t cond_effects_dropped{0};  ///< conditional effects of kept operators on no kept fact
  bool unsafe{false};       ///< the completeness check failed: nothing was pruned
  bool stopped{false};      ///< the caller's Termination stopped the analysis: nothing was pruned
  double seconds{0.0};
};

/// A task pruned to what is relevant to a goal, with the maps back to the original.
struct PrunedTask {
  std::shared_ptr<const Task> task;  ///< null when nothing was pruned (use the original)
  std::vector<int32_t> fact_map;     ///< original fact -> pruned fact, -1 = dropped
  std::vector<OpId> op_origin;       ///< pruned operator -> original operator
  Goal goal;                         ///< the goal over the pruned facts
  RelevanceStats stats;

  bool pruned() const { return task != nullptr; }
  /// The pruned task's state for an original state (`original_words` words).
  StateBits projectState(const uint64_t* s, size_t original_words) const;
};

/// Prunes `task` to what is relevant to `goal` (see the file comment). `result.task` is null
/// when nothing can be dropped or pruning is not known to be complete (`stats.unsafe`), or when
/// `term` stopped the analysis (`stats.stopped`; it is checked every 1 024 operators of its
/// loops: 0.25-0.45 s on scanalyzer-30's 207 360 operators).
/// @throws std::invalid_argument when a goal fact is out of range.
PrunedTask pruneIrrelevant(const Task& task, const Goal& goal, const Termination& term = Termination());

}  // namespace tamp::symbolic_planner
