#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <tuple>
#include <thread>

#include "tamp/core/termination.h"
#include "tamp/symbolic_planner/heuristic.h"
#include "tamp/symbolic_planner/landmarks.h"
#include "tamp/symbolic_planner/search.h"
#include "test_util.h"

namespace tamp::symbolic_planner {
namespace {

/// A request for `instance` of a benchmark folder (its domain.pddl) under tests/data/benchmarks.
PlanRequest benchmarkRequest(const std::string& folder, const std::string& instance) {
  const auto dir = test::benchmarksDir() / folder;
  PlanRequest req;
  req.domain_text = test::readFile(dir / "domain.pddl");
  req.problem_text = test::readFile(dir / instance);
  return req;
}

class EverySearch : public ::testing::TestWithParam<SearchAlgorithm> {};

TEST_P(EverySearch, SolvesTheAdlTaskWithACheckedPlan) {
  PlanReply r = test::planText(test::kAdlDomain, test::kAdlProblem, GetParam());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;  // check_plan: replayed by the checker
  EXPECT_GT(r.plan.size(), 5U);
  EXPECT_GT(r.cost, 0);
}

TEST_P(EverySearch, SolvesTheMobileManipulationProblems) {
  const auto dir = test::sourceDir() / "config/pddl";
  const std::string dom = test::readFile(dir / "mobile_manipulation.pddl");
  for (const char* p : {"occluded_can.pddl", "namo_corridor.pddl", "holding_start.pddl"}) {
    PlanReply r = test::planText(dom, test::readFile(dir / "problems" / p), GetParam());
    ASSERT_EQ(r.status, PlanStatus::kSolved) << p << ": " << r.message;
  }
}

TEST_P(EverySearch, ProvesUnsolvabilityByExhaustion) {
  // Relaxed solvable (apply both actions), really unsolvable: each action deletes what the other
  // adds. Every search (EHC through its best-first fallback) must exhaust the space and say so.
  const std::string dom = R"((define (domain swap) (:predicates (p) (q))
    (:action a :parameters () :effect (and (p) (not (q))))
    (:action b :parameters () :effect (and (q) (not (p))))))";
  const std::string prob = "(define (problem x) (:domain swap) (:init) (:goal (and (p) (q))))";
  PlanReply r = test::planText(dom, prob, GetParam());
  EXPECT_EQ(r.status, PlanStatus::kUnsolvable) << r.message;
  EXPECT_GT(r.stats.expanded, 0U);
}

TEST_P(EverySearch, SolvesATaskWithoutFactsWithTheEmptyPlan) {
  // No action changes anything, so grounding leaves no fact at all (the goal atom is static and
  // true): the state is zero bits long. It used to have zero words, and the search read past an
  // empty buffer (a crash, found on a PDDL file written for the twenty-second round).
  const std::string dom = R"((define (domain still) (:requirements :strips) (:predicates (p))
    (:action wait :parameters () :precondition (and) :effect (and))))";
  for (const char* goal : {"(and)", "(p)"}) {
    const std::string prob = std::string("(define (problem x) (:domain still) (:init (p)) (:goal ") + goal + "))";
    PlanReply r = test::planText(dom, prob, GetParam());
    ASSERT_EQ(r.status, PlanStatus::kSolved) << goal << ": " << r.message;
    EXPECT_TRUE(r.plan.empty()) << goal;
  }
  // The same task whose goal atom is static and false is proven unsolvable.
  PlanReply r = test::planText(dom, "(define (problem y) (:domain still) (:init) (:goal (p)))", GetParam());
  EXPECT_EQ(r.status, PlanStatus::kUnsolvable) << r.message;
}

INSTANTIATE_TEST_SUITE_P(All, EverySearch,
                         ::testing::Values(SearchAlgorithm::kEhc, SearchAlgorithm::kGbfs, SearchAlgorithm::kLazy,
                                           SearchAlgorithm::kWAstar, SearchAlgorithm::kAstar),
                         [](const ::testing::TestParamInfo<SearchAlgorithm>& i) { return toString(i.param); });

TEST(Search, AstarIsCostOptimalAndWastarWithinItsBound) {
  // A cost trap: the short route (2 actions) costs 20, the long route (4 actions) costs 4.
  const std::string dom = R"((define (domain trap) (:requirements :typing :action-costs)
    (:types node) (:predicates (at ?n - node) (edge ?a ?b - node))
    (:functions (total-cost) - number (w ?a ?b - node) - number)
    (:action go :parameters (?a ?b - node) :precondition (and (at ?a) (edge ?a ?b))
      :effect (and (not (at ?a)) (at ?b) (increase (total-cost) (w ?a ?b))))))";
  const std::string prob = R"((define (problem p) (:domain trap) (:objects s m g x1 x2 x3 - node)
    (:init (at s) (edge s m) (edge m g) (edge s x1) (edge x1 x2) (edge x2 x3) (edge x3 g)
      (= (w s m) 10) (= (w m g) 10) (= (w s x1) 1) (= (w x1 x2) 1) (= (w x2 x3) 1) (= (w x3 g) 1)
      (= (total-cost) 0))
    (:goal (at g)) (:metric minimize (total-cost))))";
  PlanReply a = test::planText(dom, prob, SearchAlgorithm::kAstar);
  ASSERT_EQ(a.status, PlanStatus::kSolved) << a.message;
  EXPECT_EQ(a.cost, 4);
  EXPECT_EQ(a.plan.size(), 4U);
  PlanReply w = test::planText(dom, prob, SearchAlgorithm::kWAstar);
  ASSERT_EQ(w.status, PlanStatus::kSolved);
  EXPECT_LE(w.cost, 5 * 4);
}

TEST(Search, RespectsDeadlineStopTokenAndMemoryBudget) {
  PlanRequest req = benchmarkRequest("pddl/blocks", "instance-80.pddl");  // far beyond a few milliseconds
  req.search.algorithm = SearchAlgorithm::kGbfs;
  req.timeout_seconds = 0.05;
  PlanReply r = plan(req, Termination());
  EXPECT_EQ(r.status, PlanStatus::kTimeout) << r.message;

  std::stop_source stop;
  req.timeout_seconds = 0;
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    stop.request_stop();
  });
  PlanReply c = plan(req, Termination(Deadline::never(), stop.get_token()));
  canceller.join();
  EXPECT_EQ(c.status, PlanStatus::kCancelled) << c.message;

  req.search.memory_limit_mb = 1;
  req.timeout_seconds = 60;
  PlanReply m = plan(req, Termination());
  EXPECT_EQ(m.status, PlanStatus::kOutOfMemory) << m.message;
}

TEST(Search, SecondEhcRunKeepsTheCheaperPlan) {
  // blocks-20: the FF-v2.3-order run gives a 50-step plan for an initial h of 5; the default EHC,
  // run second within its budget, a shorter one. Either way the plan is checked.
  PlanRequest req = benchmarkRequest("pddl/blocks", "instance-20.pddl");
  req.search.ehc_second_budget_per_step = 0;
  PlanReply one = plan(req, Termination());
  ASSERT_EQ(one.status, PlanStatus::kSolved) << one.message;
  EXPECT_FALSE(one.stats.ehc_second_ran);
  req.search.ehc_second_budget_per_step = 300;
  PlanReply two = plan(req, Termination());
  ASSERT_EQ(two.status, PlanStatus::kSolved) << two.message;
  EXPECT_TRUE(two.stats.ehc_second_ran);
  EXPECT_LE(two.cost, one.cost);
  EXPECT_EQ(two.stats.ehc_second_won, two.cost < one.cost);
  EXPECT_GT(two.stats.evaluated, one.stats.evaluated);
}

/// Appends an operator to a hand-built task.
void addOp(Task& t, const char* name, std::vector<FactId> pre, std::vector<FactId> add, std::vector<FactId> del = {}) {
  Operator o;
  o.name = name;
  o.pre = std::move(pre);
  o.add = std::move(add);
  o.del = std::move(del);
  t.ops.push_back(o);
}

/// a -> b (o1), b -> c (o2), a -> c (o3), c -> g (o4); g -> not g, d (o5).
Task diamondTask() {
  Task t;
  t.fact_names = {"(a)", "(b)", "(c)", "(g)", "(d)"};
  t.complement.assign(5, -1);
  auto op = [&](const char* name, std::vector<FactId> pre, std::vector<FactId> add, std::vector<FactId> del = {}) {
    addOp(t, name, std::move(pre), std::move(add), std::move(del));
  };
  op("(o1)", {0}, {1});
  op("(o2)", {1}, {2});
  op("(o3)", {0}, {2});
  op("(o4)", {2}, {3});
  op("(o5)", {3}, {4}, {3});
  t.finalize();
  return t;
}

/// h_FF that takes at least `spin` per evaluation, as it does on a task with 10^5 operators.
class SlowFF : public Heuristic {
 public:
  SlowFF(const Task& t, std::chrono::microseconds spin)
      : ff_(makeHeuristic(HeuristicKind::kFF, t, CostType::kUnit)), spin_(spin) {}
  void setGoal(const Goal& goal) override { ff_->setGoal(goal); }
  Cost evaluate(const uint64_t* state) override {
    const auto until = std::chrono::steady_clock::now() + spin_;
    while (std::chrono::steady_clock::now() < until) {
    }
    return ff_->evaluate(state);
  }
  const std::vector<OpId>& preferred() const override { return ff_->preferred(); }
  bool computesPreferred() const override { return ff_->computesPreferred(); }

 private:
  std::unique_ptr<Heuristic> ff_;
  std::chrono::microseconds spin_;
};

TEST(Search, EhcStopsAtTheDeadlineWithinANodeOfManySlowSuccessors) {
  // 200 independent goals, one operator each: every operator is helpful, so each hill-climbing
  // node evaluates up to 200 successors (300 us each here). The clock used to be read every 256
  // nodes only; the whole 200-node plan (about 6 s) then came before the first read and the
  // 20 ms deadline was overrun 300-fold. It is now also read after every 16 evaluations.
  Task t;
  Goal goal;
  goal.conjuncts.emplace_back();
  for (FactId f = 0; f < 200; ++f) {
    t.fact_names.push_back("(g" + std::to_string(f) + ")");
    addOp(t, "(set)", {}, {f});
    goal.conjuncts[0].pos.push_back(f);
  }
  t.complement.assign(t.fact_names.size(), -1);
  t.finalize();
  SearchOptions opt;
  opt.goal_agenda = false;  // all goals at once: one node, 200 helpful successors
  opt.ehc_lazy_beside = false;
  opt.ehc_ff_first = false;
  SlowFF h(t, std::chrono::microseconds(300));
  const Stopwatch clock;
  const SearchResult r = search(t, StateBits(t.numWords(), 0), goal, opt, h, Termination::after(0.02));
  EXPECT_EQ(r.status, SearchStatus::kTimeout);
  EXPECT_LT(clock.seconds(), 0.5);  // about 0.03 s; 0.5 leaves room for a loaded machine
  EXPECT_LT(r.stats.evaluated, 100U);
}

