// Repeated queries from different states on one cached grounding (the graph manager's use).
#include <gtest/gtest.h>

#include <random>

#include "test_util.h"

namespace tamp::symbolic_planner {
namespace {

class Session : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto dir = test::sourceDir() / "config/pddl";
    auto s = PlanningSession::fromText(test::readFile(dir / "mobile_manipulation.pddl"),
                                       test::readFile(dir / "problems/occluded_can.pddl"));
    ASSERT_TRUE(s.ok()) << s.error().toString();
    session_ = std::move(*s);
  }
  AtomId id(const std::string& p, std::vector<std::string> args) {
    auto r = session_->atomId(AtomSpec{p, std::move(args)});
    EXPECT_TRUE(r.ok()) << r.error().toString();
    return *r;
  }
  /// Replays `reply` with the independent checker from `init` to `goal`.
  void expectValid(const PlanReply& reply, const std::vector<AtomId>& init, const pddl::Formula& goal) {
    ASSERT_EQ(reply.status, PlanStatus::kSolved) << reply.message;
    auto tmp = session_->task();
    ASSERT_NE(tmp, nullptr);
    std::vector<pddl::Atom> atoms;
    for (AtomId a : init) {
      // Names through the public API: build atoms by parsing "(p a b)".
      atoms.push_back(atomOf(a));
    }
    ValidationResult v = validatePlan(session_->domain(), session_->problem(), reply.plan, atoms, goal);
    EXPECT_TRUE(v.valid) << v.message;
    EXPECT_DOUBLE_EQ(v.cost, static_cast<double>(reply.cost));
  }
  pddl::Atom atomOf(AtomId a) { return names_.at(a); }
  void remember(const std::string& p, const std::vector<std::string>& args) {
    pddl::Atom at;
    at.predicate = p;
    for (const auto& x : args) at.args.push_back(pddl::Term{x});
    names_[id(p, args)] = at;
  }

  std::unique_ptr<PlanningSession> session_;
  std::map<AtomId, pddl::Atom> names_;
};

TEST_F(Session, ManyQueriesFromDifferentStatesReuseTheGrounding) {
  // Static facts of the problem + varying fluent states.
  const std::vector<std::pair<std::string, std::vector<std::string>>> statics = {
      {"graspable", {"can"}}, {"graspable", {"box"}}, {"graspable", {"cup"}},
      {"reaches", {"start", "stow"}}, {"reaches", {"near_table", "stow"}}, {"reaches", {"near_counter", "stow"}},
      {"reaches", {"near_table", "over_table"}}, {"reaches", {"near_counter", "over_counter"}},
      {"conf-over", {"over_table", "table"}}, {"conf-over", {"over_counter", "counter"}}};
  for (const auto& [p, a] : statics) remember(p, a);
  const std::vector<std::string> locs = {"start", "near_table", "near_counter"};
  const std::vector<std::string> regions = {"table", "counter"};
  const std::vector<std::string> items = {"can", "box", "cup"};
  for (const auto& l : locs) remember("robot-at", {l});
  for (const auto& i : items) {
    for (const auto& r : regions) remember("on", {i, r});
    remember("holding", {i});
  }
  remember("arm-at", {"stow"});
  remember("hand-empty", {});
  remember("occludes", {"box", "can"});

  std::mt19937 rng(7);
  int reused = 0;
  for (int k = 0; k < 30; ++k) {
    std::vector<AtomId> init;
    for (const auto& [p, a] : statics) init.push_back(id(p, a));
    init.push_back(id("robot-at", {locs[rng() % locs.size()]}));
    init.push_back(id("arm-at", {"stow"}));
    init.push_back(id("hand-empty", {}));
    for (const auto& i : items) init.push_back(id("on", {i, regions[rng() % regions.size()]}));
    if (k % 3 == 0) init.push_back(id("occludes", {"box", "can"}));
    // Goal: a random item on a random region, as literals; every third query as a formula.
    const std::string item = items[rng() % items.size()];
    const std::string region = regions[rng() % regions.size()];
    Query q;
    q.init = init;
    pddl::Formula goal;
    goal.kind = pddl::FormulaKind::kAtom;
    goal.atom.predicate = "on";
    goal.atom.args = {pddl::Term{item}, pddl::Term{region}};
    if (k % 3 == 1) {
      q.goal_formula = goal;
    } else {
      q.goal_literals = {AtomLiteral{id("on", {item, region}), false}};
    }
    PlanReply r = session_->solve(q, Termination::after(10));
    expectValid(r, init, goal);
    reused += r.stats.grounding_reused ? 1 : 0;
  }
  // The first query grounds; queries with (occludes ...) differ only in fluents: all reuse.
  EXPECT_GE(reused, 28);
}

