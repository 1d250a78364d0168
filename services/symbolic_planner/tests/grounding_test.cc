#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "tamp/symbolic_planner/grounding.h"
#include "test_util.h"

namespace tamp::symbolic_planner {
namespace {

struct Grounded {
  pddl::Domain domain;
  pddl::Problem problem;
  std::unique_ptr<Grounder> grounder;
  std::vector<AtomId> init;
  std::shared_ptr<const Task> task;
};

Grounded ground(const std::string& dom, const std::string& prob, bool costs) {
  Grounded g;
  auto d = pddl::parseDomain(dom);
  EXPECT_TRUE(d.ok()) << d.error().toString();
  g.domain = *d;
  auto p = pddl::parseProblem(prob, g.domain);
  EXPECT_TRUE(p.ok()) << p.error().toString();
  g.problem = *p;
  auto gr = Grounder::create(g.domain, g.problem);
  EXPECT_TRUE(gr.ok()) << gr.error().toString();
  g.grounder = std::move(*gr);
  for (const auto& a : g.problem.init) g.init.push_back(*g.grounder->atomId(a));
  EXPECT_TRUE(g.grounder->extend(g.init, Termination()).ok());
  auto neg = g.grounder->negatedAtoms(g.problem.goal);
  auto t = g.grounder->buildTask(g.init, *neg, costs, Termination());
  EXPECT_TRUE(t.ok()) << t.error().toString();
  g.task = *t;
  return g;
}

std::vector<std::string> opNames(const Task& t) {
  std::vector<std::string> out;
  for (const auto& o : t.ops) out.push_back(o.name);
  return out;
}

bool hasOp(const Task& t, const std::string& name) {
  auto n = opNames(t);
  return std::find(n.begin(), n.end(), name) != n.end();
}

TEST(Grounding, RelaxedReachabilityStaticsAndEquality) {
  auto g = ground(test::kAdlDomain, test::kAdlProblem, true);
  const Task& t = *g.task;
  // Static `connected` with the disjunction in both directions; inequality removes self-moves.
  EXPECT_TRUE(hasOp(t, "(move hall kitchen)"));
  EXPECT_TRUE(hasOp(t, "(move kitchen hall)"));
  EXPECT_TRUE(hasOp(t, "(move kitchen store)"));
  EXPECT_FALSE(hasOp(t, "(move hall store)"));  // not connected: pruned statically
  EXPECT_FALSE(hasOp(t, "(move hall hall)"));
  // Typed with `either`: pick b1 and ball1 in reachable rooms.
  EXPECT_TRUE(hasOp(t, "(pick ball1 kitchen)"));
  // Unreachable: b1 can never be in a room it cannot be carried to? it can reach every room.
  EXPECT_TRUE(hasOp(t, "(pick b1 store)"));
  // Costs come from the static function.
  for (const auto& o : t.ops) {
    if (o.name == "(move kitchen store)") {
      EXPECT_EQ(o.cost, 3);
    } else if (o.name == "(unlock store)") {
      EXPECT_EQ(o.cost, 5);
    } else if (o.name == "(light-all)") {
      EXPECT_EQ(o.cost, 0);
    }
  }
  EXPECT_FALSE(t.unit_cost);
}

TEST(Grounding, AtomsJoinTheSchemasWhoseConstantsTheyMatchAtAnyPosition) {
  // An atom is joined only with the preconditions whose constants it matches (twenty-ninth
  // round: triggers indexed by one constant each): constants in either position, several in one
  // precondition, none (a repeated variable), a schema without parameters; fluent atoms reached
  // late (at c) and static ones (link).
  const std::string dom = R"(
(define (domain consts)
  (:requirements :strips :typing)
  (:types node)
  (:constants a b c - node)
  (:predicates (link ?x ?y - node) (at ?x - node) (seen ?x ?y - node))
  (:action from-a :parameters (?y - node)
    :precondition (and (at a) (link a ?y)) :effect (at ?y))
  (:action into-c :parameters (?x - node)
    :precondition (and (at ?x) (link ?x c)) :effect (and (at c) (seen ?x c)))
  (:action loop :parameters (?x - node)
    :precondition (and (at ?x) (link ?x ?x)) :effect (seen ?x ?x))
  (:action both :parameters ()
    :precondition (and (at b) (link b c) (seen b c)) :effect (seen b b))
  (:action never :parameters (?x - node)
    :precondition (and (at ?x) (link c ?x) (link ?x a)) :effect (seen c a)))
)";
  const std::string prob = R"(
(define (problem p) (:domain consts) (:objects d - node)
  (:init (at a) (link a b) (link b c) (link c c) (link a d))
  (:goal (seen b b)))
)";
  auto g = ground(dom, prob, false);
  auto names = opNames(*g.task);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"(both)", "(from-a b)", "(from-a d)", "(into-c b)",
                                             "(into-c c)", "(loop c)"}));
}

