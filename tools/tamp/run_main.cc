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

/// Everything `tamp run`'s command line sets, with its defaults. Validated by the checks each
/// option is declared with (CLI11 refuses a value outside them), so the run takes it as is.
struct RunCli {
  std::string scenario;  // empty: the services only
  std::string deployment_file = (tamp::configDir() / "deploy" / "local.yaml").string();
  int domain = -1;
  bool keep = false;
  std::string out_dir = "out";
  std::string policy = "effort";
  unsigned seed = 0;
  double mission_timeout = 900.0;
  std::string explicit_run_id;  // empty: generated
  bool fresh = false;
  std::string security;
  double realtime_factor = -1.0;  // negative: the simulator's configured one
};

constexpr const char* kAbout = "Run the TAMP services on this machine (one DDS domain, supervised processes)";

/// Declares every option of `tamp run` on `app`, bound to `o`, in the order --help lists them.
void defineOptions(CLI::App& app, RunCli& o) {
  app.add_option("scenario", o.scenario, "scenario YAML (config/scenarios/...) or NAMO world file");
  app.add_option("--policy", o.policy,
                 "effort (revise whenever cheaper), infeasible (move objects only when no way around) or oracle "
                 "(evaluation only: the simulator's truth, the lower bound)")
      ->check(CLI::IsMember({"effort", "infeasible", "oracle"}));
  app.add_option("--seed", o.seed, "seed of the mission's sampling (0: the graph manager's configured seed)");
  app.add_option("--mission-timeout", o.mission_timeout, "give up on the mission after this many seconds")
      ->check(CLI::PositiveNumber);
  app.add_option("--deployment", o.deployment_file, "deployment file: services to start (every host's, here)");
  app.add_option("--domain", o.domain, "DDS domain id (default: $TAMP_DOMAIN_ID or 0)")->check(CLI::Range(0, 232));
  app.add_flag("--keep-running", o.keep, "keep the services running (supervised) until Ctrl-C");
  app.add_option("--out", o.out_dir, "directory for run folders (OUT/RUN_ID: logs, events, reports)");
  app.add_option("--run-id", o.explicit_run_id, "run id (default: generated, run-YYYYmmdd-HHMMSS-xxxx)");
  app.add_flag("--fresh", o.fresh,
               "start the effort estimator from the default time models: an empty store in the run folder "
               "(RUN/effort_store; the configured store is neither read nor changed)");
  app.add_option("--security", o.security,
                 "DDS Security directory (deploy/security/make_certs.sh): every service and this tool run secured, "
                 "each with its own identity (default: $TAMP_DDS_SECURITY)")
      ->check(CLI::ExistingDirectory);
  app.add_option("--realtime-factor", o.realtime_factor,
                 "simulated seconds per wall-clock second of the simulated robot for this run (default: "
                 "config/services/sim.yaml's, 1 = real time; 0 = as fast as possible); reports and time models "
                 "stay in simulated seconds")
      ->check(CLI::NonNegativeNumber);
}

/// What the command line resolves to, checked before any service starts.
struct RunPlace {
  tamp::deploy::Deployment deployment;  // as its file says (every host's services)
  fs::path bin_dir;                     // this tool's directory: the services' executables
  std::string scenario;                 // absolute, or empty: the services only
  int domain{0};
  std::string run_id;
  fs::path run_dir;  // OUT/RUN_ID, absolute
};

/// The deployment file, every executable it names present in `bin_dir`. A missing one is an
/// input error (file, line, field), optional service or not: a typo must not become a silently
/// smaller run.
tamp::Result<tamp::deploy::Deployment> loadRunnableDeployment(const std::string& file,
                                                              const fs::path& bin_dir) {
  auto deployment = tamp::deploy::loadDeployment(file);
  if (!deployment) return deployment.error();
  if (tamp::Status s = tamp::deploy::checkExecutables(*deployment, bin_dir); !s.ok())
    return s.error();
  return deployment;
}

/// The scenario's absolute path; a bad scenario is an input error (file, line, field), found
/// before any service starts.
tamp::Result<std::string> checkedScenario(const std::string& scenario) {
  if (auto bad = tamp::runner::checkScenario(scenario))
    return tamp::Error(tamp::ErrorCode::kInvalidArgument, *bad);
  return fs::absolute(scenario).string();
}

/// --run-id when given (checked), else a generated one.
tamp::Result<std::string> runId(const std::string& explicit_run_id) {
  if (explicit_run_id.empty()) return tamp::launch::makeRunId("run");
  return tamp::dds::resolveRunId(explicit_run_id);
}

