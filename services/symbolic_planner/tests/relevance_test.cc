// Backward relevance analysis (relevance.h) and its use by the planner (issue 14, twenty-third
// round).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <tuple>
#include <stdexcept>
#include <stop_token>
#include <string>

#include "tamp/symbolic_planner/relevance.h"
#include "test_util.h"

namespace tamp::symbolic_planner {
namespace {

int32_t factOf(const Task& t, const std::string& name) {
  const auto it = std::find(t.fact_names.begin(), t.fact_names.end(), name);
  return it == t.fact_names.end() ? -1 : static_cast<int32_t>(it - t.fact_names.begin());
}

Operator op(const std::string& name, std::vector<FactId> pre, std::vector<FactId> add, std::vector<FactId> del,
            Cost cost = 1) {
  Operator o;
  o.name = name;
  o.pre = std::move(pre);
  o.add = std::move(add);
  o.del = std::move(del);
  o.cost = cost;
  return o;
}

Goal goalOf(std::vector<FactId> pos, std::vector<FactId> neg = {}) {
  Goal g;
  g.conjuncts.push_back(GoalConjunct{std::move(pos), std::move(neg)});
  return g;
}

// A robot moves between rooms (relevant); it can also paint rooms, and a move can put on one of
// two hats, which no goal and no precondition needs: each `move` exists once per hat, the same on
// the relevant facts as the cheaper `move-bare`.
const char* kDecorDomain = R"(
(define (domain decor)
  (:requirements :strips :typing :action-costs)
  (:types room hat)
  (:predicates (at ?r - room) (link ?a ?b - room) (painted ?r - room) (wears ?h - hat))
  (:functions (total-cost) - number)
  (:action move :parameters (?a ?b - room ?h - hat)
    :precondition (and (at ?a) (link ?a ?b))
    :effect (and (not (at ?a)) (at ?b) (wears ?h) (increase (total-cost) 2)))
  (:action move-bare :parameters (?a ?b - room)
    :precondition (and (at ?a) (link ?a ?b))
    :effect (and (not (at ?a)) (at ?b) (increase (total-cost) 1)))
  (:action paint :parameters (?r - room)
    :precondition (at ?r)
    :effect (and (painted ?r) (increase (total-cost) 1))))
)";

/// The problem's own question: its initial state and goal (the init is the parser's, so valid).
Query problemQuery(PlanningSession& s) {
  Query q;
  auto init = s.problemInit();
  if (!init.ok()) throw std::runtime_error(init.error().toString());
  q.init = *init;
  q.goal_formula = s.problem().goal;
  return q;
}

const char* kDecorProblem = R"(
(define (problem decor-1) (:domain decor)
  (:objects r1 r2 r3 - room h1 h2 - hat)
  (:init (at r1) (link r1 r2) (link r2 r3) (= (total-cost) 0))
  (:goal (at r3))
  (:metric minimize (total-cost)))
)";

TEST(Relevance, AStoppedAnalysisPrunesNothingAndSaysSo) {
  auto s = PlanningSession::fromText(kDecorDomain, kDecorProblem);
  ASSERT_TRUE(s.ok()) << s.error().toString();
  Query q = problemQuery(**s);
  q.prune_irrelevant = false;
  ASSERT_EQ((*s)->solve(q, Termination()).status, PlanStatus::kSolved);
  const Task& t = *(*s)->task();
  const Goal goal = goalOf({static_cast<FactId>(factOf(t, "(at r3)"))});
  ASSERT_TRUE(pruneIrrelevant(t, goal).pruned());  // the same analysis unstopped prunes
  std::stop_source stop;
  stop.request_stop();
  const PrunedTask p = pruneIrrelevant(t, goal, Termination(Deadline::never(), stop.get_token()));
  EXPECT_FALSE(p.pruned());
  EXPECT_TRUE(p.stats.stopped);
  EXPECT_FALSE(p.stats.unsafe);
  EXPECT_TRUE(p.fact_map.empty());
  const PrunedTask late = pruneIrrelevant(t, goal, Termination(Deadline::in(-1.0)));
  EXPECT_FALSE(late.pruned());
  EXPECT_TRUE(late.stats.stopped);
  // A session whose query is stopped during the analysis answers so, and the next query runs it.
  auto s2 = PlanningSession::fromText(kDecorDomain, kDecorProblem);
  ASSERT_TRUE(s2.ok());
  Query q2 = problemQuery(**s2);
  q2.prune_irrelevant = true;
  const PlanReply stopped = (*s2)->solve(q2, Termination(Deadline::never(), stop.get_token()));
  EXPECT_EQ(stopped.status, PlanStatus::kCancelled) << stopped.message;
  const PlanReply again = (*s2)->solve(q2, Termination());
  ASSERT_EQ(again.status, PlanStatus::kSolved) << again.message;
  EXPECT_TRUE(again.stats.relevance_ran);
  EXPECT_TRUE(again.stats.pruned);
}

