#include "tamp/dds/heartbeat.h"

#include <atomic>
#include <limits>
#include <thread>

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

/// Polls the monitor until `name`'s liveness is `alive` (or 10 s pass).
bool becomes(const HeartbeatMonitor& monitor, const std::string& name, bool alive) {
  const Deadline d = Deadline::in(10.0);
  while (!d.expired()) {
    for (const auto& s : monitor.services())
      if (s.name == name && s.alive == alive) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

TEST(HeartbeatTest, ALoopThatStopsKickingStopsTheBeatsUntilItKicksAgain) {
  auto p = testing::makeParticipant();
  ASSERT_TRUE(p);
  HeartbeatMonitor monitor(p);
  HeartbeatPublisher hb(p, "stalling_test", 0.05);
  hb.setState(msg::SERVICE_READY);
  ASSERT_TRUE(becomes(monitor, "stalling_test", true));
  EXPECT_EQ(hb.stalledFor(), 0.0) << "disarmed: no stall is measured";
  // Armed and never kicked again: the beats stop, and the monitor counts it dead (3 periods).
  hb.setStallLimit(0.2);
  EXPECT_TRUE(becomes(monitor, "stalling_test", false));
  EXPECT_GT(hb.stalledFor(), 0.2);
  // The loop turns again: the beats resume.
  std::atomic<bool> done{false};
  std::jthread loop([&] {
    while (!done) {
      hb.kick();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
  EXPECT_TRUE(becomes(monitor, "stalling_test", true));
  done = true;
  loop.join();
  // Disarmed: no kick needed.
  hb.setStallLimit(0.0);
  EXPECT_TRUE(becomes(monitor, "stalling_test", true));
  EXPECT_THROW(hb.setStallLimit(-1.0), std::exception);
  EXPECT_THROW(hb.setStallLimit(std::numeric_limits<double>::infinity()), std::exception);
}

// A worker (a mission, a frame) is watched while it works: idle, it needs no kick; busy and not
// kicked, the beats stop though the main loop turns; kicked or idle again, they resume.
TEST(HeartbeatTest, ABusyWorkerThatStopsKickingStopsTheBeatsAnIdleOneDoesNot) {
  auto p = testing::makeParticipant();
  ASSERT_TRUE(p);
  HeartbeatMonitor monitor(p);
  HeartbeatPublisher hb(p, "worker_test", 0.05);
  hb.setState(msg::SERVICE_READY);
  std::shared_ptr<WorkWatch> worker = hb.watchWorker("mission");
  std::atomic<bool> done{false};
  std::jthread main_loop([&] {
    while (!done) {
      hb.kick();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
  hb.setStallLimit(0.2);
  ASSERT_TRUE(becomes(monitor, "worker_test", true));
  // Idle for three times the limit (the time passing is what is tested): still beating.
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  EXPECT_EQ(worker->stalledFor(), 0.0);
  EXPECT_TRUE(becomes(monitor, "worker_test", true));
  // Busy, never kicked: dead, though the main loop turns.
  {
    WorkWatch::Scope busy(worker.get());
    EXPECT_TRUE(becomes(monitor, "worker_test", false));
    EXPECT_GT(worker->stalledFor(), 0.2);
    // It moves on again: alive.
    std::atomic<bool> working{true};
    std::jthread work([&] {
      while (working) {
        worker->kick();
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    });
    EXPECT_TRUE(becomes(monitor, "worker_test", true));
    working = false;
  }
  // Idle again (the scope ended): no kick needed.
  EXPECT_EQ(worker->stalledFor(), 0.0);
  EXPECT_TRUE(becomes(monitor, "worker_test", true));
  done = true;
  EXPECT_THROW((void)hb.watchWorker(""), std::exception);
}

}  // namespace
}  // namespace tamp::dds
