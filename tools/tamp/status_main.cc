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

/// Everything `tamp status`'s command line sets, with its defaults. Validated by the checks each
/// option is declared with (CLI11 refuses a value outside them).
struct StatusCli {
  int domain = -1;
  std::string profile, security;
  double wait_s = 1.5;
  bool wait_given = false;  // --wait on the command line (else a deployment may lengthen it)
  std::vector<std::string> expect;
  bool json = false, all = false;
  std::string deployment_file, host, run_id;
};

constexpr const char* kAbout = "List the live TAMP services of a DDS domain (from their heartbeats)";

/// Declares every option of `tamp status` on `app`, bound to `o`, in the order --help lists them.
void defineOptions(CLI::App& app, StatusCli& o) {
  app.add_option("--domain", o.domain, "DDS domain id (default: $TAMP_DOMAIN_ID or 0)")->check(CLI::Range(0, 232));
  app.add_option("--profile", o.profile, "DDS participant profile (tamp_default, tamp_udp, tamp_shm)");
  app.add_option("--wait", o.wait_s, "seconds to listen for heartbeats")->check(CLI::Range(0.1, 600.0));
  app.add_option("--expect", o.expect, "service names that must be alive (exit 40 otherwise); waits up to --wait");
  app.add_option("--deployment", o.deployment_file, "deployment file: its services are expected (exit 40 when one is missing)");
  app.add_option("--host", o.host, "with --deployment: expect only this host's services");
  app.add_option("--run-id", o.run_id, "run whose services to list (default: $TAMP_RUN_ID or none)");
  app.add_flag("--json", o.json, "print JSON");
  app.add_flag("--all", o.all, "also list services that stopped or went silent");
  app.add_option("--security", o.security, "DDS Security directory (deploy/security/make_certs.sh; default: $TAMP_DDS_SECURITY)");
}

/// --deployment: its services (or --host's) are expected, the optional ones named in
/// `optional_names`; discovery is the deployment's, and without --wait the wait lasts at least
/// four heartbeat periods. Without a deployment, --host is an input error.
tamp::Status expectDeployment(StatusCli& o, std::vector<std::string>& optional_names) {
  if (o.deployment_file.empty()) {
    if (o.host.empty()) return {};
    return tamp::Error(tamp::ErrorCode::kInvalidArgument, "--host needs --deployment");
  }
  auto d = tamp::deploy::loadDeployment(o.deployment_file);
  if (!d) return d.error();
  if (!o.host.empty() && d->host(o.host) == nullptr) {
    return tamp::Error(tamp::ErrorCode::kInvalidArgument,
                       o.deployment_file + " has no host '" + o.host + "'");
  }
  for (const auto* s : d->servicesOn(o.host)) {
    o.expect.push_back(s->name);
    if (s->optional) optional_names.push_back(s->name);
  }
  // Discover as the deployment's services do (multicast, or its discovery servers), as `tamp
  // mission --deployment` does: without it a shell without $TAMP_DDS_DISCOVERY_SERVERS saw no
  // service of a server-discovery deployment.
  setenv("TAMP_DDS_DISCOVERY_SERVERS", d->discovery.serversEnv().c_str(), 1);
  // Discovery of every service takes a few heartbeat periods: listen at least that long.
  if (!o.wait_given) o.wait_s = std::max(o.wait_s, 4.0 * d->heartbeat_period_s);
  return {};
}

/// This tool's DDS participant, in the run's partition.
tamp::Result<std::shared_ptr<tamp::dds::Participant>> createParticipant(const StatusCli& o) {
  tamp::dds::ParticipantOptions po;
  po.domain_id = o.domain;
  po.name = "tamp/status";
  if (!o.profile.empty()) po.profile = o.profile;
  po.security_dir = o.security;
  return tamp::dds::Participant::create(po, o.run_id);
}