TEST(Relevance, DropsWhatNoGoalNeedsAndKeepsTheCheapestOfTheSameOperators) {
  auto s = PlanningSession::fromText(kDecorDomain, kDecorProblem);
  ASSERT_TRUE(s.ok()) << s.error().toString();
  Query q = problemQuery(**s);
  q.prune_irrelevant = false;
  PlanReply full = (*s)->solve(q, Termination());
  ASSERT_EQ(full.status, PlanStatus::kSolved) << full.message;
  const Task& t = *(*s)->task();
  ASSERT_GE(factOf(t, "(at r3)"), 0);
  ASSERT_GE(factOf(t, "(painted r1)"), 0);
  const PrunedTask p = pruneIrrelevant(t, goalOf({static_cast<FactId>(factOf(t, "(at r3)"))}));
  ASSERT_TRUE(p.pruned());
  EXPECT_FALSE(p.stats.unsafe);
  // Kept: the robot's position only; the paint, the hats and their operators are gone.
  const Task& pt = *p.task;
  EXPECT_EQ(p.stats.facts_before, t.numFacts());
  EXPECT_EQ(pt.numFacts(), 3U);
  for (const std::string& n : pt.fact_names) EXPECT_EQ(n.rfind("(at ", 0), 0U) << n;
  EXPECT_EQ(factOf(pt, "(painted r1)"), -1);
  EXPECT_EQ(factOf(pt, "(wears h1)"), -1);
  // move r1 r2 x {h1, h2} and move-bare r1 r2 are the same on (at ...): one each, the cheaper.
  EXPECT_EQ(p.stats.ops_relevant, 6U);  // 2 moves x 2 hats + 2 bare moves
  EXPECT_EQ(p.stats.ops_before, 6U + 3U);  // and 3 paints
  EXPECT_EQ(p.stats.ops_after, 2U);
  ASSERT_EQ(pt.ops.size(), 2U);
  for (const Operator& o : pt.ops) {
    EXPECT_EQ(o.name.rfind("(move-bare ", 0), 0U) << o.name;
    EXPECT_EQ(o.cost, 1);
    EXPECT_EQ(t.ops[p.op_origin[&o - pt.ops.data()]].name, o.name);
  }
  // The maps: a kept fact's name is the same; the initial state projects onto the kept facts.
  for (size_t f = 0; f < t.numFacts(); ++f) {
    if (p.fact_map[f] < 0) continue;
    EXPECT_EQ(pt.fact_names[static_cast<size_t>(p.fact_map[f])], t.fact_names[f]);
  }
  // The planner searches the pruned task (a session that has not built the whole task's tables
  // yet) and its plan is checked on the full domain: the cheapest plan (2 bare moves; the whole
  // task's first plan may take the dearer moves), fewer operators searched.
  auto s2 = PlanningSession::fromText(kDecorDomain, kDecorProblem);
  ASSERT_TRUE(s2.ok());
  q.prune_irrelevant = true;
  q.init = *(*s2)->problemInit();
  PlanReply pruned = (*s2)->solve(q, Termination());
  ASSERT_EQ(pruned.status, PlanStatus::kSolved) << pruned.message;
  EXPECT_TRUE(pruned.stats.relevance_ran);
  EXPECT_TRUE(pruned.stats.pruned);
  EXPECT_EQ(pruned.stats.operators, 2U);
  EXPECT_GE(full.cost, 2);
  EXPECT_EQ(pruned.cost, 2);
  const ValidationResult v = validatePlan((*s)->domain(), (*s)->problem(), pruned.plan);
  EXPECT_TRUE(v.valid) << v.message;
}