TEST(Landmarks, FindsTheCausalLandmarksAndCountsThemAlongAPath) {
  const Task t = diamondTask();
  StateBits s0(t.numWords(), 0);
  setBit(s0.data(), 0);
  Goal goal;
  goal.conjuncts.push_back(GoalConjunct{{3, 4}, {}});
  LandmarkCounter lm(t, s0, goal);  // Zhu-Givan, accepted after parents
  ASSERT_TRUE(lm.enabled());
  // b is avoidable (o3 reaches c from a); a, c, g and d are not.
  EXPECT_EQ(lm.graph().landmarks, (std::vector<std::vector<FactId>>{{0}, {2}, {3}, {4}}));
  std::vector<uint64_t> acc0(lm.words()), acc1(lm.words()), acc2(lm.words()), acc3(lm.words());
  lm.initial(s0.data(), acc0.data());
  EXPECT_EQ(lm.value(s0.data(), acc0.data()), 3);  // c, g, d
  std::vector<OpId> pref;
  lm.preferred(s0.data(), acc0.data(), pref);
  EXPECT_EQ(pref, (std::vector<OpId>{2}));  // o3 adds c, whose predecessor a is accepted
  StateBits s1(t.numWords()), s2(t.numWords()), s3(t.numWords());
  t.apply(s0.data(), 2, s1.data());
  lm.progress(s0.data(), acc0.data(), s1.data(), acc1.data());
  EXPECT_EQ(lm.value(s1.data(), acc1.data()), 2);
  t.apply(s1.data(), 3, s2.data());
  lm.progress(s1.data(), acc1.data(), s2.data(), acc2.data());
  EXPECT_EQ(lm.value(s2.data(), acc2.data()), 1);
  // o5 reaches d but deletes the goal g, accepted before: g is required again.
  t.apply(s2.data(), 4, s3.data());
  lm.progress(s2.data(), acc2.data(), s3.data(), acc3.data());
  EXPECT_EQ(lm.value(s3.data(), acc3.data()), 1);
  // Disjunctive goals are not handled: no landmarks.
  Goal dnf;
  dnf.conjuncts = {GoalConjunct{{3}, {}}, GoalConjunct{{4}, {}}};
  EXPECT_FALSE(LandmarkCounter(t, s0, dnf).enabled());
  EXPECT_TRUE(rhwLandmarks(t, s0, dnf, RhwLandmarkOptions{}).empty());
}

/// Two tents, one key: (walk tN) needs the key and tent N at the place, and reaches the goal g;
/// (move tN) and (get key) need start; (drop key) deletes the key. `same_walk_name`: both walks
/// are one ground action split by grounding (one disjunctive precondition), as their name says.
Task tentTask(bool same_walk_name) {
  Task t;
  t.fact_names = {"(at t0 p)", "(at t1 p)", "(key)", "(g)", "(start)"};
  t.complement.assign(5, -1);
  auto op = [&](const char* name, std::vector<FactId> pre, std::vector<FactId> add, std::vector<FactId> del = {}) {
    addOp(t, name, std::move(pre), std::move(add), std::move(del));
  };
  op(same_walk_name ? "(walk)" : "(walk t0)", {0, 2}, {3});
  op(same_walk_name ? "(walk)" : "(walk t1)", {1, 2}, {3});
  op("(move t0)", {4}, {0});
  op("(move t1)", {4}, {1});
  op("(get key)", {4}, {2});
  op("(drop key)", {2}, {}, {2});
  t.finalize();
  return t;
}

bool hasOrder(const LandmarkGraph& g, const std::vector<FactId>& from, const std::vector<FactId>& to,
              LandmarkOrderKind kind) {
  for (const LandmarkOrder& o : g.orders) {
    if (g.landmarks[o.from] == from && g.landmarks[o.to] == to && o.kind == kind) return true;
  }
  return false;
}

TEST(Landmarks, RhwFindsSharedAndDisjunctivePreconditionsWithGreedyNecessaryOrders) {
  const Task t = tentTask(false);
  StateBits s0(t.numWords(), 0);
  setBit(s0.data(), 4);
  Goal goal;
  goal.conjuncts.push_back(GoalConjunct{{3}, {}});
  for (bool zg : {false, true}) {
    RhwLandmarkOptions opt;
    opt.add_zhu_givan = zg;
    const LandmarkGraph g = rhwLandmarks(t, s0, goal, opt);
    std::vector<std::vector<FactId>> lms = g.landmarks;
    std::sort(lms.begin(), lms.end());
    // The key (shared by both walks), one of the tents (one `at` precondition of each), start.
    EXPECT_EQ(lms, (std::vector<std::vector<FactId>>{{0, 1}, {2}, {3}, {4}})) << zg;
    EXPECT_EQ(g.numDisjunctive(), 1U);
    const auto gn = LandmarkOrderKind::kGreedyNecessary;
    EXPECT_TRUE(hasOrder(g, {2}, {3}, gn));
    EXPECT_TRUE(hasOrder(g, {0, 1}, {3}, gn));
    EXPECT_TRUE(hasOrder(g, {4}, {2}, gn));
    EXPECT_TRUE(hasOrder(g, {4}, {0, 1}, gn));
    EXPECT_EQ(g.numOrders(gn), 4U);
  }
  // No disjunction larger than allowed.
  RhwLandmarkOptions one;
  one.max_disjunction_size = 1;
  EXPECT_EQ(rhwLandmarks(t, s0, goal, one).numDisjunctive(), 0U);
  // The same two walks as one action split by its disjunctive precondition: no disjunctive
  // landmark restating that precondition, unless asked for (Fast Downward's behaviour).
  const Task split = tentTask(true);
  RhwLandmarkOptions opt;
  EXPECT_EQ(rhwLandmarks(split, s0, goal, opt).numDisjunctive(), 0U);
  EXPECT_EQ(rhwLandmarks(split, s0, goal, opt).landmarks.size(), 3U);  // g, key, start
  opt.skip_one_action_disjunctions = false;
  EXPECT_EQ(rhwLandmarks(split, s0, goal, opt).numDisjunctive(), 1U);
  opt.max_work = 0;
  EXPECT_THROW(rhwLandmarks(split, s0, goal, opt), std::invalid_argument);
}

TEST(Landmarks, PastAndFutureCountsLandmarksRequiredAgain) {
  const Task t = tentTask(false);
  StateBits s(t.numWords(), 0);
  setBit(s.data(), 4);
  Goal goal;
  goal.conjuncts.push_back(GoalConjunct{{3}, {}});
  LandmarkCounter lm(t, rhwLandmarks(t, s, goal, RhwLandmarkOptions{}), LandmarkProgression::kPastAndFuture);
  ASSERT_EQ(lm.numLandmarks(), 4U);
  std::vector<uint64_t> st(lm.words()), next(lm.words());
  lm.initial(s.data(), st.data());
  EXPECT_EQ(lm.value(s.data(), st.data()), 3);  // g, key, a tent
  std::vector<OpId> pref;
  lm.preferred(s.data(), st.data(), pref);
  std::sort(pref.begin(), pref.end());
  EXPECT_EQ(pref, (std::vector<OpId>{2, 3, 4}));  // adds a tent or the key
  auto step = [&](OpId o) {
    StateBits n(t.numWords());
    ASSERT_TRUE(t.applicable(s.data(), o)) << o;
    t.apply(s.data(), o, n.data());
    lm.progress(s.data(), st.data(), n.data(), next.data());
    s.swap(n);
    st.swap(next);
  };
  step(4);  // get key
  EXPECT_EQ(lm.value(s.data(), st.data()), 2);
  step(2);  // move t0: the disjunction holds
  EXPECT_EQ(lm.value(s.data(), st.data()), 1);
  step(5);  // drop key: past, but greedy-necessary before g, not reached yet: required again
  EXPECT_EQ(lm.value(s.data(), st.data()), 2);
  step(4);
  EXPECT_EQ(lm.value(s.data(), st.data()), 1);
  step(0);  // walk t0: the goal
  EXPECT_EQ(lm.value(s.data(), st.data()), 0);
  step(5);  // the key is no longer needed once g is past
  EXPECT_EQ(lm.value(s.data(), st.data()), 0);
}

TEST(Landmarks, PastAndFutureKeepsALandmarkReachedBeforeItsReasonablePredecessorFuture) {
  // a reasonably before b: b reached first stays future until added again after a.
  Task t;
  t.fact_names = {"(a)", "(b)"};
  t.complement.assign(2, -1);
  const std::vector<std::tuple<const char*, int, int>> ops = {{"(add a)", 0, -1}, {"(add b)", 1, -1}, {"(del b)", -1, 1}};
  for (const auto& [name, add, del] : ops) {
    Operator o;
    o.name = name;
    if (add >= 0) o.add = {static_cast<FactId>(add)};
    if (del >= 0) o.del = {static_cast<FactId>(del)};
    t.ops.push_back(o);
  }
  t.finalize();
  LandmarkGraph g;
  g.landmarks = {{0}, {1}};
  g.is_goal = {0, 0};
  g.orders = {{0, 1, LandmarkOrderKind::kReasonable}};
  LandmarkCounter lm(t, g, LandmarkProgression::kPastAndFuture);
  StateBits s(t.numWords(), 0);
  std::vector<uint64_t> st(lm.words()), next(lm.words());
  lm.initial(s.data(), st.data());
  EXPECT_EQ(lm.value(s.data(), st.data()), 2);
  auto step = [&](OpId o) {
    StateBits n(t.numWords());
    t.apply(s.data(), o, n.data());
    lm.progress(s.data(), st.data(), n.data(), next.data());
    s.swap(n);
    st.swap(next);
  };
  step(1);  // b before a
  EXPECT_EQ(lm.value(s.data(), st.data()), 2);
  step(0);  // a: past; b held already, not added now: still future
  EXPECT_EQ(lm.value(s.data(), st.data()), 1);
  step(2);
  step(1);  // b added again after a
  EXPECT_EQ(lm.value(s.data(), st.data()), 0);
  // Misuse: a disjunctive landmark where only simple ones are counted, an order to nowhere.
  LandmarkGraph disj = g;
  disj.landmarks = {{0, 1}, {1}};
  EXPECT_THROW(LandmarkCounter(t, disj, LandmarkProgression::kAcceptedAfterParents), std::invalid_argument);
  LandmarkGraph bad = g;
  bad.orders.push_back({0, 7, LandmarkOrderKind::kNatural});
  EXPECT_THROW(LandmarkCounter(t, bad, LandmarkProgression::kPastAndFuture), std::invalid_argument);
}

