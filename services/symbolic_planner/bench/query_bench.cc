// Latency of one planning query on a cached grounding for a TAMP-sized task: the mobile
// manipulation domain (config/pddl) with N locations, N regions (one pre-grasp arm configuration
// each) and N items, random start states and goals (fixed seed). Compared with a query that
// grounds from scratch (new session) and with the self-contained request path (Planner, which
// parses the request every time but reuses the cached grounding).
//
//   tamp_symbolic_planner_query_bench [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <random>
#include <string>

#include "tamp/core/paths.h"
#include "tamp/symbolic_planner/planner.h"

namespace sp = tamp::symbolic_planner;

namespace {

std::string domainText() {
  auto t = tamp::readTextFile(std::string(TAMP_SOURCE_DIR) + "/config/pddl/mobile_manipulation.pddl");
  if (!t) throw std::runtime_error(t.error().toString());
  return *t;
}

/// A problem with n locations/regions/items: location i reaches stow and the arm configuration
/// over region i (and over region i+1); items start on random regions; a few occlusions.
std::string problemText(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::string s = "(define (problem tamp-" + std::to_string(n) + ") (:domain mobile-manipulation)\n (:objects";
  for (int i = 0; i < n; ++i) s += " loc" + std::to_string(i);
  s += " - location";
  for (int i = 0; i < n; ++i) s += " reg" + std::to_string(i);
  s += " - region";
  for (int i = 0; i < n; ++i) s += " over" + std::to_string(i);
  s += " - armconf";
  for (int i = 0; i < n; ++i) s += " item" + std::to_string(i);
  s += " - item)\n (:init (robot-at loc0) (arm-at stow) (hand-empty) (= (total-cost) 0)\n";
  for (int i = 0; i < n; ++i) {
    const std::string l = "loc" + std::to_string(i);
    s += "  (reaches " + l + " stow) (reaches " + l + " over" + std::to_string(i) + ") (reaches " + l + " over" +
         std::to_string((i + 1) % n) + ") (conf-over over" + std::to_string(i) + " reg" + std::to_string(i) + ")\n";
    s += "  (graspable item" + std::to_string(i) + ") (on item" + std::to_string(i) + " reg" + std::to_string(rng() % n) + ")\n";
  }
  for (int i = 0; i + 1 < n; i += 4) s += "  (occludes item" + std::to_string(i + 1) + " item" + std::to_string(i) + ")\n";
  s += " )\n (:goal (on item0 reg1)) (:metric minimize (total-cost)))\n";
  return s;
}

struct Scenario {
  std::unique_ptr<sp::PlanningSession> session;
  std::vector<sp::Query> queries;
};

Scenario makeScenario(int n) {
  Scenario sc;
  auto s = sp::PlanningSession::fromText(domainText(), problemText(n, 1));
  if (!s) throw std::runtime_error(s.error().toString());
  sc.session = std::move(*s);
  std::mt19937 rng(2024);
  auto id = [&](const std::string& p, std::vector<std::string> args) { return *sc.session->atomId({p, std::move(args)}); };
  for (int k = 0; k < 64; ++k) {
    sp::Query q;
    for (int i = 0; i < n; ++i) {
      const std::string l = "loc" + std::to_string(i);
      q.init.push_back(id("reaches", {l, "stow"}));
      q.init.push_back(id("reaches", {l, "over" + std::to_string(i)}));
      q.init.push_back(id("reaches", {l, "over" + std::to_string((i + 1) % n)}));
      q.init.push_back(id("conf-over", {"over" + std::to_string(i), "reg" + std::to_string(i)}));
      q.init.push_back(id("graspable", {"item" + std::to_string(i)}));
      q.init.push_back(id("on", {"item" + std::to_string(i), "reg" + std::to_string(rng() % n)}));
    }
    q.init.push_back(id("robot-at", {"loc" + std::to_string(rng() % n)}));
    q.init.push_back(id("arm-at", {"stow"}));
    q.init.push_back(id("hand-empty", {}));
    for (int i = 0; i + 1 < n; i += 4) {
      if (rng() % 2) q.init.push_back(id("occludes", {"item" + std::to_string(i + 1), "item" + std::to_string(i)}));
    }
    // Goal: two distinct items on random regions (one item cannot be on two regions: such a
    // goal would be unsolvable and the search would have to exhaust the state space).
    const int a = static_cast<int>(rng() % n);
    const int b = (a + 1 + static_cast<int>(rng() % (n - 1))) % n;
    for (int item : {a, b}) {
      q.goal_literals.push_back({id("on", {"item" + std::to_string(item), "reg" + std::to_string(rng() % n)}), false});
    }
    sc.queries.push_back(std::move(q));
  }
  return sc;
}

void BM_CachedQuery(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Scenario sc = makeScenario(n);
  // Warm-up: the first query grounds (and every query after it reuses the grounding).
  for (const auto& q : sc.queries) {
    auto r = sc.session->solve(q, tamp::Termination());
    if (r.status != sp::PlanStatus::kSolved) {
      state.SkipWithError(("query not solved: " + r.message).c_str());
      return;
    }
  }
  size_t k = 0;
  double plan_len = 0, reused = 0, evaluated = 0;
  int64_t runs = 0;
  for (auto _ : state) {
    sp::PlanReply r = sc.session->solve(sc.queries[k++ % sc.queries.size()], tamp::Termination());
    benchmark::DoNotOptimize(r.plan.data());
    plan_len += static_cast<double>(r.plan.size());
    evaluated += static_cast<double>(r.stats.evaluated);
    reused += r.stats.grounding_reused ? 1 : 0;
    ++runs;
  }
  state.counters["plan_len"] = plan_len / static_cast<double>(runs);
  state.counters["reused"] = reused / static_cast<double>(runs);
  state.counters["evaluated"] = evaluated / static_cast<double>(runs);
  state.counters["operators"] = static_cast<double>(sc.session->task()->ops.size());
  state.counters["facts"] = static_cast<double>(sc.session->task()->numFacts());
}
BENCHMARK(BM_CachedQuery)->Arg(10)->Arg(30)->Unit(benchmark::kMicrosecond);

void BM_QueryGroundingFromScratch(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::string dom = domainText();
  const std::string prob = problemText(n, 1);
  for (auto _ : state) {
    auto s = sp::PlanningSession::fromText(dom, prob);
    sp::Query q;
    q.init = *(*s)->problemInit();
    q.goal_formula = (*s)->problem().goal;
    sp::PlanReply r = (*s)->solve(q, tamp::Termination());
    benchmark::DoNotOptimize(r.plan.data());
  }
}
BENCHMARK(BM_QueryGroundingFromScratch)->Arg(10)->Arg(30)->Unit(benchmark::kMicrosecond);

void BM_PlannerRequestCached(benchmark::State& state) {
  // The DDS node's path: a self-contained request (domain text + problem text) every time; the
  // Planner parses it and reuses the cached grounding.
  const int n = static_cast<int>(state.range(0));
  sp::Planner planner(4);
  sp::PlanRequest req;
  req.domain_text = domainText();
  req.problem_text = problemText(n, 1);
  req.check_plan = false;
  for (auto _ : state) {
    sp::PlanReply r = planner.solve(req, tamp::Termination());
    benchmark::DoNotOptimize(r.plan.data());
  }
}
BENCHMARK(BM_PlannerRequestCached)->Arg(30)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
