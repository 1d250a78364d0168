// Issue 14, twenty-ninth round: a fingerprint of the grounded task (facts and operators in order,
// with their preconditions, effects and costs) per instance, to compare two builds' groundings.
//   dump_task LIST   (LIST: "domain_file problem_file" per line)
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "tamp/core/paths.h"
#include "tamp/symbolic_planner/grounding.h"
#include "tamp/symbolic_planner/pddl.h"

namespace sp = tamp::symbolic_planner;

int main(int argc, char** argv) {
  std::ifstream list(argv[1]);
  std::string dom, prob;
  while (list >> dom >> prob) {
    auto dt = tamp::readTextFile(dom);
    auto pt = tamp::readTextFile(prob);
    auto d = sp::pddl::parseDomain(*dt, dom);
    if (!d) { std::printf("%s parse-error\n", prob.c_str()); continue; }
    auto p = sp::pddl::parseProblem(*pt, *d, prob);
    if (!p) { std::printf("%s parse-error\n", prob.c_str()); continue; }
    auto g = sp::Grounder::create(*d, *p);
    if (!g) { std::printf("%s ground-error\n", prob.c_str()); continue; }
    std::vector<sp::AtomId> init;
    bool ok = true;
    for (const auto& a : p->init) {
      auto id = (*g)->atomId(a);
      if (!id) { ok = false; break; }
      init.push_back(*id);
    }
    if (!ok || !(*g)->extend(init, tamp::Termination()).ok()) { std::printf("%s extend-error\n", prob.c_str()); continue; }
    auto neg = (*g)->negatedAtoms(p->goal);
    if (!neg) { std::printf("%s goal-error\n", prob.c_str()); continue; }
    auto t = (*g)->buildTask(init, *neg, true, tamp::Termination());
    if (!t) { std::printf("%s task-error\n", prob.c_str()); continue; }
    const sp::Task& task = **t;
    uint64_t h = 1469598103934665603ULL;
    auto mix = [&](const std::string& s) { for (unsigned char c : s) { h ^= c; h *= 1099511628211ULL; } h ^= 0xff; h *= 1099511628211ULL; };
    auto mixv = [&](const std::vector<sp::FactId>& v) { std::string s; for (auto f : v) s += std::to_string(f) + ","; mix(s); };
    for (const auto& n : task.fact_names) mix(n);
    for (const auto& o : task.ops) {
      mix(o.name); mixv(o.pre); mixv(o.add); mixv(o.del); mix(std::to_string(o.cost));
      for (const auto& ce : o.cond_effects) { mixv(ce.cond); mixv(ce.add); mixv(ce.del); }
    }
    std::printf("%s facts %zu ops %zu hash %016llx\n", prob.c_str(), task.fact_names.size(), task.ops.size(), (unsigned long long)h);
  }
}