TEST(Search, LazySearchWithRhwLandmarksNeedsFewerEvaluations) {
  // hiking-4 (deterministic counts): the lazy search alone with the RHW landmarks (disjunctive:
  // a tent at each place) needs 8945 evaluations, with the Zhu-Givan ones 21721; pathways-6:
  // 30541 against 924909 (the landmarks required again). Checked plans.
  for (const auto& [folder, instance] : std::vector<std::pair<std::string, std::string>>{
           {"pddl-more/hiking", "instance-4.pddl"}, {"pddl-more/pathways/instance-6", "instance-6.pddl"}}) {
    SCOPED_TRACE(folder);
    PlanRequest req = benchmarkRequest(folder, instance);
    req.search.algorithm = SearchAlgorithm::kLazy;
    req.timeout_seconds = 120;
    ASSERT_EQ(req.search.landmark_generator, LandmarkGenerator::kRhw);  // the default
    ASSERT_TRUE(req.search.rhw.reasonable_orders);                       // the default
    PlanReply with_reasonable = plan(req, Termination());
    req.search.rhw.reasonable_orders = false;  // the sixteenth round's count
    PlanReply rhw = plan(req, Termination());
    req.search.landmark_generator = LandmarkGenerator::kZhuGivan;
    PlanReply zg = plan(req, Termination());
    ASSERT_EQ(with_reasonable.status, PlanStatus::kSolved) << with_reasonable.message;
    ASSERT_EQ(rhw.status, PlanStatus::kSolved) << rhw.message;
    ASSERT_EQ(zg.status, PlanStatus::kSolved) << zg.message;
    EXPECT_LT(rhw.stats.evaluated * 2, zg.stats.evaluated);
    // With the reasonable orders (seventeenth round): hiking-4 11208, pathways-6 fewer still.
    EXPECT_LT(with_reasonable.stats.evaluated, zg.stats.evaluated);
    EXPECT_GT(rhw.stats.landmark_gn_orders, 0U);
    EXPECT_EQ(zg.stats.landmarks_disjunctive, 0U);
  }
}

TEST(Search, LazySearchWithAndWithoutLandmarksAndEhcFallbackBudgetGiveCheckedPlans) {
  const auto dir = test::benchmarksDir() / "pddl/logistics";
  for (int variant = 0; variant < 3; ++variant) {
    PlanRequest req;
    req.domain_text = test::readFile(dir / "domain.pddl");
    req.problem_text = test::readFile(dir / "instance-12.pddl");
    req.search.algorithm = variant < 2 ? SearchAlgorithm::kLazy : SearchAlgorithm::kEhc;
    req.search.landmarks = variant == 0;
    if (variant == 2) {  // hill-climbing gives up at once: the plan comes from the lazy search
      req.search.ehc_fallback_budget_per_h = 1;
      req.search.ehc_fallback_budget_min = 1;
      req.search.ehc_ff_first = false;
    }
    req.timeout_seconds = 120;
    PlanReply r = plan(req, Termination());
    ASSERT_EQ(r.status, PlanStatus::kSolved) << variant << ": " << r.message;  // replayed by the checker
    if (variant == 2) {
      EXPECT_TRUE(r.stats.ehc_failed);
    }
  }
}

TEST(Search, EhcPlateauSearchedAgainWithoutPruningIsBoundedByItsShareOfTheBudget) {
  // psr-small-40: the helpful actions exhaust a plateau, and searched again with every action the
  // plateaus are large (tens of thousands of evaluations). Bounded, the hill-climbing gives up
  // on the first such plateau and the plan comes from the complete search; unbounded, it
  // wanders until the whole fallback budget is spent. Both plans are replayed by the checker.
  PlanRequest req = benchmarkRequest("pddl-more/psr-small/instance-40", "instance-40.pddl");
  req.timeout_seconds = 120;
  req.search.ehc_lazy_beside = false;  // the hill-climbing's own mechanism, alone
  PlanReply bounded = plan(req, Termination());
  ASSERT_EQ(bounded.status, PlanStatus::kSolved) << bounded.message;
  EXPECT_GE(bounded.stats.ehc_retries_abandoned, 1U);
  EXPECT_TRUE(bounded.stats.ehc_failed);
  req.search.ehc_retry_budget_share = 0;
  PlanReply unbounded = plan(req, Termination());
  ASSERT_EQ(unbounded.status, PlanStatus::kSolved) << unbounded.message;
  EXPECT_EQ(unbounded.stats.ehc_retries_abandoned, 0U);
  EXPECT_GE(unbounded.stats.ehc_retries, 1U);
  EXPECT_TRUE(unbounded.stats.ehc_failed);  // out of the fallback budget instead
  EXPECT_GT(unbounded.stats.evaluated, bounded.stats.evaluated);
}

TEST(Search, EhcFallbackInsideAGoalAgendaEntryIsFinal) {
  // psr-small-40: the default hill-climbing fails inside its first goal-agenda entry (of two).
  // The complete search it falls back to searches for the whole goal from the initial state, so
  // its plan is the answer: the run costs exactly the hill-climbing up to its failure (measured
  // with the fallback off) plus the lazy search alone, and returns the lazy search's plan. (It
  // used to go on to the next entry from the hill-climbing's own plan, discarding that plan,
  // and fall back a second time there: 11949 evaluations instead of 6076 + 351.)
  PlanRequest req = benchmarkRequest("pddl-more/psr-small/instance-40", "instance-40.pddl");
  req.timeout_seconds = 120;
  req.search.ehc_lazy_beside = false;  // the fallback after the hill-climbing, alone
  PlanReply with = plan(req, Termination());
  ASSERT_EQ(with.status, PlanStatus::kSolved) << with.message;  // replayed by the checker
  EXPECT_EQ(with.stats.ehc_fallbacks, 1U);
  EXPECT_EQ(with.stats.ehc_fallbacks_in_agenda, 1U);
  req.search.ehc_fallback = false;
  PlanReply climbing = plan(req, Termination());
  ASSERT_EQ(climbing.status, PlanStatus::kFailed) << climbing.message;
  EXPECT_EQ(climbing.stats.ehc_fallbacks, 0U);
  req.search.ehc_fallback = true;
  req.search.algorithm = SearchAlgorithm::kLazy;
  PlanReply lazy = plan(req, Termination());
  ASSERT_EQ(lazy.status, PlanStatus::kSolved) << lazy.message;
  EXPECT_EQ(with.stats.evaluated, climbing.stats.evaluated + lazy.stats.evaluated);
  EXPECT_EQ(with.plan, lazy.plan);
}

TEST(Search, LazySearchBesideTheHillClimbingGivesThePlanWithFewerEvaluationsTheSameEveryRun) {
  // psr-small-40: both hill-climbing runs fail (the second inside a goal-agenda entry), and the
  // lazy search alone needs a few hundred evaluations. Beside the hill-climbing (from 4000
  // evaluations on, turns of 100), it gives the plan before the hill-climbing gives up: fewer
  // evaluations than the hill-climbing followed by the lazy search (6427), and the same plan and
  // evaluations in a second run (the turns are counted in evaluations, not time). Checked plans.
  PlanRequest req = benchmarkRequest("pddl-more/psr-small/instance-40", "instance-40.pddl");
  req.timeout_seconds = 120;
  ASSERT_TRUE(req.search.ehc_lazy_beside);  // the default
  PlanReply beside = plan(req, Termination());
  ASSERT_EQ(beside.status, PlanStatus::kSolved) << beside.message;
  EXPECT_TRUE(beside.stats.lazy_beside_started);
  EXPECT_TRUE(beside.stats.lazy_beside_won);
  PlanReply again = plan(req, Termination());
  ASSERT_EQ(again.status, PlanStatus::kSolved) << again.message;
  EXPECT_EQ(again.stats.evaluated, beside.stats.evaluated);
  EXPECT_EQ(again.plan, beside.plan);
  req.search.ehc_lazy_beside = false;
  PlanReply after = plan(req, Termination());
  ASSERT_EQ(after.status, PlanStatus::kSolved) << after.message;
  EXPECT_FALSE(after.stats.lazy_beside_started);
  EXPECT_TRUE(after.stats.ehc_failed);
  EXPECT_LT(beside.stats.evaluated, after.stats.evaluated);
  EXPECT_GT(beside.stats.evaluated, req.search.ehc_lazy_after);  // the hill-climbing's share included
}

TEST(Search, LazySearchBesideNotStartedChangesNothing) {
  // A hill-climbing that needs fewer evaluations than `ehc_lazy_after` (openstacks-6: 275) never
  // meets the lazy search; one that gives up before (psr-small-40 with the lazy search starting
  // only after 10^9 evaluations) is followed by the lazy search from the start, exactly as with
  // the option off: the same plan and evaluations either way.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"pddl-more/openstacks", "instance-6.pddl"},
      {"pddl-more/psr-small/instance-40", "instance-40.pddl"},
  };
  for (const auto& [folder, instance] : cases) {
    SCOPED_TRACE(folder);
    PlanRequest req = benchmarkRequest(folder, instance);
    req.timeout_seconds = 120;
    req.search.ehc_lazy_after = 1'000'000'000;
    PlanReply on = plan(req, Termination());
    req.search.ehc_lazy_beside = false;
    PlanReply off = plan(req, Termination());
    ASSERT_EQ(on.status, PlanStatus::kSolved) << on.message;
    ASSERT_EQ(off.status, PlanStatus::kSolved) << off.message;
    EXPECT_FALSE(on.stats.lazy_beside_started);
    EXPECT_EQ(on.stats.evaluated, off.stats.evaluated);
    EXPECT_EQ(on.stats.ehc_failed, off.stats.ehc_failed);
    EXPECT_EQ(on.plan, off.plan);
  }
}

