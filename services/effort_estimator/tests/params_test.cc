#include "tamp/effort_estimator/params.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>

#include "tamp/effort_estimator/models.h"

namespace tamp::effort_estimator {
namespace {

using ::testing::HasSubstr;

TEST(ParamsTest, ShippedConfigLoadsAndMatchesTheBuiltInDefaults) {
  auto p = loadEstimatorParams(std::string(TAMP_SOURCE_DIR) + "/config/services/effort_estimator.yaml");
  ASSERT_TRUE(p.ok()) << p.error().toString();
  const EstimatorParams d;
  EXPECT_EQ(p->store_directory, d.store_directory);
  EXPECT_EQ(p->refit_batch_size, d.refit_batch_size);
  EXPECT_DOUBLE_EQ(p->surprise_sigma, d.surprise_sigma);
  EXPECT_EQ(p->fit.loss, d.fit.loss);
  EXPECT_DOUBLE_EQ(p->fit.prior_noise, d.fit.prior_noise);
  for (ActionKind k : kAllActionKinds) EXPECT_EQ(p->prior(k).values, modelSpec(k).defaults()) << toString(k);
  EXPECT_TRUE(d.validate().ok());
}

TEST(ParamsTest, OverridesPriorCentres) {
  auto p = parseEstimatorParams("defaults:\n  move_base:\n    max_linear_speed: 0.8\nloss: huber\n", "p.yaml");
  ASSERT_TRUE(p.ok()) << p.error().toString();
  EXPECT_DOUBLE_EQ(p->prior(ActionKind::kMoveBase).values[0], 0.8);
  EXPECT_EQ(p->fit.loss, LossKind::kHuber);
}

TEST(ParamsTest, ReadsArmJointScales) {
  auto p = parseEstimatorParams("arm_joint_scales:\n  arm_joint_5: 1.3\n  arm_joint_6: 1.3\n", "p.yaml");
  ASSERT_TRUE(p.ok()) << p.error().toString();
  EXPECT_DOUBLE_EQ(p->features.joint_scales.at("arm_joint_5"), 1.3);
  auto bad = parseEstimatorParams("arm_joint_scales:\n  arm_joint_5: -1\n  arm_joint_6: fast\n", "p.yaml");
  ASSERT_FALSE(bad.ok());
  EXPECT_THAT(bad.error().message, HasSubstr("p.yaml:2:16: field 'arm_joint_scales.arm_joint_5': must be positive, got -1"));
  EXPECT_THAT(bad.error().message, HasSubstr("field 'arm_joint_scales.arm_joint_6': expected a number, got 'fast'"));
}

TEST(ParamsTest, ReportsEveryErrorWithFileLineAndField) {
  auto p = parseEstimatorParams(
      "refit_batch_size: 0\n"
      "loss: l1\n"
      "prior_noise: -0.1\n"
      "refit_perod_s: 3\n"
      "defaults:\n"
      "  move_base:\n"
      "    max_linear_speed: 50\n"
      "    top_speed: 1\n"
      "  fly: {}\n"
      "surprise_sigma: -1\n",
      "svc.yaml");
  ASSERT_FALSE(p.ok());
  const std::string msg = p.error().message;
  EXPECT_THAT(msg, HasSubstr("svc.yaml:1:19: field 'refit_batch_size': must be >= 1, got 0"));
  EXPECT_THAT(msg, HasSubstr("svc.yaml:2:7: field 'loss': unknown loss 'l1'"));
  EXPECT_THAT(msg, HasSubstr("field 'prior_noise': must be in (0, 2]"));
  EXPECT_THAT(msg, HasSubstr("svc.yaml:4:1: field 'refit_perod_s': unknown key"));
  EXPECT_THAT(msg, HasSubstr("svc.yaml:7:23: field 'defaults.move_base.max_linear_speed': must be within [0.01, 5] m/s, got 50"));
  EXPECT_THAT(msg, HasSubstr("field 'defaults.move_base.top_speed': unknown key"));
  EXPECT_THAT(msg, HasSubstr("field 'defaults.fly': unknown action kind 'fly'"));
  EXPECT_THAT(msg, HasSubstr("svc.yaml:10:17: field 'surprise_sigma'"));
}

TEST(ParamsTest, MissingFileNamesIt) {
  auto p = loadEstimatorParams("/nonexistent/effort.yaml");
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().code, ErrorCode::kNotFound);
  EXPECT_EQ(p.error().where.file, "/nonexistent/effort.yaml");
}

TEST(ParamsTest, RelativeStoreDirectoryLivesUnderTheDataDir) {
  ::setenv("TAMP_DATA_DIR", "/var/lib/tamp", 1);
  EXPECT_EQ(resolveStoreDirectory("effort"), std::filesystem::path("/var/lib/tamp/effort"));
  EXPECT_EQ(resolveStoreDirectory("/abs/dir"), std::filesystem::path("/abs/dir"));
  EXPECT_TRUE(resolveStoreDirectory("").empty());
  ::unsetenv("TAMP_DATA_DIR");
}

TEST(ParamsTest, ValidateCatchesProgrammaticMistakes) {
  EstimatorParams p;
  p.refit_period_s = 0;
  p.priors[0].values[0] = -1;
  Status s = p.validate();
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.error().message, HasSubstr("field 'refit_period_s'"));
  EXPECT_THAT(s.error().message, HasSubstr("field 'defaults.move_base.max_linear_speed'"));
}

}  // namespace
}  // namespace tamp::effort_estimator
