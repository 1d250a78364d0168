#pragma once
/// @file
/// Fact landmarks and the landmark-count heuristic of LAMA (Richter & Westphal 2010, JAIR 39).
///
/// Landmarks are found by Zhu & Givan's label propagation over the delete relaxation
/// ("Landmark extraction via planning graph propagation", ICAPS 2003 doctoral consortium; Fast
/// Downward's `lm_zg`): every fact reached from the initial state carries the set of facts that
/// every relaxed way of reaching it passes through (the intersection, over its achievers, of the
/// union of their preconditions' labels, plus the fact itself). The labels of the goal facts are
/// causal landmarks of the task; `l' in label(l)` gives the natural ordering l' -> l.
///
/// The heuristic is path-dependent: a landmark is *accepted* on the path to a state once it was
/// true in a state of the path after all its ordered predecessors had been accepted. Its value is
/// the number of landmarks not accepted plus the accepted goal landmarks that are false again
/// (LAMA's count without the "required again" rule for non-goal landmarks). Its preferred
/// operators are the applicable operators that add a not-yet-accepted landmark whose predecessors
/// are all accepted. Used by the lazy search (`SearchAlgorithm::kLazy`) next to h_FF.
///
/// Values are counts (every landmark counts 1, as in lama-first's `cost_type=one`), never
/// `Heuristic::kDeadEnd` (dead ends are left to h_FF).

#include <cstdint>
#include <vector>

#include "tamp/symbolic_planner/task.h"

namespace tamp::symbolic_planner {

class LandmarkCounter {
 public:
  /// Finds the landmarks of reaching `goal` (one conjunct, positive facts) from `init`.
  /// Disabled (`enabled()` false, no landmarks) for disjunctive or negative goals, when a goal
  /// fact is relaxed-unreachable, or when the labels would take more than `max_label_entries`
  /// fact ids in all (memory bound for very large tasks).
  LandmarkCounter(const Task& task, const StateBits& init, const Goal& goal, size_t max_label_entries = 50'000'000);

  bool enabled() const { return !landmarks_.empty(); }
  size_t numLandmarks() const { return landmarks_.size(); }
  /// Words of an accepted-set bitset.
  size_t words() const { return words_; }
  const std::vector<FactId>& landmarks() const { return landmarks_; }

  /// Accepted set of the initial state (`init` of the constructor) into `out` (words() words).
  void initialAccepted(const uint64_t* state, uint64_t* out) const;
  /// Accepted set of `state` reached from a state with accepted set `parent`.
  void progress(const uint64_t* parent, const uint64_t* state, uint64_t* out) const;
  /// The heuristic value of `state` with accepted set `accepted`.
  Cost value(const uint64_t* state, const uint64_t* accepted) const;
  /// Appends the preferred operators of `state` (see above) to `out`.
  void preferred(const uint64_t* state, const uint64_t* accepted, std::vector<OpId>& out) const;

 private:
  bool parentsAccepted(uint32_t l, const uint64_t* accepted) const;

  const Task& task_;
  std::vector<FactId> landmarks_;              ///< landmark index -> fact
  std::vector<uint8_t> is_goal_;               ///< landmark index -> is a goal fact
  std::vector<uint32_t> parents_begin_, parents_;  ///< CSR: landmark -> ordered predecessors
  size_t words_{0};
};

}  // namespace tamp::symbolic_planner
