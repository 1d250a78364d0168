#include "tamp/dds/heartbeat.h"
#include "tamp/dds/service_node.h"

#include <atomic>
#include <limits>
#include <optional>
#include <string>
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

/// A service that waits for an input before it can work (as the execution monitor waits for the
/// robot state).
class WaitingNode : public ServiceNode {
 public:
  explicit WaitingNode(const ServiceArgs& a) : ServiceNode(a) {}
  std::atomic<bool> input{false};

 protected:
  std::string notReadyBecause() const override { return input ? "" : "no test input yet"; }
  double spinPeriodSeconds() const override { return 0.02; }
};

/// The state and detail of the alive service `name`, once it says `state` with `detail` (any
/// detail when nullopt), or nullopt after 10 s.
std::optional<ServiceInfo> once(const HeartbeatMonitor& monitor, const std::string& name, msg::ServiceState state,
                                const std::optional<std::string>& detail = std::nullopt) {
  const Deadline d = Deadline::in(10.0);
  while (!d.expired()) {
    for (const auto& s : monitor.services())
      if (s.name == name && s.alive && s.state == state && (!detail || s.detail == *detail)) return s;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return std::nullopt;
}

// A service is alive before it is ready: STARTING, saying what it waits for, until its input
// arrives; `waitFor(..., ready)` (what tamp run and tamp mission wait on) holds until then.
TEST(HeartbeatTest, AServiceWaitingForItsInputIsAliveButNotReadyUntilItArrives) {
  const int domain = testing::isolatedDomain();
  auto p = testing::makeParticipant(domain);
  ASSERT_TRUE(p);
  HeartbeatMonitor monitor(p);
  ServiceArgs args;
  args.name = "waiting_test";
  args.domain_id = domain;
  args.heartbeat_period_s = 0.05;
  WaitingNode node(args);
  std::jthread runner([&] { (void)node.run(); });
  // Its first beats may come before run() has asked what it waits for (empty detail): then it
  // says it.
  const auto starting = once(monitor, "waiting_test", msg::SERVICE_STARTING, "no test input yet");
  ASSERT_TRUE(starting.has_value()) << "no STARTING heartbeat saying what the service waits for";
  EXPECT_TRUE(monitor.waitFor("waiting_test", 1, Termination::after(5.0)));
  EXPECT_FALSE(monitor.waitFor("waiting_test", 1, Termination::after(0.5), /*ready=*/true));
  node.input = true;
  EXPECT_TRUE(monitor.waitFor("waiting_test", 1, Termination::after(10.0), /*ready=*/true));
  const auto ready = once(monitor, "waiting_test", msg::SERVICE_READY);
  ASSERT_TRUE(ready.has_value());
  EXPECT_EQ(ready->detail, "");
  node.stop();
}

}  // namespace
}  // namespace tamp::dds
