// Issue 14, twenty-ninth round: the h^2 table's work and pairs, and reachesTogether's answer and
// work for the goal from the initial state, per instance (to compare two builds' schedules).
#include <cstdio>
#include <fstream>
#include <string>

#include "tamp/core/paths.h"
#include "tamp/symbolic_planner/grounding.h"
#include "tamp/symbolic_planner/mutexes.h"
#include "tamp/symbolic_planner/pddl.h"

namespace sp = tamp::symbolic_planner;

int main(int, char** argv) {
  std::ifstream list(argv[1]);
  std::string dom, prob;
  while (list >> dom >> prob) {
    auto d = sp::pddl::parseDomain(*tamp::readTextFile(dom), dom);
    auto p = sp::pddl::parseProblem(*tamp::readTextFile(prob), *d, prob);
    auto g = sp::Grounder::create(*d, *p);
    std::vector<sp::AtomId> init;
    for (const auto& a : p->init) init.push_back(*(*g)->atomId(a));
    if (!(*g)->extend(init, tamp::Termination()).ok()) continue;
    auto neg = (*g)->negatedAtoms(p->goal);
    auto t = (*g)->buildTask(init, *neg, true, tamp::Termination());
    if (!t) continue;
    const sp::Task& task = **t;
    auto s0 = (*g)->initialState(task, init);
    auto goal = (*g)->groundGoal(p->goal, task, init);
    sp::MutexTable m(task, s0, sp::H2MutexOptions{});
    std::printf("%s table work %llu pairs %zu", prob.c_str(), (unsigned long long)m.work(), m.numMutexPairs());
    if (goal && !goal->conjuncts.empty()) {
      uint64_t w = 0;
      auto r = sp::MutexTable::reachesTogether(task, s0, goal->conjuncts[0].pos, sp::H2MutexOptions{}, &w);
      std::printf(" together %d work %llu", r ? (*r ? 1 : 0) : -1, (unsigned long long)w);
    }
    std::printf("\n");
  }
}
