#pragma once
// States of random walks on a grounded task, for the heuristic tests and the heuristic benchmark.
#include <functional>
#include <random>
#include <vector>

#include "tamp/symbolic_planner/task.h"

namespace tamp::symbolic_planner::test {

/// `init`, then the last state of each of `walks` random walks from it: walk w takes up to
/// `steps(w)` uniformly drawn applicable operators (fewer where none applies). `steps` is called
/// before walk w, with `rng` in the state it leaves it.
inline std::vector<StateBits> randomWalkStates(const Task& task, const StateBits& init, int walks,
                                               const std::function<int(int)>& steps, std::mt19937& rng) {
  std::vector<StateBits> out{init};
  std::vector<OpId> ops;
  for (int w = 0; w < walks; ++w) {
    StateBits s = init, next(init.size());
    const int n = steps(w);
    for (int k = 0; k < n; ++k) {
      ops.clear();
      task.applicableOps(s.data(), ops);
      if (ops.empty()) break;
      task.apply(s.data(), ops[rng() % ops.size()], next.data());
      s.swap(next);
    }
    out.push_back(s);
  }
  return out;
}

}  // namespace tamp::symbolic_planner::test
