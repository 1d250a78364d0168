#include "tamp/graph_manager/params.h"

#include <gtest/gtest.h>

#include "tamp/core/paths.h"

namespace tamp::graph_manager {
namespace {

TEST(ParamsTest, TheShippedFileLoads) {
  auto p = loadParams(configDir() / "services" / "graph_manager.yaml");
  ASSERT_TRUE(p.ok()) << p.error().toString();
  EXPECT_FALSE(p->invalidReason());
}

TEST(ParamsTest, ErrorsNameLineAndField) {
  auto p = parseParams("policy: effort\nmax_evaluations: 0\n", "gm.yaml");
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.error().toString().find("gm.yaml:2"), std::string::npos) << p.error().toString();
  EXPECT_NE(p.error().toString().find("max_evaluations"), std::string::npos);
  auto q = parseParams("policy: greedy\n", "gm.yaml");
  ASSERT_FALSE(q.ok());
  EXPECT_NE(q.error().toString().find("unknown policy 'greedy'"), std::string::npos) << q.error().toString();
  auto u = parseParams("polcy: effort\n", "gm.yaml");
  EXPECT_FALSE(u.ok());
  auto w = parseParams("refit_wait_s: -1\n", "gm.yaml");
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().toString().find("refit_wait_s"), std::string::npos) << w.error().toString();
  EXPECT_TRUE(parseParams("refit_wait_s: 0\n", "gm.yaml").ok()) << "0: no wait";
}

TEST(ParamsTest, ValidateMatchesTheLoader) {
  GraphManagerParams p;
  EXPECT_FALSE(p.invalidReason());
  p.lower_bound_base_speed = 0;
  ASSERT_TRUE(p.invalidReason());
  EXPECT_NE(p.invalidReason()->find("lower_bound_base_speed"), std::string::npos);
}

TEST(ParamsTest, APushLongerThanItsStepIsRequired) {
  GraphManagerParams p;
  p.push_step_m = 0.5;
  p.push_max_m = 0.25;
  ASSERT_TRUE(p.invalidReason());
  EXPECT_NE(p.invalidReason()->find("push_max_m"), std::string::npos);
  auto q = parseParams("push_step_m: 0.5\npush_max_m: 0.25\n", "gm.yaml");
  ASSERT_FALSE(q.ok());
  EXPECT_NE(q.error().toString().find("push_max_m"), std::string::npos) << q.error().toString();
  EXPECT_FALSE(parseParams("push_gap_m: -0.1\n", "gm.yaml").ok());
  EXPECT_TRUE(parseParams("pushes_per_object: 0\n", "gm.yaml").ok()) << "0: never push";
  EXPECT_FALSE(parseParams("push_backoff_m: 0.5\n", "gm.yaml").ok()) << "backs off beyond the shortest push";
}

}  // namespace
}  // namespace tamp::graph_manager