TEST(Relevance, ASessionPrunesForItsFirstGoalOnlyAndReusesThatTask) {
  auto s = PlanningSession::fromText(kDecorDomain, kDecorProblem);
  ASSERT_TRUE(s.ok()) << s.error().toString();
  Query q = problemQuery(**s);
  PlanReply first = (*s)->solve(q, Termination());
  ASSERT_EQ(first.status, PlanStatus::kSolved);
  EXPECT_TRUE(first.stats.relevance_ran);
  EXPECT_TRUE(first.stats.pruned);
  // The same goal from another state: the pruned task again, not analysed again.
  Query again = q;
  again.init.erase(std::find(again.init.begin(), again.init.end(), *(*s)->atomId({"at", {"r1"}})));
  again.init.push_back(*(*s)->atomId({"at", {"r2"}}));
  PlanReply second = (*s)->solve(again, Termination());
  ASSERT_EQ(second.status, PlanStatus::kSolved);
  EXPECT_FALSE(second.stats.relevance_ran);
  EXPECT_TRUE(second.stats.pruned);
  EXPECT_EQ(second.plan.size(), 1U);
  // Another goal: the whole task (a session's queries keep their latency).
  Query other = q;
  other.goal_formula.reset();
  other.goal_literals = {AtomLiteral{*(*s)->atomId({"painted", {"r2"}}), false}};
  PlanReply third = (*s)->solve(other, Termination());
  ASSERT_EQ(third.status, PlanStatus::kSolved) << third.message;
  EXPECT_FALSE(third.stats.relevance_ran);
  EXPECT_FALSE(third.stats.pruned);
  EXPECT_EQ(third.stats.operators, (*s)->task()->ops.size());
  EXPECT_EQ(third.plan.size(), 2U);  // move r1 r2, paint r2
}

// Leaving out an operator the goal does not need can change what a kept conditional effect does:
// `finish` deletes g when p holds, `start` (once) is the only way to g, and only `clear` (which
// adds nothing relevant) deletes p. The analysis must see that and prune nothing; pruned, the
// task would have no plan.
const char* kTrapDomain = R"(
(define (domain trap)
  (:requirements :strips :conditional-effects)
  (:predicates (g) (h) (p) (z) (fresh))
  (:action start :parameters () :precondition (fresh) :effect (and (g) (not (fresh))))
  (:action finish :parameters () :precondition (g) :effect (and (h) (when (p) (not (g)))))
  (:action clear :parameters () :precondition (and) :effect (and (not (p)) (z))))
)";
const char* kTrapProblem = "(define (problem trap-1) (:domain trap) (:init (p) (fresh)) (:goal (and (g) (h))))";

