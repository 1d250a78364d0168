#include <gtest/gtest.h>

#include "tamp/symbolic_planner/pddl.h"
#include "test_util.h"

namespace tamp::symbolic_planner::pddl {
namespace {

using test::kAdlDomain;
using test::kAdlProblem;

TEST(PddlParser, ParsesTheAdlFragment) {
  auto d = parseDomain(kAdlDomain, "rooms.pddl");
  ASSERT_TRUE(d.ok()) << d.error().toString();
  EXPECT_EQ(d->name, "rooms");
  EXPECT_EQ(d->actions.size(), 5U);
  ASSERT_NE(d->findType("box"), nullptr);
  EXPECT_TRUE(d->isSubtype("box", "item"));
  EXPECT_TRUE(d->isSubtype("box", "object"));
  EXPECT_FALSE(d->isSubtype("room", "item"));
  ASSERT_EQ(d->constants.size(), 1U);
  EXPECT_EQ(d->constants[0].name, "hall");
  const Action& move = d->actions[0];
  EXPECT_EQ(move.parameters.size(), 2U);
  EXPECT_EQ(move.precondition.kind, FormulaKind::kAnd);
  // forall + when flattened into effect literals with their quantifier and condition.
  int conditional = 0;
  for (const auto& e : move.effects) conditional += e.forall.size() == 1 && e.condition.kind == FormulaKind::kAtom;
  EXPECT_EQ(conditional, 2);
  ASSERT_EQ(move.costs.size(), 1U);
  EXPECT_TRUE(move.costs[0].is_function);
  EXPECT_EQ(d->actions[1].parameters[0].types, (std::vector<std::string>{"box", "ball"}));
  auto p = parseProblem(kAdlProblem, *d, "rooms-1.pddl");
  ASSERT_TRUE(p.ok()) << p.error().toString();
  EXPECT_EQ(p->objects.size(), 4U);
  EXPECT_EQ(p->init.size(), 7U);
  EXPECT_EQ(p->function_values.size(), 5U);
  EXPECT_TRUE(p->minimize_total_cost);
  EXPECT_EQ(p->goal.children.size(), 4U);
}

TEST(PddlParser, IsCaseInsensitiveAndAcceptsCrlfAndComments) {
  const std::string dom =
      "; comment\r\n(DEFINE (DOMAIN Toy) (:REQUIREMENTS :STRIPS)\r\n (:PREDICATES (P ?X) (Q))\r\n"
      " (:ACTION A :PARAMETERS (?X) :PRECONDITION (P ?X) :EFFECT (Q)))\r\n";
  auto d = parseDomain(dom, "toy.pddl");
  ASSERT_TRUE(d.ok()) << d.error().toString();
  EXPECT_EQ(d->name, "toy");
  EXPECT_EQ(d->actions[0].name, "a");
  auto p = parseProblem("(define (problem x) (:domain TOY) (:objects O1) (:init (P O1)) (:goal (Q)))", *d);
  ASSERT_TRUE(p.ok()) << p.error().toString();
  EXPECT_EQ(p->objects[0].name, "o1");
}

struct BadInput {
  const char* name;
  const char* text;
  int line;
  int column;
  const char* expected_substring;
  ErrorCode code;
};

void PrintTo(const BadInput& b, std::ostream* os) { *os << b.name; }

class BadDomain : public ::testing::TestWithParam<BadInput> {};

TEST_P(BadDomain, ReportsFileLineColumnAndWhatWasExpected) {
  const BadInput& in = GetParam();
  auto d = parseDomain(in.text, "bad.pddl");
  ASSERT_FALSE(d.ok()) << in.name;
  const Error& e = d.error();
  EXPECT_EQ(e.code, in.code) << e.toString();
  EXPECT_EQ(e.where.file, "bad.pddl");
  EXPECT_EQ(e.where.line, in.line) << e.toString();
  EXPECT_EQ(e.where.column, in.column) << e.toString();
  EXPECT_NE(e.toString().find(in.expected_substring), std::string::npos) << e.toString();
}

INSTANTIATE_TEST_SUITE_P(
    Adversarial, BadDomain,
    ::testing::Values(
        BadInput{"empty", "", 1, 1, "empty file", ErrorCode::kParseError},
        BadInput{"unbalanced_open", "(define (domain d)\n  (:predicates (p)", 2, 3, "missing ')'", ErrorCode::kParseError},
        BadInput{"unbalanced_close", "(define (domain d)))", 1, 20, "unbalanced ')'", ErrorCode::kParseError},
        BadInput{"not_define", "(domain d)", 1, 1, "expected (define", ErrorCode::kParseError},
        BadInput{"derived", "(define (domain d)\n (:derived (p) (q)))", 2, 2, "derived predicates", ErrorCode::kUnsupported},
        BadInput{"durative_req", "(define (domain d) (:requirements :strips\n   :durative-actions))", 2, 4,
                 ":durative-actions is not supported", ErrorCode::kUnsupported},
        BadInput{"numeric_fluents", "(define (domain d) (:requirements :numeric-fluents))", 1, 35,
                 ":numeric-fluents is not supported", ErrorCode::kUnsupported},
        BadInput{"undeclared_pred", "(define (domain d) (:predicates (p))\n (:action a :parameters ()\n  :precondition (q) :effect (p)))",
                 3, 17, "predicate 'q' is not declared", ErrorCode::kParseError},
        BadInput{"arity", "(define (domain d) (:predicates (p ?x))\n (:action a :parameters (?y) :effect (p ?y ?y)))", 2, 38,
                 "takes 1 argument(s), got 2", ErrorCode::kParseError},
        BadInput{"unbound_var", "(define (domain d) (:predicates (p ?x))\n (:action a :parameters () :effect (p ?z)))", 2, 39,
                 "variable '?z' is not bound", ErrorCode::kParseError},
        BadInput{"unknown_type", "(define (domain d) (:types a - b))", 1, 28, "undeclared parent type 'b'", ErrorCode::kParseError},
        BadInput{"numeric_condition", "(define (domain d) (:predicates (p))\n (:action a :parameters () :precondition (< 1 2) :effect (p)))",
                 2, 42, "numeric conditions", ErrorCode::kUnsupported},
        BadInput{"bad_keyword", "(define (domain d) (:predicates (p))\n (:action a :parameters () :pre (p) :effect (p)))", 2, 28,
                 "expected ':parameters', ':precondition' or ':effect'", ErrorCode::kParseError},
        BadInput{"bad_char", "(define (domain d\x01))", 1, 18, "unexpected character", ErrorCode::kParseError},
        BadInput{"assign", "(define (domain d) (:predicates (p))\n (:action a :parameters () :effect (assign (total-cost) 1)))", 2, 36,
                 "numeric effect 'assign'", ErrorCode::kUnsupported}),
    [](const ::testing::TestParamInfo<BadInput>& i) { return std::string(i.param.name); });

TEST(PddlParser, DeepNestingIsAnErrorNotACrash) {
  std::string deep = "(define (domain d) (:predicates (p)) (:action a :parameters () :precondition ";
  for (int i = 0; i < 100000; ++i) deep += "(not ";
  auto d = parseDomain(deep, "deep.pddl");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().message.find("nesting deeper"), std::string::npos) << d.error().toString();
}

TEST(PddlParser, ReportsEverySemanticErrorOfAFile) {
  auto d = parseDomain("(define (domain d) (:predicates (p ?x))\n (:action a :parameters () :precondition (q) :effect (r)))", "x.pddl");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().message.find("'q'"), std::string::npos);
  EXPECT_NE(d.error().message.find("'r'"), std::string::npos) << d.error().toString();
}

