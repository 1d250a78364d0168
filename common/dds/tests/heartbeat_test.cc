#include "tamp/dds/heartbeat.h"

#include <gtest/gtest.h>

#include "test_util.h"

namespace tamp::dds {
namespace {

TEST(HeartbeatTest, MonitorSeesPublisherAndItsCleanExit) {
  auto p = testing::makeParticipant();
  ASSERT_TRUE(p);
  HeartbeatMonitor monitor(p);
  auto hb = std::make_unique<HeartbeatPublisher>(p, "planner_test", 0.1);
  hb->setState(msg::SERVICE_READY);
  hb->setCounters([] { return std::make_pair<uint64_t, uint64_t>(5, 1); });
  ASSERT_TRUE(monitor.waitFor("planner_test", 1, Termination::after(5.0)));
  // Wait for a beat with the counters.
  const Deadline d = Deadline::in(5.0);
  ServiceInfo info;
  while (!d.expired()) {
    auto all = monitor.services();
    ASSERT_EQ(all.size(), 1u);
    info = all[0];
    if (info.served == 5) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(info.name, "planner_test");
  EXPECT_EQ(info.pid, static_cast<uint32_t>(::getpid()));
  EXPECT_EQ(info.state, msg::SERVICE_READY);
  EXPECT_EQ(info.served, 5u);
  EXPECT_EQ(info.failed, 1u);
  EXPECT_TRUE(info.alive);

  hb.reset();  // clean exit: STOPPING + unregister
  const Deadline d2 = Deadline::in(5.0);
  while (!d2.expired() && monitor.services()[0].alive) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(monitor.services()[0].alive);
}

}  // namespace
}  // namespace tamp::dds