TEST(Relevance, PrunesNothingWhereLeavingAnOperatorOutChangesAKeptConditionalEffect) {
  auto s = PlanningSession::fromText(kTrapDomain, kTrapProblem);
  ASSERT_TRUE(s.ok()) << s.error().toString();
  Query q = problemQuery(**s);
  const PlanReply r = (*s)->solve(q, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_TRUE(r.stats.relevance_ran);
  EXPECT_TRUE(r.stats.relevance.unsafe);
  EXPECT_FALSE(r.stats.pruned);
  const ValidationResult v = validatePlan((*s)->domain(), (*s)->problem(), r.plan);
  EXPECT_TRUE(v.valid) << v.message;
  ASSERT_EQ(r.plan.size(), 3U);
  EXPECT_EQ(r.plan[2].action, "finish");  // after clear and start
}

TEST(Relevance, KeepsConditionalEffectsOnKeptFactsAndDropsTheOthers) {
  // f0 goal, f1 condition, f2 irrelevant. o0 adds f0 when f1, and f2 when f1; o1 adds f1; o2
  // adds f2 only. Without operators that delete kept facts, dropping o2 is safe.
  Task t;
  t.fact_names = {"(f0)", "(f1)", "(f2)"};
  t.complement = {-1, -1, -1};
  Operator o0 = op("(o0)", {}, {}, {});
  o0.cond_effects.push_back(ConditionalEffect{{1}, {0}, {}});
  o0.cond_effects.push_back(ConditionalEffect{{}, {2}, {}});
  t.ops = {o0, op("(o1)", {}, {1}, {}), op("(o2)", {}, {2}, {})};
  t.finalize();
  const PrunedTask p = pruneIrrelevant(t, goalOf({0}));
  ASSERT_TRUE(p.pruned());
  EXPECT_EQ(p.task->numFacts(), 2U);
  ASSERT_EQ(p.task->ops.size(), 2U);
  EXPECT_EQ(p.task->ops[0].name, "(o0)");
  ASSERT_EQ(p.task->ops[0].cond_effects.size(), 1U);
  EXPECT_EQ(p.task->ops[0].cond_effects[0].cond, std::vector<FactId>{1});
  EXPECT_EQ(p.stats.cond_effects_dropped, 1U);
  EXPECT_EQ(p.task->ops[1].name, "(o1)");
  EXPECT_EQ(p.fact_map, (std::vector<int32_t>{0, 1, -1}));
  // States project bit by bit.
  StateBits s(1, 0b110);
  EXPECT_EQ(p.projectState(s.data(), 1), StateBits{0b10});
}

TEST(Relevance, AnOperatorThatFalsifiesANegativeGoalIsRelevant) {
  // Goal: f0 true and f1 false (no complement fact). o0 adds f0, o1 deletes f1 (needs f2, which
  // o2 adds), o3 adds f1 only, o4 adds f3 only.
  Task t;
  t.fact_names = {"(f0)", "(f1)", "(f2)", "(f3)"};
  t.complement = {-1, -1, -1, -1};
  t.ops = {op("(o0)", {}, {0}, {}), op("(o1)", {2}, {}, {1}), op("(o2)", {}, {2}, {}), op("(o3)", {}, {1}, {}),
           op("(o4)", {}, {3}, {})};
  t.finalize();
  const PrunedTask p = pruneIrrelevant(t, goalOf({0}, {1}));
  ASSERT_TRUE(p.pruned());
  std::vector<std::string> names;
  for (const Operator& o : p.task->ops) names.push_back(o.name);
  EXPECT_EQ(names, (std::vector<std::string>{"(o0)", "(o1)", "(o2)"}));
  EXPECT_EQ(p.fact_map, (std::vector<int32_t>{0, 1, 2, -1}));
  ASSERT_EQ(p.goal.conjuncts.size(), 1U);
  EXPECT_EQ(p.goal.conjuncts[0].neg, std::vector<FactId>{1});
}

TEST(Relevance, NothingToDropGivesNoTaskAndBadGoalsAreRefused) {
  Task t;
  t.fact_names = {"(f0)", "(f1)"};
  t.complement = {-1, -1};
  t.ops = {op("(o0)", {1}, {0}, {}), op("(o1)", {}, {1}, {})};
  t.finalize();
  const PrunedTask p = pruneIrrelevant(t, goalOf({0}));
  EXPECT_FALSE(p.pruned());
  EXPECT_FALSE(p.stats.unsafe);
  EXPECT_EQ(p.stats.ops_after, 2U);
  EXPECT_FALSE(pruneIrrelevant(t, Goal{}).pruned());  // an unsatisfiable goal: left to the search
  try {
    pruneIrrelevant(t, goalOf({7}));
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("goal fact 7"), std::string::npos) << e.what();
  }
}

