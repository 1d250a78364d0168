// The only translation unit of tamp_dds that includes CLI11 (it is slow to compile).
#include <cstdlib>
#include <iostream>

#include <CLI/CLI.hpp>

#include "tamp/dds/service_node.h"

namespace tamp::dds {

Result<ServiceArgs> parseServiceArgs(int argc, char** argv, const std::string& default_name,
                                     const std::string& description) {
  ServiceArgs a;
  a.name = default_name;
  if (const char* env = std::getenv("TAMP_LOG_LEVEL"); env != nullptr && *env != '\0') a.log_level = env;
  CLI::App app{description, default_name};
  app.add_option("--name", a.name, "service name (heartbeat and echo topic)");
  app.add_option("--domain", a.domain_id, "DDS domain id (default: $TAMP_DOMAIN_ID or 0)")->check(CLI::Range(0, 232));
  app.add_option("--profile", a.profile, "DDS participant profile: tamp_default, tamp_udp, tamp_shm");
  app.add_option("--config", a.config_file, "service parameters (YAML)")->check(CLI::ExistingFile);
  app.add_option("--scenario", a.scenario_file,
                 "scenario YAML of the run (services that need the world, robot or priors read it)")
      ->check(CLI::ExistingFile);
  app.add_option("--log-level", a.log_level, "trace, debug, info, warn, error, off (default: $TAMP_LOG_LEVEL or info)");
  app.add_option("--heartbeat-period", a.heartbeat_period_s, "seconds between heartbeats")
      ->check(CLI::Range(0.01, 60.0));
  app.add_option("--run-id", a.run_id, "run this service belongs to (DDS partition; default: $TAMP_RUN_ID or none)");
  app.add_option("--supervisor-lease", a.supervisor_lease,
                 "file the supervisor touches; stop when it is older than --orphan-timeout");
  app.add_option("--orphan-timeout", a.orphan_timeout_s, "seconds without a supervisor before stopping (0: never)")
      ->check(CLI::Range(0.0, 1e6));
  app.add_option("--stall-timeout", a.stall_timeout_s,
                 "seconds the main loop may go without turning before heartbeats stop (0: never)")
      ->check(CLI::Range(0.0, 1e6));
  app.add_option("--security", a.security_dir,
                 "DDS Security directory made by deploy/security/make_certs.sh (default: $TAMP_DDS_SECURITY; "
                 "'none': off)");
  app.add_option("--security-identity", a.security_identity,
                 "identity (certificate and permissions) in the security directory (default: --name)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::cout << app.help();
    return Error(ErrorCode::kCancelled, "help");
  } catch (const CLI::ParseError& e) {
    return Error(ErrorCode::kInvalidArgument, e.what());
  }
  if (a.name.empty()) return Error(ErrorCode::kInvalidArgument, "--name must not be empty");
  auto run_id = resolveRunId(a.run_id);
  if (!run_id) return run_id.error();
  a.run_id = *run_id;
  return a;
}

}  // namespace tamp::dds
