// `tamp mission SCENARIO --run-id ID [--deployment FILE]`: sends the scenario's mission to the
// services of a running deployment (started by `tamp launch` on each host, or `tamp run
// --keep-running`) and follows it as `tamp run` does: waits (up to the deployment's
// readyWait()) until every service of the deployment in run ID is heard ready (join_run.h), then
// the mission; writes report.json etc. into OUT/RUN_ID/mission. Discovery is the deployment's
// (multicast, or as a client of its discovery servers). Exit codes as `tamp run`: 0 succeeded,
// 10 mission failed, 20 out of time, 30 bad input, 40 a service unavailable.
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include <CLI/CLI.hpp>

#include "cli_common.h"
#include "join_run.h"
#include "mission_run.h"
#include "tamp/core/paths.h"
#include "tamp/core/termination.h"
#include "tamp/deploy/deployment.h"
#include "tamp/dds/participant.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{"Send a mission to a running deployment and follow it", "tamp mission"};
  std::string scenario, run_id, policy = "effort", out_dir = "out";
  std::string deployment_file = (tamp::configDir() / "deploy" / "local.yaml").string();
  int domain = -1;
  unsigned seed = 0;
  double mission_timeout = 900.0;
  app.add_option("scenario", scenario, "scenario YAML (the one the services were launched with)")->required();
  app.add_option("--run-id", run_id, "run id of the running services (default: $TAMP_RUN_ID)");
  app.add_option("--deployment", deployment_file, "deployment the services run (its services and discovery)");
  app.add_option("--domain", domain, "DDS domain id (default: $TAMP_DOMAIN_ID or 0)")->check(CLI::Range(0, 232));
  app.add_option("--policy", policy, "effort, infeasible or oracle (oracle: the deployment's simulator must run with TAMP_ORACLE=1)")
      ->check(CLI::IsMember({"effort", "infeasible", "oracle"}));
  app.add_option("--seed", seed, "seed of the mission's sampling (0: the graph manager's)");
  app.add_option("--mission-timeout", mission_timeout, "give up after this many seconds")->check(CLI::PositiveNumber);
  app.add_option("--out", out_dir, "report folder root: OUT/RUN_ID/mission");
  CLI11_PARSE(app, argc, argv);

  auto deployment = tamp::deploy::loadDeployment(deployment_file);
  if (!deployment) {
    std::cerr << "tamp mission: " << deployment.error().toString() << "\n";
    return tamp::cli::kExitInputError;
  }
  if (auto bad = tamp::runner::checkScenario(scenario)) {
    std::cerr << "tamp mission: " << *bad << "\n";
    return tamp::cli::kExitInputError;
  }
  auto rid = tamp::dds::resolveRunId(run_id);
  auto dom = tamp::dds::resolveDomainId(domain);
  if (!rid || !dom || rid->empty()) {
    std::cerr << "tamp mission: "
              << (!rid ? rid.error().toString()
                       : !dom ? dom.error().toString() : std::string("give the run id of the services: --run-id"))
              << "\n";
    return tamp::cli::kExitInputError;
  }
  setenv("TAMP_DDS_DISCOVERY_SERVERS", deployment->discovery.serversEnv().c_str(), 1);
  tamp::cli::stopOnSignals({SIGINT, SIGTERM}, /*restart=*/true);
  const tamp::runner::JoinedRun joined = tamp::runner::joinRun(*deployment, *dom, *rid);
  if (!joined.participant) {
    std::fprintf(stderr, "tamp mission: run %s: %s\n", rid->c_str(), joined.error.c_str());
    return joined.exit_code;
  }
  const auto& participant = joined.participant;
  std::printf("tamp mission: run %s, DDS domain %d, %zu services alive%s\n", rid->c_str(), *dom,
              deployment->services.size(), participant->usesDiscoveryServer() ? " (discovery server)" : "");
  std::fflush(stdout);
  tamp::runner::MissionOptions mo;
  mo.scenario = fs::absolute(scenario).string();
  mo.policy = policy;
  mo.seed = seed;
  mo.timeout_s = mission_timeout;
  mo.out_dir = fs::absolute(fs::path(out_dir) / *rid / "mission");
  fs::create_directories(mo.out_dir);
  const tamp::Stopwatch wall;
  const int rc = tamp::runner::runMission(participant, mo, [] { return tamp::cli::stopRequested(); });
  // From the mission sent to its end (services already alive): what benchmarks compare.
  std::printf("tamp mission: wall time %.2f s\n", wall.seconds());
  return rc;
}
