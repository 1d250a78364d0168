// Parameters: defaults valid, YAML overrides, every bad field named with its location.
#include <gtest/gtest.h>

#include "tamp/core/paths.h"
#include "tamp/motion_planner/params.h"

namespace tamp::motion_planner {
namespace {

TEST(ParamsTest, DefaultsAreValid) { EXPECT_TRUE(MotionPlannerParams{}.validate().ok()); }

TEST(ParamsTest, ShippedConfigLoads) {
  auto p = loadMotionPlannerParams(configDir() / "services" / "motion_planner.yaml", {"node"});
  ASSERT_TRUE(p.ok()) << p.error().toString();
  EXPECT_TRUE(p->validate().ok());
}

TEST(ParamsTest, OverridesAreRead) {
  auto p = parseMotionPlannerParams(
      "seed: 7\nsampling:\n  full_planner: rrtconnect\n  validity_resolution: 0.01\nlazy:\n  roadmap_samples: 50\n",
      "x.yaml");
  ASSERT_TRUE(p.ok()) << p.error().toString();
  EXPECT_EQ(p->seed, 7u);
  EXPECT_EQ(p->sampling.full_planner, PlannerKind::kRrtConnect);
  EXPECT_DOUBLE_EQ(p->sampling.validity_resolution, 0.01);
  EXPECT_EQ(p->lazy.roadmap_samples, 50);
}

TEST(ParamsTest, EveryErrorNamesFileLineAndField) {
  auto p = parseMotionPlannerParams(
      "lazy:\n  roadmap_neighbors: 1\n  optimise: true\ntiming:\n  arm_speed_scale: 2\nsampling:\n  lazy_planner: prm\n",
      "bad.yaml");
  ASSERT_FALSE(p.ok());
  const std::string m = p.error().message;
  EXPECT_NE(m.find("bad.yaml:2:"), std::string::npos) << m;
  EXPECT_NE(m.find("lazy.roadmap_neighbors"), std::string::npos) << m;
  EXPECT_NE(m.find("unknown key 'optimise'"), std::string::npos) << m;
  EXPECT_NE(m.find("timing.arm_speed_scale"), std::string::npos) << m;
  EXPECT_NE(m.find("unknown planner 'prm'"), std::string::npos) << m;
}

TEST(ParamsTest, NonMappingSectionIsAnError) {
  auto p = parseMotionPlannerParams("lazy: 3\n", "s.yaml");
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.error().message.find("lazy"), std::string::npos);
}

TEST(ParamsTest, ValidateNamesTheField) {
  MotionPlannerParams p;
  p.proof.min_cell_size = 1.0;  // > cell_size
  p.cost.base_speed = -1;
  const Status s = p.validate();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("proof.min_cell_size"), std::string::npos);
  EXPECT_NE(s.error().message.find("cost.base_speed"), std::string::npos);
}

TEST(ParamsTest, TheLazyProofShareIsAtMostTheFullModeOne) {
  MotionPlannerParams p;
  p.proof.time_share = 0.5;
  p.proof.lazy_time_share = 0.5;
  EXPECT_TRUE(p.validate().ok());
  p.proof.lazy_time_share = 0.6;
  const Status s = p.validate();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("proof.lazy_time_share"), std::string::npos) << s.error().message;
}

}  // namespace
}  // namespace tamp::motion_planner