TEST(PddlParser, ProblemErrorsNameTheProblemFile) {
  auto d = parseDomain(kAdlDomain, "rooms.pddl");
  ASSERT_TRUE(d.ok());
  auto p = parseProblem("(define (problem x) (:domain rooms)\n (:objects a - room)\n (:init (at-robot zz))\n (:goal (handempty)))", *d,
                        "p.pddl");
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().where.file, "p.pddl");
  EXPECT_EQ(p.error().where.line, 3);
  EXPECT_NE(p.error().message.find("unknown object 'zz'"), std::string::npos) << p.error().toString();
  auto q = parseProblem("(define (problem x) (:domain other) (:goal (handempty)))", *d, "q.pddl");
  ASSERT_FALSE(q.ok());
  EXPECT_NE(q.error().message.find("domain 'other'"), std::string::npos);
  auto r = parseProblem("(define (problem x) (:domain rooms) (:goal (handempty)) (:metric maximize (total-cost)))", *d, "r.pddl");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kUnsupported);
}

TEST(PddlParser, GoalAndAtomListHelpersUseTheProblemObjects) {
  auto d = parseDomain(kAdlDomain);
  ASSERT_TRUE(d.ok());
  auto p = parseProblem(kAdlProblem, *d);
  ASSERT_TRUE(p.ok());
  auto g = parseGoalFormula("(forall (?i - item) (at ?i kitchen))", *d, *p);
  ASSERT_TRUE(g.ok()) << g.error().toString();
  EXPECT_EQ(g->kind, FormulaKind::kForall);
  EXPECT_EQ(toString(*g), "(forall (?i - item) (at ?i kitchen))");
  auto atoms = parseAtomList("(at b1 hall) (handempty)", *d, *p);
  ASSERT_TRUE(atoms.ok());
  EXPECT_EQ(atoms->size(), 2U);
  EXPECT_FALSE(parseAtomList("(at nobody hall)", *d, *p).ok());
}

TEST(PddlParser, ParsesEveryBenchmarkAndProjectFile) {
  namespace fs = std::filesystem;
  int files = 0;
  std::vector<fs::path> dirs;
  for (const char* set : {"pddl", "pddl-adl"}) {
    const fs::path root = test::benchmarksDir() / set;
    ASSERT_TRUE(fs::is_directory(root)) << "benchmark set missing: " << root;
    for (const auto& e : fs::directory_iterator(root)) {
      if (e.is_directory()) dirs.push_back(e.path());
    }
  }
  for (const auto& dir : dirs) {
    auto d = parseDomain(test::readFile(dir / "domain.pddl"), (dir / "domain.pddl").string());
    ASSERT_TRUE(d.ok()) << d.error().toString();
    for (const auto& e : fs::directory_iterator(dir)) {
      if (e.path().filename().string().rfind("instance-", 0) != 0) continue;
      auto p = parseProblem(test::readFile(e.path()), *d, e.path().string());
      ASSERT_TRUE(p.ok()) << p.error().toString();
      ++files;
    }
  }
  auto d = parseDomain(test::readFile(test::sourceDir() / "config/pddl/mobile_manipulation.pddl"));
  ASSERT_TRUE(d.ok()) << d.error().toString();
  for (const auto& e : fs::directory_iterator(test::sourceDir() / "config/pddl/problems")) {
    auto p = parseProblem(test::readFile(e.path()), *d, e.path().string());
    ASSERT_TRUE(p.ok()) << p.error().toString();
    ++files;
  }
  EXPECT_GE(files, 3);
}

}  // namespace
}  // namespace tamp::symbolic_planner::pddl
