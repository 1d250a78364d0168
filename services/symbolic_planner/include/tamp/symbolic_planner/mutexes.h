#pragma once
/// @file
/// Fact mutexes by h^2 reachability (Haslum & Geffner, "Admissible heuristics for optimal
/// planning", AIPS 2000; Bonet & Geffner's h^m): two facts are *mutex* when no state reachable
/// from the initial state holds both. The fixpoint over fact pairs over-approximates the pairs
/// that hold together in some reachable state, so every pair it never reaches is a true mutex.
///
/// Used by the reasonable orders of the landmark graph (landmarks.h, Hoffmann, Porteous & Sebastia
/// 2004), which need "a and b cannot hold together"; Fast Downward takes its mutexes from its
/// invariant synthesis, which the STRIPS task here does not have. h^2 finds every mutex of an
/// exactly-one invariant and more.
///
/// Conditional effects are over-approximated: every conditional effect whose conditions can hold
/// with the operator's precondition may fire together with any other, and conditional deletes are
/// ignored (a fact survives unless the operator deletes it unconditionally and no effect adds it).
/// That keeps the answer sound (a pair reported mutex is one).
///
/// Cost: one bit per fact pair (n^2 / 8 bytes) and, per fixpoint round, one AND of the
/// precondition rows per operator whose precondition rows changed. Bounded by `H2MutexOptions`:
/// a task over the bound gets an empty table (no pair mutex), never a partial one.

#include <cstdint>
#include <optional>
#include <vector>

#include "tamp/core/termination.h"
#include "tamp/symbolic_planner/task.h"

namespace tamp::symbolic_planner {

struct H2MutexOptions {
  /// Tasks with more facts get no mutexes (memory: n^2 / 8 bytes, 50 MB at the default).
  size_t max_facts{20'000};
  /// Work bound of the fixpoint in 64-bit words touched; past it the table is empty. Must be > 0.
  uint64_t max_work{600'000'000};

  /// @throws std::invalid_argument naming the bad field.
  void validate() const;
};

/// The h^2 mutex pairs of a task from one initial state. Empty (enabled() false, every pair
/// reported not mutex) when the task is over the bounds.
class MutexTable {
 public:
  MutexTable() = default;
  /// @throws std::invalid_argument when `options` are invalid or `init` has fewer words than the
  /// task's states.
  /// `term` stops the fixpoint (checked every 64 operators): the table is then empty, as over
  /// the work bound (airport-50: 0.3-0.5 s at the lazy search's start, for the reasonable orders).
  MutexTable(const Task& task, const StateBits& init, const H2MutexOptions& options,
             const Termination& term = Termination());

  bool enabled() const { return n_ > 0; }
  /// True when `a` and `b` (distinct facts) never hold together in a reachable state, or when
  /// one of them is unreachable. False for a == b and whenever the table is not enabled.
  bool mutex(FactId a, FactId b) const {
    if (n_ == 0 || a == b) return false;
    return !testBit(rows_.data() + static_cast<size_t>(a) * words_, b);
  }
  /// True when `f` holds in some state h^2 reaches (always true when the table is not enabled).
  bool reachable(FactId f) const { return n_ == 0 || pairReachable(f, f); }
  /// Fact pairs {a, b}, a < b, both reachable, that are mutex.
  size_t numMutexPairs() const;
  /// Work the fixpoint took (words touched), for statistics.
  uint64_t work() const { return work_; }

  /// Whether h^2 from `from` reaches every fact of `facts` and every pair of them (a dead-end
  /// test stronger than the delete relaxation: false means no state reachable from `from` holds
  /// them all). The fixpoint stops as soon as the last pair is reached, so a true answer usually
  /// costs a fraction of a full table. nullopt when the task is over the bounds of `options`
  /// (nothing known). `work`, when given, receives the words touched.
  /// @throws std::invalid_argument as the constructor.
  static std::optional<bool> reachesTogether(const Task& task, const StateBits& from,
                                             const std::vector<FactId>& facts,
                                             const H2MutexOptions& options,
                                             uint64_t* work = nullptr,
                                             const Termination& term = Termination());

 private:
  /// The fixpoint; with `stop_facts`, it returns as soon as all their pairs are reachable.
  void compute(const Task& task, const StateBits& init, const H2MutexOptions& options,
               const std::vector<FactId>* stop_facts, const Termination& term);
  bool pairReachable(FactId a, FactId b) const {
    return testBit(rows_.data() + static_cast<size_t>(a) * words_, b);
  }
  uint64_t* row(FactId f) { return rows_.data() + static_cast<size_t>(f) * words_; }
  bool allPairsReachable(const std::vector<FactId>& facts) const;
  bool processOperator(const Task& task, OpId o);
  bool markPairs(FactId p, const uint64_t* with);

  size_t n_{0};
  size_t words_{0};
  std::vector<uint64_t> rows_;  ///< rows_[a * words_ ..]: bit b set = {a, b} may hold together
  uint64_t work_{0};
  // Scratch of processOperator.
  std::vector<uint64_t> compat_, adds_;
  std::vector<FactId> add_list_, new_bits_;
  // compute()'s change clock as markPairs sees it: fact -> tick of its row's last change, the
  // tick of the operator in progress, and whether the rows changed are listed in new_bits_.
  uint64_t* row_tick_{nullptr};
  uint64_t tick_{0};
  bool track_new_{false};
  // reachesTogether(): per fact 1 if it is one of the facts, and the pairs of them (a fact with
  // itself included) not reached yet; the fixpoint stops when that count is 0.
  std::vector<uint8_t> stop_flag_;
  size_t stop_left_{0};
};

}  // namespace tamp::symbolic_planner
