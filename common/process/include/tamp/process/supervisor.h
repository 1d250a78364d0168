#pragma once
/// @file
/// Child processes for deployments and tests: start service executables, restart the ones that
/// crash (exponential back-off and a limit), stop them all (SIGTERM, then SIGKILL after a grace
/// period). No DDS here: liveness over DDS (heartbeats) is the caller's job, which reports a
/// frozen process with declareDead(); this class watches process exits.
///
/// Two lifetimes of a child:
/// - attached (default): it dies with the process that started it (`PR_SET_PDEATHSIG`), so a
///   crashed test or `tamp run` leaves nothing behind;
/// - detached (`ProcessSpec::detach`): it leads its own session and outlives a crashed supervisor;
///   a later supervisor adopts it by pid (adopt()), or it stops by itself when nobody renews its
///   lease (see ServiceArgs::supervisor_lease in common/dds).
///
/// Every start, exit, restart, kill and adoption is reported to the event handler (onEvent), so a
/// deployment can log restarts into its run folder.

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <functional>
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
  int max_restarts{5};                    ///< consecutive restarts (see stable_after_s) before giving up
  double restart_backoff_s{0.5};          ///< first back-off; doubled at each consecutive restart
  double restart_backoff_max_s{8.0};      ///< back-off cap, seconds
  /// A process that ran this long before dying is restarted from the first back-off again, and
  /// its consecutive-restart count starts over (the total is kept in ProcessStatus::restarts).
  double stable_after_s{30.0};
  bool detach{false};                     ///< own session, survives the supervisor (see file doc)
};

enum class ProcessPhase { kNotStarted, kRunning, kBackoff, kExited, kFailed };
const char* toString(ProcessPhase phase);

struct ProcessStatus {
  std::string name;
  pid_t pid{-1};
  ProcessPhase phase{ProcessPhase::kNotStarted};
  int restarts{0};               ///< total restarts
  int consecutive_restarts{0};   ///< restarts since it last ran stable_after_s
  int last_exit_code{0};         ///< exit code, or 128+signal; -1 unknown (adopted process)
  std::string last_exit;         ///< "exit 3", "signal 9 (Killed)", "no heartbeat for 2.0 s"
  bool adopted{false};           ///< started by an earlier supervisor, not our child
  std::chrono::steady_clock::time_point started{};  ///< when the current pid was started/adopted
};

enum class ProcessEventKind {
  kStarted,           ///< spawned (first start)
  kStartFailed,       ///< spawn() failed; detail has the error
  kAdopted,           ///< an earlier supervisor's process taken over
  kExited,            ///< ended; detail says how
  kKilled,            ///< declared dead by the caller (detail: why) and killed
  kRestartScheduled,  ///< will restart after backoff_s
  kRestarted,         ///< spawned again
  kGaveUp,            ///< restart limit reached
};
const char* toString(ProcessEventKind kind);

struct ProcessEvent {
  ProcessEventKind kind{ProcessEventKind::kStarted};
  std::string name;
  pid_t pid{-1};         ///< the process concerned (new pid for kStarted/kRestarted)
  int restarts{0};       ///< total restarts so far
  double backoff_s{0};   ///< kRestartScheduled
  std::string detail;
};

/// Starts one process now. Errors name the executable (kNotFound, kIo).
Result<pid_t> spawn(const ProcessSpec& spec);

/// The kernel's start time of `pid` (clock ticks since boot, /proc/<pid>/stat field 22); with the
/// pid it identifies a process across pid reuse. nullopt when there is no such process.
std::optional<unsigned long long> processStartTime(pid_t pid);
/// True while `pid` exists and is not a zombie.
bool processRunning(pid_t pid);

class Supervisor {
 public:
  using EventHandler = std::function<void(const ProcessEvent&)>;

  Supervisor() = default;
  Supervisor(const Supervisor&) = delete;
  Supervisor& operator=(const Supervisor&) = delete;
  /// Stops everything still running, detached processes included (call release() first to leave
  /// them running).
  ~Supervisor();

  /// Called (on the calling thread of add/startAll/poll/declareDead/stopAll) for every event.
  void onEvent(EventHandler handler) { handler_ = std::move(handler); }

  /// @throws std::invalid_argument for a duplicate name.
  void add(ProcessSpec spec);
  /// Takes over `pid`, a process started earlier (by a supervisor that died) from `spec`: it is
  /// watched like a child (by polling, since it is not ours to wait for), restarted from `spec`
  /// when it ends, and stopped by stopAll(). @throws std::invalid_argument for a duplicate name.
  void adopt(ProcessSpec spec, pid_t pid);
  /// Starts every process not yet started; the first failure is returned (others still start).
  Status startAll();
  /// Starts process `name` if it is not started yet (Ok when it already runs).
  /// @throws std::invalid_argument for an unknown name.
  Status start(const std::string& name);
  /// Reaps exited children and restarts the ones due. Call periodically (e.g. every 100 ms).
  void poll();
  /// The caller found `name` dead although it runs (e.g. no heartbeat): SIGKILL to its process
  /// group, then restarted like a crash, with `reason` as its last exit. False if not running.
  bool declareDead(const std::string& name, const std::string& reason);
  /// Stops the children one after the other, in the reverse of the order they were added (a
  /// deployment lists a service after those it uses, so a service that hands over what it holds
  /// when it stops, like the execution monitor's unacknowledged records to the effort estimator,
  /// does so while they still run): SIGTERM, up to `grace_s` for it to exit, then SIGKILL. Once
  /// twice `grace_s` has gone by (services that did not stop), the rest get SIGTERM together and
  /// one `grace_s` more: a stop lasts at most about 3 `grace_s` however many services hang. Reaps
  /// everything; a killed process's last exit says so (`signal 9 ... (did not stop within ...)`).
  void stopAll(double grace_s = 3.0);
  /// Forgets every process without stopping it (a supervisor that hands its services over).
  void release();
  /// Sends `signal` to one process group (tests: kill -9 a service). Returns false if not running.
  bool signal(const std::string& name, int signal);
  std::vector<ProcessStatus> status() const;
  std::optional<ProcessStatus> status(const std::string& name) const;
  const ProcessSpec* spec(const std::string& name) const;

 private:
  struct Child {
    ProcessSpec spec;
    ProcessStatus st;
    std::chrono::steady_clock::time_point restart_at;
    bool stopping{false};
  };
  Status startChild(Child& c);
  void onExit(Child& c, const std::string& how, int exit_code, bool clean);
  /// True (and the exit handled) when the child ended.
  /// `cause`: what ended it when we know better than its exit status (declareDead).
  bool reap(Child& c, bool block, const std::string& cause = {}, const std::string& note = {});
  void emit(ProcessEventKind kind, const Child& c, std::string detail = {}, double backoff_s = 0) const;
  void checkUnique(const std::string& name) const;
  std::vector<Child> children_;
  EventHandler handler_;
};

std::string describeExit(int wstatus);

}  // namespace tamp::process
