#include <algorithm>
#include <gtest/gtest.h>

#include "tamp/symbolic_planner/validator.h"
#include "test_util.h"

namespace tamp::symbolic_planner {
namespace {

class Validator : public ::testing::Test {
 protected:
  void SetUp() override {
    auto d = pddl::parseDomain(test::kAdlDomain);
    ASSERT_TRUE(d.ok());
    domain_ = *d;
    auto p = pddl::parseProblem(test::kAdlProblem, domain_);
    ASSERT_TRUE(p.ok());
    problem_ = *p;
  }
  std::vector<PlanStep> steps(const std::string& text) {
    auto r = parsePlan(text);
    EXPECT_TRUE(r.ok()) << r.error().toString();
    return r.ok() ? *r : std::vector<PlanStep>{};
  }
  pddl::Domain domain_;
  pddl::Problem problem_;
};

// A hand-written plan: fetch the ball from the kitchen, unlock the store, carry the box there.
constexpr const char* kGoodPlan = R"(
(move hall kitchen)   ; 2
(pick ball1 kitchen)  ; 1
(move kitchen hall)   ; 2
(drop ball1 hall)     ; 1
(pick b1 hall)        ; 1
(move hall kitchen)   ; 2
(drop b1 kitchen)     ; 1  (unlock needs empty hands)
(unlock store)        ; 5
(pick b1 kitchen)     ; 1
(move kitchen store)  ; 3
(drop b1 store)       ; 1
; cost = 20
)";

TEST_F(Validator, AcceptsAValidPlanAndSumsItsCost) {
  ValidationResult v = validatePlan(domain_, problem_, steps(kGoodPlan));
  EXPECT_TRUE(v.valid) << v.message;
  EXPECT_DOUBLE_EQ(v.cost, 20.0);
}

TEST_F(Validator, ReportsTheStatesAlongThePlan) {
  const auto plan = steps(kGoodPlan);
  ValidationResult v = validatePlan(domain_, problem_, plan);
  ASSERT_TRUE(v.valid) << v.message;
  ASSERT_EQ(v.states.size(), plan.size() + 1);
  auto has = [](const std::vector<std::string>& s, const std::string& a) {
    return std::find(s.begin(), s.end(), a) != s.end();
  };
  EXPECT_TRUE(has(v.states.back(), "(at b1 store)"));
  EXPECT_FALSE(has(v.states.front(), "(at b1 store)"));
  for (const auto& s : v.states) EXPECT_TRUE(std::is_sorted(s.begin(), s.end()));
}

// Issue 14, twenty-eighth round: a caller that wants only the verdict leaves the states out and
// gets the same verdict, cost, step and message, valid plan or not.
TEST_F(Validator, LeavesTheStatesOutWhenNotAskedAndGivesTheSameVerdict) {
  auto plan = steps(kGoodPlan);
  ValidationResult with = validatePlan(domain_, problem_, plan);
  ValidationResult without = validatePlan(domain_, problem_, plan, std::nullopt, std::nullopt, false);
  ASSERT_TRUE(with.valid) << with.message;
  EXPECT_EQ(with.states.size(), plan.size() + 1);
  EXPECT_TRUE(without.valid) << without.message;
  EXPECT_TRUE(without.states.empty());
  EXPECT_DOUBLE_EQ(without.cost, with.cost);
  EXPECT_EQ(without.failed_step, -1);
  plan.erase(plan.begin() + 6);  // unlock while holding b1: step 7 fails
  with = validatePlan(domain_, problem_, plan);
  without = validatePlan(domain_, problem_, plan, std::nullopt, std::nullopt, false);
  EXPECT_FALSE(without.valid);
  EXPECT_EQ(without.failed_step, with.failed_step);
  EXPECT_EQ(without.message, with.message);
  EXPECT_EQ(with.states.size(), 7U);  // up to the failed step
  EXPECT_TRUE(without.states.empty());
}

TEST_F(Validator, NamesTheFirstInapplicableStep) {
  auto p = steps(kGoodPlan);
  p.erase(p.begin() + 6);  // keep holding b1: unlock's forall (not (holding ?i)) fails
  ValidationResult v = validatePlan(domain_, problem_, p);
  EXPECT_FALSE(v.valid);
  EXPECT_EQ(v.failed_step, 6);
  EXPECT_NE(v.message.find("step 7 (unlock store)"), std::string::npos) << v.message;
}

TEST_F(Validator, ConditionalEffectsMoveHeldItemsOnly) {
  // The ball is carried (conditional effect), the box stays: the goal is not reached.
  auto p = steps("(move hall kitchen)\n(pick ball1 kitchen)\n(move kitchen hall)\n");
  std::vector<pddl::Atom> none;
  auto g = pddl::parseGoalFormula("(and (at ball1 hall) (at b1 hall) (not (at ball1 kitchen)))", domain_, problem_);
  ASSERT_TRUE(g.ok());
  ValidationResult v = validatePlan(domain_, problem_, p, std::nullopt, *g);
  EXPECT_TRUE(v.valid) << v.message;
  auto g2 = pddl::parseGoalFormula("(at b1 kitchen)", domain_, problem_);
  EXPECT_FALSE(validatePlan(domain_, problem_, p, std::nullopt, *g2).valid);
}

TEST_F(Validator, RejectsUnknownActionsWrongArityAndTypes) {
  EXPECT_FALSE(validatePlan(domain_, problem_, steps("(fly hall kitchen)")).valid);
  EXPECT_FALSE(validatePlan(domain_, problem_, steps("(move hall)")).valid);
  ValidationResult v = validatePlan(domain_, problem_, steps("(pick kitchen hall)"));
  EXPECT_FALSE(v.valid);
  EXPECT_NE(v.message.find("not an object of type"), std::string::npos) << v.message;
  EXPECT_FALSE(validatePlan(domain_, problem_, {}).valid);  // goal not reached
}

TEST_F(Validator, PlanParserErrorsHaveLineAndColumn) {
  auto r = parsePlan("(move a b)\n  move c d\n", "x.plan");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().where.line, 2);
  EXPECT_EQ(r.error().where.column, 3);
  auto ok = parsePlan("0: (MOVE A B)\n\n; cost = 1\n1: (pick x y)");
  ASSERT_TRUE(ok.ok());
  ASSERT_EQ(ok->size(), 2U);
  EXPECT_EQ((*ok)[0].toString(), "(move a b)");
}

}  // namespace
}  // namespace tamp::symbolic_planner