TEST(Search, LazySearchBesidePrefersTheRelaxedPlansOperatorsAndNoneOfTheLandmarkCounts) {
  // hiking-4: both hill-climbing runs give up and the lazy search beside them gives the plan.
  // With LAMA-first's preferred operators (`lazy_plan_preferred`, off by default) it needs fewer
  // evaluations than with FF's helpful actions and the landmarks' achievers (20 833 against
  // 36 497 when written); the same plan and count in a second run; both plans checked.
  PlanRequest req = benchmarkRequest("pddl-more/hiking", "instance-4.pddl");
  req.timeout_seconds = 120;
  ASSERT_FALSE(req.search.lazy_plan_preferred);  // the default
  req.search.lazy_plan_preferred = true;
  PlanReply lama = plan(req, Termination());
  ASSERT_EQ(lama.status, PlanStatus::kSolved) << lama.message;  // replayed by the checker
  EXPECT_TRUE(lama.stats.lazy_beside_won);
  PlanReply again = plan(req, Termination());
  ASSERT_EQ(again.status, PlanStatus::kSolved) << again.message;
  EXPECT_EQ(again.stats.evaluated, lama.stats.evaluated);
  EXPECT_EQ(again.plan, lama.plan);
  req.search.lazy_plan_preferred = false;
  req.search.lazy_beside_both = false;  // the default lazy search alone beside the hill-climbing
  PlanReply ff = plan(req, Termination());
  ASSERT_EQ(ff.status, PlanStatus::kSolved) << ff.message;
  EXPECT_TRUE(ff.stats.lazy_beside_won);
  EXPECT_LT(lama.stats.evaluated * 3, ff.stats.evaluated * 2);
  // openstacks-6: the hill-climbing needs fewer evaluations than `ehc_lazy_after`, so the lazy
  // search never starts and the option changes nothing (the hill-climbing keeps FF's helpful
  // actions).
  PlanRequest os = benchmarkRequest("pddl-more/openstacks", "instance-6.pddl");
  os.timeout_seconds = 120;
  os.search.lazy_plan_preferred = true;
  PlanReply on = plan(os, Termination());
  os.search.lazy_plan_preferred = false;
  PlanReply off = plan(os, Termination());
  ASSERT_EQ(on.status, PlanStatus::kSolved) << on.message;
  ASSERT_EQ(off.status, PlanStatus::kSolved) << off.message;
  EXPECT_FALSE(on.stats.lazy_beside_started);
  EXPECT_EQ(on.stats.evaluated, off.stats.evaluated);
  EXPECT_EQ(on.plan, off.plan);
}

TEST(Search, TwoLazySearchesBesideTheHillClimbingGiveTheFirstAnswerOfEither) {
  // `lazy_beside_both`: the default lazy search and one with LAMA-first's preferred operators take
  // turns beside the hill-climbing. Each searches as it would alone (its own states, heuristic
  // and turns counted in its own evaluations), so the answer is the plan of whichever finds one
  // first: on hiking-4 LAMA-first's (the plan of the `lazy_plan_preferred` run), on depots-6 the
  // default one's (main's plan; LAMA-first's alone does not finish in 60 s). Both checked, with
  // more evaluations than that search's run (the other's are counted), the same in a second run.
  // Both start together here (`lazy_second_after` 0); the default's delay is tested below.
  struct Case {
    std::string folder, instance;
    bool lama_first_wins;
  };
  const std::vector<Case> cases = {{"pddl-more/hiking", "instance-4.pddl", true},
                                   {"pddl/depots", "instance-6.pddl", false}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.folder);
    PlanRequest req = benchmarkRequest(c.folder, c.instance);
    req.timeout_seconds = 120;
    req.search.lazy_plan_preferred = c.lama_first_wins;
    req.search.lazy_beside_both = false;
    PlanReply alone = plan(req, Termination());
    req.search.lazy_plan_preferred = false;
    req.search.lazy_beside_both = true;
    req.search.lazy_second_after = 0;
    req.search.lazy_second_hadd = false;  // the second as the `lazy_plan_preferred` run's (tested below)
    req.search.lazy_hadd_lane_budget = 0;  // two lazy searches (the third: tested below)
    PlanReply both = plan(req, Termination());
    PlanReply again = plan(req, Termination());
    ASSERT_EQ(alone.status, PlanStatus::kSolved) << alone.message;
    ASSERT_EQ(both.status, PlanStatus::kSolved) << both.message;  // replayed by the checker
    EXPECT_TRUE(both.stats.lazy_beside_won);
    EXPECT_EQ(both.plan, alone.plan);
    EXPECT_GT(both.stats.evaluated, alone.stats.evaluated);
    EXPECT_EQ(again.plan, both.plan);
    EXPECT_EQ(again.stats.evaluated, both.stats.evaluated);
  }
}