TEST_F(Session, NegativeGoalsAndDroppedStaticsAndNewAtoms) {
  auto init = session_->problemInit();
  ASSERT_TRUE(init.ok());
  // Negative goal: the can must not be on the table any more.
  Query q;
  q.init = *init;
  q.goal_literals = {AtomLiteral{id("on", {"can", "table"}), true}};
  PlanReply r = session_->solve(q, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_GE(r.plan.size(), 3U);
  // Drop a static fact (the table cannot be reached any more): unsolvable, proven.
  std::vector<AtomId> no_reach;
  const AtomId reach = id("reaches", {"near_table", "over_table"});
  for (AtomId a : *init) {
    if (a != reach) no_reach.push_back(a);
  }
  q.init = no_reach;
  PlanReply u = session_->solve(q, Termination());
  EXPECT_EQ(u.status, PlanStatus::kUnsolvable) << u.message;
  // A new static atom outside the grounding extends it: the counter becomes reachable from start.
  std::vector<AtomId> more = *init;
  more.push_back(id("reaches", {"start", "over_counter"}));
  q.init = more;
  q.goal_literals = {AtomLiteral{id("arm-at", {"over_counter"}), false}};
  PlanReply e = session_->solve(q, Termination());
  ASSERT_EQ(e.status, PlanStatus::kSolved) << e.message;
  EXPECT_FALSE(e.stats.grounding_reused);
  EXPECT_EQ(e.plan.size(), 1U);  // move_arm at start straight to over_counter
}

TEST_F(Session, AddObjectsRegroundsAndKeepsWorking) {
  const uint64_t gen = session_->generation();
  ASSERT_TRUE(session_->addObjects({{"shelf", "region"}, {"over_shelf", "armconf"}, {"near_shelf", "location"}}).ok());
  EXPECT_GT(session_->generation(), gen);
  EXPECT_FALSE(session_->addObjects({{"bad", "no-such-type"}}).ok());
  auto init = session_->problemInit();
  ASSERT_TRUE(init.ok());
  std::vector<AtomId> i2 = *init;
  i2.push_back(id("reaches", {"near_shelf", "stow"}));
  i2.push_back(id("reaches", {"near_shelf", "over_shelf"}));
  i2.push_back(id("conf-over", {"over_shelf", "shelf"}));
  Query q;
  q.init = i2;
  q.goal_literals = {AtomLiteral{id("on", {"cup", "shelf"}), false}};
  PlanReply r = session_->solve(q, Termination());
  ASSERT_EQ(r.status, PlanStatus::kSolved) << r.message;
  EXPECT_EQ(r.plan.back().toString(), "(place cup shelf over_shelf)");
}

TEST(Planner, CachesSessionsAcrossSelfContainedRequests) {
  const auto dir = test::sourceDir() / "config/pddl";
  Planner planner(2);
  PlanRequest req;
  req.domain_path = (dir / "mobile_manipulation.pddl").string();
  req.objects = {{"start", "location"}, {"near_table", "location"}, {"table", "region"},
                 {"over_table", "armconf"}, {"can", "item"}};
  req.init = {{"robot-at", {"start"}}, {"arm-at", {"stow"}}, {"hand-empty", {}}, {"on", {"can", "table"}},
              {"graspable", {"can"}}, {"reaches", {"start", "stow"}}, {"reaches", {"near_table", "stow"}},
              {"reaches", {"near_table", "over_table"}}, {"conf-over", {"over_table", "table"}}};
  req.goal = "(holding can)";
  PlanReply a = planner.solve(req, Termination());
  ASSERT_EQ(a.status, PlanStatus::kSolved) << a.message;
  EXPECT_FALSE(a.stats.grounding_reused);
  EXPECT_EQ(a.plan.size(), 3U);
  // Same domain and objects, another goal: the cached grounding is reused.
  req.goal = "(and (robot-at near_table) (arm-at stow))";
  PlanReply b = planner.solve(req, Termination());
  ASSERT_EQ(b.status, PlanStatus::kSolved) << b.message;
  EXPECT_TRUE(b.stats.grounding_reused);
  EXPECT_EQ(b.plan.size(), 1U);
  // Input errors are replies, not exceptions.
  req.goal = "(holding nothing)";
  PlanReply c = planner.solve(req, Termination());
  EXPECT_EQ(c.status, PlanStatus::kInputError);
  EXPECT_NE(c.message.find("unknown object 'nothing'"), std::string::npos) << c.message;
  req.domain_path = "/nonexistent/domain.pddl";
  PlanReply d = planner.solve(req, Termination());
  EXPECT_EQ(d.status, PlanStatus::kInputError);
  EXPECT_NE(d.message.find("/nonexistent/domain.pddl"), std::string::npos) << d.message;
}

// Issue 14, twenty-eighth round: the replay's states are returned only when asked for; the plan
// is checked either way, and the check's time is counted when it runs.
TEST(Planner, ReturnsTheReplayedStatesOnlyWhenAskedAndTimesTheCheck) {
  const auto dir = test::sourceDir() / "config/pddl";
  Planner planner(0);
  PlanRequest req;
  req.domain_path = (dir / "mobile_manipulation.pddl").string();
  req.objects = {{"start", "location"}, {"near_table", "location"}, {"table", "region"},
                 {"over_table", "armconf"}, {"can", "item"}};
  req.init = {{"robot-at", {"start"}}, {"arm-at", {"stow"}}, {"hand-empty", {}}, {"on", {"can", "table"}},
              {"graspable", {"can"}}, {"reaches", {"start", "stow"}}, {"reaches", {"near_table", "stow"}},
              {"reaches", {"near_table", "over_table"}}, {"conf-over", {"over_table", "table"}}};
  req.goal = "(holding can)";
  PlanReply with = planner.solve(req, Termination());
  ASSERT_EQ(with.status, PlanStatus::kSolved) << with.message;
  EXPECT_EQ(with.states.size(), with.plan.size() + 1);
  EXPECT_GT(with.stats.check_seconds, 0.0);
  req.return_states = false;
  PlanReply without = planner.solve(req, Termination());
  ASSERT_EQ(without.status, PlanStatus::kSolved) << without.message;
  EXPECT_TRUE(without.states.empty());
  EXPECT_EQ(without.plan, with.plan);
  EXPECT_EQ(without.cost, with.cost);
  EXPECT_GT(without.stats.check_seconds, 0.0);  // checked all the same
  req.check_plan = false;
  req.return_states = true;
  PlanReply unchecked = planner.solve(req, Termination());
  ASSERT_EQ(unchecked.status, PlanStatus::kSolved) << unchecked.message;
  EXPECT_TRUE(unchecked.states.empty());
  EXPECT_EQ(unchecked.stats.check_seconds, 0.0);
}

}  // namespace
}  // namespace tamp::symbolic_planner
