#include "tamp/effort_estimator/features.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace tamp::effort_estimator {
namespace {

using ::testing::ElementsAre;
using ::testing::DoubleNear;
using ::testing::HasSubstr;
constexpr double kPi = std::numbers::pi;

ActionDescription basePath(std::vector<std::vector<double>> waypoints) {
  ActionDescription a;
  a.kind = ActionKind::kMoveBase;
  a.path.joint_names = {"base_x", "base_y", "base_theta"};
  a.path.waypoints = std::move(waypoints);
  return a;
}

ActionDescription armPath(std::vector<std::vector<double>> waypoints) {
  ActionDescription a;
  a.kind = ActionKind::kMoveArm;
  a.path.joint_names = {"j1", "j2"};
  a.path.waypoints = std::move(waypoints);
  return a;
}

TEST(MoveSetTest, SortsAndKeepsPrefixSums) {
  MoveSet s({4.0, 1.0, 9.0});
  EXPECT_THAT(s.lengths(), ElementsAre(1.0, 4.0, 9.0));
  EXPECT_THAT(s.prefixSum(), ElementsAre(0.0, 1.0, 5.0, 14.0));
  EXPECT_THAT(s.prefixSqrtSum(), ElementsAre(0.0, 1.0, 3.0, 6.0));
  EXPECT_EQ(s.countBelow(4.0), 1u);
  EXPECT_EQ(s.countBelow(4.5), 2u);
  EXPECT_EQ(s.countBelow(100.0), 3u);
  EXPECT_DOUBLE_EQ(s.total(), 14.0);
  EXPECT_DOUBLE_EQ(MoveSet().total(), 0.0);
  EXPECT_THROW(MoveSet({1.0, -0.5}), std::invalid_argument);
  EXPECT_THROW(MoveSet({std::numeric_limits<double>::quiet_NaN()}), std::invalid_argument);
}

TEST(BaseFeaturesTest, LShapedPathIsTwoDrivesAndOneTurn) {
  auto f = extractFeatures(basePath({{0, 0, 0}, {2, 0, 0}, {2, 2, kPi / 2}}));
  ASSERT_TRUE(f.ok()) << f.error().toString();
  EXPECT_THAT(f->moves.lengths(), ElementsAre(DoubleNear(2.0, 1e-12), DoubleNear(2.0, 1e-12)));
  EXPECT_THAT(f->turns.lengths(), ElementsAre(DoubleNear(kPi / 2, 1e-12)));
}

TEST(BaseFeaturesTest, DenselySampledStraightLineIsOneDrive) {
  auto f = extractFeatures(basePath({{0, 0, 0}, {0.5, 0, 0}, {1.0, 0.001, 0}, {1.5, 0, 0}}));
  ASSERT_TRUE(f.ok());
  ASSERT_EQ(f->moves.size(), 1u);
  EXPECT_NEAR(f->moves.total(), 1.5, 1e-5);
  EXPECT_TRUE(f->turns.empty());
}

TEST(BaseFeaturesTest, TurnsToHeadingThenToFinalTheta) {
  // Start facing +y, drive along +x: turn pi/2 first; finish facing -x: turn pi at the end.
  auto f = extractFeatures(basePath({{0, 0, kPi / 2}, {1, 0, 0}, {1, 0, kPi}}));
  ASSERT_TRUE(f.ok());
  EXPECT_THAT(f->moves.lengths(), ElementsAre(DoubleNear(1.0, 1e-12)));
  EXPECT_THAT(f->turns.lengths(), ElementsAre(DoubleNear(kPi / 2, 1e-12), DoubleNear(kPi, 1e-12)));
}

TEST(BaseFeaturesTest, TurnsTakeTheShortWayAcrossPi) {
  auto f = extractFeatures(basePath({{0, 0, 3.1}, {0, 0, -3.1}}));
  ASSERT_TRUE(f.ok());
  EXPECT_TRUE(f->moves.empty());
  EXPECT_THAT(f->turns.lengths(), ElementsAre(DoubleNear(2 * kPi - 6.2, 1e-9)));
}

// A time-parameterized trajectory samples one turn in place at every sample period: still one
// turn (the simulator times each step rest-to-rest, so 40 samples were 40 stops).
TEST(BaseFeaturesTest, ATurnInPlaceSampledAtManyWaypointsIsOneTurn) {
  std::vector<std::vector<double>> wp;
  for (int i = 0; i <= 40; ++i) wp.push_back({0, 0, -kPi / 2 - 1.2 * i / 40.0});
  // The drive along -x needs a heading of pi: 0.37 rad more the same way, still the same turn.
  wp.push_back({-1, 0, kPi});
  auto f = extractFeatures(basePath(wp));
  ASSERT_TRUE(f.ok());
  EXPECT_THAT(f->turns.lengths(), ElementsAre(DoubleNear(kPi / 2, 1e-9)));
  EXPECT_THAT(f->moves.lengths(), ElementsAre(DoubleNear(1.0, 1e-12)));
}

TEST(BaseFeaturesTest, ATurnBackTheOtherWayIsASecondTurn) {
  auto f = extractFeatures(basePath({{0, 0, 0}, {0, 0, 0.25}, {0, 0, 0.5}, {0, 0, 0.2}}));
  ASSERT_TRUE(f.ok());
  EXPECT_THAT(f->turns.lengths(), ElementsAre(DoubleNear(0.3, 1e-12), DoubleNear(0.5, 1e-12)));
}

TEST(BaseFeaturesTest, ColumnOrderDoesNotMatter) {
  ActionDescription a;
  a.kind = ActionKind::kMoveBase;
  a.path.joint_names = {"base_theta", "base_y", "base_x"};
  a.path.waypoints = {{0, 0, 0}, {kPi / 2, 2, 2}};
  auto f = extractFeatures(a);
  ASSERT_TRUE(f.ok());
  auto g = extractFeatures(basePath({{0, 0, 0}, {2, 2, kPi / 2}}));
  ASSERT_TRUE(g.ok());
  EXPECT_EQ(*f, *g);
}

TEST(BaseFeaturesTest, SingleWaypointHasNoMoves) {
  auto f = extractFeatures(basePath({{1, 2, 3}}));
  ASSERT_TRUE(f.ok());
  EXPECT_TRUE(f->moves.empty());
  EXPECT_TRUE(f->turns.empty());
}

TEST(ArmFeaturesTest, StraightJointLineIsOneMoveOfItsLargestDisplacement) {
  auto f = extractFeatures(armPath({{0, 0}, {0.1, -0.2}, {0.2, -0.4}, {0.2, -0.4}}));
  ASSERT_TRUE(f.ok());
  EXPECT_THAT(f->moves.lengths(), ElementsAre(DoubleNear(0.4, 1e-12)));
}

TEST(ArmFeaturesTest, CornerSplitsMoves) {
  auto f = extractFeatures(armPath({{0, 0}, {0.3, 0}, {0.3, 0.5}, {0.0, 0.5}}));
  ASSERT_TRUE(f.ok());
  EXPECT_THAT(f->moves.lengths(), ElementsAre(DoubleNear(0.3, 1e-12), DoubleNear(0.3, 1e-12), DoubleNear(0.5, 1e-12)));
}

TEST(ArmFeaturesTest, JointScalesMakeTheSlowestJointTheOneWithTheLargestScaledMove) {
  FeatureOptions o;
  o.joint_scales["j2"] = 4.0;  // j2 is four times faster than j1
  auto f = extractFeatures(armPath({{0, 0}, {0.3, 0.8}}), o);
  ASSERT_TRUE(f.ok());
  EXPECT_THAT(f->moves.lengths(), ElementsAre(DoubleNear(0.3, 1e-12)));  // max(0.3/1, 0.8/4)
  auto g = extractFeatures(armPath({{0, 0}, {0.3, 0.8}}));
  ASSERT_TRUE(g.ok());
  EXPECT_THAT(g->moves.lengths(), ElementsAre(DoubleNear(0.8, 1e-12)));
  o.joint_scales["j1"] = 0.0;
  EXPECT_FALSE(o.validate().ok());
  EXPECT_THROW((void)extractFeatures(armPath({{0, 0}}), o), std::invalid_argument);
}

TEST(ManipulationFeaturesTest, KeepsDistancesAndMass) {
  ActionDescription a;
  a.kind = ActionKind::kPick;
  a.approach_m = 0.1;
  a.retreat_m = 0.2;
  a.object_mass_kg = 1.5;
  auto f = extractFeatures(a);
  ASSERT_TRUE(f.ok());
  EXPECT_DOUBLE_EQ(f->approach_m, 0.1);
  EXPECT_DOUBLE_EQ(f->retreat_m, 0.2);
  EXPECT_DOUBLE_EQ(f->object_mass_kg, 1.5);
  EXPECT_TRUE(f->moves.empty());
}

// Adversarial inputs: each is rejected with a message and field that say what is wrong.
struct BadCase {
  const char* name;
  ActionDescription action;
  const char* message;
  const char* field;
};

std::vector<BadCase> badCases() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<BadCase> c;
  c.push_back({"empty_base_path", basePath({}), "empty path", "path.waypoints"});
  c.push_back({"short_waypoint", basePath({{0, 0, 0}, {1, 0}}), "waypoint has 2 values for 3 joints",
               "path.waypoints[1]"});
  c.push_back({"nan_value", basePath({{0, 0, 0}, {nan, 0, 0}}), "joint 'base_x' is not finite", "path.waypoints[1]"});
  ActionDescription missing = basePath({{0, 0}});
  missing.path.joint_names = {"base_x", "base_y"};
  c.push_back({"missing_theta", missing, "needs joints base_x, base_y and base_theta", "path.joint_names"});
  ActionDescription extra = basePath({{0, 0, 0, 0}});
  extra.path.joint_names.push_back("arm_joint_1");
  c.push_back({"extra_joint", extra, "non-base joint 'arm_joint_1'", "path.joint_names"});
  ActionDescription arm_base = armPath({{0, 0}});
  arm_base.path.joint_names = {"j1", "base_x"};
  c.push_back({"arm_with_base_joint", arm_base, "base joint 'base_x'", "path.joint_names"});
  ActionDescription dup = armPath({{0, 0}});
  dup.path.joint_names = {"j1", "j1"};
  c.push_back({"duplicate_joint", dup, "duplicate joint name 'j1'", "path.joint_names"});
  c.push_back({"empty_arm_path", armPath({}), "empty path", "path.waypoints"});
  ActionDescription pick_path = armPath({{0, 0}});
  pick_path.kind = ActionKind::kPick;
  c.push_back({"pick_with_path", pick_path, "pick takes approach_m/retreat_m, not a path", "path"});
  ActionDescription neg;
  neg.kind = ActionKind::kPlace;
  neg.approach_m = -0.1;
  c.push_back({"negative_approach", neg, "distance must be finite and in [0, 100] m", "approach_m"});
  ActionDescription heavy = basePath({{0, 0, 0}});
  heavy.object_mass_kg = -1;
  c.push_back({"negative_mass", heavy, "object mass must be finite and in [0, 10000] kg", "object_mass_kg"});
  c.push_back({"huge_coordinate", basePath({{0, 0, 0}, {1e300, 0, 0}}), "exceeds the limit of 100000",
               "path.waypoints[1]"});
  ActionDescription far;
  far.kind = ActionKind::kPlace;
  far.approach_m = 8.6e245;  // found by fuzz_effort_record: overflowed the model before the limit
  c.push_back({"huge_distance", far, "distance must be finite and in [0, 100] m", "approach_m"});
  ActionDescription unknown;
  unknown.kind = static_cast<ActionKind>(9);
  c.push_back({"unknown_kind", unknown, "unknown action kind 9", "kind"});
  ActionDescription base_dist = basePath({{0, 0, 0}});
  base_dist.retreat_m = 0.1;
  c.push_back({"distance_on_motion", base_dist, "approach_m/retreat_m are for pick/place only", "retreat_m"});
  return c;
}

class BadActionTest : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadActionTest, IsRejectedWithReason) {
  const BadCase& c = GetParam();
  auto f = extractFeatures(c.action);
  ASSERT_FALSE(f.ok()) << c.name;
  EXPECT_EQ(f.error().code, ErrorCode::kInvalidArgument);
  EXPECT_THAT(f.error().message, HasSubstr(c.message));
  EXPECT_EQ(f.error().where.field, c.field);
}

INSTANTIATE_TEST_SUITE_P(Adversarial, BadActionTest, ::testing::ValuesIn(badCases()),
                         [](const auto& test_info) { return std::string(test_info.param.name); });

}  // namespace
}  // namespace tamp::effort_estimator
