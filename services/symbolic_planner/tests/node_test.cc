// The planner service in-process on an isolated DDS domain, called through the real RPC path.
#include "planner_node.h"

#include <unistd.h>

#include <algorithm>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tamp/core/paths.h"
#include "tamp/symbolic_planner/validator.h"

namespace tamp::symbolic_planner {
namespace {

using ::testing::HasSubstr;
using Client = dds::RpcClient<msg::PlanRequest, msg::PlanReply>;

class PlannerNodeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dds::ServiceArgs args;
    args.name = "symbolic_planner_test";
    args.domain_id = 20 + static_cast<int>(::getpid() % 200);
    node_ = std::make_unique<PlannerNode>(args, PlannerNodeParams{});
    client_ = std::make_unique<Client>(node_->participant(), dds::services::kPlan);
    domain_path_ = (std::filesystem::path(TAMP_SOURCE_DIR) / "config/pddl/mobile_manipulation.pddl").string();
  }

  /// The occluded-can task given as objects/init/goal (how the graph manager asks).
  msg::PlanRequest occludedCan(std::vector<std::string> goal) const {
    msg::PlanRequest r;
    r.domain_path(domain_path_);
    r.objects({"start - location", "near_table - location", "near_counter - location", "table - region",
               "counter - region", "over_table - armconf", "over_counter - armconf", "can - item", "box - item",
               "cup - item"});
    r.init({"(robot-at start)", "(arm-at stow)", "(hand-empty)", "(on can table)", "(on box table)",
            "(on cup table)", "(graspable can)", "(graspable box)", "(graspable cup)", "(occludes box can)",
            "(occludes cup can)", "(reaches start stow)", "(reaches near_table stow)", "(reaches near_counter stow)",
            "(reaches near_table over_table)", "(reaches near_counter over_counter)",
            "(conf-over over_table table)", "(conf-over over_counter counter)", "(= (total-cost) 0)"});
    r.goal(std::move(goal));
    r.use_costs(true);
    return r;
  }

  /// Replays `actions` with the independent checker on the same task.
  ValidationResult replay(const msg::PlanRequest& req, const std::vector<std::string>& actions) const {
    auto domain_text = readTextFile(domain_path_);
    auto domain = pddl::parseDomain(*domain_text, domain_path_);
    EXPECT_TRUE(domain.ok());
    std::string problem = "(define (problem p) (:domain mobile-manipulation) (:objects";
    for (const auto& o : req.objects()) problem += " " + o;
    problem += ") (:init";
    for (const auto& a : req.init()) problem += " " + a;
    problem += ") (:goal (and";
    for (const auto& g : req.goal()) problem += " " + g;
    problem += ")) (:metric minimize (total-cost)))";
    auto prob = pddl::parseProblem(problem, *domain, "<request>");
    EXPECT_TRUE(prob.ok()) << (prob ? "" : prob.error().toString());
    std::string text;
    for (const auto& a : actions) text += a + "\n";
    auto plan = parsePlan(text);
    EXPECT_TRUE(plan.ok());
    return validatePlan(*domain, *prob, *plan);
  }

  std::unique_ptr<PlannerNode> node_;
  std::unique_ptr<Client> client_;
  std::string domain_path_;
};