TEST(Grounding, NegationBecomesComplementFactsKeptConsistent) {
  auto g = ground(test::kAdlDomain, test::kAdlProblem, true);
  const Task& t = *g.task;
  // (not (locked store)) is used in a precondition and in the goal: a complement fact exists.
  int64_t locked = -1;
  for (FactId f = 0; f < t.numFacts(); ++f) {
    if (t.fact_names[f] == "(locked store)") locked = f;
  }
  ASSERT_GE(locked, 0);
  const int32_t comp = t.complement[static_cast<size_t>(locked)];
  ASSERT_GE(comp, 0);
  EXPECT_EQ(t.fact_names[static_cast<size_t>(comp)], "(not (locked store))");
  EXPECT_EQ(t.complement[static_cast<size_t>(comp)], locked);
  StateBits s = g.grounder->initialState(t, g.init);
  EXPECT_TRUE(testBit(s.data(), static_cast<FactId>(locked)));
  EXPECT_FALSE(testBit(s.data(), static_cast<FactId>(comp)));
  // Applying unlock flips both.
  for (OpId o = 0; o < t.ops.size(); ++o) {
    if (t.ops[o].name != "(unlock store)") continue;
    StateBits s2 = s;
    // Move the robot to the kitchen first (unlock needs an adjacent robot).
    for (OpId m = 0; m < t.ops.size(); ++m) {
      if (t.ops[m].name == "(move hall kitchen)" && t.applicable(s.data(), m)) t.apply(s.data(), m, s2.data());
    }
    ASSERT_TRUE(t.applicable(s2.data(), o));
    StateBits s3 = s2;
    t.apply(s2.data(), o, s3.data());
    EXPECT_FALSE(testBit(s3.data(), static_cast<FactId>(locked)));
    EXPECT_TRUE(testBit(s3.data(), static_cast<FactId>(comp)));
  }
}

TEST(Grounding, ConditionalEffectsAndQuantifiedPreconditions) {
  auto g = ground(test::kAdlDomain, test::kAdlProblem, true);
  const Task& t = *g.task;
  bool saw_move = false, saw_light = false;
  for (const auto& o : t.ops) {
    if (o.name == "(move hall kitchen)") {
      saw_move = true;
      EXPECT_EQ(o.cond_effects.size(), 2U);  // one per item (forall expanded), condition (holding i)
      for (const auto& ce : o.cond_effects) {
        ASSERT_EQ(ce.cond.size(), 1U);
        EXPECT_NE(t.fact_names[ce.cond[0]].find("(holding"), std::string::npos);
      }
    }
    if (o.name == "(light-all)") {
      saw_light = true;
      // (locked hall/kitchen) are unreachable, so their lit effects are unconditional; only
      // (lit store) depends on (not (locked store)).
      EXPECT_EQ(o.cond_effects.size(), 1U);
      EXPECT_EQ(o.add.size(), 2U);
    }
    if (o.name == "(unlock store)") {
      // forall (?i) (not (holding ?i)) became complement-fact preconditions.
      int neg = 0;
      for (FactId f : o.pre) neg += t.fact_names[f].rfind("(not (holding", 0) == 0;
      EXPECT_EQ(neg, 2);
    }
  }
  EXPECT_TRUE(saw_move);
  EXPECT_TRUE(saw_light);
}

TEST(Grounding, UndefinedCostTermsMakeActionsInapplicable) {
  const std::string prob = R"((define (problem p) (:domain rooms) (:objects kitchen - room)
    (:init (at-robot hall) (connected hall kitchen) (= (dist hall kitchen) 4))
    (:goal (at-robot kitchen)) (:metric minimize (total-cost))))";
  auto g = ground(test::kAdlDomain, prob, true);
  EXPECT_TRUE(hasOp(*g.task, "(move hall kitchen)"));
  EXPECT_FALSE(hasOp(*g.task, "(move kitchen hall)"));  // (dist kitchen hall) undefined
}

TEST(Grounding, CoversAndExtendsTheSeeds) {
  auto g = ground(test::kAdlDomain, test::kAdlProblem, true);
  Grounder& gr = *g.grounder;
  EXPECT_TRUE(gr.covers(g.init));
  // A reachable atom is covered; a new static atom is not, and extends the grounding.
  auto reachable = gr.atomId("at-robot", {"store"});
  ASSERT_TRUE(reachable.ok());
  EXPECT_TRUE(gr.isReachable(*reachable));
  auto fresh = gr.atomId("connected", {"store", "hall"});
  ASSERT_TRUE(fresh.ok());
  EXPECT_FALSE(gr.covers({*fresh}));
  const size_t before = gr.stats().action_instances;
  std::vector<AtomId> init2 = g.init;
  init2.push_back(*fresh);
  ASSERT_TRUE(gr.extend(init2, Termination()).ok());
  EXPECT_TRUE(gr.covers(init2));
  EXPECT_GT(gr.stats().action_instances, before);
  // Unit costs: (dist store hall) is undefined, which would make the move inapplicable with costs.
  auto t = gr.buildTask(init2, {}, false, Termination());
  ASSERT_TRUE(t.ok());
  EXPECT_TRUE(hasOp(**t, "(move store hall)"));
  auto tc = gr.buildTask(init2, {}, true, Termination());
  ASSERT_TRUE(tc.ok());
  EXPECT_FALSE(hasOp(**tc, "(move store hall)"));
  // Dropping the static fact again removes the operator (statics are per query).
  auto t2 = gr.buildTask(g.init, {}, false, Termination());
  ASSERT_TRUE(t2.ok());
  EXPECT_FALSE(hasOp(**t2, "(move store hall)"));
  EXPECT_FALSE(gr.atomId("connected", {"nowhere", "hall"}).ok());
  EXPECT_FALSE(gr.atomId("connected", {"hall"}).ok());
}

