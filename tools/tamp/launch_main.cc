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

int main(int argc, char** argv) {
  CLI::App app{"Start and supervise the TAMP services of one host of a deployment", "tamp launch"};
  std::string file, host, run_id, profile, scenario, out_dir = "out";
  int domain = -1;
  double grace_s = 5.0;
  app.add_option("deployment", file, "deployment file (config/deploy/*.yaml)")->required();
  app.add_option("--host", host, "host of the deployment to start (default: its only host)");
  app.add_option("--run-id", run_id,
                 "run id shared by every host of the run (default: $TAMP_RUN_ID; generated for a "
                 "one-host deployment)");
  app.add_option("--domain", domain, "DDS domain id (default: $TAMP_DOMAIN_ID or 0)")
      ->check(CLI::Range(0, 232));
  app.add_option("--profile", profile,
                 "DDS participant profile of the services (tamp_default, tamp_udp, tamp_shm)");
  app.add_option("--scenario", scenario,
                 "scenario of the run (for services whose args name {scenario})")
      ->check(CLI::ExistingFile);
  app.add_option("--out", out_dir,
                 "root of the run folders: logs and events go to OUT/RUN_ID/HOST");
  app.add_option("--grace", grace_s, "seconds a service has to stop on SIGTERM before SIGKILL")
      ->check(CLI::Range(0.0, 600.0));
  CLI11_PARSE(app, argc, argv);

  auto deployment = tamp::deploy::loadDeployment(file);
  if (!deployment) {
    std::cerr << "tamp launch: " << deployment.error().toString() << "\n";
    return tamp::cli::kExitInputError;
  }
  if (host.empty()) {
    if (deployment->hosts.size() != 1) {
      std::cerr << "tamp launch: " << file << " has " << deployment->hosts.size()
                << " hosts; choose one with --host:";
      for (const auto& h : deployment->hosts) std::cerr << " " << h.name;
      std::cerr << "\n";
      return tamp::cli::kExitInputError;
    }
    host = deployment->hosts.front().name;
  }
  if (deployment->host(host) == nullptr) {
    std::cerr << "tamp launch: " << file << " has no host '" << host << "' (hosts:";
    for (const auto& h : deployment->hosts) std::cerr << " " << h.name;
    std::cerr << ")\n";
    return tamp::cli::kExitInputError;
  }
  const fs::path bin_dir = fs::read_symlink("/proc/self/exe").parent_path();
  if (tamp::Status s = tamp::deploy::checkExecutables(*deployment, bin_dir, host); !s.ok()) {
    std::cerr << "tamp launch: " << s.error().toString() << "\n";
    return tamp::cli::kExitInputError;
  }
  auto rid = tamp::dds::resolveRunId(run_id);
  auto dom = tamp::dds::resolveDomainId(domain);
  if (!rid || !dom) {
    std::cerr << "tamp launch: " << (!rid ? rid.error() : dom.error()).toString() << "\n";
    return tamp::cli::kExitInputError;
  }
  run_id = *rid;
  if (run_id.empty()) {
    if (deployment->hosts.size() > 1) {
      std::cerr << "tamp launch: " << file << " spans " << deployment->hosts.size()
                << " hosts: give every host the same --run-id (or $TAMP_RUN_ID)\n";
      return tamp::cli::kExitInputError;
    }
    run_id = tamp::launch::makeRunId("launch");
  }

  tamp::launch::LaunchOptions o;
  o.deployment = *deployment;
  o.host = host;
  o.run_id = run_id;
  o.domain = *dom;
  o.profile = profile;
  o.run_dir = fs::absolute(fs::path(out_dir) / run_id / host);
  o.scenario = scenario.empty() ? std::string() : fs::absolute(scenario).string();
  o.bin_dir = bin_dir;
  o.config_dir = tamp::configDir();

  tamp::cli::stopOnSignals({SIGINT, SIGTERM, SIGHUP}, /*restart=*/false);

  tamp::launch::Launcher launcher(o);
  if (tamp::Status s = launcher.start(); !s.ok()) {
    std::cerr << "tamp launch: " << s.error().toString() << "\n";
    return tamp::cli::kExitServiceError;
  }
  std::printf(
      "tamp launch: run %s, host %s, DDS domain %d, %zu services (%zu adopted); logs and events in "
      "%s\n",
      run_id.c_str(), host.c_str(), *dom, launcher.services().size(), launcher.adopted().size(),
      o.run_dir.c_str());
  std::fflush(stdout);

  bool announced = false;
  int rc = tamp::cli::kExitOk;
  while (!tamp::cli::stopRequested()) {
    launcher.poll();
    const auto statuses = launcher.supervisor().status();
    bool all_failed = !statuses.empty();
    for (const auto& st : statuses)
      all_failed = all_failed && st.phase == tamp::process::ProcessPhase::kFailed;
    if (all_failed) {
      std::fprintf(stderr, "tamp launch: every service gave up (see %s)\n",
                   launcher.eventsFile().c_str());
      rc = tamp::cli::kExitServiceError;
      break;
    }
    if (!announced) {
      const auto beats = launcher.monitor().services();
      std::size_t alive = 0;
      for (const auto& st : statuses) {
        for (const auto& b : beats)
          alive += (b.alive && b.name == st.name && b.pid == static_cast<uint32_t>(st.pid)) ? 1 : 0;
      }
      if (alive == statuses.size()) {
        std::printf("tamp launch: all %zu services alive\n", alive);
        std::fflush(stdout);
        launcher.note("all_alive", std::to_string(alive) + " services");
        announced = true;
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  std::printf("tamp launch: stopping %zu services\n", launcher.services().size());
  std::fflush(stdout);
  launcher.stop(grace_s);
  for (const auto& st : launcher.supervisor().status()) {
    if (st.last_exit != "exit 0" && st.last_exit.rfind("signal 15", 0) != 0 &&
        st.last_exit.rfind("stopped", 0) != 0) {
      std::printf("tamp launch: %s ended with %s\n", st.name.c_str(), st.last_exit.c_str());
    }
  }
  return rc;
}