/// Listens for heartbeats for --wait seconds, or until every expected service is heard (at most
/// as long).
void listenForHeartbeats(const tamp::dds::HeartbeatMonitor& monitor, const StatusCli& o) {
  const tamp::Termination until = tamp::Termination::after(o.wait_s);
  if (o.expect.empty()) {
    while (!until()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  } else {
    for (const auto& name : o.expect) (void)monitor.waitFor(name, 1, until);
  }
}

/// The expected services not heard alive: those that fail the check and the optional ones.
struct Missing {
  std::vector<std::string> required, optional;
};

/// The services of `expect` not heard alive among `services`.
Missing missingServices(const std::vector<tamp::dds::ServiceInfo>& services,
                        const std::vector<std::string>& expect,
                        const std::vector<std::string>& optional_names) {
  Missing missing;
  for (const auto& name : expect) {
    bool found = false;
    for (const auto& s : services) found = found || (s.alive && s.name == name);
    if (found) continue;
    const bool opt =
        std::find(optional_names.begin(), optional_names.end(), name) != optional_names.end();
    (opt ? missing.optional : missing.required).push_back(name);
  }
  return missing;
}

/// --json: the services heard (all of them with --all) and the missing ones, on stdout.
void printJson(const tamp::dds::Participant& participant,
               const std::vector<tamp::dds::ServiceInfo>& services, const Missing& missing,
               bool all) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& s : services) {
    if (!all && !s.alive) continue;
    out.push_back({{"service_id", s.service_id}, {"name", s.name}, {"host", s.host}, {"pid", s.pid},
                   {"state", tamp::dds::toString(s.state)}, {"alive", s.alive}, {"uptime_s", s.uptime_s},
                   {"last_heartbeat_s", s.age_s}, {"served", s.served}, {"failed", s.failed},
                   {"version", s.version}, {"detail", s.detail}});
  }
  std::cout << nlohmann::json{{"domain", participant.domainId()},
                              {"run_id", participant.runId()},
                              {"services", out},
                              {"missing", missing.required},
                              {"missing_optional", missing.optional}}
                   .dump(2)
            << "\n";
}

/// The table of the services heard (all of them with --all), one line each; how many were shown.
int printServiceTable(const std::vector<tamp::dds::ServiceInfo>& services, bool all) {
  std::printf("%-20s %-16s %7s %-9s %8s %8s %7s %9s  %s\n", "SERVICE", "HOST", "PID", "STATE",
              "UPTIME", "SERVED", "FAILED", "HEARD", "DETAIL");
  int shown = 0;
  for (const auto& s : services) {
    if (!all && !s.alive) continue;
    ++shown;
    std::printf("%-20s %-16s %7u %-9s %8s %8llu %7llu %9s  %s\n", s.name.c_str(), s.host.c_str(),
                s.pid, s.alive ? tamp::dds::toString(s.state) : "gone",
                duration(s.uptime_s).c_str(), static_cast<unsigned long long>(s.served),
                static_cast<unsigned long long>(s.failed), (duration(s.age_s) + " ago").c_str(),
                s.detail.c_str());
  }
  return shown;
}

/// The domain and run, the table, and the missing services, as text on stdout.
void printText(const tamp::dds::Participant& participant,
               const std::vector<tamp::dds::ServiceInfo>& services, const Missing& missing,
               const StatusCli& o) {
  std::printf("DDS domain %d, run %s\n", participant.domainId(),
              participant.runId().empty() ? "(none)" : participant.runId().c_str());
  if (printServiceTable(services, o.all) == 0)
    std::printf("(no live service heard within %.1f s)\n", o.wait_s);
  for (const auto& m : missing.required) std::printf("MISSING: %s\n", m.c_str());
  for (const auto& m : missing.optional) std::printf("MISSING (optional): %s\n", m.c_str());
  if (!missing.required.empty()) {
    std::printf("%zu of %zu expected services missing\n", missing.required.size(), o.expect.size());
  }
}

/// Listens on `participant`, prints what it heard; kExitServiceError when an expected service
/// that is not optional is missing, else kExitOk.
int reportStatus(const std::shared_ptr<tamp::dds::Participant>& participant, const StatusCli& o,
                 const std::vector<std::string>& optional_names) {
  tamp::dds::HeartbeatMonitor monitor(participant);
  listenForHeartbeats(monitor, o);
  const auto services = monitor.services();
  const Missing missing = missingServices(services, o.expect, optional_names);
  if (o.json)
    printJson(*participant, services, missing, o.all);
  else
    printText(*participant, services, missing, o);
  return missing.required.empty() ? tamp::cli::kExitOk : tamp::cli::kExitServiceError;
}

}  // namespace

int main(int argc, char** argv) {
  StatusCli o;
  CLI::App app{kAbout, "tamp status"};
  defineOptions(app, o);
  CLI11_PARSE(app, argc, argv);
  o.wait_given = app.count("--wait") != 0;
  std::vector<std::string> optional_names;
  if (tamp::Status s = expectDeployment(o, optional_names); !s.ok()) {
    return tamp::cli::fail("tamp status", s.error(), tamp::cli::kExitInputError);
  }
  const auto participant = createParticipant(o);
  if (!participant)
    return tamp::cli::fail("tamp status", participant.error(), tamp::cli::kExitServiceError);
  return reportStatus(*participant, o, optional_names);
}
