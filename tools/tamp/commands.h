#pragma once
/// @file
/// The `tamp` command-line tool's subcommands. CLI11 is included only by main.cc (it costs ~9 s
/// per translation unit); each subcommand is an options struct filled by main.cc and a `run*`
/// function in its own cmd_<name>.cc that returns the process exit code.
///
/// Exit codes follow Fast Downward's ranges: 0 success, 10-19 no solution (proven), 20-29 out of
/// time/memory, 30-39 input or usage errors, 40-49 a service/peer problem.

#include <string>
#include <vector>

namespace tamp::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitNoSolution = 10;
inline constexpr int kExitTimeout = 20;
inline constexpr int kExitInputError = 30;
inline constexpr int kExitServiceError = 40;

/// Options shared by every subcommand that talks DDS.
struct DdsOptions {
  int domain_id{-1};  ///< -1: $TAMP_DOMAIN_ID or 0
  std::string profile{"default"};  ///< participant profile name in config/dds/*.xml
};

}  // namespace tamp::cli
