// The pure pieces of policy oracle (oracle.h): the removal subsets it evaluates exhaustively,
// the price of scripted failures, the hidden objects in the world it plans in.
#include "tamp/graph_manager/oracle.h"

#include <gtest/gtest.h>

#include "tamp/graph_manager/params.h"

namespace tamp::graph_manager {
namespace {

using Subsets = std::vector<std::vector<std::size_t>>;

TEST(OracleTest, RemovalSubsetsAreEverySubsetUpToTheStatedSizeSmallestFirst) {
  EXPECT_EQ(removalSubsets(3, 2), (Subsets{{0}, {1}, {2}, {0, 1}, {0, 2}, {1, 2}}));
  EXPECT_EQ(removalSubsets(3, 3), (Subsets{{0}, {1}, {2}, {0, 1}, {0, 2}, {1, 2}, {0, 1, 2}}));
  EXPECT_EQ(removalSubsets(4, 4).size(), 15u);                   // 2^4 - 1
  EXPECT_EQ(removalSubsets(4, 2).size(), 10u);                   // 4 + 6
  EXPECT_EQ(removalSubsets(2, 9), (Subsets{{0}, {1}, {0, 1}}));  // capped by n
  EXPECT_TRUE(removalSubsets(0, 3).empty());
  EXPECT_TRUE(removalSubsets(3, 0).empty());
  EXPECT_TRUE(removalSubsets(3, -1).empty());
}

OracleFault failAt(int step, std::optional<ActionKind> kind) {
  OracleFault f;
  f.id = "f";
  f.type = OracleFault::Type::kFailAction;
  f.step = step;
  f.action = kind;
  return f;
}

// Drive 10 s, arm 3 s, pick 5 s, drive 8 s: commands 0, 1, 2, 3 when nothing ran yet.
const std::vector<BranchStep> kBranch{{ActionKind::kMoveBase, 10.0, 1},
                                      {ActionKind::kMoveArm, 3.0, 1},
                                      {ActionKind::kPick, 5.0, 1},
                                      {ActionKind::kMoveBase, 8.0, 1}};

TEST(OracleTest, AFailingPickIsPricedAsTheRetryItCosts) {
  // The pick is command 2: a pick failure scripted at step 2 costs the pick once more.
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(2, ActionKind::kPick)}, 0, kBranch), 5.0);
  // Scripted earlier: it waits for the first pick at or after its step (the simulator's rule).
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(0, ActionKind::kPick)}, 0, kBranch), 5.0);
  // Any kind: the action at the step itself.
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(1, std::nullopt)}, 0, kBranch), 3.0);
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(3, std::nullopt)}, 0, kBranch), 8.0);
  // After the branch, or already passed (the simulator accepted more commands): free.
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(4, std::nullopt)}, 0, kBranch), 0.0);
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(2, ActionKind::kPick)}, 3, kBranch), 0.0);
  // Counted from the commands already accepted: at 2, the branch's pick is command 4.
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(3, ActionKind::kMoveArm)}, 2, kBranch), 3.0);
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(4, ActionKind::kPick)}, 2, kBranch), 5.0);
  // No pick in the branch: nothing to pay.
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(0, ActionKind::kPlace)}, 0, kBranch), 0.0);
  // Two faults, two retries.
  EXPECT_DOUBLE_EQ(
      faultRetryPenalty({failAt(0, ActionKind::kPick), failAt(0, ActionKind::kMoveBase)}, 0,
                        kBranch),
      15.0);
  // A time trigger or another fault type has no fixed price.
  OracleFault timed = failAt(0, ActionKind::kPick);
  timed.step.reset();
  timed.time_s = 1.0;
  OracleFault drop = failAt(0, std::nullopt);
  drop.type = OracleFault::Type::kDropHeldObject;
  EXPECT_DOUBLE_EQ(faultRetryPenalty({timed, drop}, 0, kBranch), 0.0);
}

// namo_corridor_slippery: every pick of the box fails. With max_action_failures 2 the graph
// manager gives the pick up after two failures, so a branch through it is not executed as
// planned: priced beyond any branch that avoids it, not as a few cheap retries.
TEST(OracleTest, AnActionThatWillFailAsOftenAsTheGraphManagerToleratesIsGivenUp) {
  const std::vector<OracleFault> once{failAt(0, ActionKind::kPick)};
  const std::vector<OracleFault> twice{failAt(0, ActionKind::kPick), failAt(1, ActionKind::kPick)};
  EXPECT_DOUBLE_EQ(faultRetryPenalty(once, 0, kBranch, 2), 5.0);
  EXPECT_DOUBLE_EQ(faultRetryPenalty(twice, 0, kBranch, 2), 10.0 + kGivenUpPenaltyS);
  EXPECT_DOUBLE_EQ(faultRetryPenalty(twice, 0, kBranch, 3), 10.0);
  EXPECT_DOUBLE_EQ(faultRetryPenalty(twice, 0, kBranch), 10.0) << "no limit: retries only";
  // Struck on two different actions once each: retried, not given up.
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(0, ActionKind::kPick), failAt(0, ActionKind::kMoveArm)}, 0, kBranch, 2),
                   8.0);
}

