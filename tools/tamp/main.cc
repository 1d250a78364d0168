// The `tamp` tool: one binary, one subcommand per task. Only this file includes CLI11.
#include <iostream>

#include <CLI/CLI.hpp>

#include "commands.h"
#include "tamp/core/log.h"

int main(int argc, char** argv) {
  CLI::App app{"tamp: conditional task and motion planning through an effort-based approach"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "tamp 0.1.0");
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "critical", "off"}));

  int exit_code = tamp::cli::kExitOk;
  // Subcommands register here (one block each); their callbacks set exit_code.

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : tamp::cli::kExitInputError;
  }
  (void)log_level;
  return exit_code;
}
