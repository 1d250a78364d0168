#pragma once
/// @file
/// Conventions shared by the `tamp-*` subcommand executables (tools/tamp/*_main.cc).
///
/// Exit codes follow Fast Downward's ranges: 0 success, 10-19 no solution (proven), 20-29 out of
/// time/memory, 30-39 input or usage errors, 40-49 a service/peer problem, 50 an output that could not
/// be written.

#include <csignal>
#include <initializer_list>
#include <iostream>

#include "tamp/core/error.h"

namespace tamp::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitNoSolution = 10;
inline constexpr int kExitTimeout = 20;
inline constexpr int kExitInputError = 30;
inline constexpr int kExitServiceError = 40;
inline constexpr int kExitOutputError = 50;

/// Prints "`tool`: `error`" on stderr and returns `exit_code`, for `return cli::fail(...)`.
inline int fail(const char* tool, const Error& error, int exit_code) {
  std::cerr << tool << ": " << error.toString() << "\n";
  return exit_code;
}

/// Set once one of the signals of `stopOnSignals` arrived: the tool's loops end and it cleans up.
inline volatile std::sig_atomic_t g_stop_requested = 0;
inline bool stopRequested() { return g_stop_requested != 0; }

/// Makes `signals` request a stop (stopRequested()) instead of terminating the tool.
/// `restart`: interrupted system calls resume (std::signal's semantics) instead of failing with EINTR.
inline void stopOnSignals(std::initializer_list<int> signals, bool restart) {
  struct sigaction sa {};
  sa.sa_handler = [](int) { g_stop_requested = 1; };
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = restart ? SA_RESTART : 0;
  for (int sig : signals) sigaction(sig, &sa, nullptr);
}

}  // namespace tamp::cli