TEST_F(PlannerNodeTest, SolvesAndThePlanReplaysToTheGoal) {
  auto req = occludedCan({"(on can counter)"});
  auto rep = client_->call(req, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  ASSERT_EQ(rep->status(), msg::PLAN_SOLVED) << rep->header().message();
  auto v = replay(req, rep->actions());
  EXPECT_TRUE(v.valid) << v.message;
  EXPECT_DOUBLE_EQ(rep->cost(), v.cost);
  EXPECT_GT(rep->operators(), 0u);
}

// PlanReply.states over the wire: one state per step plus the initial one, each sorted, the
// initial one holding the request's init, the last the goal, and each step changing the state
// the way its action says (pick: holding; place: on).
TEST_F(PlannerNodeTest, ThePlanStatesFollowTheActions) {
  auto req = occludedCan({"(on can counter)"});
  auto rep = client_->call(req, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  ASSERT_EQ(rep->status(), msg::PLAN_SOLVED) << rep->header().message();
  const auto& actions = rep->actions();
  const auto& states = rep->states();
  ASSERT_EQ(states.size(), actions.size() + 1);
  auto has = [&](std::size_t i, const std::string& atom) {
    const auto& a = states[i].atoms();
    return std::find(a.begin(), a.end(), atom) != a.end();
  };
  for (const auto& atom : req.init()) {
    if (atom.rfind("(=", 0) == 0) continue;  // numeric fluents are not atoms
    EXPECT_TRUE(has(0, atom)) << atom;
  }
  EXPECT_FALSE(has(0, "(on can counter)"));
  EXPECT_TRUE(has(states.size() - 1, "(on can counter)"));
  EXPECT_FALSE(has(states.size() - 1, "(robot-at start)"));
  for (std::size_t i = 0; i < states.size(); ++i) {
    const auto& a = states[i].atoms();
    EXPECT_TRUE(std::is_sorted(a.begin(), a.end())) << "state " << i;
    for (const auto& atom : a) EXPECT_EQ(atom.rfind("(not ", 0), std::string::npos) << atom;
    if (i == 0) continue;
    EXPECT_NE(states[i].atoms(), states[i - 1].atoms()) << "step " << i << " " << actions[i - 1];
    // "(pick o ...)" leaves o held, "(place o r ...)" leaves o on r.
    std::istringstream words(actions[i - 1].substr(1, actions[i - 1].size() - 2));
    std::string name, o, r;
    words >> name >> o >> r;
    if (name == "pick") {
      EXPECT_TRUE(has(i, "(holding " + o + ")")) << actions[i - 1];
    }
    if (name == "place") {
      EXPECT_TRUE(has(i, "(on " + o + " " + r + ")")) << actions[i - 1];
    }
  }
}

TEST_F(PlannerNodeTest, RepeatedQueriesReuseTheGrounding) {
  auto first = client_->call(occludedCan({"(holding can)"}), dds::CallOptions{30.0, {}});
  ASSERT_TRUE(first.ok());
  ASSERT_EQ(first->status(), msg::PLAN_SOLVED);
  // Same domain and objects, another state: the graph manager's TP(v, s).
  auto req = occludedCan({"(on box counter)"});
  auto init = req.init();
  init.erase(std::remove(init.begin(), init.end(), std::string("(robot-at start)")), init.end());
  init.push_back("(robot-at near_counter)");
  req.init(init);
  auto second = client_->call(req, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(second.ok()) << second.error().toString();
  ASSERT_EQ(second->status(), msg::PLAN_SOLVED) << second->header().message();
  EXPECT_TRUE(second->grounding_cached());
  auto v = replay(req, second->actions());
  EXPECT_TRUE(v.valid) << v.message;
}

TEST_F(PlannerNodeTest, UnreachableGoalIsProvenUnsolvable) {
  // Nothing can make an item graspable: a goal needing a non-graspable item held is unsolvable.
  auto req = occludedCan({"(holding can)"});
  auto init = req.init();
  init.erase(std::remove(init.begin(), init.end(), std::string("(graspable can)")), init.end());
  req.init(init);
  auto rep = client_->call(req, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  EXPECT_EQ(rep->status(), msg::PLAN_UNSOLVABLE);
  EXPECT_TRUE(rep->actions().empty());
}

TEST_F(PlannerNodeTest, MalformedInputNamesWhereItIs) {
  auto bad_atom = occludedCan({"(holding can)"});
  auto init = bad_atom.init();
  init[2] = "(hand-empty";
  bad_atom.init(init);
  auto r1 = client_->call(bad_atom, dds::CallOptions{30.0, {}});
  ASSERT_FALSE(r1.ok());
  EXPECT_EQ(r1.error().code, ErrorCode::kInvalidArgument);
  EXPECT_THAT(r1.error().message, HasSubstr("init[2]"));

  msg::PlanRequest bad_domain;
  bad_domain.domain_pddl("(define (domain d)\n  (:requirements :strips)\n  (:action a :parameters (?x)\n");
  bad_domain.problem_pddl("(define (problem p) (:domain d) (:init) (:goal (and)))");
  auto r2 = client_->call(bad_domain, dds::CallOptions{30.0, {}});
  ASSERT_FALSE(r2.ok());
  EXPECT_EQ(r2.error().code, ErrorCode::kParseError);
  EXPECT_THAT(r2.error().message, HasSubstr("<domain>:"));  // file:line:column of the PDDL error

  msg::PlanRequest no_domain;
  auto r3 = client_->call(no_domain, dds::CallOptions{30.0, {}});
  ASSERT_FALSE(r3.ok());
  EXPECT_THAT(r3.error().message, HasSubstr("domain_pddl"));
  // The service is still up.
  EXPECT_TRUE(client_->call(occludedCan({"(holding can)"}), dds::CallOptions{30.0, {}}).ok());
}

TEST(PlannerNodeParsingTest, AtomsAndFunctionValues) {
  auto a = parseAtom("  (on can  table) ");
  ASSERT_TRUE(a.ok());
  EXPECT_EQ(a->predicate, "on");
  EXPECT_EQ(a->args, (std::vector<std::string>{"can", "table"}));
  EXPECT_FALSE(parseAtom("on can table").ok());
  EXPECT_FALSE(parseAtom("(on (can) table)").ok());
  auto f = parseFunctionValue("(= (travel-slow n1 n2) 12)");
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(f->first.predicate, "travel-slow");
  EXPECT_DOUBLE_EQ(f->second, 12.0);
  EXPECT_FALSE(parseFunctionValue("(= (total-cost) x)").ok());
}

}  // namespace
}  // namespace tamp::symbolic_planner
