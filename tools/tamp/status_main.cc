// `tamp status [--deployment FILE [--host NAME]] [--run-id ID]`: the live services of a DDS domain
// and run, from their heartbeats (discovered as the deployment's services discover). With a deployment (or --expect), every expected service that is
// not alive is listed as MISSING and the exit code is 40; optional services of the deployment are
// listed as missing too but do not fail the check.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "tamp/deploy/deployment.h"
#include "tamp/dds/heartbeat.h"

namespace {

std::string duration(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof(buf), "%.1fs", s);
  else if (s < 3600) std::snprintf(buf, sizeof(buf), "%dm%02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  else std::snprintf(buf, sizeof(buf), "%dh%02dm", static_cast<int>(s) / 3600, (static_cast<int>(s) % 3600) / 60);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"List the live TAMP services of a DDS domain (from their heartbeats)", "tamp status"};
  int domain = -1;
  std::string profile, security;
  double wait_s = 1.5;
  std::vector<std::string> expect;
  bool json = false, all = false;
  app.add_option("--domain", domain, "DDS domain id (default: $TAMP_DOMAIN_ID or 0)")->check(CLI::Range(0, 232));
  app.add_option("--profile", profile, "DDS participant profile (tamp_default, tamp_udp, tamp_shm)");
  app.add_option("--wait", wait_s, "seconds to listen for heartbeats")->check(CLI::Range(0.1, 600.0));
  app.add_option("--expect", expect, "service names that must be alive (exit 40 otherwise); waits up to --wait");
  std::string deployment_file, host, run_id;
  app.add_option("--deployment", deployment_file, "deployment file: its services are expected (exit 40 when one is missing)");
  app.add_option("--host", host, "with --deployment: expect only this host's services");
  app.add_option("--run-id", run_id, "run whose services to list (default: $TAMP_RUN_ID or none)");
  app.add_flag("--json", json, "print JSON");
  app.add_flag("--all", all, "also list services that stopped or went silent");
  app.add_option("--security", security, "DDS Security directory (deploy/security/make_certs.sh; default: $TAMP_DDS_SECURITY)");
  CLI11_PARSE(app, argc, argv);

  std::vector<std::string> optional_names;
  if (!deployment_file.empty()) {
    auto d = tamp::deploy::loadDeployment(deployment_file);
    if (!d) {
      std::cerr << "tamp status: " << d.error().toString() << "\n";
      return tamp::cli::kExitInputError;
    }
    if (!host.empty() && d->host(host) == nullptr) {
      std::cerr << "tamp status: " << deployment_file << " has no host '" << host << "'\n";
      return tamp::cli::kExitInputError;
    }
    for (const auto* s : d->servicesOn(host)) {
      expect.push_back(s->name);
      if (s->optional) optional_names.push_back(s->name);
    }
    // Discover as the deployment's services do (multicast, or its discovery servers), as `tamp
    // mission --deployment` does: without it a shell without $TAMP_DDS_DISCOVERY_SERVERS saw no
    // service of a server-discovery deployment.
    setenv("TAMP_DDS_DISCOVERY_SERVERS", d->discovery.serversEnv().c_str(), 1);
    // Discovery of every service takes a few heartbeat periods: listen at least that long.
    if (app.count("--wait") == 0) wait_s = std::max(wait_s, 4.0 * d->heartbeat_period_s);
  } else if (!host.empty()) {
    std::cerr << "tamp status: --host needs --deployment\n";
    return tamp::cli::kExitInputError;
  }
  tamp::dds::ParticipantOptions po;
  po.domain_id = domain;
  po.name = "tamp/status";
  if (!profile.empty()) po.profile = profile;
  po.security_dir = security;
  auto participant = tamp::dds::Participant::create(po, run_id);
  if (!participant) {
    std::cerr << "tamp status: " << participant.error().toString() << "\n";
    return tamp::cli::kExitServiceError;
  }
  tamp::dds::HeartbeatMonitor monitor(*participant);
  const tamp::Termination until = tamp::Termination::after(wait_s);
  if (expect.empty()) {
    while (!until()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  } else {
    for (const auto& name : expect) (void)monitor.waitFor(name, 1, until);
  }
  auto services = monitor.services();
  std::vector<std::string> missing, missing_optional;
  for (const auto& name : expect) {
    bool found = false;
    for (const auto& s : services) found = found || (s.alive && s.name == name);
    if (found) continue;
    const bool opt = std::find(optional_names.begin(), optional_names.end(), name) != optional_names.end();
    (opt ? missing_optional : missing).push_back(name);
  }

  if (json) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& s : services) {
      if (!all && !s.alive) continue;
      out.push_back({{"service_id", s.service_id}, {"name", s.name}, {"host", s.host}, {"pid", s.pid},
                     {"state", tamp::dds::toString(s.state)}, {"alive", s.alive}, {"uptime_s", s.uptime_s},
                     {"last_heartbeat_s", s.age_s}, {"served", s.served}, {"failed", s.failed},
                     {"version", s.version}, {"detail", s.detail}});
    }
    std::cout << nlohmann::json{{"domain", (*participant)->domainId()}, {"run_id", (*participant)->runId()},
                                {"services", out}, {"missing", missing}, {"missing_optional", missing_optional}}
                     .dump(2)
              << "\n";
  } else {
    std::printf("DDS domain %d, run %s\n", (*participant)->domainId(),
                (*participant)->runId().empty() ? "(none)" : (*participant)->runId().c_str());
    std::printf("%-20s %-16s %7s %-9s %8s %8s %7s %9s  %s\n", "SERVICE", "HOST", "PID", "STATE", "UPTIME", "SERVED",
                "FAILED", "HEARD", "DETAIL");
    int shown = 0;
    for (const auto& s : services) {
      if (!all && !s.alive) continue;
      ++shown;
      std::printf("%-20s %-16s %7u %-9s %8s %8llu %7llu %9s  %s\n", s.name.c_str(), s.host.c_str(), s.pid,
                  s.alive ? tamp::dds::toString(s.state) : "gone", duration(s.uptime_s).c_str(),
                  static_cast<unsigned long long>(s.served), static_cast<unsigned long long>(s.failed),
                  (duration(s.age_s) + " ago").c_str(), s.detail.c_str());
    }
    if (shown == 0) std::printf("(no live service heard within %.1f s)\n", wait_s);
    for (const auto& m : missing) std::printf("MISSING: %s\n", m.c_str());
    for (const auto& m : missing_optional) std::printf("MISSING (optional): %s\n", m.c_str());
    if (!missing.empty()) std::printf("%zu of %zu expected services missing\n", missing.size(), expect.size());
  }
  return missing.empty() ? tamp::cli::kExitOk : tamp::cli::kExitServiceError;
}