/// A random STRIPS task (fixed seed): facts 0..kept-1 are reachable and may be goals, facts from
/// `kept` on are "decoration" no precondition needs. Operators come in families that differ only
/// in the decoration they add or delete, and in cost, so that many are the same on the kept
/// facts; a few add only decoration.
Task randomDecoratedTask(uint32_t seed, size_t kept, size_t decoration, size_t families) {
  std::mt19937 rng(seed);
  Task t;
  for (size_t f = 0; f < kept + decoration; ++f) t.fact_names.push_back("(f" + std::to_string(f) + ")");
  t.complement.assign(kept + decoration, -1);
  t.unit_cost = false;
  auto someOf = [&](size_t lo, size_t n, size_t k) {
    std::set<FactId> out;
    for (size_t i = 0; i < k; ++i) out.insert(static_cast<FactId>(lo + rng() % n));
    return std::vector<FactId>(out.begin(), out.end());
  };
  for (size_t fam = 0; fam < families; ++fam) {
    const auto pre = someOf(0, kept, rng() % 3);
    const auto add = someOf(0, kept, 1 + rng() % 2);
    const auto del = someOf(0, kept, rng() % 2);
    const size_t members = 1 + rng() % 4;
    for (size_t m = 0; m < members; ++m) {
      std::vector<FactId> a = add, d = del;
      for (FactId x : someOf(kept, decoration, rng() % 3)) a.push_back(x);
      for (FactId x : someOf(kept, decoration, rng() % 2)) d.push_back(x);
      std::sort(a.begin(), a.end());
      a.erase(std::unique(a.begin(), a.end()), a.end());
      std::sort(d.begin(), d.end());
      d.erase(std::unique(d.begin(), d.end()), d.end());
      const std::string name = "(o" + std::to_string(fam) + "-" + std::to_string(m) + ")";
      t.ops.push_back(op(name, pre, a, d, 1 + static_cast<Cost>(rng() % 5)));
    }
    if (rng() % 4 == 0) t.ops.push_back(op("(deco" + std::to_string(fam) + ")", {}, someOf(kept, decoration, 1), {}));
  }
  t.finalize();
  return t;
}

// The pruned operators against a brute-force grouping: the relevant operators (those adding a
// kept fact, as the task is STRIPS without negative goals), projected on the kept facts and
// grouped by (precondition, add, delete), give one pruned operator per group, at the place of the
// group's first operator, with the group's least cost and that operator's name and origin (the
// first of them on ties).
TEST(Relevance, MergedOperatorsAreTheCheapestOfEachGroupOnRandomTasks) {
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const size_t kept = 12;
    const Task t = randomDecoratedTask(seed, kept, 8, 60);
    const PrunedTask p = pruneIrrelevant(t, goalOf({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}));
    ASSERT_TRUE(p.pruned());
    auto project = [&](const std::vector<FactId>& v) {
      std::vector<FactId> out;
      for (FactId f : v) {
        if (f < kept) out.push_back(static_cast<FactId>(p.fact_map[f]));
      }
      return out;
    };
    using Key = std::tuple<std::vector<FactId>, std::vector<FactId>, std::vector<FactId>>;
    std::vector<Key> order;
    std::map<Key, OpId> best;  // the group's first cheapest operator
    for (OpId o = 0; o < t.ops.size(); ++o) {
      const Operator& x = t.ops[o];
      if (std::none_of(x.add.begin(), x.add.end(), [&](FactId f) { return f < kept; })) continue;
      const Key k{project(x.pre), project(x.add), project(x.del)};
      const auto [it, inserted] = best.emplace(k, o);
      if (inserted) order.push_back(k);
      if (x.cost < t.ops[it->second].cost) it->second = o;
    }
    ASSERT_EQ(p.task->ops.size(), order.size());
    for (size_t j = 0; j < order.size(); ++j) {
      const Operator& got = p.task->ops[j];
      const OpId want = best.at(order[j]);
      EXPECT_EQ(Key(got.pre, got.add, got.del), order[j]) << j;
      EXPECT_EQ(p.op_origin[j], want) << j;
      EXPECT_EQ(got.cost, t.ops[want].cost) << j;
      EXPECT_EQ(got.name, t.ops[want].name) << j;
    }
  }
}

