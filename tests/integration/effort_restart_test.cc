// The effort estimator killed (SIGKILL) and restarted by a supervisor, as `tamp run` does (issue
// 13, kill -9 matrix): a client asking it for estimates with the graph manager's RPC settings is
// answered within its deadline ("effort estimator killed during a move_arm": an estimate went
// unanswered for 5 s although the restarted estimator was up), and execution records forwarded by
// the execution monitor while the estimator is down, or while the monitor itself is killed,
// reach the estimator's store exactly once. Real processes, real Fast DDS transports, their own
// domain.
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <thread>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "integration_util.h"
#include "tamp/core/paths.h"
#include "tamp/dds/rpc.h"
#include "tamp/dds/topics.h"
#include "tamp/effort_estimator/store.h"

namespace tamp::integration {
namespace {

using EffortClient = dds::RpcClient<msg::EffortRequest, msg::EffortReply>;
using Clock = std::chrono::steady_clock;

/// The graph manager's client settings (services/graph_manager/node/dds_clients.cc) and deadline.
constexpr dds::RpcClientOptions kGraphManagerRpc{2.0, 4, 0};
constexpr double kEffortDeadlineS = 5.0;

class EffortRestartTest : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_ = isolatedDomain();
    store_dir_ = tempFile("tamp_it_restart_store");
    std::filesystem::remove_all(store_dir_);
    config_ = tempFile("tamp_it_restart_effort.yaml");
    {
      std::ofstream out(config_);
      out << "store_directory: " << store_dir_.string() << "\n";
    }
    process::ProcessSpec spec = serviceSpec("tamp_effort_estimator_service", "effort_estimator", domain_,
                                            {"--config", config_.string()});
    std::filesystem::remove(spec.log_file);
    spec.restart = true;  // as tamp run's supervisor: 0.5 s back-off
    sup_.add(spec);
    ASSERT_TRUE(sup_.startAll().ok());
    auto p = dds::Participant::create({domain_, dds::kProfileDefault, "tamp/effort_restart_test", {}});
    ASSERT_TRUE(p) << p.error().toString();
    participant_ = *p;
  }

  void TearDown() override {
    sup_.stopAll(5.0);
    if (HasFailure()) {
      std::cerr << "---- effort_estimator log ----\n" << readFile(tempFile("tamp_it_effort_estimator.log")) << "\n";
    }
    std::filesystem::remove_all(store_dir_);
    std::filesystem::remove(config_);
  }

  static msg::EffortRequest pickQuery() {
    msg::EffortQuery q;
    q.kind(msg::ACTION_PICK);
    q.object_mass(1.0);
    q.approach_m(0.1);
    q.retreat_m(0.1);
    msg::EffortRequest r;
    r.queries().push_back(q);
    return r;
  }