TEST(Search, SecondLazySearchJoinsOnlyAfterLazySecondAfterEvaluations) {
  // The default: both lazy searches, the second (LAMA-first's preferred operators) joining once
  // the hill-climbing and the first have used `lazy_second_after` evaluations since the first
  // started. depots-6 ends before (about 14 000): the same plan and evaluations as the first lazy
  // search alone beside the hill-climbing, and fewer than with both from the start. hiking-4 with
  // the second after 16 000 (the first alone: 36 497 evaluations in all when written, 4 000 of
  // them before it started, so the default's 32 000 is about when it answers): the second joins and its
  // evaluations count, but the first, which had the turns alone until then, still answers first
  // (its plan), while with both from the start the second's plan is the answer (the
  // `lazy_plan_preferred` run's, which builds its own landmark graph: the shared one is the
  // same). Checked plans, the same in a second run.
  PlanRequest dp = benchmarkRequest("pddl/depots", "instance-6.pddl");
  dp.timeout_seconds = 120;
  ASSERT_TRUE(dp.search.lazy_beside_both);  // the default
  ASSERT_EQ(dp.search.lazy_second_after, 32'000U);
  PlanReply delayed = plan(dp, Termination());
  PlanReply again = plan(dp, Termination());
  dp.search.lazy_beside_both = false;
  PlanReply one = plan(dp, Termination());
  dp.search.lazy_beside_both = true;
  dp.search.lazy_second_after = 0;
  PlanReply together = plan(dp, Termination());
  ASSERT_EQ(delayed.status, PlanStatus::kSolved) << delayed.message;  // replayed by the checker
  ASSERT_EQ(one.status, PlanStatus::kSolved) << one.message;
  ASSERT_EQ(together.status, PlanStatus::kSolved) << together.message;
  EXPECT_TRUE(delayed.stats.lazy_beside_won);
  EXPECT_EQ(delayed.plan, one.plan);
  EXPECT_EQ(delayed.stats.evaluated, one.stats.evaluated);
  EXPECT_LT(delayed.stats.evaluated, together.stats.evaluated);
  EXPECT_EQ(again.plan, delayed.plan);
  EXPECT_EQ(again.stats.evaluated, delayed.stats.evaluated);

  PlanRequest hk = benchmarkRequest("pddl-more/hiking", "instance-4.pddl");
  hk.timeout_seconds = 120;
  hk.search.lazy_hadd_lane_budget = 0;  // two lazy searches (the third: tested below)
  hk.search.lazy_second_after = 16'000;  // the default joins about when the first answers
  PlanReply hk_delayed = plan(hk, Termination());
  PlanReply hk_again = plan(hk, Termination());
  hk.search.lazy_second_after = 0;
  hk.search.lazy_second_hadd = false;  // the `lazy_plan_preferred` run's heuristic (see below)
  PlanReply hk_together = plan(hk, Termination());
  hk.search.lazy_beside_both = false;
  PlanReply hk_one = plan(hk, Termination());
  hk.search.lazy_plan_preferred = true;
  PlanReply lama = plan(hk, Termination());
  ASSERT_EQ(hk_delayed.status, PlanStatus::kSolved) << hk_delayed.message;
  ASSERT_EQ(hk_together.status, PlanStatus::kSolved) << hk_together.message;
  ASSERT_EQ(hk_one.status, PlanStatus::kSolved) << hk_one.message;
  ASSERT_EQ(lama.status, PlanStatus::kSolved) << lama.message;
  EXPECT_TRUE(hk_delayed.stats.lazy_beside_won);
  EXPECT_EQ(hk_delayed.plan, hk_one.plan);
  EXPECT_GT(hk_delayed.stats.evaluated, hk_one.stats.evaluated);  // the second joined
  EXPECT_EQ(hk_together.plan, lama.plan);
  EXPECT_NE(hk_together.plan, hk_one.plan);
  EXPECT_EQ(hk_again.plan, hk_delayed.plan);
  EXPECT_EQ(hk_again.stats.evaluated, hk_delayed.stats.evaluated);
}

TEST(Search, SecondLazySearchTakesItsRelaxedPlanThroughHaddSupporters) {
  // `lazy_second_hadd` (off by default): the second lazy search's h_FF is Fast Downward's (the relaxed
  // plan through h_add's best supporters) also on unit-cost tasks, where the others take FF's
  // layered graph, so that search is LAMA-first's. hiking-4 with both from the start: the second
  // answers, with the plan of a single `lazy_plan_preferred` lazy search on `kFFHadd` (it searches
  // as it would alone), not the plan it gives with the layered graph; checked, the same in a
  // second run. Off, the second's plan is the layered graph's (the test above).
  PlanRequest hk = benchmarkRequest("pddl-more/hiking", "instance-4.pddl");
  hk.timeout_seconds = 120;
  ASSERT_FALSE(hk.search.lazy_second_hadd);  // the default
  hk.search.lazy_hadd_lane_budget = 0;  // `layered` below: two lazy searches (the third: tested below)
  hk.search.lazy_second_hadd = true;
  hk.search.lazy_second_after = 0;
  PlanReply hadd = plan(hk, Termination());
  PlanReply again = plan(hk, Termination());
  hk.search.lazy_second_hadd = false;
  PlanReply layered = plan(hk, Termination());
  hk.search.lazy_beside_both = false;
  hk.search.lazy_plan_preferred = true;
  hk.search.heuristic = HeuristicKind::kFFHadd;
  PlanReply alone = plan(hk, Termination());
  ASSERT_EQ(hadd.status, PlanStatus::kSolved) << hadd.message;  // replayed by the checker
  ASSERT_EQ(layered.status, PlanStatus::kSolved) << layered.message;
  ASSERT_EQ(alone.status, PlanStatus::kSolved) << alone.message;
  EXPECT_TRUE(hadd.stats.lazy_beside_won);
  EXPECT_TRUE(alone.stats.lazy_beside_won);
  EXPECT_EQ(hadd.plan, alone.plan);
  EXPECT_NE(hadd.plan, layered.plan);
  EXPECT_EQ(again.plan, hadd.plan);
  EXPECT_EQ(again.stats.evaluated, hadd.stats.evaluated);
}

TEST(Search, ThirdLazySearchOnHaddSupportersJoinsWithTheSecondAndIsDroppedAtItsBudget) {
  // `lazy_hadd_lane_budget`: a third lazy search, the second's but for its h_FF (h_add's
  // supporters), joins with the second. The searches' own states do not depend on the turns, so
  // (1) dropped after its first turn (a budget of 1) it leaves the answer of the two others, plus
  // its initial state and a turn of evaluations (101); (2) with a budget it does not reach, the answer is the
  // plan of one of the two lanes with LAMA-first's preferred operators (layered graph or h_add's
  // supporters) and, on hiking-4, the third's; checked, the same in a second run.
  PlanRequest hk = benchmarkRequest("pddl-more/hiking", "instance-4.pddl");
  hk.timeout_seconds = 120;
  hk.search.lazy_second_after = 0;
  ASSERT_EQ(hk.search.lazy_hadd_lane_budget, 50'000U);  // the default
  hk.search.lazy_hadd_lane_budget = 0;
  PlanReply two = plan(hk, Termination());
  hk.search.lazy_hadd_lane_budget = 1;
  PlanReply dropped = plan(hk, Termination());
  hk.search.lazy_hadd_lane_budget = 1'000'000;
  PlanReply three = plan(hk, Termination());
  PlanReply again = plan(hk, Termination());
  hk.search.lazy_hadd_lane_budget = 0;
  hk.search.lazy_second_hadd = true;
  PlanReply hadd = plan(hk, Termination());
  for (const PlanReply* r : {&two, &dropped, &three, &again, &hadd}) {
    ASSERT_EQ(r->status, PlanStatus::kSolved) << r->message;  // replayed by the checker
    EXPECT_TRUE(r->stats.lazy_beside_won);
  }
  EXPECT_EQ(dropped.plan, two.plan);
  EXPECT_GT(dropped.stats.evaluated, two.stats.evaluated);
  EXPECT_LE(dropped.stats.evaluated, two.stats.evaluated + 101);  // its initial state and one turn
  EXPECT_NE(hadd.plan, two.plan);  // the two h_FF's lanes give different plans: the test can tell
  EXPECT_EQ(three.plan, hadd.plan);  // h_add's supporters answer first on hiking-4
  EXPECT_EQ(again.plan, three.plan);
  EXPECT_EQ(again.stats.evaluated, three.stats.evaluated);

  // Where the operators differ in cost (cost + 1), h_FF is h_add's already: no third lane.
  PlanRequest tr = benchmarkRequest("pddl-more/transport", "instance-6.pddl");
  tr.timeout_seconds = 120;
  tr.search.ehc_lazy_after = 1;
  tr.search.lazy_second_after = 0;
  tr.search.lazy_hadd_lane_budget = 0;
  PlanReply tr_two = plan(tr, Termination());
  tr.search.lazy_hadd_lane_budget = 1'000'000;
  PlanReply tr_three = plan(tr, Termination());
  ASSERT_EQ(tr_two.status, PlanStatus::kSolved) << tr_two.message;
  ASSERT_EQ(tr_three.status, PlanStatus::kSolved) << tr_three.message;
  EXPECT_EQ(tr_three.plan, tr_two.plan);
  EXPECT_EQ(tr_three.stats.evaluated, tr_two.stats.evaluated);
  tr.search.cost_type = CostType::kUnit;  // with unit costs it joins
  PlanReply unit_three = plan(tr, Termination());
  tr.search.lazy_hadd_lane_budget = 0;
  PlanReply unit_two = plan(tr, Termination());
  ASSERT_EQ(unit_three.status, PlanStatus::kSolved) << unit_three.message;
  ASSERT_EQ(unit_two.status, PlanStatus::kSolved) << unit_two.message;
  EXPECT_NE(unit_three.stats.evaluated, unit_two.stats.evaluated);
}

TEST(Search, LazySearchBesideProvesUnsolvabilityAndGoesOnAloneWhenTheHillClimbingGivesUp) {
  // Turns of one evaluation from the first one on. (1) The swap task (relaxed solvable, really
  // unsolvable): the answer is the proof. (2) logistics-12 with a hill-climbing that gives up
  // after a few evaluations (its fallback budget: 1 + h(init)): the lazy search, already started, goes on
  // alone and gives a checked plan; the hill-climbing counts as failed.
  const std::string dom = R"((define (domain swap) (:predicates (p) (q))
    (:action a :parameters () :effect (and (p) (not (q))))
    (:action b :parameters () :effect (and (q) (not (p))))))";
  PlanRequest req;
  req.domain_text = dom;
  req.problem_text = "(define (problem x) (:domain swap) (:init) (:goal (and (p) (q))))";
  req.search.ehc_lazy_after = 1;
  req.search.ehc_lazy_turn_ehc = 1;
  req.search.ehc_lazy_turn_lazy = 1;
  req.timeout_seconds = 60;
  PlanReply swap = plan(req, Termination());
  EXPECT_EQ(swap.status, PlanStatus::kUnsolvable) << swap.message;
  EXPECT_TRUE(swap.stats.lazy_beside_started);

  PlanRequest lg = benchmarkRequest("pddl/logistics", "instance-12.pddl");
  lg.search.ehc_lazy_after = 1;
  lg.search.ehc_lazy_turn_ehc = 1;
  lg.search.ehc_lazy_turn_lazy = 1;
  lg.search.ehc_ff_first = false;
  lg.search.ehc_fallback_budget_min = 1;  // gives up after 1 + h(init) evaluations
  lg.search.ehc_fallback_budget_per_h = 1;
  lg.timeout_seconds = 120;
  PlanReply r = plan(lg, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;  // replayed by the checker
  EXPECT_TRUE(r.stats.lazy_beside_started);
  EXPECT_FALSE(r.stats.lazy_beside_won);
  EXPECT_TRUE(r.stats.ehc_failed);
  EXPECT_EQ(r.stats.ehc_fallbacks, 1U);
}

// One-way roads (test::kOneWayDomain): from a, b looks one step closer to g than d does (the
// delete relaxation goes b -> c, turns south, and takes b -> g, which the vehicle at b never can,
// facing north), but from b the only road leads to c, a dead end; the way is a -> d -> e -> f -> g.
TEST(Search, EhcStartsAgainTestingWithH2AfterCommittingToADeadEnd) {
  PlanRequest req;
  req.domain_text = test::kOneWayDomain;
  req.problem_text = test::kOneWayProblem;
  req.timeout_seconds = 60;
  req.check_plan = true;
  req.search.ehc_fallback = false;  // the hill-climbing alone
  req.search.ehc_lazy_beside = false;
  for (bool ff_first : {true, false}) {
    SCOPED_TRACE(ff_first ? "with the first run" : "default run only");
    req.search.ehc_ff_first = ff_first;
    // Without the restart the hill-climbing commits to b (h_FF lower than d's), proves it a dead
    // end, and gives up.
    req.search.ehc_h2_restart = false;
    const PlanReply without = plan(req, Termination());
    EXPECT_EQ(without.status, PlanStatus::kFailed) << without.message;
    EXPECT_EQ(without.stats.ehc_h2_restarts, 0U);
    EXPECT_EQ(without.stats.ehc_h2_tests, 0U);
    // With it, the run starts again and h^2 from b rejects b: a -> d -> e -> f -> g.
    req.search.ehc_h2_restart = true;
    const PlanReply with = plan(req, Termination());
    ASSERT_EQ(with.status, PlanStatus::kSolved) << with.message;  // replayed by the checker
    EXPECT_EQ(with.plan.size(), 4U);
    // The default run restarts once; the first run (FF-v2.3's variant) ends at its dead end
    // (`ehc_ff_first_h2_restart` false) and leaves the task to the default run.
    EXPECT_EQ(with.stats.ehc_h2_restarts, 1U);
    if (ff_first) {
      // Restarting it too: that run and, its plan being long for its initial h, the default run
      // beside it (`ehc_second_budget_per_step`), the same plan.
      req.search.ehc_ff_first_h2_restart = true;
      const PlanReply both = plan(req, Termination());
      ASSERT_EQ(both.status, PlanStatus::kSolved) << both.message;
      EXPECT_EQ(both.stats.ehc_h2_restarts, 2U);
      EXPECT_EQ(both.plan, with.plan);
      req.search.ehc_ff_first_h2_restart = false;
    }
    EXPECT_GE(with.stats.ehc_h2_dead_ends, 1U);
    EXPECT_GT(with.stats.ehc_h2_tests, with.stats.ehc_h2_dead_ends);  // d's and e's successors pass
    // Testing from the start needs no restart.
    req.search.ehc_h2_commits = true;
    const PlanReply from_start = plan(req, Termination());
    ASSERT_EQ(from_start.status, PlanStatus::kSolved) << from_start.message;
    EXPECT_EQ(from_start.stats.ehc_h2_restarts, 0U);
    EXPECT_EQ(from_start.plan, with.plan);
    EXPECT_LT(from_start.stats.evaluated, with.stats.evaluated);
    req.search.ehc_h2_commits = false;
  }
}

// One-way roads with the trap after a stretch of good road: a -> p1 -> .. -> p4, then either
// the trap p4 -> b1 -> .. -> b4 -> c (h_FF falls all the way to b4, as b4 -> g looks open facing
// south) or the way p4 -> d1 -> .. -> d6 -> g. Testing every state tests each of the 11 states
// committed to but g; testing later commits to p1 .. p4 and b1 .. b3 on tests of p1 and p3 only,
// finds b3 dead, and bisection finds b1, the first dead state, and goes back to p4.
TEST(Search, EhcTestingWithH2LaterFindsTheFirstDeadStateByBisectionInFewerTests) {
  PlanRequest req;
  req.domain_text = test::kOneWayDomain;
  req.problem_text = R"((define (problem long-trap) (:domain oneway)
    (:objects a p1 p2 p3 p4 b1 b2 b3 b4 c d1 d2 d3 d4 d5 d6 g north south)
    (:init (at a) (facing north)
           (road a p1 north north) (road p1 p2 north north) (road p2 p3 north north)
           (road p3 p4 north north)
           (road p4 b1 north north) (road b1 b2 north north) (road b2 b3 north north)
           (road b3 b4 north north) (road b4 c north south) (road b4 g south south)
           (road p4 d1 north north) (road d1 d2 north north) (road d2 d3 north north)
           (road d3 d4 north north) (road d4 d5 north north) (road d5 d6 north north)
           (road d6 g north north))
    (:goal (at g))))";
  req.timeout_seconds = 60;
  req.check_plan = true;
  req.search.ehc_fallback = false;  // the hill-climbing alone
  req.search.ehc_lazy_beside = false;
  req.search.ehc_ff_first = false;
  req.search.ehc_h2_test_gap_max = 0;
  const PlanReply every = plan(req, Termination());
  ASSERT_EQ(every.status, PlanStatus::kSolved) << every.message;  // replayed by the checker
  EXPECT_EQ(every.plan.size(), 11U);                                // a p1..p4 d1..d6 g
  EXPECT_EQ(every.stats.ehc_h2_restarts, 1U);
  EXPECT_EQ(every.stats.ehc_h2_dead_ends, 1U);  // b1, tested before the run takes it
  EXPECT_EQ(every.stats.ehc_h2_tests, 9U);      // p1 .. p4, b1, d3 .. d6 (d1, d2 no better than p4)
  req.search.ehc_h2_test_gap_max = 16;
  const PlanReply later = plan(req, Termination());
  ASSERT_EQ(later.status, PlanStatus::kSolved) << later.message;
  EXPECT_EQ(later.plan, every.plan);  // back to p4, not to p3 nor past b1
  EXPECT_EQ(later.stats.ehc_h2_restarts, 1U);
  EXPECT_EQ(later.stats.ehc_h2_dead_ends, 2U);  // b3, then b1 in the bisection
  // p1, p3 (gap 2), b3 (gap 4: p4 b1 b2 b3), then b1 and p4 in the bisection; from p4 again (gap
  // 1): d3, d5 (gap 2).
  EXPECT_EQ(later.stats.ehc_h2_tests, 7U);
  // The restarted run expands b1 and b2 on its way into the trap and p4 once more after going
  // back; going back further (to p3, the last state tested before the trap) would expand p3 too.
  EXPECT_EQ(later.stats.expanded, every.stats.expanded + 3);
}

