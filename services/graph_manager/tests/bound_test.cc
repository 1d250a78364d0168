// DriveBound (bound.h): calibrated from answers of the effort model's form, it never exceeds the
// model's predicted effort of a base path between poses that far apart, whatever the path, load,
// parameters and variance; answers of another form leave the distance bound.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "tamp/effort_model/models.h"
#include "tamp/graph_manager/bound.h"

namespace tamp::graph_manager {
namespace {

JointPath basePath(const std::vector<std::vector<double>>& waypoints) {
  JointPath p;
  p.joint_names = {"base_x", "base_y", "base_theta"};
  p.waypoints = waypoints;
  return p;
}

/// What the effort estimator answers: the log-normal mean and stddev around the model's nominal
/// time, `var` the variance of log T (parameters and noise).
EffortAnswer modelAnswer(const JointPath& path, double mass, const std::vector<double>& params, double var) {
  effort_model::ActionDescription d;
  d.kind = ActionKind::kMoveBase;
  d.path = path;
  d.object_mass_kg = mass;
  const auto t = effort_model::predictDuration(d, params);
  EffortAnswer a;
  if (!t) return a;
  a.ok = true;
  a.mean_s = *t * std::exp(0.5 * var);
  a.stddev_s = a.mean_s * std::sqrt(std::expm1(var));
  return a;
}

std::vector<EffortAnswer> calibrationAnswers(const std::vector<double>& params, std::mt19937& rng) {
  std::uniform_real_distribution<double> var(0.0, 0.3);
  std::vector<EffortAnswer> out;
  for (const auto& q : DriveBound::queries()) out.push_back(modelAnswer(q.path, 0.0, params, var(rng)));
  return out;
}

TEST(DriveBoundTest, TheModelsStraightDriveBoundsEveryBasePathBetweenPosesThatFarApart) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto defaults = effort_model::modelSpec(ActionKind::kMoveBase).defaults();
  for (int set = 0; set < 6; ++set) {
    // The default parameters, then parameters scaled anywhere in [1/3, 3] each.
    std::vector<double> params = defaults;
    if (set > 0)
      for (double& p : params) p *= std::exp(std::log(3.0) * (2.0 * unit(rng) - 1.0));
    DriveBound bound(1.5);
    ASSERT_TRUE(bound.calibrate(calibrationAnswers(params, rng))) << "set " << set;
    ASSERT_TRUE(bound.calibrated());
    for (int i = 0; i < 2000; ++i) {
      // 2 to 6 waypoints anywhere within 150 m (up to 420 m apart: past the last calibrated
      // length), any headings, a load up to 5 kg, a variance up to 0.3.
      const int n = 2 + static_cast<int>(unit(rng) * 5.0);
      std::vector<std::vector<double>> w;
      for (int k = 0; k < n; ++k) {
        const double scale = i % 3 == 0 ? 1.0 : (i % 3 == 1 ? 10.0 : 150.0);
        w.push_back({scale * (2.0 * unit(rng) - 1.0), scale * (2.0 * unit(rng) - 1.0), M_PI * (2.0 * unit(rng) - 1.0)});
      }
      const double d = std::hypot(w.back()[0] - w.front()[0], w.back()[1] - w.front()[1]);
      const EffortAnswer a = modelAnswer(basePath(w), 5.0 * unit(rng), params, 0.3 * unit(rng));
      ASSERT_TRUE(a.ok);
      ASSERT_LE(bound(d), a.mean_s * (1.0 + 1e-9) + 1e-9) << "set " << set << ", path " << i << ", " << d << " m";
    }
  }
}

TEST(DriveBoundTest, TheModelsBoundIsTighterThanTheDistanceAtTopSpeed) {
  std::mt19937 rng(3);
  const auto params = effort_model::modelSpec(ActionKind::kMoveBase).defaults();
  DriveBound bound(1.5);
  ASSERT_TRUE(bound.calibrate(calibrationAnswers(params, rng)));
  const JointPath straight = basePath({{0, 0, 0}, {5, 0, 0}});
  const double nominal = *effort_model::predictDuration(effort_model::ActionDescription{ActionKind::kMoveBase, straight}, params);
  // A straight drive of 5 m is bounded by (about) its own nominal time, well above 5 m at 1.5 m/s.
  EXPECT_GT(bound(5.0), 1.5 * (5.0 / 1.5));
  EXPECT_NEAR(bound(5.0), nominal, 0.05 * nominal);
  // Beyond the samples (about 200 m): the last one (N increases), or the distance bound past it.
  EXPECT_DOUBLE_EQ(bound(300.0), bound(250.0));
  EXPECT_DOUBLE_EQ(bound(1e4), 1e4 / 1.5);
}

TEST(DriveBoundTest, AnswersNotOfTheModelsFormLeaveTheDistanceBound) {
  auto answers = [](auto time_of) {
    std::vector<EffortAnswer> out;
    for (double d : DriveBound::lengths()) out.push_back(EffortAnswer{true, time_of(d), 0.0, ""});
    return out;
  };
  DriveBound bound(2.0);
  // Convex in the length (quadratic): the chords would lie above the times.
  EXPECT_FALSE(bound.calibrate(answers([](double d) { return 1.0 + d * d; })));
  EXPECT_FALSE(bound.calibrated());
  EXPECT_DOUBLE_EQ(bound(4.0), 2.0);
  // Decreasing.
  EXPECT_FALSE(bound.calibrate(answers([](double d) { return 10.0 - d * 0.01; })));
  // One failed answer, or too few answers.
  auto one_failed = answers([](double d) { return 1.0 + d; });
  one_failed[3].ok = false;
  EXPECT_FALSE(bound.calibrate(one_failed));
  EXPECT_FALSE(bound.calibrate({}));
  // Linear is concave: taken, and never below the distance bound.
  ASSERT_TRUE(bound.calibrate(answers([](double d) { return 1.0 + d; })));
  EXPECT_DOUBLE_EQ(bound(4.0), 5.0);
  EXPECT_THROW(DriveBound(0.0), std::invalid_argument);
}

}  // namespace
}  // namespace tamp::graph_manager
