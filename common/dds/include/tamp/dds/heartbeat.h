#pragma once
/// @file
/// Service liveness. Every service publishes a `msg::Heartbeat` on tamp/heartbeat (keyed by
/// "<name>@<host>:<pid>") every `period_s` and whenever its state changes; on clean shutdown it
/// publishes SERVICE_STOPPING and unregisters. `HeartbeatMonitor` keeps the latest heartbeat of
/// each service; a service is alive while its last heartbeat is younger than 3 periods and its
/// instance was not unregistered (a killed process's writer disappears with it).
///
/// Beats come from a thread of their own, so a process whose work is stuck would still beat. A
/// publisher armed with a stall limit (`setStallLimit`) therefore beats only while the loop that
/// does the service's work has called `kick()` within that limit (ServiceNode::run arms it for its
/// main loop): a service whose main loop hangs stops beating and counts as dead, as a stopped
/// process does, and its supervisor restarts it. Worker threads (a mission, a frame) are watched
/// the same way while they work (`watchWorker`): busy and not kicked within the limit withholds
/// the beats too; a worker waiting for work is not watched.

#include <atomic>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "tamp/dds/topics.h"

namespace tamp::dds {

/// A worker thread's liveness: while it is busy (between `busy()` and `idle()`) it must `kick()`
/// within the heartbeat's stall limit. Thread-safe, wait-free.
class WorkWatch {
 public:
  explicit WorkWatch(std::string name) : name_(std::move(name)) {}
  const std::string& name() const { return name_; }
  /// Work starts (counts as a kick).
  void busy();
  /// The work goes on; ignored while idle.
  void kick();
  /// Waiting for work: not watched.
  void idle();
  /// Seconds since the last kick while busy; 0 while idle.
  double stalledFor() const;

  /// busy() for a scope, idle() at its end.
  class Scope {
   public:
    explicit Scope(WorkWatch* w) : w_(w) {
      if (w_) w_->busy();
    }
    ~Scope() {
      if (w_) w_->idle();
    }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    WorkWatch* w_;
  };

 private:
  std::string name_;
  std::atomic<bool> busy_{false};
  std::atomic<int64_t> last_kick_ns_{0};
};

class HeartbeatPublisher {
 public:
  HeartbeatPublisher(std::shared_ptr<Participant> p, const std::string& name, double period_s = 1.0);
  ~HeartbeatPublisher();

  const std::string& serviceId() const { return service_id_; }
  void setState(msg::ServiceState state);
  void setDetail(const std::string& detail);
  /// Called at each beat to fill the request counters (e.g. from the node's RPC servers).
  void setCounters(std::function<std::pair<uint64_t, uint64_t>()> served_failed);
  /// Beats are withheld while the last kick() is older than `limit_s`; 0 disarms (the default).
  /// Arming counts as a kick. Throws std::invalid_argument for a negative or non-finite limit.
  void setStallLimit(double limit_s);
  /// The watched loop is alive. Thread-safe, wait-free.
  void kick();
  /// Seconds since the last kick() while armed; 0 when disarmed.
  double stalledFor() const;
  /// A worker thread watched under the same stall limit (while it is armed). The publisher keeps
  /// it; the node owns the thread.
  std::shared_ptr<WorkWatch> watchWorker(const std::string& name);

 private:
  void publish();
  /// The periodic beat: published unless the watched loop or a busy worker stalled (logged once
  /// per stall).
  void beat();
  /// What stalled beyond `limit_ns` ("its main loop", "its worker 'mission'") and for how long; empty when none.
  std::pair<std::string, double> stalled(int64_t limit_ns) const;
  std::shared_ptr<Participant> participant_;
  Writer<msg::Heartbeat> writer_;
  std::string service_id_;
  double period_s_;
  mutable std::mutex mutex_;
  msg::Heartbeat beat_;
  std::function<std::pair<uint64_t, uint64_t>()> counters_;
  std::condition_variable_any cv_;
  std::atomic<int64_t> stall_limit_ns_{0};
  std::atomic<int64_t> last_kick_ns_{0};
  std::vector<std::shared_ptr<WorkWatch>> workers_;  // guarded by mutex_
  bool withheld_{false};  // the beat thread's own: whether it is withholding beats now
  std::jthread thread_;
};

struct ServiceInfo {
  std::string service_id;
  std::string name;
  std::string host;
  uint32_t pid{0};
  msg::ServiceState state{msg::SERVICE_STARTING};
  double uptime_s{0};
  double age_s{0};          ///< seconds since its last heartbeat was received
  double period_s{1.0};
  uint64_t served{0};
  uint64_t failed{0};
  std::string version;
  std::string detail;
  bool alive{false};
};

const char* toString(msg::ServiceState state);

class HeartbeatMonitor {
 public:
  explicit HeartbeatMonitor(std::shared_ptr<Participant> p);
  /// Every service heard of, alive ones first, by name.
  std::vector<ServiceInfo> services() const;
  /// Waits until `count` alive services called `name` are seen (or the termination fires); with
  /// `ready`, only those past SERVICE_STARTING (their inputs arrived: ServiceNode::notReadyBecause).
  bool waitFor(const std::string& name, int count, const Termination& until, bool ready = false) const;

 private:
  struct Entry {
    msg::Heartbeat beat;
    Clock::time_point received;
    bool gone{false};
  };
  void onBeat(const msg::Heartbeat& hb, const SampleMeta& meta);
  mutable std::mutex mutex_;
  std::map<std::string, Entry> entries_;
  Reader<msg::Heartbeat> reader_;
};

}  // namespace tamp::dds
