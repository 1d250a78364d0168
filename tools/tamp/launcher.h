#pragma once
/// @file
/// One host's share of a deployment as supervised processes: what `tamp launch` runs, and what
/// `tamp run` uses for the services of its single machine.
///
/// The run folder (`run_dir`) holds, per host:
/// - `<service>.log`: each service's stdout and stderr (appended across restarts);
/// - `events.jsonl`: one JSON object per line for every start, exit, kill, restart, adoption and
///   give-up, with the time, host, run id, service, pid and reason (restarts are never only on
///   the supervisor's stderr);
/// - `launch.pids`: the services' pids and kernel start times, rewritten at every change, so a
///   later supervisor of the same run and host adopts the services that still run;
/// - `launch.lock`: held (flock) by the live supervisor: a second one for the same folder refuses;
/// - `supervisor.lease`: touched every heartbeat period; detached services stop by themselves
///   when it is older than the deployment's `orphan_timeout_s`.
///
/// Liveness: a service counts as dead when its process ends, when it sends no heartbeat within
/// `startup_timeout_s` of its start, or when its last heartbeat (from its own pid) is older than
/// `liveness_periods` heartbeat periods (a frozen process: SIGSTOP, a deadlocked heartbeat). A
/// dead service is killed (SIGKILL to its process group) and restarted with exponential back-off.
///
/// Readiness: a service alive but not ready (its heartbeat says STARTING: an input it cannot work
/// without never arrived) `ready_timeout_s` after its start is restarted the same way, at most
/// `ready_restarts` times per launch, then left running, not ready.

#include <sys/types.h>

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "tamp/deploy/deployment.h"
#include "tamp/process/supervisor.h"

namespace tamp::dds {
class Participant;
class HeartbeatMonitor;
class DiscoveryServer;
}  // namespace tamp::dds

namespace tamp::launch {

struct LaunchOptions {
  deploy::Deployment deployment;
  std::string host;    ///< a host of the deployment
  std::string run_id;  ///< every service gets --run-id; may be empty (no run: default partition)
  int domain{0};
  std::string profile;  ///< DDS participant profile for the services (empty: their default)
  std::filesystem::path run_dir;  ///< created if missing
  std::string scenario;           ///< absolute path or empty
  std::filesystem::path bin_dir;
  std::filesystem::path config_dir;
  bool detach{true};    ///< services outlive the supervisor (tamp launch); attached for tamp run
  bool restart{true};   ///< restart dead services (those with `restart: true`)
  bool liveness{true};  ///< kill services whose heartbeats stop (only with restart)
  bool adopt{true};     ///< adopt the services of launch.pids that still run
};

/// Generates a run id: "<prefix>-YYYYmmdd-HHMMSS-<4 hex>" (unique enough for concurrent runs).
std::string makeRunId(const std::string& prefix);

/// After a stop: prints "`tool`: NAME ended with HOW" on stdout for every service of `sup` that
/// did not end cleanly (exit 0, SIGTERM, or stopped after its adoption by this supervisor).
void printUncleanEnds(const char* tool, const process::Supervisor& sup);

class Launcher {
 public:
  explicit Launcher(LaunchOptions options);
  /// Stops every service (unless released).
  ~Launcher();
  Launcher(const Launcher&) = delete;
  Launcher& operator=(const Launcher&) = delete;

  /// With `discovery: {mode: server}`, first starts the discovery servers the deployment puts on
  /// this host (in this process: they live as long as the supervisor; clients keep what they
  /// discovered when it dies, the servers of other hosts go on serving them, and a new
  /// supervisor serves them again). Sets
  /// $TAMP_DDS_DISCOVERY_SERVERS of this process to the deployment's servers ("" for multicast),
  /// and of every service.
  /// Takes the run folder's lock, creates the DDS participant for liveness, adopts the services
  /// of launch.pids that still run and starts the others. Errors: kUnavailable when another
  /// supervisor holds the folder, kInternal when DDS fails, kNotFound when a service cannot start.
  Status start();
  /// One supervision step: reaps and restarts, checks heartbeats, renews the lease, rewrites
  /// launch.pids. Call every ~100 ms.
  void poll();
  /// Stops every service (SIGTERM, SIGKILL after `grace_s`), removes launch.pids.
  void stop(double grace_s = 5.0);

  /// Names of this host's services, in deployment order.
  std::vector<std::string> services() const;
  process::Supervisor& supervisor() { return sup_; }
  const LaunchOptions& options() const { return o_; }
  std::filesystem::path eventsFile() const { return o_.run_dir / "events.jsonl"; }
  std::filesystem::path logFile(const std::string& service) const {
    return o_.run_dir / (service + ".log");
  }
  /// Services adopted from an earlier supervisor at start().
  const std::vector<std::string>& adopted() const { return adopted_; }
  /// The participant watching heartbeats (in the run's partition).
  const std::shared_ptr<dds::Participant>& participant() const { return participant_; }
  const dds::HeartbeatMonitor& monitor() const { return *monitor_; }
  /// True when `name`'s current process has been alive but not ready for the deployment's
  /// ready_timeout_s and will not be restarted for it any more (ready_restarts used, or a
  /// service that is not restarted): whoever waits for it to be ready may stop waiting.
  bool readinessGivenUp(const std::string& name) const;
  /// Appends a supervisor-level event (service "") to events.jsonl.
  void note(const std::string& event, const std::string& detail);

 private:
  Status startDiscoveryServers();
  process::ProcessSpec specOf(const deploy::ServiceSpec& s) const;
  void logEvent(const process::ProcessEvent& e);
  void writeEvent(const std::string& service, const std::string& event, pid_t pid, int restarts,
                  double backoff_s, const std::string& detail);
  void writePidFile();
  void touchLease();
  void checkLiveness();
  /// Restarts a service alive but not ready for ready_timeout_s (at most ready_restarts times).
  void checkReadiness();
  /// True when `name` is a restarted service with readiness restarts (ready_restarts) left.
  bool readinessRestartsLeft(const std::string& name) const;
  Status startOneByOne();

  LaunchOptions o_;
  process::Supervisor sup_;
  std::vector<std::unique_ptr<dds::DiscoveryServer>> discovery_servers_;  ///< outlive participant_
  std::shared_ptr<dds::Participant> participant_;
  std::unique_ptr<dds::HeartbeatMonitor> monitor_;
  std::vector<std::string> adopted_;
  std::map<std::string, int> ready_restarts_;  ///< readiness restarts made, by service
  int lock_fd_{-1};
  bool owns_run_dir_{false};  ///< holds launch.lock
  bool pids_dirty_{true};
  bool stopped_{false};
  std::chrono::steady_clock::time_point lease_touched_{};
};

}  // namespace tamp::launch