TEST(Grounding, DisjunctivePreconditionsSplitIntoOperators) {
  const std::string dom = R"((define (domain d) (:predicates (a) (b) (c) (g))
    (:action x :parameters () :precondition (and (or (a) (b)) (or (c) (not (a)))) :effect (g))
    (:action z :parameters () :precondition (g) :effect (and (not (a)) (not (b)) (not (c))))))";
  const std::string prob = "(define (problem p) (:domain d) (:init (a) (b) (c)) (:goal (g)))";
  auto g = ground(dom, prob, false);
  // (a and c), (b and c), (b and not a); (a and not a) is contradictory and dropped; no
  // duplicates.
  int n = 0;
  for (const auto& o : g.task->ops) n += o.name == "(x)";
  EXPECT_EQ(n, 3);
}

TEST(Grounding, FlatAndNestedPreconditionsGroundAlike) {
  // `flat` has a flat precondition (literals, negation, inequality: the fast path); `nested` has
  // the same one plus a quantified conjunct that grounds to true (the general path). Their
  // operators must have the same preconditions; `clash` needs p and not p and grounds to nothing.
  const std::string dom = R"(
(define (domain flat) (:requirements :adl)
  (:types obj)
  (:predicates (p ?x - obj) (q ?x - obj) (r ?x ?y - obj) (s ?x - obj) (done ?x ?y - obj))
  (:action flat :parameters (?a ?b - obj)
    :precondition (and (p ?a) (not (q ?b)) (r ?a ?b) (not (= ?a ?b)) (p ?a))
    :effect (and (done ?a ?b) (q ?a)))
  (:action nested :parameters (?a ?b - obj)
    :precondition (and (p ?a) (not (q ?b)) (r ?a ?b) (not (= ?a ?b)) (forall (?z - obj) (s ?z)))
    :effect (and (done ?a ?b) (q ?a)))
  (:action clash :parameters (?a - obj)
    :precondition (and (p ?a) (not (p ?a)))
    :effect (and (q ?a) (not (p ?a)))))
)";
  const std::string prob = R"(
(define (problem f) (:domain flat) (:objects o1 o2 o3 - obj)
  (:init (p o1) (p o2) (r o1 o2) (r o2 o1) (r o1 o1) (r o2 o3) (s o1) (s o2) (s o3))
  (:goal (and (done o1 o2) (not (q o3)))))
)";
  auto g = ground(dom, prob, false);
  const Task& t = *g.task;
  std::map<std::string, std::vector<FactId>> flat, nested;
  for (const auto& o : t.ops) {
    EXPECT_NE(o.name.rfind("(clash", 0), 0U) << o.name;
    const std::string args = o.name.substr(o.name.find(' '));
    if (o.name.rfind("(flat", 0) == 0) flat[args] = o.pre;
    if (o.name.rfind("(nested", 0) == 0) nested[args] = o.pre;
  }
  EXPECT_EQ(flat, nested);
  // (r o1 o1) is excluded by the inequality; (r o2 o3) with p o2: yes.
  EXPECT_EQ(flat.count(" o1 o1)"), 0U);
  ASSERT_EQ(flat.count(" o2 o3)"), 1U);
  ASSERT_EQ(flat.count(" o1 o2)"), 1U);
  // (p ?a) twice is one precondition (p is fluent: clash deletes it): p, not q (a complement
  // fact), and no static r.
  EXPECT_EQ(flat[" o1 o2)"].size(), 2U);
}

TEST(Grounding, StopsOnAnExpiredDeadline) {
  auto d = pddl::parseDomain(test::kAdlDomain);
  auto p = pddl::parseProblem(test::kAdlProblem, *d);
  auto gr = Grounder::create(*d, *p);
  ASSERT_TRUE(gr.ok());
  std::vector<AtomId> init;
  for (const auto& a : p->init) init.push_back(*(*gr)->atomId(a));
  // A deadline in the past: exploration of this tiny task may finish before the first check,
  // but task construction checks first thing.
  Termination expired(Deadline::in(-1.0));
  (void)(*gr)->extend(init, Termination());
  auto t = (*gr)->buildTask(init, {}, true, expired);
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.error().code, ErrorCode::kTimeout);
}

}  // namespace
}  // namespace tamp::symbolic_planner
