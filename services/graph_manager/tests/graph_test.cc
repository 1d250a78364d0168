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
