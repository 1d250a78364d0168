#pragma once
/// @file
/// Child processes for deployments and tests: start service executables, restart the ones that
/// crash (with back-off and a limit), stop them all (SIGTERM, then SIGKILL after a grace period).
/// No DDS here: liveness over DDS is the heartbeat monitor's job; this watches process exits.

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tamp/core/error.h"

namespace tamp::process {

struct ProcessSpec {
  std::string name;                       ///< unique within a supervisor
  std::filesystem::path executable;
  std::vector<std::string> args;
  std::map<std::string, std::string> env; ///< added to (or overriding) the parent's environment
  std::filesystem::path log_file;         ///< stdout+stderr go here (appended); empty: inherit
  bool restart{true};                     ///< restart when it exits unexpectedly
  int max_restarts{5};
  double restart_backoff_s{0.5};          ///< doubled at each restart, capped at 8 s
};

enum class ProcessPhase { kNotStarted, kRunning, kBackoff, kExited, kFailed };

struct ProcessStatus {
  std::string name;
  pid_t pid{-1};
  ProcessPhase phase{ProcessPhase::kNotStarted};
  int restarts{0};
  int last_exit_code{0};     ///< exit code, or 128+signal
  std::string last_exit;     ///< "exit 3", "signal 9 (Killed)"
};

/// Starts one process now. Errors name the executable (kNotFound, kIo).
Result<pid_t> spawn(const ProcessSpec& spec);

class Supervisor {
 public:
  Supervisor() = default;
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;
  /// Stops everything still running.
  ~Supervisor();

  /// @throws std::invalid_argument for a duplicate name.
  void add(ProcessSpec spec);
  /// Starts every process not yet started; the first failure is returned (others still start).
  Status startAll();
  /// Reaps exited children and restarts the ones due. Call periodically (e.g. every 100 ms).
  void poll();
  /// SIGTERM to all, waits up to `grace_s`, then SIGKILL; reaps everything.
  void stopAll(double grace_s = 3.0);
  /// Sends `signal` to one process (tests: kill -9 a service). Returns false if not running.
  bool signal(const std::string& name, int signal);
  std::vector<ProcessStatus> status() const;
  std::optional<ProcessStatus> status(const std::string& name) const;

 private:
  struct Child {
    ProcessSpec spec;
    ProcessStatus st;
    std::chrono::steady_clock::time_point restart_at;
    bool stopping{false};
  };
  void onExit(Child& c, int wstatus);
  std::vector<Child> children_;
};

std::string describeExit(int wstatus);

}  // namespace tamp::process
