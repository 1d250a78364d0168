// `tamp run [SCENARIO] [--policy effort|infeasible|oracle] [--out DIR] [--seed N] [--realtime-factor F]`:
// the main job. Starts
// every service of a deployment (config/deploy/local.yaml by default) as supervised processes on
// one DDS domain, waits until each is alive (heartbeats) and answers a request (echo), then sends
// the scenario's mission to the graph manager and follows it: one line per executed action
// (predicted and measured seconds), a progress bar weighted by predicted effort. At the end it
// writes report.json, graph.dot/.svg and world.png/.svg into the run's folder beside every
// service's log, stops the services (or keeps them with --keep-running) and exits with the
// mission's code: 0 succeeded, 10 mission failed, 20 out of time, 30 bad input, 40 a service
// unavailable. Without a scenario it only starts and checks the services.
//
// Each run has its own run id (printed; the run folder is OUT/RUN_ID): every service gets it and
// talks only to services of the same run, so two `tamp run`s on one DDS domain do not mix. A
// service that dies is restarted with back-off (events.jsonl in the run folder); a restarted graph
// manager takes the mission up from its journal (graph_manager.journal.json in the run folder).
// A service that freezes (no heartbeat: a stopped process, a hung main loop, or a busy worker that
// stopped making progress, dds::WorkWatch) is killed and restarted too, as is one that stays not
// ready (an input it cannot work without never arrived; the deployment's ready_timeout_s).
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iostream>

#include <CLI/CLI.hpp>

#include "cli_common.h"
#include "launcher.h"
#include "tamp/core/paths.h"
#include "tamp/dds/heartbeat.h"
#include "tamp/dds/service_node.h"
#include "tamp/process/supervisor.h"
#include "mission_run.h"

namespace fs = std::filesystem;