TEST(OracleTest, APickWithATransferArmMotionCountsTwoCommands) {
  // Drive (command 0), then a pick sent as its transfer arm motion (1) and the pick (2).
  const std::vector<BranchStep> b{{ActionKind::kMoveBase, 10.0, 1}, {ActionKind::kPick, 6.0, 2}};
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(2, ActionKind::kPick)}, 0, b), 6.0);
  EXPECT_DOUBLE_EQ(faultRetryPenalty({failAt(3, ActionKind::kPick)}, 0, b), 0.0);
}

world::Object boxAt(const std::string& id, double x, double y) {
  world::Object o;
  o.id = id;
  o.kind = world::ObjectKind::kMovable;
  o.shape = world::Shape::box(0.4, 0.4, 0.4);
  o.pose = Eigen::Isometry3d::Identity();
  o.pose.translation() = Eigen::Vector3d(x, y, 0.2);
  o.mass = 3.0;
  o.graspable = true;
  return o;
}

TEST(OracleTest, HiddenObjectsJoinTheWorldUntilPerceptionHasThem) {
  world::World live;
  ASSERT_TRUE(live.addObject(boxAt("box_1", 5.02, 3.0)));  // perception's id for the crate it found
  world::Object crate = boxAt("crate", 5.0, 3.0);
  crate.hidden = true;
  world::Object chair = boxAt("chair", 1.0, 1.0);
  chair.hidden = true;
  world::Object known = boxAt("box_1", 9.0, 9.0);  // same id as a live object: the live one stays
  const world::World w = withHidden(live, {crate, chair, known});
  EXPECT_EQ(w.objects().size(), 2u);
  EXPECT_EQ(w.findObject("crate"), nullptr);  // seen already, as box_1
  ASSERT_NE(w.findObject("chair"), nullptr);
  EXPECT_FALSE(w.findObject("chair")->hidden);  // in the planner's world
  EXPECT_NEAR(w.findObject("box_1")->pose.translation().x(), 5.02, 1e-12);
}

TEST(OracleTest, AHiddenObjectFoundOffCentreOrMovedAwayIsNotAddedAgain) {
  world::Object slab = boxAt("slab", 6.1, 1.2);  // a thin box: 5 cm along x
  slab.shape = world::Shape::box(0.05, 0.3, 0.3);
  slab.hidden = true;
  std::set<std::string> found;
  world::World live;
  EXPECT_NE(withHidden(live, {slab}, &found).findObject("slab"), nullptr);
  EXPECT_TRUE(found.empty());
  // Perception's estimate is centred 4 cm beyond it (outside its box) but overlaps it.
  ASSERT_TRUE(live.addObject(boxAt("light_box_1", 6.14, 1.2)).ok());
  EXPECT_EQ(withHidden(live, {slab}, &found).findObject("slab"), nullptr);
  EXPECT_EQ(found, std::set<std::string>{"slab"});
  // The robot moved it away: no ghost where it was hidden.
  ASSERT_TRUE(live.setObjectPose("light_box_1", boxAt("x", 1.0, 3.0).pose).ok());
  EXPECT_EQ(withHidden(live, {slab}, &found).findObject("slab"), nullptr);
  EXPECT_NE(withHidden(live, {slab}).findObject("slab"), nullptr);  // without memory it would be
}

TEST(OracleTest, ThePolicyAndItsBoundAreValidatedParameters) {
  EXPECT_EQ(policyFromString("oracle"), Policy::kOracle);
  EXPECT_EQ(toString(Policy::kOracle), "oracle");
  auto p = parseParams("policy: oracle\noracle_max_objects: 2\n", "gm.yaml");
  ASSERT_TRUE(p.ok()) << p.error().toString();
  EXPECT_EQ(p->policy, Policy::kOracle);
  EXPECT_EQ(p->oracle_max_objects, 2);
  auto bad = parseParams("policy: oracle\noracle_max_objects: 5\n", "gm.yaml");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().toString().find("gm.yaml:2"), std::string::npos) << bad.error().toString();
  EXPECT_NE(bad.error().toString().find("oracle_max_objects"), std::string::npos)
      << bad.error().toString();
  GraphManagerParams q;
  q.oracle_max_objects = 0;
  ASSERT_TRUE(q.invalidReason());
  EXPECT_NE(q.invalidReason()->find("oracle_max_objects"), std::string::npos);
}

}  // namespace
}  // namespace tamp::graph_manager