/// The deployment, scenario, DDS domain and run id the command line names; the first input error.
tamp::Result<RunPlace> resolveRun(const RunCli& o) {
  RunPlace r;
  r.bin_dir = fs::read_symlink("/proc/self/exe").parent_path();
  auto deployment = loadRunnableDeployment(o.deployment_file, r.bin_dir);
  if (!deployment) return deployment.error();
  r.deployment = std::move(*deployment);
  if (!o.scenario.empty()) {
    auto scenario = checkedScenario(o.scenario);
    if (!scenario) return scenario.error();
    r.scenario = *scenario;
  }
  auto dom = tamp::dds::resolveDomainId(o.domain);
  if (!dom) return dom.error();
  r.domain = *dom;
  auto rid = runId(o.explicit_run_id);
  if (!rid) return rid.error();
  r.run_id = *rid;
  r.run_dir = fs::absolute(fs::path(o.out_dir) / r.run_id);
  return r;
}

/// --fresh: the estimator keeps its store in the run folder (whatever its store_directory says).
void useFreshEffortStore(const fs::path& run_dir) {
  const fs::path store = run_dir / "effort_store";
  fs::create_directories(store);
  setenv("TAMP_EFFORT_STORE", store.c_str(), 1);
  std::fprintf(stderr, "tamp run: --fresh: default time models, effort store %s\n", store.c_str());
}

/// --realtime-factor: the simulated robot's pace for this run, said on stdout.
void setRealtimeFactor(double realtime_factor) {
  setenv("TAMP_SIM_REALTIME_FACTOR", std::to_string(realtime_factor).c_str(), 1);
  if (realtime_factor == 0)
    std::printf("tamp run: the simulated robot runs as fast as it can\n");
  else
    std::printf(
        "tamp run: the simulated robot runs at %gx real time (times are simulated seconds)\n",
        realtime_factor);
}

/// The environment the services inherit from this process for this run.
void setServiceEnvironment(const RunCli& o, const RunPlace& r) {
  // The simulator writes the ground truth it ends with here (tests and reports judge by it).
  if (!r.scenario.empty())
    setenv("TAMP_SIM_FINAL_WORLD", (fs::absolute(r.run_dir) / "sim_final_world.json").c_str(), 1);
  if (o.fresh) useFreshEffortStore(r.run_dir);
  // --policy oracle: the simulator serves its truth (true durations, hidden objects, scripted
  // faults) to the graph manager for this run only; a normal run does not expose it.
  if (o.policy == "oracle")
    setenv("TAMP_ORACLE", "1", 1);
  else
    unsetenv("TAMP_ORACLE");
  if (o.realtime_factor >= 0) setRealtimeFactor(o.realtime_factor);
  // The services inherit the security directory; each picks its identity by its --name.
  if (!o.security.empty()) setenv("TAMP_DDS_SECURITY", fs::absolute(o.security).c_str(), 1);
}

/// `deployment` with every host's services on this machine, each with its host's environment
/// (the service's own entries last); so is the host that runs the discovery servers (mode server).
tamp::deploy::Deployment allOnThisMachine(const tamp::deploy::Deployment& deployment) {
  tamp::deploy::Deployment local = deployment;
  for (auto& s : local.services) {
    std::vector<std::string> env = deployment.host(s.host)->env;
    env.insert(env.end(), s.env.begin(), s.env.end());
    s.env = std::move(env);
    s.host = tamp::deploy::kLocalHost;
  }
  local.hosts = {tamp::deploy::HostSpec{tamp::deploy::kLocalHost, "this machine", {}}};
  local.discovery.runAllOn(tamp::deploy::kLocalHost);
  return local;
}

/// The names of the deployment's services (only the optional ones with `optional_only`), in order.
std::vector<std::string> serviceNames(const tamp::deploy::Deployment& deployment,
                                      bool optional_only) {
  std::vector<std::string> names;
  for (const auto& s : deployment.services)
    if (s.optional || !optional_only) names.push_back(s.name);
  return names;
}

/// Every service of every host of the deployment, on this machine, attached to this process
/// (they die with it); restarted when they die or freeze. A busy service is not frozen: its
/// heartbeat thread beats on while its worker makes progress (dds::WorkWatch).
tamp::launch::LaunchOptions launchOptions(const RunPlace& r) {
  tamp::launch::LaunchOptions lo;
  lo.deployment = allOnThisMachine(r.deployment);
  lo.host = tamp::deploy::kLocalHost;
  lo.run_id = r.run_id;
  lo.domain = r.domain;
  lo.run_dir = r.run_dir;
  lo.scenario = r.scenario;
  lo.bin_dir = r.bin_dir;
  lo.config_dir = tamp::configDir();
  lo.detach = false;
  lo.restart = true;
  lo.liveness = true;
  lo.adopt = false;
  return lo;
}

