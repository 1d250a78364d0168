#pragma once
/// @file
/// A deployment description (config/deploy/*.yaml): the hosts of an installation, the services
/// each runs and their parameters, and how they are supervised. `tamp launch FILE --host NAME`
/// starts one host's services, `tamp run` all of them on this machine, `tamp status --deployment
/// FILE` checks that every expected service is alive.
///
///   heartbeat_period_s: 0.5   # every service's heartbeat period
///   liveness_periods: 6       # heartbeats a service may miss before it counts as dead
///   startup_timeout_s: 30     # from start to first heartbeat
///   orphan_timeout_s: 60      # a launched service outlives a dead supervisor so long (0: always)
///   stall_timeout_s: 20       # a service's main loop may hang so long before it stops beating (0: never)
///   ready_timeout_s: 20       # alive but not ready (an input never arrived) so long after its start:
///   ready_restarts: 2         #   restarted, at most this many times per launch (0: never)
///   restart: {max_restarts: 5, backoff_s: 0.5, backoff_max_s: 8, stable_after_s: 30}
///   discovery: {mode: multicast}  # default; or, on networks without multicast:
///   discovery: {mode: server, servers: ["10.0.0.1:11811"], server_host: workstation}
///                             # every participant is a client of the servers; `tamp launch
///                             # --host <server_host>` runs them (an IPv4 of that host each);
///                             # or one host per server, so that no host is the only one:
///                             # servers: ["10.0.0.1:11811", "10.0.0.2:11811"],
///                             # server_hosts: [workstation, robot]
///   hosts:                    # optional; without it every service is on host "local"
///     robot: {env: ["KEY=value"], description: "..."}
///     workstation: {}
///   services:
///     - name: sim                     # unique in the file
///       host: robot                   # required when `hosts` is given
///       executable: tamp_sim_service  # a name in the build's bin/ directory, or absolute
///       args: [--config, "{config}/services/sim.yaml", --scenario, "{scenario}"]
///       env: ["KEY=value"]
///       optional: false               # the run may go on without it
///       restart: true                 # restarted when it dies (tamp launch)
///
/// Placeholders in args: {config} (config/ directory), {scenario} (the run's scenario; an
/// "--option {scenario}" pair is dropped without one), {run_dir}, {run_id}, {host}. Every error
/// names the file, line and field.

#include <filesystem>
#include <string>
#include <vector>

#include "tamp/core/error.h"

namespace tamp::deploy {

struct HostSpec {
  std::string name;
  std::string description;
  std::vector<std::string> env;  ///< "KEY=value", for every service of the host
};

struct ServiceSpec {
  std::string name;
  std::string host;        ///< a HostSpec name
  std::string executable;  ///< as written: a file name in the bin directory or an absolute path
  std::vector<std::string> args;
  std::vector<std::string> env;  ///< "KEY=value", after the host's
  bool optional{false};
  bool restart{true};
  SourceLocation executable_at;  ///< where `executable` is written (for errors)
};

struct RestartPolicy {
  int max_restarts{5};          ///< consecutive restarts before giving up; >= 0
  double backoff_s{0.5};        ///< first back-off, doubled per consecutive restart; > 0
  double backoff_max_s{8.0};    ///< >= backoff_s
  double stable_after_s{30.0};  ///< a service that ran this long restarts from backoff_s again
};

/// How the participants of a deployment discover each other (tamp/dds/discovery.h).
struct DiscoverySpec {
  enum class Mode { kMulticast, kServer };
  Mode mode{Mode::kMulticast};
  std::vector<std::string> servers;  ///< "IPv4:PORT", server i has GUID prefix id i; kServer only
  /// Host whose `tamp launch` runs server i (as long as `servers`); kServer only. The file gives
  /// either `server_host` (one host for every server) or `server_hosts` (one per server).
  std::vector<std::string> server_hosts;
  /// The indices into `servers` of the servers `host` runs.
  std::vector<std::size_t> serversOn(const std::string& host) const;
  /// Every server runs on `host` (tamp run on one machine).
  void runAllOn(const std::string& host) { server_hosts.assign(servers.size(), host); }
  /// "IP:PORT;IP:PORT" ($TAMP_DDS_DISCOVERY_SERVERS) or "" for multicast.
  std::string serversEnv() const;
};

struct Deployment {
  std::string file;
  double heartbeat_period_s{0.5};  ///< (0, 10]
  int liveness_periods{6};         ///< >= 2
  double startup_timeout_s{30.0};  ///< > 0
  double orphan_timeout_s{60.0};   ///< >= 0; 0: launched services never stop by themselves
  /// >= 0; a service whose main loop does not turn for this long stops beating (then counts as
  /// dead after livenessTimeout() more); 0: never (ServiceArgs::stall_timeout_s).
  double stall_timeout_s{20.0};
  /// > 0; a service alive but not ready (ServiceNode::notReadyBecause: an input it cannot work
  /// without never arrived) this long after its start is restarted, at most `ready_restarts`
  /// times (>= 0) per launch: a new participant matches every other one anew (on Fast DDS 2.9.1,
  /// secured, a pair of participants sometimes never matched; docs/reliability.md). After that it
  /// is left running, not ready (a robot driver that is off is not cured by restarts).
  double ready_timeout_s{20.0};
  int ready_restarts{2};
  RestartPolicy restart;
  DiscoverySpec discovery;
  std::vector<HostSpec> hosts;  ///< at least one ("local" when the file names none)
  std::vector<ServiceSpec> services;

  const HostSpec* host(const std::string& name) const;
  /// The services of `host` (every service when `host` is empty), in file order.
  std::vector<const ServiceSpec*> servicesOn(const std::string& host) const;
  /// Seconds without a heartbeat after which a running service counts as dead.
  double livenessTimeout() const { return heartbeat_period_s * liveness_periods; }
  /// How long a tool waits for every service to be ready: the first heartbeat, then every
  /// readiness restart the supervisor may make, each after ready_timeout_s and a back-off.
  double readyWait() const {
    return startup_timeout_s + ready_restarts * (ready_timeout_s + restart.backoff_max_s) + ready_timeout_s;
  }
};

/// The implicit host of a file without `hosts`.
inline constexpr const char* kLocalHost = "local";

/// Reads and validates a deployment file. Every problem found is reported (one error listing
/// them), each as "file:line:col: field 'services[2].host': ...".
Result<Deployment> loadDeployment(const std::filesystem::path& file);

/// Where a service's executable is: absolute as written, else `bin_dir / executable`.
std::filesystem::path resolveExecutable(const ServiceSpec& service,
                                        const std::filesystem::path& bin_dir);

/// Every service of `host` (all hosts when empty) has an executable file; errors (kNotFound) name
/// the deployment file, the line and the field of each missing one, and the path looked for.
Status checkExecutables(const Deployment& deployment, const std::filesystem::path& bin_dir,
                        const std::string& host = {});

/// Values of the placeholders in a service's args.
struct Placeholders {
  std::string scenario;  ///< empty: no scenario ("--option {scenario}" pairs are dropped)
  std::string config_dir;
  std::string run_dir;
  std::string run_id;
  std::string host;
};

/// The service's args with placeholders replaced.
std::vector<std::string> expandArgs(const ServiceSpec& service, const Placeholders& values);

}  // namespace tamp::deploy
