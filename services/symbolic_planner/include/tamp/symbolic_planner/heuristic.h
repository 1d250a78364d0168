#pragma once
/// @file
/// Delete-relaxation heuristics over a grounded `Task`.
///
/// All of them share one counter-based relaxed exploration (as in FF and Fast Downward's
/// `relaxation_heuristic`): every relaxed operator (an operator's unconditional part, and each of
/// its conditional effects with the condition added to the precondition) keeps a counter of
/// unsatisfied preconditions; facts are settled in order of cost from a priority queue, so the
/// exploration stops as soon as a goal conjunct is settled.
///
/// - `hmax`: cost of the costliest goal/precondition (admissible).
/// - `hadd`: sum of the costs (not admissible, informative).
/// - `hff`: the cost of a relaxed plan extracted backwards through the best supporters of `hadd`
///   (Hoffmann & Nebel 2001, with FD's h_add supporters), with FF's *helpful actions*: the
///   operators applicable in the state that add a sub-goal of the relaxed plan's first layer.
///   Where every operator costs the same, FF's own layered planning graph instead (the same
///   value scale; its relaxed plan takes each sub-goal's achiever from the first layer).
/// - `hff_hadd`: h_FF through h_add's best supporters whatever the costs (Fast Downward's `ff()`,
///   and so LAMA-first's), also where `hff` would take FF's layered graph.
///
/// Contract (tested for every heuristic): h(s) = 0 when s satisfies the goal, h(s) >= 0, and
/// `kDeadEnd` exactly when the goal is unreachable even under the relaxation (so `kDeadEnd`
/// proves s unsolvable).

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "tamp/symbolic_planner/task.h"

namespace tamp::symbolic_planner {

/// How operator costs enter the heuristic.
enum class CostType {
  kUnit,     ///< every operator costs 1 (plan length)
  kCost,     ///< the operator's cost
  kPlusOne,  ///< cost + 1 (LAMA's choice for zero-cost actions in satisficing search)
};

enum class HeuristicKind {
  kFF,      ///< h_FF: FF's layered graph on uniform costs, h_add's best supporters otherwise
  kAdd,     ///< h_add
  kMax,     ///< h_max
  kBlind,   ///< 0 at the goal, 1 elsewhere
  kFFHadd,  ///< h_FF through h_add's best supporters on every task (Fast Downward's ff())
};

class Heuristic {
 public:
  static constexpr Cost kDeadEnd = std::numeric_limits<Cost>::max();
  virtual ~Heuristic() = default;
  /// Sets the goal for subsequent evaluations (the task stays the same).
  virtual void setGoal(const Goal& goal) = 0;
  /// Heuristic value of `state` (numWords() words), or kDeadEnd.
  virtual Cost evaluate(const uint64_t* state) = 0;
  /// Helpful actions of the last evaluation (empty when the heuristic does not compute them).
  virtual const std::vector<OpId>& preferred() const { return no_ops_; }
  virtual bool computesPreferred() const { return false; }
  /// Switches the helpful actions to FF-v2.3's order (fewest deleted goals and relaxed-plan
  /// sub-goals first; among equals, the last collected first) or back to the default order (the
  /// relaxed plan's own first-layer actions first). Returns false (and changes nothing) when the
  /// heuristic has no such variant.
  virtual bool setFFStyle(bool on) {
    (void)on;
    return false;
  }
  /// Switches `preferred()` to the relaxed plan's own first-layer operators (those applicable in
  /// the state, each once: Fast Downward's preferred operators of h_FF, and so LAMA-first's) or
  /// back to FF's helpful actions (every applicable operator that adds a first-layer sub-goal, a
  /// superset: on hiking hundreds where the relaxed plan has a few). Takes precedence over
  /// `setFFStyle`; values are unchanged. Returns false (and changes nothing) when the heuristic
  /// computes no helpful actions.
  virtual bool setRelaxedPlanPreferred(bool on) {
    (void)on;
    return false;
  }

 protected:
  std::vector<OpId> no_ops_;
};

/// A heuristic for `task` (which must outlive it). @throws std::invalid_argument on misuse
/// (unknown kind).
std::unique_ptr<Heuristic> makeHeuristic(HeuristicKind kind, const Task& task, CostType cost_type);

namespace detail {
/// h_FF's layered graph (what `makeHeuristic(kFF, ...)` gives when every operator costs the same
/// under `cost_type`) with `factor` choosing whether rops that share all preconditions but one
/// count the shared part through one node (the default) or each their own. Both give the same
/// values and helpful actions in the same order; for the test that says so.
/// @throws std::invalid_argument when the operators differ in cost under `cost_type`.
std::unique_ptr<Heuristic> makeLayeredFF(const Task& task, CostType cost_type, bool factor);
}  // namespace detail

/// Operator cost under `type`.
inline Cost adjustedCost(const Operator& op, CostType type, bool unit_task) {
  if (type == CostType::kUnit || unit_task) return 1;
  return type == CostType::kPlusOne ? op.cost + 1 : op.cost;
}

}  // namespace tamp::symbolic_planner
