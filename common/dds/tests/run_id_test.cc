// Run ids: validation, and the isolation they give (a DDS partition per run) on one domain.
#include <cstdlib>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tamp/dds/heartbeat.h"
#include "test_util.h"

namespace tamp::dds {
namespace {

using ::testing::HasSubstr;

std::shared_ptr<Participant> inRun(const std::string& run_id) {
  auto p = Participant::create(
      ParticipantOptions{testing::isolatedDomain(), kProfileDefault, "run_test", {}}, run_id);
  if (!p) ADD_FAILURE() << p.error().toString();
  return p ? *p : nullptr;
}

TEST(RunIdTest, ValidationAndEnvironment) {
  ::unsetenv("TAMP_RUN_ID");
  EXPECT_EQ(resolveRunId("").value(), "");
  EXPECT_EQ(resolveRunId("run-20261201-1200.a_b").value(), "run-20261201-1200.a_b");
  for (const std::string& bad :
       std::vector<std::string>{"a b", "a/b", "tamp*", std::string(65, 'x')}) {
    auto r = resolveRunId(bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_THAT(r.error().toString(),
                HasSubstr("--run-id must be 1-64 characters of [A-Za-z0-9_.-], got '" + bad + "'"));
  }
  ::setenv("TAMP_RUN_ID", "from-env", 1);
  EXPECT_EQ(resolveRunId("").value(), "from-env");
  EXPECT_EQ(resolveRunId("flag").value(), "flag");
  ::setenv("TAMP_RUN_ID", "bad id", 1);
  EXPECT_THAT(resolveRunId("").error().toString(), HasSubstr("TAMP_RUN_ID must be"));
  EXPECT_FALSE(
      Participant::create(ParticipantOptions{testing::isolatedDomain(), kProfileDefault, "x", {}})
          .ok());
  ::unsetenv("TAMP_RUN_ID");
  EXPECT_EQ(runPartition(""), "");
  EXPECT_EQ(runPartition("r1"), "tamp.run.r1");
}

TEST(RunIdTest, EndpointsMatchOnlyWithinTheirRun) {
  ::unsetenv("TAMP_RUN_ID");
  auto a1 = inRun("run-a");
  auto a2 = inRun("run-a");
  auto b = inRun("run-b");
  auto none = inRun("");
  ASSERT_TRUE(a1 && a2 && b && none);
  EXPECT_EQ(a1->runId(), "run-a");
  EXPECT_EQ(none->runId(), "");
  HeartbeatMonitor seen_by_a(a2), seen_by_b(b), seen_by_none(none);
  HeartbeatPublisher beat(a1, "svc_in_a", 0.1);
  ASSERT_TRUE(seen_by_a.waitFor("svc_in_a", 1, Termination::after(10.0)));
  // Discovery within run a is done; the heartbeat writer matched exactly one monitor: its run's.
  Writer<msg::Heartbeat> probe(a1, topics::kHeartbeat);
  ASSERT_TRUE(probe.waitForReaders(Termination::after(10.0), 1));
  EXPECT_EQ(probe.matchedReaders(), 1);
  HeartbeatPublisher other(b, "svc_in_b", 0.1);
  ASSERT_TRUE(seen_by_b.waitFor("svc_in_b", 1, Termination::after(10.0)));
  for (const auto& s : seen_by_b.services()) EXPECT_NE(s.name, "svc_in_a");
  for (const auto& s : seen_by_a.services()) EXPECT_NE(s.name, "svc_in_b");
  EXPECT_TRUE(seen_by_none.services().empty());
  EXPECT_EQ(probe.matchedReaders(), 1);
}

}  // namespace
}  // namespace tamp::dds
