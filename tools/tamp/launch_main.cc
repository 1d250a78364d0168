// `tamp launch DEPLOYMENT [--host NAME] [--run-id ID]`: starts the services of one host of a
// deployment and supervises them until SIGINT/SIGTERM: a service that exits, or stops sending
// heartbeats for `liveness_periods` periods (frozen), is killed and restarted with exponential
// back-off; every start, exit, kill and restart is a line of <out>/<run id>/<host>/events.jsonl.
// The services lead their own sessions, so killing this supervisor (even with SIGKILL) leaves
// them running: a `tamp launch` of the same run id and host adopts them (launch.pids), and if none
// comes they stop by themselves after `orphan_timeout_s`. On SIGINT/SIGTERM every service is
// stopped (SIGTERM, SIGKILL after --grace) and the exit code is 0.
// Exit codes: 0 stopped on a signal, 30 bad deployment or arguments (a missing executable names
// the file, line and field), 40 DDS failure, another supervisor of this run and host, or every
// service gave up.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <thread>

#include <CLI/CLI.hpp>

#include "cli_common.h"
#include "launcher.h"
#include "tamp/core/paths.h"
#include "tamp/dds/heartbeat.h"
#include "tamp/dds/participant.h"

namespace fs = std::filesystem;

namespace {

/// Everything `tamp launch`'s command line sets, with its defaults. Validated by the checks each
/// option is declared with (CLI11 refuses a value outside them).
struct LaunchCli {
  std::string file;      // the deployment
  std::string host;      // empty: the deployment's only host
  std::string run_id;    // empty: $TAMP_RUN_ID, else generated for a one-host deployment
  std::string profile;   // empty: the services' default
  std::string scenario;  // empty: none
  std::string out_dir = "out";
  int domain = -1;
  double grace_s = 5.0;
};

constexpr const char* kAbout = "Start and supervise the TAMP services of one host of a deployment";

/// Declares every option of `tamp launch` on `app`, bound to `o`, in the order --help lists them.
void defineOptions(CLI::App& app, LaunchCli& o) {
  app.add_option("deployment", o.file, "deployment file (config/deploy/*.yaml)")->required();
  app.add_option("--host", o.host, "host of the deployment to start (default: its only host)");
  app.add_option("--run-id", o.run_id,
                 "run id shared by every host of the run (default: $TAMP_RUN_ID; generated for a "
                 "one-host deployment)");
  app.add_option("--domain", o.domain, "DDS domain id (default: $TAMP_DOMAIN_ID or 0)")
      ->check(CLI::Range(0, 232));
  app.add_option("--profile", o.profile,
                 "DDS participant profile of the services (tamp_default, tamp_udp, tamp_shm)");
  app.add_option("--scenario", o.scenario,
                 "scenario of the run (for services whose args name {scenario})")
      ->check(CLI::ExistingFile);
  app.add_option("--out", o.out_dir,
                 "root of the run folders: logs and events go to OUT/RUN_ID/HOST");
  app.add_option("--grace", o.grace_s, "seconds a service has to stop on SIGTERM before SIGKILL")
      ->check(CLI::Range(0.0, 600.0));
}

/// " a b c": the deployment's host names, each after a space.
std::string hostList(const tamp::deploy::Deployment& deployment) {
  std::string out;
  for (const auto& h : deployment.hosts) out += " " + h.name;
  return out;
}

/// The host to start: --host, which the deployment must have, or else its only host.
tamp::Result<std::string> chooseHost(const tamp::deploy::Deployment& deployment,
                                     const LaunchCli& o) {
  const auto error = [](const std::string& message) {
    return tamp::Error(tamp::ErrorCode::kInvalidArgument, message);
  };
  if (o.host.empty() && deployment.hosts.size() != 1) {
    return error(o.file + " has " + std::to_string(deployment.hosts.size()) +
                 " hosts; choose one with --host:" + hostList(deployment));
  }
  const std::string host = o.host.empty() ? deployment.hosts.front().name : o.host;
  if (deployment.host(host) == nullptr)
    return error(o.file + " has no host '" + host + "' (hosts:" + hostList(deployment) + ")");
  return host;
}

/// --run-id or $TAMP_RUN_ID, else a generated one where the deployment has one host (a run over
/// several hosts needs the id they share).
tamp::Result<std::string> chooseRunId(const tamp::deploy::Deployment& deployment,
                                      const LaunchCli& o, const std::string& resolved) {
  if (!resolved.empty()) return resolved;
  if (deployment.hosts.size() > 1) {
    return tamp::Error(tamp::ErrorCode::kInvalidArgument,
                       o.file + " spans " + std::to_string(deployment.hosts.size()) +
                           " hosts: give every host the same --run-id (or $TAMP_RUN_ID)");
  }
  return tamp::launch::makeRunId("launch");
}

/// The deployment, its host, run id and DDS domain, as the launcher takes them; the first input
/// error (a missing executable names the file, line and field).
tamp::Result<tamp::launch::LaunchOptions> launchOptions(const LaunchCli& o) {
  tamp::launch::LaunchOptions lo;
  auto deployment = tamp::deploy::loadDeployment(o.file);
  if (!deployment) return deployment.error();
  auto host = chooseHost(*deployment, o);
  if (!host) return host.error();
  lo.bin_dir = fs::read_symlink("/proc/self/exe").parent_path();
  if (tamp::Status s = tamp::deploy::checkExecutables(*deployment, lo.bin_dir, *host); !s.ok())
    return s.error();
  auto rid = tamp::dds::resolveRunId(o.run_id);
  auto dom = tamp::dds::resolveDomainId(o.domain);
  if (!rid || !dom) return !rid ? rid.error() : dom.error();
  auto run_id = chooseRunId(*deployment, o, *rid);
  if (!run_id) return run_id.error();
  lo.deployment = std::move(*deployment);
  lo.host = *host;
  lo.run_id = *run_id;
  lo.domain = *dom;
  lo.profile = o.profile;
  lo.run_dir = fs::absolute(fs::path(o.out_dir) / lo.run_id / lo.host);
  lo.scenario = o.scenario.empty() ? std::string() : fs::absolute(o.scenario).string();
  lo.config_dir = tamp::configDir();
  return lo;
}

/// True when the supervisor has given up on every one of its services.
bool everyServiceGaveUp(const std::vector<tamp::process::ProcessStatus>& statuses) {
  bool all_failed = !statuses.empty();
  for (const auto& st : statuses)
    all_failed = all_failed && st.phase == tamp::process::ProcessPhase::kFailed;
  return all_failed;
}

/// True when every service's current process is heard alive (a heartbeat from its own pid).
bool everyServiceAlive(const tamp::launch::Launcher& launcher,
                       const std::vector<tamp::process::ProcessStatus>& statuses) {
  const auto beats = launcher.monitor().services();
  std::size_t alive = 0;
  for (const auto& st : statuses) {
    for (const auto& b : beats)
      alive += (b.alive && b.name == st.name && b.pid == static_cast<uint32_t>(st.pid)) ? 1 : 0;
  }
  return alive == statuses.size();
}

/// Supervises the services until a stop is requested (kExitOk) or every service gave up
/// (kExitServiceError); says once when they are all alive.
int superviseUntilStopped(tamp::launch::Launcher& launcher) {
  bool announced = false;
  while (!tamp::cli::stopRequested()) {
    launcher.poll();
    const auto statuses = launcher.supervisor().status();
    if (everyServiceGaveUp(statuses)) {
      std::fprintf(stderr, "tamp launch: every service gave up (see %s)\n",
                   launcher.eventsFile().c_str());
      return tamp::cli::kExitServiceError;
    }
    if (!announced && everyServiceAlive(launcher, statuses)) {
      std::printf("tamp launch: all %zu services alive\n", statuses.size());
      std::fflush(stdout);
      launcher.note("all_alive", std::to_string(statuses.size()) + " services");
      announced = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return tamp::cli::kExitOk;
}

/// Starts the host's services (adopting those of an earlier supervisor), supervises them until a
/// stop, then stops them; the exit code.
int launchHost(const tamp::launch::LaunchOptions& lo, double grace_s) {
  tamp::launch::Launcher launcher(lo);
  if (tamp::Status s = launcher.start(); !s.ok()) {
    return tamp::cli::fail("tamp launch", s.error(), tamp::cli::kExitServiceError);
  }
  std::printf(
      "tamp launch: run %s, host %s, DDS domain %d, %zu services (%zu adopted); logs and events in "
      "%s\n",
      lo.run_id.c_str(), lo.host.c_str(), lo.domain, launcher.services().size(),
      launcher.adopted().size(), lo.run_dir.c_str());
  std::fflush(stdout);
  const int rc = superviseUntilStopped(launcher);
  std::printf("tamp launch: stopping %zu services\n", launcher.services().size());
  std::fflush(stdout);
  launcher.stop(grace_s);
  tamp::launch::printUncleanEnds("tamp launch", launcher.supervisor());
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  LaunchCli o;
  CLI::App app{kAbout, "tamp launch"};
  defineOptions(app, o);
  CLI11_PARSE(app, argc, argv);
  const tamp::Result<tamp::launch::LaunchOptions> lo = launchOptions(o);
  if (!lo) return tamp::cli::fail("tamp launch", lo.error(), tamp::cli::kExitInputError);
  tamp::cli::stopOnSignals({SIGINT, SIGTERM, SIGHUP}, /*restart=*/false);
  return launchHost(*lo, o.grace_s);
}
