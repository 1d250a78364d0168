// `tamp run [SCENARIO] [--policy effort|infeasible] [--out DIR] [--seed N]`: the main job. Starts
// every service of a deployment (config/deploy/local.yaml by default) as supervised processes on
// one DDS domain, waits until each is alive (heartbeats) and answers a request (echo), then sends
// the scenario's mission to the graph manager and follows it: one line per executed action
// (predicted and measured seconds), a progress bar weighted by predicted effort. At the end it
// writes report.json, graph.dot/.svg and world.png/.svg into the run's folder beside every
// service's log, stops the services (or keeps them with --keep-running) and exits with the
// mission's code: 0 succeeded, 10 mission failed, 20 out of time, 30 bad input, 40 a service
// unavailable. Without a scenario it only starts and checks the services.
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
#include "tamp/config/yaml_reader.h"
#include "tamp/core/paths.h"
#include "tamp/dds/heartbeat.h"
#include "tamp/dds/service_node.h"
#include "tamp/process/supervisor.h"
#include "mission_run.h"

namespace fs = std::filesystem;

namespace {

struct ServiceEntry {
  std::string name;
  std::string executable;
  std::vector<std::string> args;
  bool optional{false};
};

struct Deployment {
  double heartbeat_period_s{0.5};
  double startup_timeout_s{30.0};
  std::vector<ServiceEntry> services;
};

tamp::Result<Deployment> loadDeployment(const fs::path& file) {
  auto doc = tamp::config::loadYamlFile(file);
  if (!doc) return doc.error();
  tamp::config::FieldReader r(*doc);
  Deployment d;
  r.optional("heartbeat_period_s", d.heartbeat_period_s);
  r.optional("startup_timeout_s", d.startup_timeout_s);
  r.check(d.heartbeat_period_s > 0 && d.heartbeat_period_s <= 10, "heartbeat_period_s", "must be in (0, 10]");
  r.check(d.startup_timeout_s > 0, "startup_timeout_s", "must be positive");
  for (auto& s : r.sequence("services")) {
    ServiceEntry e;
    s.required("name", e.name);
    s.required("executable", e.executable);
    s.optional("args", e.args);
    s.optional("optional", e.optional);
    s.refuseUnknownKeys();
    for (const auto& other : d.services) {
      s.check(other.name != e.name, "name", "duplicate service name '" + e.name + "'");
    }
    d.services.push_back(std::move(e));
  }
  r.refuseUnknownKeys();
  if (!r.ok()) return r.status().error();
  return d;
}

std::string expand(std::string s, const std::string& key, const std::string& value) {
  for (size_t pos; (pos = s.find(key)) != std::string::npos;) s.replace(pos, key.size(), value);
  return s;
}

volatile sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }

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
  app.add_option("--policy", policy, "effort (revise whenever cheaper) or infeasible (move objects only when no way around)")
      ->check(CLI::IsMember({"effort", "infeasible"}));
  app.add_option("--seed", seed, "seed of the mission's sampling (0: the graph manager's configured seed)");
  app.add_option("--mission-timeout", mission_timeout, "give up on the mission after this many seconds")
      ->check(CLI::PositiveNumber);
  app.add_option("--deployment", deployment_file, "deployment file: services to start")->check(CLI::ExistingFile);
  app.add_option("--domain", domain, "DDS domain id (default: $TAMP_DOMAIN_ID or 0)")->check(CLI::Range(0, 232));
  app.add_flag("--keep-running", keep, "keep the services running (supervised) until Ctrl-C");
  app.add_option("--out", out_dir, "directory for run logs and reports");
  std::string security;
  app.add_option("--security", security,
                 "DDS Security directory (deploy/security/make_certs.sh): every service and this tool run secured, "
                 "each with its own identity (default: $TAMP_DDS_SECURITY)")
      ->check(CLI::ExistingDirectory);
  CLI11_PARSE(app, argc, argv);

  auto deployment = loadDeployment(deployment_file);
  if (!deployment) {
    std::cerr << "tamp run: " << deployment.error().toString() << "\n";
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

  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", std::localtime(&now));
  const fs::path run_dir = fs::path(out_dir) / (std::string("run-") + stamp);
  fs::create_directories(run_dir);
  const fs::path bin_dir = fs::read_symlink("/proc/self/exe").parent_path();

  // The simulator writes the ground truth it ends with here (tests and reports judge by it).
  if (!scenario.empty()) setenv("TAMP_SIM_FINAL_WORLD", (fs::absolute(run_dir) / "sim_final_world.json").c_str(), 1);
  // The services inherit the security directory; each picks its identity by its --name.
  if (!security.empty()) setenv("TAMP_DDS_SECURITY", fs::absolute(security).c_str(), 1);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);

  tamp::process::Supervisor sup;
  std::vector<std::string> started, skipped;
  for (const auto& s : deployment->services) {
    const fs::path exe = bin_dir / s.executable;
    if (access(exe.c_str(), X_OK) != 0) {
      if (s.optional) {
        skipped.push_back(s.name);
        continue;
      }
      std::cerr << "tamp run: service '" << s.name << "' needs " << exe << ", which is not built\n";
      return tamp::cli::kExitInputError;
    }
    tamp::process::ProcessSpec spec;
    spec.name = s.name;
    spec.executable = exe;
    spec.args = {"--name", s.name, "--domain", std::to_string(*dom), "--heartbeat-period",
                 std::to_string(deployment->heartbeat_period_s)};
    for (std::size_t i = 0; i < s.args.size(); ++i) {
      // "--option {scenario}" is left out as a pair when the run has no scenario.
      if (scenario.empty() && i + 1 < s.args.size() && s.args[i].rfind("--", 0) == 0 &&
          s.args[i + 1] == "{scenario}") {
        ++i;
        continue;
      }
      spec.args.push_back(
          expand(expand(s.args[i], "{scenario}", scenario), "{config}", tamp::configDir().string()));
    }
    spec.log_file = run_dir / (s.name + ".log");
    spec.restart = keep;
    sup.add(spec);
    started.push_back(s.name);
  }
  std::printf("tamp run: DDS domain %d, deployment %s, logs in %s\n", *dom, deployment_file.c_str(), run_dir.c_str());
  if (!skipped.empty()) {
    std::printf("tamp run: not built yet, skipped:");
    for (const auto& s : skipped) std::printf(" %s", s.c_str());
    std::printf("\n");
  }
  if (auto st = sup.startAll(); !st.ok()) {
    std::cerr << "tamp run: " << st.error().toString() << "\n";
    sup.stopAll();
    return tamp::cli::kExitServiceError;
  }

  auto participant = tamp::dds::Participant::create({*dom, tamp::dds::kProfileDefault, "tamp/run", {}});
  if (!participant) {
    std::cerr << "tamp run: " << participant.error().toString() << "\n";
    return tamp::cli::kExitServiceError;
  }
  tamp::dds::HeartbeatMonitor monitor(*participant);
  const tamp::Termination startup = tamp::Termination::after(deployment->startup_timeout_s);
  std::vector<std::string> not_alive;
  for (const auto& name : started) {
    while (!monitor.waitFor(name, 1, startup.tightened(tamp::Deadline::in(0.1)))) {
      sup.poll();
      auto st = sup.status(name);
      if (startup() || g_stop || (st && st->phase != tamp::process::ProcessPhase::kRunning &&
                                   st->phase != tamp::process::ProcessPhase::kBackoff)) {
        not_alive.push_back(name);
        break;
      }
    }
  }
  // Every service answers on its echo endpoint: a real request/reply round trip through DDS.
  int rc = tamp::cli::kExitOk;
  std::printf("\n%-20s %8s %10s  %s\n", "SERVICE", "PID", "ROUND TRIP", "RESULT");
  for (const auto& name : started) {
    auto st = sup.status(name);
    const bool alive = std::find(not_alive.begin(), not_alive.end(), name) == not_alive.end();
    if (!alive) {
      std::printf("%-20s %8s %10s  NOT ALIVE (%s; see %s)\n", name.c_str(), "-", "-",
                  st ? (st->last_exit.empty() ? "no heartbeat" : st->last_exit.c_str()) : "?",
                  (run_dir / (name + ".log")).c_str());
      rc = tamp::cli::kExitServiceError;
      continue;
    }
    tamp::dds::RpcClient<tamp::msg::EchoRequest, tamp::msg::EchoReply> echo(*participant,
                                                                             tamp::dds::echoService(name));
    tamp::msg::EchoRequest req;
    req.payload({1, 2, 3, 4});
    tamp::Stopwatch sw;
    auto rep = echo.call(req, tamp::dds::CallOptions{10.0, {}});
    if (!rep) {
      std::printf("%-20s %8d %10s  NO REPLY: %s\n", name.c_str(), st ? st->pid : -1, "-",
                  rep.error().toString().c_str());
      rc = tamp::cli::kExitServiceError;
      continue;
    }
    std::printf("%-20s %8u %8.0fus  ok\n", name.c_str(), rep->pid(), sw.seconds() * 1e6);
  }
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
                  .c_str());

  if (scenario.empty()) {
    std::printf("\ntamp run: no scenario given: services only.\n");
  } else if (rc == tamp::cli::kExitOk) {
    tamp::runner::MissionOptions mo;
    mo.scenario = scenario;
    mo.policy = policy;
    mo.seed = seed;
    mo.timeout_s = mission_timeout;
    mo.out_dir = run_dir;
    rc = tamp::runner::runMission(*participant, mo, [&] {
      sup.poll();
      return g_stop != 0;
    });
  }
  if (keep && rc == tamp::cli::kExitOk) {
    std::printf("tamp run: services running (supervised); Ctrl-C to stop.\n");
    while (!g_stop) {
      sup.poll();
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  sup.stopAll(5.0);
  for (const auto& st : sup.status()) {
    if (st.last_exit != "exit 0" && st.last_exit.rfind("signal 15", 0) != 0) {
      std::printf("tamp run: %s ended with %s\n", st.name.c_str(), st.last_exit.c_str());
    }
  }
  return rc;
}