TEST(Search, EhcWithoutADeadEndNeverTestsWithH2) {
  // openstacks-6: the hill-climbing solves it without ever proving a dead end, so nothing is
  // tested and the search is the same with the restart on or off.
  PlanRequest req = benchmarkRequest("pddl-more/openstacks", "instance-6.pddl");
  req.timeout_seconds = 60;
  const PlanReply on = plan(req, Termination());
  ASSERT_EQ(on.status, PlanStatus::kSolved) << on.message;
  EXPECT_EQ(on.stats.ehc_h2_restarts, 0U);
  EXPECT_EQ(on.stats.ehc_h2_tests, 0U);
  req.search.ehc_h2_restart = false;
  const PlanReply off = plan(req, Termination());
  ASSERT_EQ(off.status, PlanStatus::kSolved) << off.message;
  EXPECT_EQ(on.plan, off.plan);
  EXPECT_EQ(on.stats.evaluated, off.stats.evaluated);
}

TEST(Search, EhcFirstRunContinuesFromTheFirstBetterState) {
  // openstacks-12: the first run (FF-v2.3 variant) solves it; continuing from the first better
  // state instead of evaluating every sibling needs fewer evaluations. Both plans are checked.
  PlanRequest req = benchmarkRequest("pddl-more/openstacks", "instance-12.pddl");
  req.timeout_seconds = 120;
  req.search.ehc_ff_first_improvement = true;
  PlanReply first = plan(req, Termination());
  ASSERT_EQ(first.status, PlanStatus::kSolved) << first.message;
  EXPECT_FALSE(first.stats.ehc_ff_failed);
  req.search.ehc_ff_first_improvement = false;  // the default
  PlanReply best = plan(req, Termination());
  ASSERT_EQ(best.status, PlanStatus::kSolved) << best.message;
  EXPECT_FALSE(best.stats.ehc_ff_failed);
  EXPECT_LT(first.stats.evaluated, best.stats.evaluated);
}

/// The cost trap: s -> m -> g is short (2 steps) but costs 11; s x1 x2 x3 g costs 8. Plans checked.
PlanRequest costTrapRequest() {
  PlanRequest req;
  req.domain_text = R"((define (domain trap) (:requirements :typing :action-costs)
    (:types node) (:predicates (at ?n - node) (edge ?a ?b - node))
    (:functions (total-cost) - number (w ?a ?b - node) - number)
    (:action go :parameters (?a ?b - node) :precondition (and (at ?a) (edge ?a ?b))
      :effect (and (not (at ?a)) (at ?b) (increase (total-cost) (w ?a ?b))))))";
  req.problem_text = R"((define (problem p) (:domain trap) (:objects s m g x1 x2 x3 - node)
    (:init (at s) (edge s m) (edge m g) (edge s x1) (edge x1 x2) (edge x2 x3) (edge x3 g)
      (= (w s m) 1) (= (w m g) 10) (= (w s x1) 2) (= (w x1 x2) 2) (= (w x2 x3) 2) (= (w x3 g) 2)
      (= (total-cost) 0))
    (:goal (at g)) (:metric minimize (total-cost))))";
  req.check_plan = true;
  return req;
}

