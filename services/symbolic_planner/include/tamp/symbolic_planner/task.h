#pragma once
/// @file
/// The compact grounded task the search works on: facts are dense integers, states are bitsets,
/// operators have positive fact preconditions and (conditional) add/delete effects.
///
/// Negative preconditions, negated effect conditions and negative goals are compiled as in FF:
/// an atom `p` used negatively gets a complement fact `not-p`, kept consistent by every effect
/// that adds or deletes `p` (and by the initial state). Disjunctions are split into several
/// operators with the same name (ground DNF); quantifiers are expanded over the objects. Static
/// atoms (of predicates no action changes) are evaluated during grounding and do not appear.

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace tamp::symbolic_planner {

using FactId = uint32_t;
using OpId = uint32_t;
/// Action costs are integers (PDDL `total-cost` increases); unit-cost tasks use 1.
using Cost = int64_t;

/// One `(when cond effect)` after grounding: fires when every `cond` fact holds in the state the
/// operator is applied in.
struct ConditionalEffect {
  std::vector<FactId> cond;
  std::vector<FactId> add;
  std::vector<FactId> del;
};

/// A ground operator. Deletes are applied before adds (an atom both added and deleted is true
/// afterwards, as in PDDL).
struct Operator {
  std::string name;                 ///< IPC form, e.g. "(pick can table over_table)"; empty = internal
  std::vector<FactId> pre;          ///< sorted, unique
  std::vector<FactId> add;          ///< unconditional, sorted
  std::vector<FactId> del;          ///< unconditional, sorted
  std::vector<ConditionalEffect> cond_effects;
  Cost cost{1};
  /// Some fact may be both added and deleted depending on conditions: the complement facts
  /// have to be recomputed after applying (rare; see `Task::apply`).
  bool needs_fixup{false};
};

/// A goal in disjunctive normal form: the goal holds when every literal of some conjunct holds.
/// `pos` facts must be true; `neg` facts must be false (used only where no complement fact exists:
/// negated goal atoms normally become complement facts in `pos`).
struct GoalConjunct {
  std::vector<FactId> pos;
  std::vector<FactId> neg;
};
struct Goal {
  std::vector<GoalConjunct> conjuncts;  ///< empty = unsatisfiable goal
  bool unsatisfiable() const { return conjuncts.empty(); }
};

/// Inverted indices over the *effects* of a task (effect e < ops.size() is operator e's
/// unconditional part, the others are the conditional effects in operator order), in CSR form:
/// `x_begin[f] .. x_begin[f + 1]` index `x` for fact f. Built by `Task::finalize()`; used by
/// analyses over the whole task (FF's goal agenda) that would otherwise rebuild them per query.
struct EffectIndex {
  std::vector<OpId> op;          ///< effect -> operator
  std::vector<int32_t> ce;       ///< effect -> conditional effect index, -1 = unconditional part
  std::vector<uint32_t> adders_begin, adders;      ///< fact -> effects adding it
  std::vector<uint32_t> users_begin, users;        ///< fact -> effects needing it (pre or condition)
  std::vector<uint32_t> deleters_begin, deleters;  ///< fact -> effects deleting it (a conditional
                                                   ///< effect also counts its operator's deletes)
  size_t size() const { return op.size(); }
};

/// A state: one bit per fact.
using StateBits = std::vector<uint64_t>;

inline bool testBit(const uint64_t* s, FactId f) { return (s[f >> 6] >> (f & 63)) & 1U; }
inline void setBit(uint64_t* s, FactId f) { s[f >> 6] |= uint64_t{1} << (f & 63); }
inline void clearBit(uint64_t* s, FactId f) { s[f >> 6] &= ~(uint64_t{1} << (f & 63)); }

/// The grounded task. Immutable once built; shared by the heuristics and searches of many
/// queries.
class Task {
 public:
  std::vector<std::string> fact_names;   ///< "(at a b)" or "(not (at a b))" for complements
  std::vector<int32_t> complement;       ///< complement fact of each fact, or -1
  std::vector<Operator> ops;
  bool unit_cost{true};                  ///< true: every operator costs 1 (no metric)
  std::vector<std::vector<OpId>> achievers;  ///< ops whose (conditional) effects add the fact
  EffectIndex effects;                       ///< built by finalize()

  size_t numFacts() const { return fact_names.size(); }
  /// Words of a state: at least one, so that a task without facts (every predicate static or
  /// unused) still has a state to store, hash and compare.
  size_t numWords() const { return std::max<size_t>(1, (fact_names.size() + 63) / 64); }

  /// Rebuilds the derived tables (achievers, effect index, successor index). Call once after
  /// filling.
  void finalize();

  bool applicable(const uint64_t* s, OpId op) const {
    for (FactId f : ops[op].pre) {
      if (!testBit(s, f)) return false;
    }
    return true;
  }
  /// Writes the successor of `s` under `op` into `out` (numWords() words; may not alias `s`).
  void apply(const uint64_t* s, OpId op, uint64_t* out) const;
  /// Appends every operator applicable in `s` to `out`.
  void applicableOps(const uint64_t* s, std::vector<OpId>& out) const;

  bool goalReached(const uint64_t* s, const Goal& g) const;

 private:
  void buildEffectIndex();
  // Successor generation: each operator is indexed under its "key" precondition (the one least
  // likely to hold); operators without preconditions are always checked.
  std::vector<std::vector<OpId>> ops_by_key_;
  std::vector<OpId> ops_without_pre_;
};

}  // namespace tamp::symbolic_planner