TEST(Relevance, AFactRecomputedWithItsComplementKeepsBoth) {
  // f0 = (q), f1 = (not (q)) its complement; o0 needs (not (q)) and adds the goal f2; o1 adds
  // (not (q)) when f3 and (q) otherwise; o2 adds f3, o3 the irrelevant f4. Nothing needs (q)
  // itself: it is dropped, unless o1 recomputes complements after applying (needs_fixup), which
  // reads (q).
  for (bool fixup : {false, true}) {
    Task t;
    t.fact_names = {"(q)", "(not (q))", "(g)", "(c)", "(w)"};
    t.complement = {1, 0, -1, -1, -1};
    t.ops = {op("(o0)", {1}, {2}, {})};
    Operator o1 = op("(o1)", {}, {}, {});
    o1.cond_effects.push_back(ConditionalEffect{{3}, {1}, {0}});
    o1.cond_effects.push_back(ConditionalEffect{{}, {0}, {1}});
    o1.needs_fixup = fixup;
    t.ops.push_back(o1);
    t.ops.push_back(op("(o2)", {}, {3}, {}));
    t.ops.push_back(op("(o3)", {}, {4}, {}));
    t.finalize();
    const PrunedTask p = pruneIrrelevant(t, goalOf({2}));
    ASSERT_TRUE(p.pruned()) << fixup;
    EXPECT_EQ(p.fact_map[4], -1);
    if (!fixup) {
      EXPECT_EQ(p.fact_map[0], -1);
      EXPECT_EQ(p.task->complement[static_cast<size_t>(p.fact_map[1])], -1);
      continue;
    }
    ASSERT_GE(p.fact_map[0], 0);
    EXPECT_EQ(p.task->complement[static_cast<size_t>(p.fact_map[0])], p.fact_map[1]);
    EXPECT_EQ(p.task->complement[static_cast<size_t>(p.fact_map[1])], p.fact_map[0]);
  }
}

// Every plan of a pruned task is checked on the full domain: over one small instance of each
// shipped ADL domain and a few STRIPS ones (conditional effects, negation, costs), with pruning
// on and off, the same status.
TEST(Relevance, PlansOfPrunedTasksAreValidOnTheShippedSets) {
  // (folder, problem): the domain is the folder's domain.pddl.
  const std::vector<std::pair<std::string, std::string>> instances = {
      {"pddl-adl/assembly", "instance-5"},   {"pddl-adl/miconic-adl", "instance-15"},
      {"pddl-adl/citycar", "instance-1"},    {"pddl-adl/elevators", "instance-2"},
      {"pddl/logistics", "instance-4"},      {"pddl/rovers", "instance-2"},
      {"pddl-more/tpp", "instance-6"},       {"pddl-more/pathways/instance-6", "instance-6"}};
  size_t pruned_somewhere = 0;
  for (const auto& [dir, name] : instances) {
    const auto d = test::benchmarksDir() / dir;
    ASSERT_TRUE(std::filesystem::exists(d / (name + ".pddl"))) << d / (name + ".pddl");
    for (bool prune : {true, false}) {
      PlanRequest req;
      req.domain_path = (d / "domain.pddl").string();
      req.problem_path = (d / (name + ".pddl")).string();
      req.timeout_seconds = 20;
      req.prune_irrelevant = prune;
      const PlanReply r = plan(req, Termination());
      EXPECT_EQ(r.status, PlanStatus::kSolved) << dir << " " << name << " prune " << prune << ": " << r.message;
      EXPECT_EQ(r.stats.relevance_ran, prune);
      if (prune && r.stats.pruned) ++pruned_somewhere;
    }
  }
  EXPECT_GT(pruned_somewhere, 0U);
}

}  // namespace
}  // namespace tamp::symbolic_planner
