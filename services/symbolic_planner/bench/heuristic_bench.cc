// Time per evaluation of the delete-relaxation heuristics on fixed states (issue 14, twenty-fourth
// round): the search's counts of a time-bounded run are no per-evaluation measure (its phases
// start and stop by time), so this evaluates the same states every repetition. The states: the
// initial state and random walks from it (fixed seed), the goal the problem's, on the task pruned to
// what is relevant to it (as the planner searches it; since the thirty-sixth round). Cost-based h_FF
// (cost + 1, what the search uses on tasks whose operators differ in cost), h_add, and h_FF with
// unit costs (the layered graph); the `Children` variants evaluate states next to each other, as a
// search does (each of the first states, then its successors; up to 4096 states).
//
//   tamp_symbolic_planner_heuristic_bench [--benchmark_filter=...] [DOMAIN PROBLEM]...
//   (default instances: shipped ones of tests/data/benchmarks; more as DOMAIN PROBLEM pairs)
#include <benchmark/benchmark.h>

#include <filesystem>
#include <iostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tamp/core/paths.h"
#include "tamp/symbolic_planner/grounding.h"
#include "tamp/symbolic_planner/heuristic.h"
#include "tamp/symbolic_planner/pddl.h"
#include "tamp/symbolic_planner/relevance.h"
#include "../tests/random_walks.h"

namespace sp = tamp::symbolic_planner;