  /// Polls the supervisor until it runs the service under a pid other than `old_pid`.
  bool awaitRestart(pid_t old_pid, double timeout_s) {
    const Deadline d = Deadline::in(timeout_s);
    while (!d.expired()) {
      sup_.poll();
      const auto st = sup_.status("effort_estimator");
      if (st->phase == process::ProcessPhase::kRunning && st->pid != old_pid) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  int domain_{0};
  std::filesystem::path store_dir_, config_;
  process::Supervisor sup_;
  std::shared_ptr<dds::Participant> participant_;
};

// The root of the matrix failure: a restarted service is not reachable through shared memory
// while its peers still hold the killed process (until its 5 s lease ends), when it took over the
// killed process's transport ports. Restarted 0.5 s after the kill, the estimator's heartbeat
// reaches the client and a call resent every 0.25 s is answered within 2 s of the kill (with the
// ports taken over: its heartbeat came 2.6 s and 4.6 s after the kill; now ~0.75 s).
TEST_F(EffortRestartTest, ARestartedEstimatorIsReachableAsSoonAsItIsUp) {
  std::mutex m;
  std::condition_variable cv;
  std::set<std::uint32_t> ready_pids;
  dds::Reader<msg::Heartbeat> heartbeats(participant_, dds::topics::kHeartbeat,
                                         [&](const msg::Heartbeat& h, const dds::SampleMeta&) {
                                           if (h.state() != msg::SERVICE_READY && h.state() != msg::SERVICE_BUSY) return;
                                           std::lock_guard l(m);
                                           ready_pids.insert(h.pid());
                                           cv.notify_all();
                                         });
  EffortClient client(participant_, dds::services::kEffort, dds::RpcClientOptions{0.25, 40, 0});
  auto first = client.call(pickQuery(), dds::CallOptions{15.0, {}});
  ASSERT_TRUE(first.ok()) << first.error().toString();
  const pid_t old_pid = sup_.status("effort_estimator")->pid;
  ASSERT_TRUE(sup_.signal("effort_estimator", SIGKILL));
  const auto killed = Clock::now();
  ASSERT_TRUE(awaitRestart(old_pid, 10.0)) << "the supervisor did not restart the estimator";
  const auto new_pid = static_cast<std::uint32_t>(sup_.status("effort_estimator")->pid);
  {
    std::unique_lock l(m);
    ASSERT_TRUE(cv.wait_for(l, std::chrono::seconds(10), [&] { return ready_pids.count(new_pid) > 0; }))
        << "no heartbeat from the restarted estimator";
  }
  const auto up = Clock::now();
  auto rep = client.call(pickQuery(), dds::CallOptions{kEffortDeadlineS, {}});
  const double up_after = std::chrono::duration<double>(up - killed).count();
  const double answered_after = std::chrono::duration<double>(Clock::now() - killed).count();
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  EXPECT_LT(answered_after, 2.0) << "its heartbeat came " << up_after << " s after the kill, the answer "
                                 << answered_after << " s after it";
  if (std::getenv("TAMP_RESTART_DEBUG") != nullptr) {
    std::cerr << "up " << up_after << " s after the kill, answered " << answered_after << " s after it\n";
  }
}

// As in the kill -9 matrix (seed 1): the estimator killed while the client is quiet (the robot
// executes a move_arm), restarted, and the client's next call comes once the killed
// participant's 5 s lease has ended. It and the calls after it are answered within the deadline.
TEST_F(EffortRestartTest, ACallAfterTheKilledParticipantsLeaseEndedIsAnswered) {
  EffortClient client(participant_, dds::services::kEffort, kGraphManagerRpc);
  for (int i = 0; i < 3; ++i) {
    auto rep = client.call(pickQuery(), dds::CallOptions{15.0, {}});
    ASSERT_TRUE(rep.ok()) << rep.error().toString();
  }
  const pid_t old_pid = sup_.status("effort_estimator")->pid;
  ASSERT_TRUE(sup_.signal("effort_estimator", SIGKILL));
  ASSERT_TRUE(awaitRestart(old_pid, 10.0)) << "the supervisor did not restart the estimator";
  // The killed participant's lease (tamp_profiles.xml: 5 s) ends while the client says nothing.
  std::this_thread::sleep_for(std::chrono::milliseconds(5500));
  std::ostringstream calls;
  int failed = 0;
  for (int i = 0; i < 3; ++i) {
    const auto t0 = Clock::now();
    auto rep = client.call(pickQuery(), dds::CallOptions{kEffortDeadlineS, {}});
    const double took = std::chrono::duration<double>(Clock::now() - t0).count();
    calls << "  call " << i << ": " << (rep ? rep->header().server_id() : rep.error().toString()) << " in " << took
          << " s\n";
    failed += rep ? 0 : 1;
  }
  EXPECT_EQ(failed, 0) << calls.str();
  if (std::getenv("TAMP_RESTART_DEBUG") != nullptr) std::cerr << calls.str();
}

// Calls back to back from the restart until 8 s after the kill (past the killed participant's
// 5 s lease, when its endpoints are unmatched): every call is answered within the graph
// manager's deadline, by the new process.
TEST_F(EffortRestartTest, EveryCallAfterAKillAndRestartIsAnsweredWithinItsDeadline) {
  EffortClient client(participant_, dds::services::kEffort, kGraphManagerRpc);
  auto first = client.call(pickQuery(), dds::CallOptions{15.0, {}});
  ASSERT_TRUE(first.ok()) << first.error().toString();
  const pid_t old_pid = sup_.status("effort_estimator")->pid;

  ASSERT_TRUE(sup_.signal("effort_estimator", SIGKILL));
  const auto killed = Clock::now();
  ASSERT_TRUE(awaitRestart(old_pid, 10.0)) << "the supervisor did not restart the estimator";
  const pid_t new_pid = sup_.status("effort_estimator")->pid;
  const std::string new_server = dds::detail::hostName() + ":" + std::to_string(new_pid);

  std::ostringstream calls;
  int failed = 0, total = 0;
  auto since = [&] { return std::chrono::duration<double>(Clock::now() - killed).count(); };
  while (since() < 8.0) {
    const double at = since();
    auto rep = client.call(pickQuery(), dds::CallOptions{kEffortDeadlineS, {}});
    const double took = since() - at;
    ++total;
    char line[200];
    std::snprintf(line, sizeof(line), "  +%.2f s: %s in %.2f s\n", at,
                  rep ? rep->header().server_id().c_str() : rep.error().toString().c_str(), took);
    calls << line;
    if (!rep) {
      ++failed;
      continue;
    }
    EXPECT_EQ(rep->header().server_id(), new_server) << "answered by the killed process?";
    ASSERT_EQ(rep->estimates().size(), 1u);
    EXPECT_EQ(rep->estimates()[0].code(), msg::STATUS_OK) << rep->estimates()[0].message();
  }
  EXPECT_EQ(failed, 0) << failed << " of " << total << " calls after the kill failed:\n" << calls.str();
  EXPECT_GE(total, 2) << calls.str();
  if (std::getenv("TAMP_RESTART_DEBUG") != nullptr) std::cerr << calls.str();
}

/// Ids seen on a topic, for a test to wait on (any callback thread).
class IdSet {
 public:
  void add(const std::string& id) {
    std::lock_guard l(m_);
    ids_.insert(id);
    cv_.notify_all();
  }
  /// True once every id of `want` was seen, false after `seconds`.
  bool waitForAll(const std::set<std::string>& want, double seconds) {
    std::unique_lock l(m_);
    return cv_.wait_for(l, std::chrono::duration<double>(seconds), [&] {
      return std::includes(ids_.begin(), ids_.end(), want.begin(), want.end());
    });
  }
  std::size_t size() {
    std::lock_guard l(m_);
    return ids_.size();
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  std::set<std::string> ids_;
};

// The effort estimator and the execution monitor as processes (the monitor with a run folder,
// as `tamp run` starts it); the test is the robot driver, publishing raw records on
// tamp/robot/record, which the monitor forwards.
class RecordDeliveryTest : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_ = isolatedDomain();
    store_dir_ = tempFile("tamp_it_records_store");
    run_dir_ = tempFile("tamp_it_records_run");
    std::filesystem::remove_all(store_dir_);
    std::filesystem::remove_all(run_dir_);
    std::filesystem::create_directories(run_dir_);
    config_ = tempFile("tamp_it_records_effort.yaml");
    std::ofstream(config_) << "store_directory: " << store_dir_.string() << "\n";
    // Restarted only when the test polls the supervisor: it decides how long each stays dead.
    process::ProcessSpec est = serviceSpec("tamp_effort_estimator_service", "effort_estimator", domain_,
                                           {"--config", config_.string()});
    process::ProcessSpec mon = serviceSpec("tamp_execution_monitor_service", "execution_monitor", domain_,
                                           {"--config", (configDir() / "services" / "execution_monitor.yaml").string()});
    for (auto* spec : {&est, &mon}) {
      std::filesystem::remove(spec->log_file);
      spec->restart = true;
      spec->env["TAMP_RUN_DIR"] = run_dir_.string();
      sup_.add(*spec);
    }
    ASSERT_TRUE(sup_.startAll().ok());
    auto p = dds::Participant::create({domain_, dds::kProfileDefault, "tamp/record_delivery_test", {}});
    ASSERT_TRUE(p) << p.error().toString();
    participant_ = *p;
    robot_ = std::make_unique<dds::Writer<msg::ExecutionRecord>>(participant_, dds::topics::kRobotRecords);
    forwarded_reader_ = std::make_unique<dds::Reader<msg::ExecutionRecord>>(
        participant_, dds::topics::kExecutionRecords,
        [this](const msg::ExecutionRecord& m, const dds::SampleMeta&) { forwarded_.add(m.record_id()); });
    ASSERT_TRUE(robot_->waitForReaders(Termination::after(30.0))) << "the monitor does not read robot records";
  }

  void TearDown() override {
    forwarded_reader_.reset();
    robot_.reset();
    sup_.stopAll(5.0);
    if (HasFailure()) {
      for (const char* name : {"effort_estimator", "execution_monitor"}) {
        std::cerr << "---- " << name << " log ----\n"
                  << readFile(tempFile(std::string("tamp_it_") + name + ".log")) << "\n";
      }
    }
    std::filesystem::remove_all(store_dir_);
    std::filesystem::remove_all(run_dir_);
    std::filesystem::remove(config_);
  }

  /// A raw pick record as the robot driver writes it.
  static msg::ExecutionRecord record(const std::string& id) {
    msg::ExecutionRecord r;
    r.record_id(id);
    r.kind(msg::ACTION_PICK);
    r.object_mass(0.5);
    r.approach_m(0.1);
    r.retreat_m(0.1);
    r.duration_s(6.0);
    r.success(true);
    r.stamp_ns(dds::nowNs());
    r.source("sim");
    return r;
  }

  /// `n` records as the robot finishes actions, in batches of 10 that the monitor has forwarded
  /// before the next (a burst beyond the topics' depth would test DDS history, not delivery).
  std::set<std::string> publish(const std::string& prefix, int n) {
    std::set<std::string> ids;
    for (int i = 0; i < n;) {
      std::set<std::string> batch;
      for (int k = 0; k < 10 && i < n; ++k, ++i) {
        const std::string id = prefix + std::to_string(i);
        EXPECT_TRUE(robot_->write(record(id)));
        batch.insert(id);
      }
      EXPECT_TRUE(forwarded_.waitForAll(batch, 30.0)) << "the monitor did not forward " << prefix << " records";
      ids.insert(batch.begin(), batch.end());
    }
    return ids;
  }

  /// SIGKILL; returns once the supervisor has reaped it. Its restart waits for restart(): the
  /// supervisor restarts only when polled.
  void killService(const std::string& name) {
    ASSERT_TRUE(sup_.signal(name, SIGKILL));
    const Deadline d = Deadline::in(10.0);
    while (sup_.status(name)->phase == process::ProcessPhase::kRunning && !d.expired()) {
      sup_.poll();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_NE(sup_.status(name)->phase, process::ProcessPhase::kRunning) << name << " did not die";
  }

  /// Lets the supervisor restart what died, until `name` runs again.
  bool restart(const std::string& name) {
    const Deadline d = Deadline::in(10.0);
    while (!d.expired()) {
      sup_.poll();
      if (sup_.status(name)->phase == process::ProcessPhase::kRunning) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  /// True once the monitor's outbox (its file in the run folder) holds an acknowledgement for
  /// every id of `want`, false after `seconds`. The monitor's view, not the test's: an
  /// acknowledgement that a restarted estimator writes before this test's participant has
  /// discovered it never reaches the test (VOLATILE topic; the first ones too, when the estimator's ack
  /// writer matches the monitor before this test: CI failed so once), while the monitor, which stops
  /// resending only on an acknowledgement, is what delivery depends on.
  bool monitorAcknowledged(const std::set<std::string>& want, double seconds) {
    const Deadline d = Deadline::in(seconds);
    const std::filesystem::path outbox = run_dir_ / "execution_monitor.records";
    while (true) {
      std::set<std::string> acked;
      std::istringstream lines(readFile(outbox));
      for (std::string line; std::getline(lines, line);) {
        if (line.rfind("a ", 0) == 0) acked.insert(line.substr(2));
      }
      if (std::includes(acked.begin(), acked.end(), want.begin(), want.end())) return true;
      if (d.expired()) {
        std::cerr << acked.size() << " of " << want.size() << " acknowledged in " << outbox << "\n";
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }

  /// The store's records: (rows, distinct ids). Read with the estimator stopped.
  std::pair<std::size_t, std::set<std::string>> stored() {
    sup_.stopAll(5.0);
    auto opened = effort_estimator::EffortStore::open(store_dir_);
    std::set<std::string> ids;
    for (const auto& r : opened.records) ids.insert(r.record_id);
    return {opened.records.size(), ids};
  }

  int domain_{0};
  std::filesystem::path store_dir_, run_dir_, config_;
  process::Supervisor sup_;
  std::shared_ptr<dds::Participant> participant_;
  std::unique_ptr<dds::Writer<msg::ExecutionRecord>> robot_;
  IdSet forwarded_;
  std::unique_ptr<dds::Reader<msg::ExecutionRecord>> forwarded_reader_;
};

// More records while the estimator is dead than the record topics keep for a late reader (KEEP_LAST
// 100): the monitor keeps them until acknowledged, so every one is stored once after the restart.
TEST_F(RecordDeliveryTest, RecordsForwardedWhileTheEstimatorIsDownAllArriveOnceAfterItRestarts) {
  std::set<std::string> all = publish("before-", 3);
  ASSERT_TRUE(monitorAcknowledged(all, 30.0)) << "the estimator did not acknowledge the first records";
  killService("effort_estimator");
  const std::set<std::string> down = publish("down-", 130);
  all.insert(down.begin(), down.end());
  ASSERT_TRUE(restart("effort_estimator"));
  EXPECT_TRUE(monitorAcknowledged(all, 60.0));
  const auto [rows, ids] = stored();
  EXPECT_EQ(ids, all) << ids.size() << " distinct ids stored of " << all.size();
  EXPECT_EQ(rows, all.size()) << "a record stored twice";
}

// The monitor killed while records it forwarded wait for the dead estimator, and the robot's own
// record writer gone (its history is not the monitor's to rely on): the restarted monitor sends
// them from its outbox in the run folder; each is stored once, none of the earlier ones again.
TEST_F(RecordDeliveryTest, AMonitorRestartedWithUnacknowledgedRecordsDeliversThemOnce) {
  std::set<std::string> all = publish("before-", 3);
  ASSERT_TRUE(monitorAcknowledged(all, 30.0)) << "the estimator did not acknowledge the first records";
  killService("effort_estimator");
  const std::set<std::string> waiting = publish("waiting-", 5);
  all.insert(waiting.begin(), waiting.end());
  robot_.reset();
  killService("execution_monitor");
  ASSERT_TRUE(restart("execution_monitor"));
  ASSERT_TRUE(restart("effort_estimator"));
  EXPECT_TRUE(monitorAcknowledged(all, 60.0));
  const auto [rows, ids] = stored();
  EXPECT_EQ(ids, all) << ids.size() << " distinct ids stored of " << all.size();
  EXPECT_EQ(rows, all.size()) << "a record stored twice";
}

}  // namespace
}  // namespace tamp::integration
