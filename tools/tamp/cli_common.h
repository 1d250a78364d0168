#pragma once
/// @file
/// Conventions shared by the `tamp-*` subcommand executables (tools/tamp/*_main.cc).
///
/// Exit codes follow Fast Downward's ranges: 0 success, 10-19 no solution (proven), 20-29 out of
/// time/memory, 30-39 input or usage errors, 40-49 a service/peer problem.

namespace tamp::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitNoSolution = 10;
inline constexpr int kExitTimeout = 20;
inline constexpr int kExitInputError = 30;
inline constexpr int kExitServiceError = 40;

}  // namespace tamp::cli
