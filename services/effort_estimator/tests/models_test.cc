#include "tamp/effort_estimator/models.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include "synthetic.h"

namespace tamp::effort_estimator {
namespace {

TEST(ModelSpecTest, EveryKindHasConsistentNamedParameters) {
  for (ActionKind kind : kAllActionKinds) {
    const ModelSpec& spec = modelSpec(kind);
    EXPECT_EQ(spec.kind, kind);
    EXPECT_LE(spec.size(), kMaxModelParameters);
    std::set<std::string> names;
    for (const auto& p : spec.parameters) {
      EXPECT_TRUE(names.insert(p.name).second) << "duplicate " << p.name;
      EXPECT_GT(p.lower, 0.0) << p.name;
      EXPECT_LT(p.lower, p.default_value) << p.name;
      EXPECT_LT(p.default_value, p.upper) << p.name;
      EXPECT_GT(p.prior_log_stddev, 0.0) << p.name;
      EXPECT_FALSE(p.unit.empty()) << p.name;
    }
  }
  EXPECT_THROW(modelSpec(static_cast<ActionKind>(7)), std::invalid_argument);
}

TEST(TrapezoidTest, KnownValues) {
  // Long move: cruise. 2 m at 0.5 m/s, 0.5 m/s^2: 2/0.5 + 0.5/0.5 = 5 s.
  EXPECT_DOUBLE_EQ(trapezoidTime(2.0, 0.5, 0.5), 5.0);
  // Short move (d < v^2/a = 0.5): triangle, 2*sqrt(d/a).
  EXPECT_DOUBLE_EQ(trapezoidTime(0.1, 0.5, 0.5), 2.0 * std::sqrt(0.2));
  EXPECT_DOUBLE_EQ(trapezoidTime(0.0, 0.5, 0.5), 0.0);
  // Continuous at the switch d = v^2/a: both branches give 2v/a.
  EXPECT_NEAR(trapezoidTime(0.5 - 1e-12, 0.5, 0.5), 2.0, 1e-6);
  EXPECT_NEAR(trapezoidTime(0.5, 0.5, 0.5), 2.0, 1e-12);
  EXPECT_THROW(trapezoidTime(-1.0, 0.5, 0.5), std::invalid_argument);
  EXPECT_THROW(trapezoidTime(1.0, 0.0, 0.5), std::invalid_argument);
}

// The O(log n) prefix-sum evaluation against a direct per-move sum, on random actions.
TEST(PredictDurationTest, MatchesDirectSumOfMoveTimes) {
  std::mt19937_64 rng(7);
  for (ActionKind kind : {ActionKind::kMoveBase, ActionKind::kMoveArm}) {
    const std::vector<double> p = synthetic::trueParameters(kind);
    for (int i = 0; i < 200; ++i) {
      auto f = extractFeatures(synthetic::randomAction(kind, rng));
      ASSERT_TRUE(f.ok());
      double direct = 0.0;
      if (kind == ActionKind::kMoveBase) {
        const double slow = 1.0 + p[6] * f->object_mass_kg;
        direct = p[5] + p[4] * static_cast<double>(f->moves.size() + f->turns.size());
        for (double d : f->moves.lengths()) direct += trapezoidTime(d, p[0] / slow, p[1] / slow);
        for (double d : f->turns.lengths()) direct += trapezoidTime(d, p[2] / slow, p[3] / slow);
      } else {
        const double slow = 1.0 + p[4] * f->object_mass_kg;
        direct = p[3] + p[2] * static_cast<double>(f->moves.size());
        for (double d : f->moves.lengths()) direct += trapezoidTime(d, p[0] / slow, p[1] / slow);
      }
      EXPECT_NEAR(predictDuration(*f, p), direct, 1e-9 * direct) << toString(kind) << " case " << i;
    }
  }
}

TEST(PredictDurationTest, ArmSegmentTimeIsThatOfTheSlowestJoint) {
  ActionDescription a;
  a.kind = ActionKind::kMoveArm;
  a.path.joint_names = {"j1", "j2", "j3"};
  a.path.waypoints = {{0, 0, 0}, {0.2, -1.5, 0.7}};
  const std::vector<double> p{1.0, 2.0, 0.1, 0.3, 0.1};  // v, a, settle, overhead, payload
  auto t = predictDuration(a, p);
  ASSERT_TRUE(t.ok());
  EXPECT_NEAR(*t, 0.3 + 0.1 + (1.5 / 1.0 + 1.0 / 2.0), 1e-12);
}

TEST(PredictDurationTest, HeavierObjectsAreSlower) {
  for (ActionKind kind : {ActionKind::kPick, ActionKind::kPlace, ActionKind::kMoveArm}) {
    std::mt19937_64 rng(3);
    ActionDescription a = synthetic::randomAction(kind, rng);
    const std::vector<double> p = modelSpec(kind).defaults();
    double last = 0.0;
    for (double m : {0.0, 0.5, 2.0, 5.0}) {
      a.object_mass_kg = m;
      auto t = predictDuration(a, p);
      ASSERT_TRUE(t.ok());
      EXPECT_GT(*t, last) << toString(kind) << " mass " << m;
      last = *t;
    }
  }
}

TEST(PredictDurationTest, PickRetreatsLoadedAndPlaceApproachesLoaded) {
  const std::vector<double> p{0.05, 0.2, 1.5, 1.0};  // v, a, gripper, payload slowdown 1/kg
  ActionFeatures f;
  f.kind = ActionKind::kPick;
  f.approach_m = 0.2;
  f.retreat_m = 0.1;
  f.object_mass_kg = 1.0;  // slowdown factor 2
  EXPECT_NEAR(predictDuration(f, p), trapezoidTime(0.2, 0.05, 0.2) + 1.5 + trapezoidTime(0.1, 0.025, 0.1), 1e-12);
  f.kind = ActionKind::kPlace;
  EXPECT_NEAR(predictDuration(f, p), trapezoidTime(0.2, 0.025, 0.1) + 1.5 + trapezoidTime(0.1, 0.05, 0.2), 1e-12);
}

TEST(PredictDurationTest, LogGradientMatchesFiniteDifferences) {
  std::mt19937_64 rng(11);
  for (ActionKind kind : kAllActionKinds) {
    for (int i = 0; i < 20; ++i) {
      auto f = extractFeatures(synthetic::randomAction(kind, rng));
      ASSERT_TRUE(f.ok());
      std::vector<double> p = synthetic::trueParameters(kind);
      std::vector<double> g(p.size());
      const double t = predictDurationWithLogGradient(*f, p, g);
      EXPECT_DOUBLE_EQ(t, predictDuration(*f, p));
      for (std::size_t j = 0; j < p.size(); ++j) {
        const double h = 1e-6;
        std::vector<double> up = p, down = p;
        up[j] *= std::exp(h);
        down[j] *= std::exp(-h);
        const double fd = (predictDuration(*f, up) - predictDuration(*f, down)) / (2 * h);
        EXPECT_NEAR(g[j], fd, 1e-5 * (1.0 + std::abs(t))) << toString(kind) << " param " << j;
      }
    }
  }
}

TEST(PredictDurationTest, RejectsWrongParameters) {
  ActionFeatures f;
  f.kind = ActionKind::kPick;
  EXPECT_THROW(predictDuration(f, std::vector<double>{1.0, 2.0}), std::invalid_argument);
  EXPECT_THROW(predictDuration(f, std::vector<double>{1.0, 2.0, -1.0, 0.1}), std::invalid_argument);
  EXPECT_THROW(predictDuration(f, std::vector<double>{1.0, 2.0, NAN, 0.1}), std::invalid_argument);
  ActionDescription bad;
  bad.kind = ActionKind::kMoveBase;  // empty path
  EXPECT_FALSE(predictDuration(bad, modelSpec(ActionKind::kMoveBase).defaults()).ok());
}

}  // namespace
}  // namespace tamp::effort_estimator