TEST(Search, AnytimePhaseNeverReturnsADearerPlanAndEndsOptimalOnASmallTask) {
  // The cost trap of AstarIsCostOptimalAndWastarWithinItsBound: whatever the first plan, the
  // bounded iterations exhaust the small space and end at the optimum (cost 4).
  PlanRequest req = costTrapRequest();
  req.search.anytime_seconds = 60;  // a budget, not an expectation: the space is exhausted at once
  req.search.neighbourhood_time_share = 0;  // LAMA 2011's iterations alone (the next test: with it)
  PlanReply r = plan(req, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_EQ(r.cost, 8);
  EXPECT_GE(r.stats.anytime_iterations, 1U);
  // As LAMA 2011, the first plan is searched for with unit costs: the short way through m
  // (cost 11); the anytime phase then finds the cheap one (8). Without the unit-cost first run,
  // or with an explicit cost type, cost + 1 finds 8 at once and nothing improves it.
  EXPECT_GE(r.stats.anytime_improvements, 1U);
  EXPECT_FALSE(r.stats.unit_first_failed);
  req.search.unit_cost_first = false;
  PlanReply plus_one = plan(req, Termination());
  ASSERT_EQ(plus_one.status, PlanStatus::kSolved) << plus_one.message;
  EXPECT_EQ(plus_one.cost, 8);
  EXPECT_EQ(plus_one.stats.anytime_improvements, 0U);
  req.search.unit_cost_first = true;
  req.search.cost_type = CostType::kPlusOne;
  plus_one = plan(req, Termination());
  ASSERT_EQ(plus_one.status, PlanStatus::kSolved) << plus_one.message;
  EXPECT_EQ(plus_one.cost, 8);
  EXPECT_EQ(plus_one.stats.anytime_improvements, 0U);
  req.search.cost_type.reset();

  // An IPC cost task: the anytime plan (checked) costs at most the first plan.
  const auto dir = test::benchmarksDir() / "pddl-adl/elevators";
  req.domain_text = test::readFile(dir / "domain.pddl");
  req.problem_text = test::readFile(dir / "instance-6.pddl");
  req.search.anytime_seconds = 0;
  PlanReply first = plan(req, Termination());
  ASSERT_EQ(first.status, PlanStatus::kSolved) << first.message;
  EXPECT_EQ(first.stats.anytime_iterations, 0U);
  req.search.anytime_seconds = 1;
  PlanReply better = plan(req, Termination());
  ASSERT_EQ(better.status, PlanStatus::kSolved) << better.message;
  EXPECT_GE(better.stats.anytime_iterations, 1U);
  EXPECT_LE(better.cost, first.cost);
}

TEST(Search, PlanNeighbourhoodSearchFindsTheCheaperWayAndProvesItOptimalOnASmallTask) {
  // The cost trap again. The unit-cost first plan goes s -> m -> g (cost 11). The neighbourhood
  // starts at 1 state and doubles: 1 and 2 hold only the plan's states {s, m, g} (registered
  // whatever the cap), 4 adds x1 (no way round yet), 8 holds all 6 states, every one expanded:
  // the cheapest path through them (s x1 x2 x3 g, cost 8) is optimal, and the phase ends there,
  // before any weighted iteration.
  PlanRequest req = costTrapRequest();
  req.search.anytime_seconds = 60;  // a budget: the neighbourhoods are bounded by their states
  req.search.neighbourhood_first_states = 1;
  PlanReply r = plan(req, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_EQ(r.cost, 8);
  ASSERT_EQ(r.plan.size(), 4U);
  EXPECT_EQ(r.plan[0].toString(), "(go s x1)");
  EXPECT_EQ(r.stats.neighbourhood_runs, 4U);
  EXPECT_EQ(r.stats.neighbourhood_improvements, 1U);
  EXPECT_EQ(r.stats.neighbourhood_states, 6U);
  EXPECT_EQ(r.stats.anytime_iterations, 0U);

  // With the share at 0 there is no neighbourhood search: LAMA's iterations find 8 (previous test).
  req.search.neighbourhood_time_share = 0;
  r = plan(req, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_EQ(r.stats.neighbourhood_runs, 0U);
  EXPECT_GE(r.stats.anytime_iterations, 1U);
  EXPECT_EQ(r.cost, 8);
}

TEST(Search, AnExhaustedLazyGreedyIterationDoesNotEndTheAnytimePhase) {
  // The first plan (unit costs) is the direct edge s -> g, cost 20, the bound of the anytime
  // iterations. The lazy greedy iteration (cost + 1) prefers a (h lower than b's), reaches x over
  // a with g = 16, where x -> g (5) passes the bound, and keeps that first path to x: reached
  // again over b and c with g = 3, x is not re-opened, and the open list runs out. That proves
  // nothing; weighted A* (w = 5), which re-opens, finds s b c x g (cost 8).
  const std::string dom = R"((define (domain trap2) (:requirements :typing :action-costs)
    (:types node) (:predicates (at ?n - node) (edge ?a ?b - node))
    (:functions (total-cost) - number (w ?a ?b - node) - number)
    (:action go :parameters (?a ?b - node) :precondition (and (at ?a) (edge ?a ?b))
      :effect (and (not (at ?a)) (at ?b) (increase (total-cost) (w ?a ?b))))))";
  const std::string prob = R"((define (problem p) (:domain trap2) (:objects s a b c x g - node)
    (:init (at s) (edge s g) (edge s a) (edge a x) (edge s b) (edge b c) (edge c x) (edge x g)
      (= (w s g) 20) (= (w s a) 15) (= (w a x) 1) (= (w s b) 1) (= (w b c) 1) (= (w c x) 1)
      (= (w x g) 5) (= (total-cost) 0))
    (:goal (at g)) (:metric minimize (total-cost))))";
  PlanRequest req;
  req.domain_text = dom;
  req.problem_text = prob;
  req.check_plan = true;
  req.search.anytime_seconds = 60;  // a budget: weighted A* exhausts the small space at once
  req.search.neighbourhood_time_share = 0;  // the iterations alone
  PlanReply r = plan(req, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_EQ(r.cost, 8);
  EXPECT_GE(r.stats.anytime_iterations, 2U);
  EXPECT_EQ(r.stats.anytime_improvements, 1U);
  // With the neighbourhood search (the default), the whole space is its neighbourhood.
  req.search.neighbourhood_time_share = SearchOptions{}.neighbourhood_time_share;
  r = plan(req, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_EQ(r.cost, 8);
  EXPECT_EQ(r.stats.neighbourhood_improvements, 1U);
  EXPECT_EQ(r.stats.anytime_iterations, 0U);
}

TEST(Search, PlanNeighbourhoodSearchNeverReturnsADearerPlanOnIpcCostTasks) {
  // Conditional effects and negation (citycar), costs from functions of several arguments
  // (elevators, parcprinter): the plan after the neighbourhood search alone (the whole anytime
  // phase given to it) replays under the checker and costs at most the first plan. The time is
  // a budget, not an expectation.
  for (const auto& [dir, file] : std::vector<std::pair<std::string, std::string>>{
           {"pddl-adl/elevators", "instance-6.pddl"},
           {"pddl-adl/citycar", "instance-1.pddl"},
           {"pddl-more/parcprinter/instance-18", "instance-18.pddl"}}) {
    const auto d = test::benchmarksDir() / dir;
    PlanRequest req;
    req.domain_text = test::readFile(d / "domain.pddl");
    req.problem_text = test::readFile(d / file);
    req.check_plan = true;
    req.timeout_seconds = 120;
    req.search.anytime_seconds = 1e-9;  // a phase that ends at once: the unit-cost first plan
    PlanReply first = plan(req, Termination());
    ASSERT_EQ(first.status, PlanStatus::kSolved) << dir << ": " << first.message;
    EXPECT_EQ(first.stats.neighbourhood_runs, 0U) << dir;
    req.search.anytime_seconds = 0.5;
    req.search.neighbourhood_time_share = 1;
    PlanReply r = plan(req, Termination());
    ASSERT_EQ(r.status, PlanStatus::kSolved) << dir << ": " << r.message;
    EXPECT_GE(r.stats.neighbourhood_runs, 1U) << dir;
    EXPECT_LE(r.cost, first.cost) << dir;
  }
}

TEST(Search, AGrownPlanNeighbourhoodHoldsTheStatesOfARebuiltOneForLessWork) {
  // parcprinter-12: the neighbourhood doubles and improves the plan until it holds every
  // reachable state and proves its plan optimal, so the run is bounded by states, not by time.
  // Grown in place or rebuilt at each doubling, the neighbourhoods hold the same states in the
  // same order: the same searches, improvements, largest neighbourhood and plan; growing expands
  // fewer states (the rebuilt one expands again what the smaller one expanded).
  const auto d = test::benchmarksDir() / "pddl-more/parcprinter/instance-12";
  PlanRequest req;
  req.domain_text = test::readFile(d / "domain.pddl");
  req.problem_text = test::readFile(d / "instance-12.pddl");
  req.check_plan = true;
  req.search.anytime_seconds = 600;  // a budget: the complete neighbourhood ends the phase
  req.search.neighbourhood_time_share = 1;
  req.search.neighbourhood_first_states = 64;  // more doublings than the default's
  req.search.neighbourhood_grow = false;
  PlanReply rebuilt = plan(req, Termination());
  ASSERT_EQ(rebuilt.status, PlanStatus::kSolved) << rebuilt.message;
  req.search.neighbourhood_grow = true;
  PlanReply grown = plan(req, Termination());
  ASSERT_EQ(grown.status, PlanStatus::kSolved) << grown.message;
  EXPECT_EQ(grown.stats.anytime_iterations, 0U);  // proved optimal by the neighbourhood
  EXPECT_GE(grown.stats.neighbourhood_runs - grown.stats.neighbourhood_improvements, 3U);  // doublings
  EXPECT_EQ(grown.stats.neighbourhood_runs, rebuilt.stats.neighbourhood_runs);
  EXPECT_EQ(grown.stats.neighbourhood_improvements, rebuilt.stats.neighbourhood_improvements);
  EXPECT_EQ(grown.stats.neighbourhood_states, rebuilt.stats.neighbourhood_states);
  EXPECT_EQ(grown.cost, rebuilt.cost);
  ASSERT_EQ(grown.plan.size(), rebuilt.plan.size());
  for (size_t i = 0; i < grown.plan.size(); ++i) EXPECT_EQ(grown.plan[i].toString(), rebuilt.plan[i].toString());
  EXPECT_LT(grown.stats.expanded, rebuilt.stats.expanded);
}

TEST(Search, UnitCostFirstRunFallsBackToCostPlusOneWhenOutOfTimeShareOrMemory) {
  // pegsol-18 takes thousands of expansions with either cost type: a unit-cost run given 1e-9
  // of the time left runs out of it at its first time check, and the first plan comes from the
  // cost + 1 run, with the time left (checked by replaying it).
  const auto pegsol = test::benchmarksDir() / "pddl-more/pegsol";
  PlanRequest req;
  req.domain_text = test::readFile(pegsol / "domain.pddl");
  req.problem_text = test::readFile(pegsol / "instance-18.pddl");
  req.check_plan = true;
  req.search.anytime_seconds = 0.2;
  req.search.unit_first_time_share = 1e-9;
  req.search.unit_beside_time_share = 0;  // the unit-cost run ends at its share (the next test: beside)
  req.timeout_seconds = 120;
  PlanReply r = plan(req, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_TRUE(r.stats.unit_first_failed);
  EXPECT_FALSE(r.stats.unit_beside);
  // The whole share: the unit-cost run finds the first plan itself.
  req.search.unit_first_time_share = 1.0;
  r = plan(req, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_FALSE(r.stats.unit_first_failed);
  // No deadline: no time share, the unit-cost run is bounded by memory only.
  req.search.unit_first_time_share = 1e-9;
  req.timeout_seconds = 0;
  r = plan(req, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_FALSE(r.stats.unit_first_failed);
  // Without the anytime phase there is no unit-cost run (TAMP queries keep cost + 1).
  req.search.anytime_seconds = 0;
  req.timeout_seconds = 120;
  r = plan(req, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_FALSE(r.stats.unit_first_failed);

  // citycar-1 within 1 MiB: with unit costs the search needs about 100k evaluations and runs
  // out of memory; with cost + 1, 3k, and it fits (the case of citycar-6 and -11 at 4 GiB).
  const auto citycar = test::benchmarksDir() / "pddl-adl/citycar";
  req.domain_text = test::readFile(citycar / "domain.pddl");
  req.problem_text = test::readFile(citycar / "instance-1.pddl");
  req.search.anytime_seconds = 0.2;
  req.search.unit_first_time_share = 1.0;
  req.search.memory_limit_mb = 1;
  r = plan(req, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_TRUE(r.stats.unit_first_failed);
}

/// The plan's steps, one string.
std::string planText(const PlanReply& r) {
  std::string out;
  for (const auto& st : r.plan) out += st.toString() + "\n";
  return out;
}

TEST(Search, UnitCostRunGoesOnBesideTheCostPlusOneRunInTurns) {
  // pegsol-18 (a cost domain): the unit-cost run's first share (1e-9 of the time left) ends at
  // its first time check, 16 evaluations in; it then goes on beside the cost + 1 run, 1000
  // evaluations a turn each, with the whole time left (no second deadline): every turn ends at
  // a count of evaluations, so the run is the same in every run. The winner's plan is the plan
  // it finds alone (the turns change neither run's states), and the effort counted is both runs'.
  PlanRequest req = benchmarkRequest("pddl-more/pegsol", "instance-18.pddl");
  req.check_plan = true;
  req.timeout_seconds = 120;
  req.search.anytime_seconds = 1e-9;  // the first plan, as found (no time to improve it)
  req.search.unit_first_time_share = 1e-9;
  req.search.unit_beside_time_share = 1.0;
  req.search.unit_beside_stall_share = 0;  // in turns, whatever its progress
  req.search.unit_progress_alone = false;
  PlanReply turns = plan(req, Termination());
  ASSERT_EQ(turns.status, PlanStatus::kSolved) << turns.message;
  EXPECT_TRUE(turns.stats.unit_beside);
  PlanReply again = plan(req, Termination());
  ASSERT_EQ(again.status, PlanStatus::kSolved) << again.message;
  EXPECT_EQ(planText(again), planText(turns));
  EXPECT_EQ(again.stats.evaluated, turns.stats.evaluated);
  EXPECT_EQ(again.stats.unit_first_failed, turns.stats.unit_first_failed);

  req.search.unit_first_time_share = 1.0;  // the unit-cost run alone
  req.search.unit_beside_time_share = 0;
  PlanReply unit = plan(req, Termination());
  ASSERT_EQ(unit.status, PlanStatus::kSolved) << unit.message;
  EXPECT_FALSE(unit.stats.unit_first_failed);
  req.search.unit_cost_first = false;  // the cost + 1 run alone
  PlanReply plus = plan(req, Termination());
  ASSERT_EQ(plus.status, PlanStatus::kSolved) << plus.message;
  const PlanReply& winner = turns.stats.unit_first_failed ? plus : unit;
  const PlanReply& loser = turns.stats.unit_first_failed ? unit : plus;
  EXPECT_EQ(planText(turns), planText(winner));
  // The winner's evaluations, and at most one turn more of the loser's than the winner's (turns
  // of 1000 after the unit-cost run's first 16).
  EXPECT_GT(turns.stats.evaluated, winner.stats.evaluated);
  EXPECT_LT(turns.stats.evaluated, winner.stats.evaluated + std::min<uint64_t>(loser.stats.evaluated, winner.stats.evaluated + 1100));
  EXPECT_NE(unit.stats.evaluated, plus.stats.evaluated);  // the two runs differ: the test can tell them apart
  EXPECT_NE(planText(unit), planText(plus));
}

TEST(Search, UnitCostRunBesideIsStoppedOnceItMakesNoProgress) {
  // pegsol-18, as above: the unit-cost run's first share ends at its first time check, 16
  // evaluations in, inside an evaluation (before the step it may take after it). With a stall
  // share that no run can meet (1.0), the run is the one without it (the same plan and
  // evaluations); with one that any evaluation since the last progress exceeds, the unit-cost run
  // is stopped at the end of its first share, before any turn: the cost + 1 run's plan.
  PlanRequest req = benchmarkRequest("pddl-more/pegsol", "instance-18.pddl");
  req.check_plan = true;
  req.timeout_seconds = 120;
  req.search.anytime_seconds = 1e-9;
  req.search.unit_first_time_share = 1e-9;
  req.search.unit_beside_time_share = 1.0;
  req.search.unit_beside_stall_share = 0;
  req.search.unit_progress_alone = false;  // in turns (the next test: alone)
  PlanReply turns = plan(req, Termination());
  ASSERT_EQ(turns.status, PlanStatus::kSolved) << turns.message;
  ASSERT_TRUE(turns.stats.unit_beside);
  req.search.unit_beside_stall_share = 1.0;
  PlanReply never = plan(req, Termination());
  ASSERT_EQ(never.status, PlanStatus::kSolved) << never.message;
  EXPECT_EQ(planText(never), planText(turns));
  EXPECT_EQ(never.stats.evaluated, turns.stats.evaluated);
  EXPECT_TRUE(never.stats.unit_beside);
  req.search.unit_beside_stall_share = 1e-9;
  PlanReply stalled = plan(req, Termination());
  ASSERT_EQ(stalled.status, PlanStatus::kSolved) << stalled.message;
  EXPECT_TRUE(stalled.stats.unit_first_failed);
  EXPECT_FALSE(stalled.stats.unit_beside);  // stopped before the cost + 1 run started
  req.search.unit_cost_first = false;
  PlanReply plus = plan(req, Termination());
  ASSERT_EQ(plus.status, PlanStatus::kSolved) << plus.message;
  EXPECT_EQ(planText(stalled), planText(plus));
  EXPECT_GT(stalled.stats.evaluated, plus.stats.evaluated);  // the unit-cost run's 16 counted
  EXPECT_LT(stalled.stats.evaluated, plus.stats.evaluated + 200);
}

TEST(Search, UnitCostRunThatMakesProgressGoesOnAloneBeforeTheCostPlusOneRun) {
  // pegsol-18, as above (the unit-cost run's first share ends 16 evaluations in), with
  // `unit_progress_alone`: a unit-cost run that never counts as stalled (stall share 1.0) goes on
  // alone to its end, with no cost + 1 evaluation at all: the plan and the evaluations of the
  // unit-cost run alone (in turns, the count has the other run's evaluations too). One that is
  // stalled at the end of its first share (1e-9), or whose share in all is used up at once (2e-9
  // of the time left), is stopped, and the cost + 1 run alone gives its plan, after the unit-cost
  // run's few evaluations.
  PlanRequest req = benchmarkRequest("pddl-more/pegsol", "instance-18.pddl");
  req.check_plan = true;
  req.timeout_seconds = 120;
  req.search.anytime_seconds = 1e-9;
  req.search.unit_first_time_share = 1.0;  // the unit-cost run alone, by its first share
  PlanReply unit = plan(req, Termination());
  ASSERT_EQ(unit.status, PlanStatus::kSolved) << unit.message;
  ASSERT_FALSE(unit.stats.unit_first_failed);
  req.search.unit_cost_first = false;  // the cost + 1 run alone
  PlanReply plus = plan(req, Termination());
  ASSERT_EQ(plus.status, PlanStatus::kSolved) << plus.message;
  ASSERT_NE(planText(unit), planText(plus));  // the test can tell the two runs' plans apart
  req.search.unit_cost_first = true;

  req.search.unit_first_time_share = 1e-9;
  req.search.unit_beside_time_share = 1.0;
  req.search.unit_beside_stall_share = 1.0;
  req.search.unit_progress_alone = false;
  PlanReply turns = plan(req, Termination());
  ASSERT_EQ(turns.status, PlanStatus::kSolved) << turns.message;
  req.search.unit_progress_alone = true;
  PlanReply alone = plan(req, Termination());
  ASSERT_EQ(alone.status, PlanStatus::kSolved) << alone.message;
  EXPECT_FALSE(alone.stats.unit_first_failed);
  EXPECT_FALSE(alone.stats.unit_beside);
  EXPECT_EQ(planText(alone), planText(unit));
  EXPECT_EQ(alone.stats.evaluated, unit.stats.evaluated);
  EXPECT_TRUE(planText(turns) != planText(alone) || turns.stats.evaluated > alone.stats.evaluated);

  req.search.unit_beside_stall_share = 1e-9;  // stalled at the end of its first share
  PlanReply stalled = plan(req, Termination());
  ASSERT_EQ(stalled.status, PlanStatus::kSolved) << stalled.message;
  EXPECT_TRUE(stalled.stats.unit_first_failed);
  EXPECT_FALSE(stalled.stats.unit_beside);
  EXPECT_EQ(planText(stalled), planText(plus));
  EXPECT_GT(stalled.stats.evaluated, plus.stats.evaluated);  // the unit-cost run's 16 counted
  EXPECT_LT(stalled.stats.evaluated, plus.stats.evaluated + 200);

  req.search.unit_beside_stall_share = 1.0;
  req.search.unit_beside_time_share = 2e-9;  // its share in all used up at its first step
  PlanReply spent = plan(req, Termination());
  ASSERT_EQ(spent.status, PlanStatus::kSolved) << spent.message;
  EXPECT_TRUE(spent.stats.unit_first_failed);
  EXPECT_EQ(planText(spent), planText(plus));
  EXPECT_LT(spent.stats.evaluated, plus.stats.evaluated + 1200);  // at most one step of 1000 more
}

TEST(Search, UnitCostRunBesideStopsAtItsShareAndOnTheCallersStop) {
  // The unit-cost run's share of the time left in all just above its first share: it is
  // stopped at its first turn beside the cost + 1 run, which gives the plan.
  PlanRequest req = benchmarkRequest("pddl-more/pegsol", "instance-18.pddl");
  req.check_plan = true;
  req.timeout_seconds = 120;
  req.search.anytime_seconds = 1e-9;
  req.search.unit_first_time_share = 1e-9;
  req.search.unit_beside_time_share = 2e-9;
  req.search.unit_beside_stall_share = 0;
  req.search.unit_progress_alone = false;
  PlanReply r = plan(req, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_TRUE(r.stats.unit_first_failed);
  EXPECT_TRUE(r.stats.unit_beside);
  req.search.unit_cost_first = false;
  PlanReply plus = plan(req, Termination());
  ASSERT_EQ(plus.status, PlanStatus::kSolved) << plus.message;
  EXPECT_EQ(planText(r), planText(plus));

  // A stop requested while both run ends both (the unit-cost one on its own thread) at once.
  PlanRequest hard = benchmarkRequest("pddl-more/transport", "instance-30.pddl");
  hard.search.anytime_seconds = 5;
  hard.search.unit_first_time_share = 1e-9;
  hard.search.unit_beside_time_share = 1.0;
  hard.search.unit_beside_stall_share = 0;
  hard.search.unit_progress_alone = false;
  hard.timeout_seconds = 600;
  std::stop_source stop;
  std::thread stopper([&stop] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    stop.request_stop();
  });
  Stopwatch sw;
  PlanReply cancelled = plan(hard, Termination(Deadline::never(), stop.get_token()));
  stopper.join();
  EXPECT_EQ(cancelled.status, PlanStatus::kCancelled) << cancelled.message;
  EXPECT_LT(sw.seconds(), 5.0);
}

TEST(Search, OptionsAreValidated) {
  SearchOptions o;
  o.weight = 0.5;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  o.weight = 2;
  EXPECT_NO_THROW(o.validate());
  o.anytime_seconds = -1;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  o.anytime_seconds = 0;
  for (double bad : {0.0, -0.5, 1.5, std::nan("")}) {
    o.unit_first_time_share = bad;
    EXPECT_THROW(o.validate(), std::invalid_argument) << bad;
  }
  o.unit_first_time_share = 1.0;
  EXPECT_NO_THROW(o.validate());
  for (double bad : {-0.1, 1.5, std::nan("")}) {
    o.unit_beside_time_share = bad;
    EXPECT_THROW(o.validate(), std::invalid_argument) << bad;
  }
  o.unit_beside_time_share = 0;
  for (double bad : {-0.1, 1.5, std::nan("")}) {
    o.unit_beside_stall_share = bad;
    EXPECT_THROW(o.validate(), std::invalid_argument) << bad;
  }
  o.unit_beside_stall_share = 0.5;
  EXPECT_NO_THROW(o.validate());
  o.unit_beside_stall_share = 0;
  EXPECT_NO_THROW(o.validate());
  o.unit_beside_turn = 0;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  o.unit_beside_turn = 1;
  EXPECT_NO_THROW(o.validate());
  for (double bad : {-0.1, 1.5, std::nan("")}) {
    o.neighbourhood_time_share = bad;
    EXPECT_THROW(o.validate(), std::invalid_argument) << bad;
  }
  o.neighbourhood_time_share = 0;
  EXPECT_NO_THROW(o.validate());
  o.neighbourhood_first_states = 0;
  EXPECT_THROW(o.validate(), std::invalid_argument);
  o.neighbourhood_first_states = 1;
  EXPECT_NO_THROW(o.validate());
  for (double bad : {-0.1, 1.5, std::nan("")}) {
    o.ehc_retry_budget_share = bad;
    EXPECT_THROW(o.validate(), std::invalid_argument) << bad;
  }
  o.ehc_retry_budget_share = 0;  // unbounded
  EXPECT_NO_THROW(o.validate());
  for (int field = 0; field < 3; ++field) {
    SearchOptions b = o;
    (field == 0 ? b.ehc_lazy_after : field == 1 ? b.ehc_lazy_turn_ehc : b.ehc_lazy_turn_lazy) = 0;
    EXPECT_THROW(b.validate(), std::invalid_argument) << field;
  }
  SearchOptions r = o;
  r.rhw.max_work = 0;
  EXPECT_THROW(r.validate(), std::invalid_argument);
  SearchOptions h2 = o;
  h2.ehc_h2_mutexes.max_work = 0;
  try {
    h2.validate();
    ADD_FAILURE() << "ehc_h2_mutexes.max_work 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ehc_h2_mutexes.max_work"), std::string::npos) << e.what();
  }
  EXPECT_EQ(parseSearchAlgorithm("astar"), SearchAlgorithm::kAstar);
  EXPECT_EQ(parseSearchAlgorithm("lazy"), SearchAlgorithm::kLazy);
  EXPECT_FALSE(parseSearchAlgorithm("dfs").has_value());
}

}  // namespace
}  // namespace tamp::symbolic_planner
