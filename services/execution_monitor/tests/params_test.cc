// Parameters: defaults valid, the shipped file loads, bad values and unknown keys are refused with
// file, line and field.
#include <gtest/gtest.h>

#include "tamp/core/paths.h"
#include "tamp/execution_monitor/params.h"

namespace tamp::execution_monitor {
namespace {

TEST(MonitorParamsTest, DefaultsAndShippedFileAreValid) {
  EXPECT_TRUE(MonitorParams{}.validate());
  auto p = loadMonitorParams(configDir() / "services" / "execution_monitor.yaml");
  ASSERT_TRUE(p) << p.error().toString();
  EXPECT_DOUBLE_EQ(p->start_tolerance.position_m, MonitorParams{}.start_tolerance.position_m);
  EXPECT_DOUBLE_EQ(p->timeout.margin_s, MonitorParams{}.timeout.margin_s);
  EXPECT_TRUE(p->robot_description.empty());
}

TEST(MonitorParamsTest, BadValuesNameFileLineAndField) {
  auto p = parseMonitorParams("timeout: {stddevs: 3, margin_s: -1}\npath_check: {step_m: 0}\n",
                              "em.yaml");
  ASSERT_FALSE(p);
  const std::string m = p.error().toString();
  EXPECT_NE(m.find("em.yaml:1"), std::string::npos) << m;
  EXPECT_NE(m.find("timeout.margin_s"), std::string::npos) << m;
  EXPECT_NE(m.find("path_check.step_m"), std::string::npos) << m;

  auto unknown = parseMonitorParams("status_period: 0.2\n", "em.yaml");
  ASSERT_FALSE(unknown);
  EXPECT_NE(unknown.error().toString().find("status_period"), std::string::npos)
      << unknown.error().toString();

  auto empty_world = parseMonitorParams("world_id: \"\"\n", "em.yaml");
  ASSERT_FALSE(empty_world);
  EXPECT_NE(empty_world.error().toString().find("world_id"), std::string::npos);

  MonitorParams q;
  q.result_wait_s = 0;
  const Status s = q.validate();
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().where.field, "result_wait_s");
}

TEST(MonitorParamsTest, EmptyFileGivesDefaults) {
  auto p = parseMonitorParams("", "empty.yaml");
  ASSERT_TRUE(p) << p.error().toString();
  EXPECT_DOUBLE_EQ(p->status_period_s, MonitorParams{}.status_period_s);
}

}  // namespace
}  // namespace tamp::execution_monitor