/// The same table `tamp status` prints, from the heartbeats. A new participant must discover every
/// service first: it listens for a few heartbeat periods.
void printStatusTable(const RunPlace& r) {
  const double status_wait = std::max(1.5, 3.0 * r.deployment.heartbeat_period_s);
  std::system((r.bin_dir / "tamp-status")
                  .string()
                  .append(" --wait ")
                  .append(std::to_string(status_wait))
                  .append(" --domain ")
                  .append(std::to_string(r.domain))
                  .append(" --run-id ")
                  .append(r.run_id)
                  .c_str());
}

/// Waits until the started services are ready, echoes each and prints the status table: kExitOk
/// when every service that is not optional answers, else kExitServiceError.
int checkServices(tamp::launch::Launcher& launcher, const RunPlace& r) {
  const std::vector<std::string> started = serviceNames(r.deployment, /*optional_only=*/false);
  const std::vector<std::string> not_alive = waitUntilReady(launcher, started, r.deployment);
  const int rc = echoEach(launcher, started, not_alive,
                          serviceNames(r.deployment, /*optional_only=*/true), r.run_dir);
  std::printf("\n");
  std::fflush(stdout);
  printStatusTable(r);
  return rc;
}

/// Sends the scenario's mission and follows it to its end; the mission's exit code. The
/// launcher's participant, which has heard the services start, serves the mission too: a second
/// one would have to match every service anew (under DDS Security on Fast DDS 2.9.1, one such
/// pair in about twenty-five never matched: a service "not alive" that was; docs/reliability.md).
int runScenarioMission(const RunCli& o, const RunPlace& r, tamp::launch::Launcher& launcher) {
  tamp::runner::MissionOptions mo;
  mo.scenario = r.scenario;
  mo.policy = o.policy;
  mo.seed = o.seed;
  mo.timeout_s = o.mission_timeout;
  mo.out_dir = r.run_dir;
  mo.latest_dir = r.run_dir.parent_path();
  return tamp::runner::runMission(launcher.participant(), mo, [&] {
    launcher.poll();
    return tamp::cli::stopRequested();
  });
}

/// The mission when a scenario was given and the services answered; `rc` (the services' check)
/// otherwise.
int runMissionIfAny(const RunCli& o, const RunPlace& r, tamp::launch::Launcher& launcher, int rc) {
  if (r.scenario.empty()) {
    std::printf("\ntamp run: no scenario given: services only.\n");
    std::fflush(stdout);
    return rc;
  }
  if (rc != tamp::cli::kExitOk) return rc;
  return runScenarioMission(o, r, launcher);
}

/// --keep-running: supervises the services until a stop is requested (Ctrl-C).
void keepRunning(tamp::launch::Launcher& launcher) {
  std::printf("tamp run: services running (supervised); Ctrl-C to stop.\n");
  std::fflush(stdout);
  while (!tamp::cli::stopRequested()) {
    launcher.poll();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

/// Starts the services, checks them, runs the mission (if any), stops them; the exit code.
int runServices(const RunCli& o, const RunPlace& r) {
  tamp::launch::Launcher launcher(launchOptions(r));
  std::printf("tamp run: run %s, DDS domain %d, deployment %s, logs in %s\n", r.run_id.c_str(),
              r.domain, o.deployment_file.c_str(), r.run_dir.c_str());
  if (auto st = launcher.start(); !st.ok()) {
    std::cerr << "tamp run: " << st.error().toString() << "\n";
    launcher.stop();
    return tamp::cli::kExitServiceError;
  }
  int rc = checkServices(launcher, r);
  rc = runMissionIfAny(o, r, launcher, rc);
  if (o.keep && rc == tamp::cli::kExitOk) keepRunning(launcher);
  launcher.stop(5.0);
  tamp::launch::printUncleanEnds("tamp run", launcher.supervisor());
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  RunCli o;
  CLI::App app{kAbout, "tamp run"};
  defineOptions(app, o);
  CLI11_PARSE(app, argc, argv);
  const tamp::Result<RunPlace> run = resolveRun(o);
  if (!run) return tamp::cli::fail("tamp run", run.error(), tamp::cli::kExitInputError);
  fs::create_directories(run->run_dir);
  setServiceEnvironment(o, *run);
  tamp::cli::stopOnSignals({SIGINT, SIGTERM}, /*restart=*/true);
  return runServices(o, *run);
}