namespace {

/// Waits until every service in `started` is alive and ready: alive within startup_timeout_s of
/// its (re)start; ready as long as the launcher may still restart a service that stays not ready
/// (ready_timeout_s, ready_restarts). Returns those given up on (also on a stop request).
std::vector<std::string> waitUntilReady(tamp::launch::Launcher& launcher, const std::vector<std::string>& started,
                                        const tamp::deploy::Deployment& deployment) {
  const tamp::dds::HeartbeatMonitor& monitor = launcher.monitor();
  tamp::process::Supervisor& sup = launcher.supervisor();
  const tamp::Termination ready_wait = tamp::Termination::after(deployment.readyWait());
  std::vector<std::string> not_alive;
  for (const auto& name : started) {
    while (!monitor.waitFor(name, 1, ready_wait.tightened(tamp::Deadline::in(0.1)), /*ready=*/true)) {
      launcher.poll();
      auto st = sup.status(name);
      bool heard = false;
      for (const auto& info : monitor.services()) heard = heard || (info.alive && info.name == name);
      const bool ended = st && st->phase != tamp::process::ProcessPhase::kRunning &&
                         st->phase != tamp::process::ProcessPhase::kBackoff;
      const bool silent =
          !heard && st && st->phase == tamp::process::ProcessPhase::kRunning &&
          std::chrono::duration<double>(std::chrono::steady_clock::now() - st->started).count() > deployment.startup_timeout_s;
      if (ready_wait() || silent || launcher.readinessGivenUp(name) || tamp::cli::stopRequested() || ended) {
        not_alive.push_back(name);
        break;
      }
    }
  }
  return not_alive;
}

/// Every service answers on its echo endpoint: a real request/reply round trip through DDS, one
/// line of a table each (those in `not_alive` say why not). kExitServiceError when a service that
/// is not optional is not alive or does not answer, else kExitOk.
int echoEach(tamp::launch::Launcher& launcher, const std::vector<std::string>& started,
             const std::vector<std::string>& not_alive, const std::vector<std::string>& optional_names,
             const fs::path& run_dir) {
  const std::shared_ptr<tamp::dds::Participant>& participant = launcher.participant();
  const tamp::dds::HeartbeatMonitor& monitor = launcher.monitor();
  tamp::process::Supervisor& sup = launcher.supervisor();
  int rc = tamp::cli::kExitOk;
  std::printf("\n%-20s %8s %10s  %s\n", "SERVICE", "PID", "ROUND TRIP", "RESULT");
  for (const auto& name : started) {
    auto st = sup.status(name);
    const bool alive = std::find(not_alive.begin(), not_alive.end(), name) == not_alive.end();
    const bool optional = std::find(optional_names.begin(), optional_names.end(), name) != optional_names.end();
    if (!alive) {
      std::string why = st ? (st->last_exit.empty() ? "no heartbeat" : st->last_exit) : "?";
      const char* label = "NOT ALIVE";
      for (const auto& info : monitor.services())
        if (info.alive && info.name == name) why = info.detail, label = "NOT READY";
      std::printf("%-20s %8s %10s  %s (%s; see %s)%s\n", name.c_str(), "-", "-", label, why.c_str(),
                  (run_dir / (name + ".log")).c_str(), optional ? " -- optional, going on" : "");
      if (!optional) rc = tamp::cli::kExitServiceError;
      continue;
    }
    tamp::dds::RpcClient<tamp::msg::EchoRequest, tamp::msg::EchoReply> echo(participant,
                                                                             tamp::dds::echoService(name));
    tamp::msg::EchoRequest req;
    req.payload({1, 2, 3, 4});
    tamp::Stopwatch sw;
    auto rep = echo.call(req, tamp::dds::CallOptions{10.0, {}});
    if (!rep) {
      std::printf("%-20s %8d %10s  NO REPLY: %s\n", name.c_str(), st ? st->pid : -1, "-",
                  rep.error().toString().c_str());
      if (!optional) rc = tamp::cli::kExitServiceError;
      continue;
    }
    std::printf("%-20s %8u %8.0fus  ok\n", name.c_str(), rep->pid(), sw.seconds() * 1e6);
  }
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Run the TAMP services on this machine (one DDS domain, supervised processes)", "tamp run"};
  std::string scenario;
  std::string deployment_file = (tamp::configDir() / "deploy" / "local.yaml").string();
  int domain = -1;
  bool keep = false;
  std::string out_dir = "out";
  std::string policy = "effort";
  unsigned seed = 0;
  double mission_timeout = 900.0;
  app.add_option("scenario", scenario, "scenario YAML (config/scenarios/...) or NAMO world file");
  app.add_option("--policy", policy,
                 "effort (revise whenever cheaper), infeasible (move objects only when no way around) or oracle "
                 "(evaluation only: the simulator's truth, the lower bound)")
      ->check(CLI::IsMember({"effort", "infeasible", "oracle"}));
  app.add_option("--seed", seed, "seed of the mission's sampling (0: the graph manager's configured seed)");
  app.add_option("--mission-timeout", mission_timeout, "give up on the mission after this many seconds")
      ->check(CLI::PositiveNumber);
  app.add_option("--deployment", deployment_file, "deployment file: services to start (every host's, here)");
  app.add_option("--domain", domain, "DDS domain id (default: $TAMP_DOMAIN_ID or 0)")->check(CLI::Range(0, 232));
  app.add_flag("--keep-running", keep, "keep the services running (supervised) until Ctrl-C");
  app.add_option("--out", out_dir, "directory for run folders (OUT/RUN_ID: logs, events, reports)");
  std::string explicit_run_id;
  app.add_option("--run-id", explicit_run_id, "run id (default: generated, run-YYYYmmdd-HHMMSS-xxxx)");
  bool fresh = false;
  app.add_flag("--fresh", fresh,
               "start the effort estimator from the default time models: an empty store in the run folder "
               "(RUN/effort_store; the configured store is neither read nor changed)");
  std::string security;
  app.add_option("--security", security,
                 "DDS Security directory (deploy/security/make_certs.sh): every service and this tool run secured, "
                 "each with its own identity (default: $TAMP_DDS_SECURITY)")
      ->check(CLI::ExistingDirectory);
  double realtime_factor = -1.0;
  app.add_option("--realtime-factor", realtime_factor,
                 "simulated seconds per wall-clock second of the simulated robot for this run (default: "
                 "config/services/sim.yaml's, 1 = real time; 0 = as fast as possible); reports and time models "
                 "stay in simulated seconds")
      ->check(CLI::NonNegativeNumber);
  CLI11_PARSE(app, argc, argv);

  auto deployment = tamp::deploy::loadDeployment(deployment_file);
  if (!deployment) {
    std::cerr << "tamp run: " << deployment.error().toString() << "\n";
    return tamp::cli::kExitInputError;
  }
  const fs::path bin_dir = fs::read_symlink("/proc/self/exe").parent_path();
  // A deployment naming an executable that does not exist is an input error (file, line, field),
  // optional service or not: a typo must not become a silently smaller run.
  if (tamp::Status s = tamp::deploy::checkExecutables(*deployment, bin_dir); !s.ok()) {
    std::cerr << "tamp run: " << s.error().toString() << "\n";
    return tamp::cli::kExitInputError;
  }
  if (!scenario.empty()) {
    // A bad scenario is an input error (file, line, field), found before any service starts.
    if (auto bad = tamp::runner::checkScenario(scenario)) {
      std::cerr << "tamp run: " << *bad << "\n";
      return tamp::cli::kExitInputError;
    }
    scenario = fs::absolute(scenario).string();
  }
  auto dom = tamp::dds::resolveDomainId(domain);
  if (!dom) {
    std::cerr << "tamp run: " << dom.error().toString() << "\n";
    return tamp::cli::kExitInputError;
  }

  std::string run_id = tamp::launch::makeRunId("run");
  if (!explicit_run_id.empty()) {
    auto rid = tamp::dds::resolveRunId(explicit_run_id);
    if (!rid) {
      std::cerr << "tamp run: " << rid.error().toString() << "\n";
      return tamp::cli::kExitInputError;
    }
    run_id = *rid;
  }
  const fs::path run_dir = fs::absolute(fs::path(out_dir) / run_id);
  fs::create_directories(run_dir);

  // The simulator writes the ground truth it ends with here (tests and reports judge by it).
  if (!scenario.empty()) setenv("TAMP_SIM_FINAL_WORLD", (fs::absolute(run_dir) / "sim_final_world.json").c_str(), 1);
  // --fresh: the estimator keeps its store in the run folder (whatever its store_directory says).
  if (fresh) {
    const fs::path store = run_dir / "effort_store";
    fs::create_directories(store);
    setenv("TAMP_EFFORT_STORE", store.c_str(), 1);
    std::fprintf(stderr, "tamp run: --fresh: default time models, effort store %s\n", store.c_str());
  }
  // --policy oracle: the simulator serves its truth (true durations, hidden objects, scripted
  // faults) to the graph manager for this run only; a normal run does not expose it.
  if (policy == "oracle") setenv("TAMP_ORACLE", "1", 1);
  else unsetenv("TAMP_ORACLE");
  if (realtime_factor >= 0) {
    setenv("TAMP_SIM_REALTIME_FACTOR", std::to_string(realtime_factor).c_str(), 1);
    if (realtime_factor == 0) std::printf("tamp run: the simulated robot runs as fast as it can\n");
    else std::printf("tamp run: the simulated robot runs at %gx real time (times are simulated seconds)\n", realtime_factor);
  }
  // The services inherit the security directory; each picks its identity by its --name.
  if (!security.empty()) setenv("TAMP_DDS_SECURITY", fs::absolute(security).c_str(), 1);
  tamp::cli::stopOnSignals({SIGINT, SIGTERM}, /*restart=*/true);

  // Every service of every host of the deployment, on this machine, attached to this process
  // (they die with it); restarted when they die or freeze. A busy service is not frozen: its
  // heartbeat thread beats on while its worker makes progress (dds::WorkWatch).
  tamp::deploy::Deployment local = *deployment;
  std::vector<std::string> started, optional_names;
  for (auto& s : local.services) {
    // The host's environment goes with each of its services (the service's own entries last).
    std::vector<std::string> env = deployment->host(s.host)->env;
    env.insert(env.end(), s.env.begin(), s.env.end());
    s.env = std::move(env);
    s.host = tamp::deploy::kLocalHost;
    started.push_back(s.name);
    if (s.optional) optional_names.push_back(s.name);
  }
  local.hosts = {tamp::deploy::HostSpec{tamp::deploy::kLocalHost, "this machine", {}}};
  // Every host is this one: so is the one that runs the discovery servers (mode server).
  local.discovery.runAllOn(tamp::deploy::kLocalHost);
  tamp::launch::LaunchOptions lo;
  lo.deployment = local;
  lo.host = tamp::deploy::kLocalHost;
  lo.run_id = run_id;
  lo.domain = *dom;
  lo.run_dir = run_dir;
  lo.scenario = scenario;
  lo.bin_dir = bin_dir;
  lo.config_dir = tamp::configDir();
  lo.detach = false;
  lo.restart = true;
  lo.liveness = true;
  lo.adopt = false;
  tamp::launch::Launcher launcher(lo);
  tamp::process::Supervisor& sup = launcher.supervisor();
  std::printf("tamp run: run %s, DDS domain %d, deployment %s, logs in %s\n", run_id.c_str(), *dom,
              deployment_file.c_str(), run_dir.c_str());
  if (auto st = launcher.start(); !st.ok()) {
    std::cerr << "tamp run: " << st.error().toString() << "\n";
    launcher.stop();
    return tamp::cli::kExitServiceError;
  }

  // The launcher's participant, which has heard the services start, serves the mission too: a
  // second one would have to match every service anew (under DDS Security on Fast DDS 2.9.1, one
  // such pair in about twenty-five never matched: a service "not alive" that was; docs/reliability.md).
  const std::shared_ptr<tamp::dds::Participant> participant = launcher.participant();
  const std::vector<std::string> not_alive = waitUntilReady(launcher, started, *deployment);
  int rc = echoEach(launcher, started, not_alive, optional_names, run_dir);
  std::printf("\n");
  std::fflush(stdout);
  // The same table `tamp status` prints, from the heartbeats.
  // A new participant must discover every service first: listen for a few heartbeat periods.
  const double status_wait = std::max(1.5, 3.0 * deployment->heartbeat_period_s);
  std::system((bin_dir / "tamp-status")
                  .string()
                  .append(" --wait ")
                  .append(std::to_string(status_wait))
                  .append(" --domain ")
                  .append(std::to_string(*dom))
                  .append(" --run-id ")
                  .append(run_id)
                  .c_str());

  if (scenario.empty()) {
    std::printf("\ntamp run: no scenario given: services only.\n");
    std::fflush(stdout);
  } else if (rc == tamp::cli::kExitOk) {
    tamp::runner::MissionOptions mo;
    mo.scenario = scenario;
    mo.policy = policy;
    mo.seed = seed;
    mo.timeout_s = mission_timeout;
    mo.out_dir = run_dir;
    mo.latest_dir = run_dir.parent_path();
    rc = tamp::runner::runMission(participant, mo, [&] {
      launcher.poll();
      return tamp::cli::stopRequested();
    });
  }
  if (keep && rc == tamp::cli::kExitOk) {
    std::printf("tamp run: services running (supervised); Ctrl-C to stop.\n");
    std::fflush(stdout);
    while (!tamp::cli::stopRequested()) {
      launcher.poll();
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  launcher.stop(5.0);
  for (const auto& st : sup.status()) {
    if (st.last_exit != "exit 0" && st.last_exit.rfind("signal 15", 0) != 0) {
      std::printf("tamp run: %s ended with %s\n", st.name.c_str(), st.last_exit.c_str());
    }
  }
  return rc;
}