namespace {

struct Instance {
  std::string label;
  std::shared_ptr<const sp::Task> task;
  sp::Goal goal;
  std::vector<sp::StateBits> states;
  /// Each of the first states followed by its successors, as a search evaluates them (a state's
  /// children differ from it in a few facts; the layered graph moves its layer 0 through those).
  std::vector<sp::StateBits> children;
};

std::string readOrThrow(const std::string& path) {
  auto t = tamp::readTextFile(path);
  if (!t) throw std::runtime_error(t.error().toString());
  return *t;
}

template <class T>
T orThrow(tamp::Result<T> r, const std::string& what) {
  if (!r) throw std::runtime_error(what + ": " + r.error().toString());
  return std::move(*r);
}

/// The initial state and the states of `walks` random walks of up to `length` steps from it.
std::vector<sp::StateBits> sampleStates(const sp::Task& task, const sp::StateBits& init, int walks, int length) {
  std::mt19937 rng(14);
  auto steps = [&](int) { return 1 + static_cast<int>(rng() % static_cast<unsigned>(length)); };
  return sp::test::randomWalkStates(task, init, walks, steps, rng);
}

Instance load(const std::string& domain_file, const std::string& problem_file) {
  const auto domain = orThrow(sp::pddl::parseDomain(readOrThrow(domain_file), domain_file), domain_file);
  const auto problem = orThrow(sp::pddl::parseProblem(readOrThrow(problem_file), domain, problem_file), problem_file);
  auto grounder = orThrow(sp::Grounder::create(domain, problem), "grounding");
  std::vector<sp::AtomId> init;
  for (const auto& a : problem.init) init.push_back(orThrow(grounder->atomId(a), "init atom"));
  if (!grounder->extend(init, tamp::Termination()).ok()) throw std::runtime_error("grounding failed");
  const auto negated = orThrow(grounder->negatedAtoms(problem.goal), "goal");
  Instance in;
  const std::filesystem::path p(problem_file);
  in.label = p.parent_path().filename().string() + "/" + p.stem().string();
  in.task = orThrow(grounder->buildTask(init, negated, true, tamp::Termination()), "task");
  in.goal = orThrow(grounder->groundGoal(problem.goal, *in.task, init), "goal");
  sp::StateBits start = grounder->initialState(*in.task, init);
  // The task the planner searches: pruned to what is relevant to the goal (when that is safe).
  if (auto pruned = sp::pruneIrrelevant(*in.task, in.goal); pruned.pruned()) {
    start = pruned.projectState(start.data(), in.task->numWords());
    in.task = pruned.task;
    in.goal = pruned.goal;
  }
  in.states = sampleStates(*in.task, start, 255, 60);
  std::vector<sp::OpId> ops;
  for (const auto& s : in.states) {
    if (in.children.size() >= 4096) break;
    in.children.push_back(s);
    ops.clear();
    in.task->applicableOps(s.data(), ops);
    for (sp::OpId o : ops) {
      in.children.emplace_back(s.size());
      in.task->apply(s.data(), o, in.children.back().data());
    }
  }
  return in;
}

/// Evaluates every state once per iteration; the rate is evaluations per second.
void evaluateAll(benchmark::State& st, const Instance& in, sp::HeuristicKind kind, sp::CostType ct,
                 const std::vector<sp::StateBits> Instance::*which = &Instance::states) {
  const std::vector<sp::StateBits>& states = in.*which;
  auto h = sp::makeHeuristic(kind, *in.task, ct);
  h->setGoal(in.goal);
  // What the states evaluate to, so that two builds can be compared: the sum of the finite values,
  // the number of dead ends, and a hash of the helpful actions (order included), mod 2^40.
  double hsum = 0, dead = 0;
  uint64_t pref = 0;
  for (const auto& s : states) {
    const sp::Cost v = h->evaluate(s.data());
    (v == sp::Heuristic::kDeadEnd ? dead : hsum) += v == sp::Heuristic::kDeadEnd ? 1 : static_cast<double>(v);
    for (sp::OpId o : h->preferred()) pref = (pref ^ o) * 0x100000001B3ULL;
    pref = (pref ^ 0xFFFFFFFFULL) * 0x100000001B3ULL;
  }
  int64_t sum = 0;
  for (auto _ : st) {
    for (const auto& s : states) sum += static_cast<int64_t>(h->evaluate(s.data()) % 1000003);
  }
  benchmark::DoNotOptimize(sum);
  st.SetItemsProcessed(st.iterations() * static_cast<int64_t>(states.size()));
  st.counters["ops"] = static_cast<double>(in.task->ops.size());
  st.counters["facts"] = static_cast<double>(in.task->numFacts());
  st.counters["hsum"] = hsum;
  st.counters["dead"] = dead;
  st.counters["pref"] = static_cast<double>(pref & ((1ULL << 40) - 1));
}

void registerInstance(const std::string& domain_file, const std::string& problem_file) {
  auto in = std::make_shared<Instance>(load(domain_file, problem_file));
  const bool costs = !in->task->unit_cost;
  if (costs) {
    benchmark::RegisterBenchmark(("BM_CostFF/" + in->label).c_str(), [in](benchmark::State& st) {
      evaluateAll(st, *in, sp::HeuristicKind::kFF, sp::CostType::kPlusOne);
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_CostAdd/" + in->label).c_str(), [in](benchmark::State& st) {
      evaluateAll(st, *in, sp::HeuristicKind::kAdd, sp::CostType::kPlusOne);
    })->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_CostFFChildren/" + in->label).c_str(), [in](benchmark::State& st) {
      evaluateAll(st, *in, sp::HeuristicKind::kFF, sp::CostType::kPlusOne, &Instance::children);
    })->Unit(benchmark::kMicrosecond);
  }
  benchmark::RegisterBenchmark(("BM_UnitFF/" + in->label).c_str(), [in](benchmark::State& st) {
    evaluateAll(st, *in, sp::HeuristicKind::kFF, sp::CostType::kUnit);
  })->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark(("BM_UnitFFChildren/" + in->label).c_str(), [in](benchmark::State& st) {
    evaluateAll(st, *in, sp::HeuristicKind::kFF, sp::CostType::kUnit, &Instance::children);
  })->Unit(benchmark::kMicrosecond);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  try {
    if (argc > 1) {
      if (argc % 2 != 1) throw std::invalid_argument("expected DOMAIN PROBLEM pairs after the benchmark flags");
      for (int i = 1; i + 1 < argc; i += 2) registerInstance(argv[i], argv[i + 1]);
    } else {
      const std::string b = TAMP_BENCHMARKS_DIR;
      for (const char* dp : {"pddl-more/transport/instance-30", "pddl-more/scanalyzer/instance-6",
                             "pddl-more/pegsol/instance-6", "pddl-adl/citycar/instance-4"}) {
        const std::filesystem::path p = b + "/" + dp + ".pddl";
        registerInstance((p.parent_path() / "domain.pddl").string(), p.string());
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "tamp_symbolic_planner_heuristic_bench: " << e.what() << "\n";
    return 30;
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
