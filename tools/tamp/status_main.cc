// `tamp status`: the live services of a DDS domain, from their heartbeats.
#include <cstdio>
#include <iostream>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_common.h"
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
  app.add_flag("--json", json, "print JSON");
  app.add_flag("--all", all, "also list services that stopped or went silent");
  app.add_option("--security", security, "DDS Security directory (deploy/security/make_certs.sh; default: $TAMP_DDS_SECURITY)");
  CLI11_PARSE(app, argc, argv);

  tamp::dds::ParticipantOptions po;
  po.domain_id = domain;
  po.name = "tamp/status";
  if (!profile.empty()) po.profile = profile;
  po.security_dir = security;
  auto participant = tamp::dds::Participant::create(po);
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
  std::vector<std::string> missing;
  for (const auto& name : expect) {
    bool found = false;
    for (const auto& s : services) found = found || (s.alive && s.name == name);
    if (!found) missing.push_back(name);
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
    std::cout << nlohmann::json{{"domain", (*participant)->domainId()}, {"services", out}, {"missing", missing}}.dump(2)
              << "\n";
  } else {
    std::printf("DDS domain %d\n", (*participant)->domainId());
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
  }
  return missing.empty() ? tamp::cli::kExitOk : tamp::cli::kExitServiceError;
}
