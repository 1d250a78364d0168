#include "tamp/effort_estimator/records.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

namespace tamp::effort_estimator {
namespace {

using ::testing::HasSubstr;

ExecutionRecord goodRecord() {
  ExecutionRecord r;
  r.action.kind = ActionKind::kMoveBase;
  r.action.path.joint_names = {"base_x", "base_y", "base_theta"};
  r.action.path.waypoints = {{0, 0, 0}, {1, 0, 0}};
  r.duration_s = 3.2;
  r.timestamp_s = 1.7e9;
  r.source = "test";
  return r;
}

TEST(RecordsTest, GoodRecordBecomesFeatures) {
  auto f = toFeatureRecord(goodRecord());
  ASSERT_TRUE(f.ok()) << f.error().toString();
  EXPECT_EQ(f->features.kind, ActionKind::kMoveBase);
  EXPECT_EQ(f->features.moves.size(), 1u);
  EXPECT_DOUBLE_EQ(f->duration_s, 3.2);
  EXPECT_EQ(f->source, "test");
  EXPECT_TRUE(validateFeatureRecord(*f).ok());
}

struct BadRecord {
  const char* name;
  ExecutionRecord record;
  const char* message;
  const char* field;
};

std::vector<BadRecord> badRecords() {
  std::vector<BadRecord> c;
  auto with = [](auto mutate) {
    ExecutionRecord r = goodRecord();
    mutate(r);
    return r;
  };
  c.push_back({"negative", with([](auto& r) { r.duration_s = -1.0; }), "duration must be positive, got -1 s", "duration_s"});
  c.push_back({"zero", with([](auto& r) { r.duration_s = 0.0; }), "duration must be positive", "duration_s"});
  c.push_back({"nan", with([](auto& r) { r.duration_s = std::numeric_limits<double>::quiet_NaN(); }),
               "duration is NaN", "duration_s"});
  c.push_back({"inf", with([](auto& r) { r.duration_s = std::numeric_limits<double>::infinity(); }),
               "duration is infinite", "duration_s"});
  c.push_back({"too_long", with([](auto& r) { r.duration_s = 7200.0; }), "exceeds the limit of 3600 s", "duration_s"});
  c.push_back({"bad_timestamp", with([](auto& r) { r.timestamp_s = -5.0; }), "timestamp must be finite", "timestamp_s"});
  c.push_back({"empty_path", with([](auto& r) { r.action.path.waypoints.clear(); }), "empty path",
               "action.path.waypoints"});
  c.push_back({"mismatched_path", with([](auto& r) { r.action.path.waypoints[1].pop_back(); }),
               "waypoint has 2 values for 3 joints", "action.path.waypoints[1]"});
  c.push_back({"failed_action", with([](auto& r) { r.success = false; }), "the action failed", "success"});
  c.push_back({"unknown_kind", with([](auto& r) { r.action.kind = static_cast<ActionKind>(42); }),
               "unknown action kind 42", "action.kind"});
  return c;
}

class BadRecordTest : public ::testing::TestWithParam<BadRecord> {};

TEST_P(BadRecordTest, IsRejectedWithReason) {
  const BadRecord& c = GetParam();
  auto f = toFeatureRecord(c.record);
  ASSERT_FALSE(f.ok());
  EXPECT_EQ(f.error().code, ErrorCode::kInvalidArgument);
  EXPECT_THAT(f.error().message, HasSubstr(c.message));
  EXPECT_EQ(f.error().where.field, c.field);
}

INSTANTIATE_TEST_SUITE_P(Adversarial, BadRecordTest, ::testing::ValuesIn(badRecords()),
                         [](const auto& test_info) { return std::string(test_info.param.name); });

TEST(RecordsTest, DurationLimitIsConfigurable) {
  ExecutionRecord r = goodRecord();
  r.duration_s = 7200.0;
  EXPECT_TRUE(toFeatureRecord(r, 10000.0).ok());
}

}  // namespace
}  // namespace tamp::effort_estimator
