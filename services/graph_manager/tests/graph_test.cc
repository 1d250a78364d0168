#include "tamp/graph_manager/graph.h"

#include <gtest/gtest.h>

namespace tamp::graph_manager {
namespace {

TEST(GraphTest, EqualStatesAreOneNodeAndPlansMergeWhereTheyMeet) {
  ReachabilityGraph g;
  const std::vector<std::string> s0{"(robot-at a)"}, s1{"(robot-at b)"}, s2{"(robot-at c)"};
  auto p1 = g.addPlan({"(move_base a c)"}, {s0, s2}, "plan 0");
  auto p2 = g.addPlan({"(move_base a b)", "(move_base b c)"}, {s0, s1, s2}, "sub-task");
  EXPECT_EQ(g.nodes().size(), 3u);
  EXPECT_EQ(g.edges().size(), 3u);
  EXPECT_EQ(g.edge(p1[0]).to, g.edge(p2[1]).to) << "both plans end in the same node";
  EXPECT_EQ(g.out(g.edge(p1[0]).from).size(), 2u);
  // The same plan again adds nothing.
  g.addPlan({"(move_base a c)"}, {s0, s2}, "again");
  EXPECT_EQ(g.edges().size(), 3u);
  EXPECT_EQ(g.edge(p1[0]).kind, ActionKind::kMoveBase);
  EXPECT_EQ(g.edge(p1[0]).tokens, (std::vector<std::string>{"move_base", "a", "c"}));
}

// Traverse and the conditional branches hold a node's atoms or an edge while they plan sub-tasks
// that grow the graph (a graph manager crashed on occluded_can when this did not hold).
TEST(GraphTest, ReferencesToNodesAndEdgesStayValidWhileTheGraphGrows) {
  ReachabilityGraph g;
  auto first = g.addPlan({"(move_base l0 l1)"}, {{"(robot-at l0)"}, {"(robot-at l1)"}}, "plan 0");
  const Node& n0 = g.node(g.edge(first[0]).from);
  const Edge& e0 = g.edge(first[0]);
  const std::vector<std::string>* atoms = &n0.atoms;
  for (int i = 1; i < 2000; ++i) {
    const std::string a = "l" + std::to_string(i), b = "l" + std::to_string(i + 1);
    g.addPlan({"(move_base " + a + " " + b + ")"}, {{"(robot-at " + a + ")"}, {"(robot-at " + b + ")"}}, "grow");
  }
  ASSERT_EQ(g.nodes().size(), 2001u);
  EXPECT_EQ(&g.node(g.edge(first[0]).from), &n0);
  EXPECT_EQ(&g.edge(first[0]), &e0);
  EXPECT_EQ(&g.node(g.edge(first[0]).from).atoms, atoms);
  EXPECT_EQ(e0.action, "(move_base l0 l1)");
  EXPECT_EQ(n0.atoms, (std::vector<std::string>{"(robot-at l0)"}));
}

TEST(GraphTest, AtomOrderDoesNotMatter) {
  ReachabilityGraph g;
  const NodeId a = g.addNode({"(b)", "(a)"}, "x");
  const NodeId b = g.addNode({"(a)", "(b)", "(a)"}, "y");
  EXPECT_EQ(a, b);
}

TEST(GraphTest, VariantsAreParallelEdges) {
  ReachabilityGraph g;
  auto p = g.addPlan({"(move_base a c)"}, {{"(robot-at a)"}, {"(robot-at c)"}}, "plan 0");
  const EdgeId around = g.addVariant(p[0], Variant::kAround, "detour");
  EXPECT_NE(around, p[0]);
  EXPECT_EQ(g.addVariant(p[0], Variant::kAround, "again"), around);
  EXPECT_EQ(g.edge(around).to, g.edge(p[0]).to);
  EXPECT_EQ(g.edge(around).variant, Variant::kAround);
  const std::string dot = g.toDot({around}, 0);
  EXPECT_NE(dot.find("[around]"), std::string::npos);
  EXPECT_NE(dot.find("penwidth"), std::string::npos);
}

TEST(GraphTest, MismatchedPlanIsMisuse) {
  ReachabilityGraph g;
  EXPECT_THROW(g.addPlan({"(move_base a c)"}, {{"(robot-at a)"}}, "bad"), std::invalid_argument);
}

}  // namespace
}  // namespace tamp::graph_manager
