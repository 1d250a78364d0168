#include "tamp/process/supervisor.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include "tamp/core/format.h"
#include "tamp/core/log.h"

extern char** environ;

namespace tamp::process {

std::string describeExit(int wstatus) {
  if (WIFEXITED(wstatus)) return "exit " + std::to_string(WEXITSTATUS(wstatus));
  if (WIFSIGNALED(wstatus)) {
    const int s = WTERMSIG(wstatus);
    return "signal " + std::to_string(s) + " (" + strsignal(s) + ")";
  }
  return "status " + std::to_string(wstatus);
}

const char* toString(ProcessPhase phase) {
  switch (phase) {
    case ProcessPhase::kNotStarted: return "not started";
    case ProcessPhase::kRunning: return "running";
    case ProcessPhase::kBackoff: return "backoff";
    case ProcessPhase::kExited: return "exited";
    case ProcessPhase::kFailed: return "failed";
  }
  return "?";
}

const char* toString(ProcessEventKind kind) {
  switch (kind) {
    case ProcessEventKind::kStarted: return "started";
    case ProcessEventKind::kStartFailed: return "start_failed";
    case ProcessEventKind::kAdopted: return "adopted";
    case ProcessEventKind::kExited: return "exited";
    case ProcessEventKind::kKilled: return "killed";
    case ProcessEventKind::kRestartScheduled: return "restart_scheduled";
    case ProcessEventKind::kRestarted: return "restarted";
    case ProcessEventKind::kGaveUp: return "gave_up";
  }
  return "?";
}

namespace {
/// /proc/<pid>/stat: "pid (comm) state ppid ... starttime(22) ..."; comm may hold spaces/parens.
bool readStat(pid_t pid, char& state, unsigned long long& start_time) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto close = text.rfind(')');
  if (close == std::string::npos) return false;
  std::istringstream rest(text.substr(close + 1));
  std::string field;
  rest >> state;
  for (int i = 4; i <= 21 && rest >> field; ++i) {
  }
  return static_cast<bool>(rest >> start_time);
}
}  // namespace

std::optional<unsigned long long> processStartTime(pid_t pid) {
  char state = 0;
  unsigned long long t = 0;
  if (pid <= 0 || !readStat(pid, state, t)) return std::nullopt;
  return t;
}

bool processRunning(pid_t pid) {
  char state = 0;
  unsigned long long t = 0;
  if (pid <= 0 || !readStat(pid, state, t)) return false;
  return state != 'Z' && state != 'X';
}

Result<pid_t> spawn(const ProcessSpec& spec) {
  if (access(spec.executable.c_str(), X_OK) != 0) {
    return Error(ErrorCode::kNotFound, "not an executable file", SourceLocation{spec.executable.string()});
  }
  // Everything the child needs is prepared before fork(): after it, only async-signal-safe calls.
  std::vector<std::string> argv_s{spec.executable.string()};
  argv_s.insert(argv_s.end(), spec.args.begin(), spec.args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);

  std::map<std::string, std::string> env_map;
  for (char** e = environ; *e != nullptr; ++e) {
    const char* eq = std::strchr(*e, '=');
    if (eq != nullptr) env_map[std::string(*e, static_cast<size_t>(eq - *e))] = eq + 1;
  }
  for (const auto& [k, v] : spec.env) env_map[k] = v;
  std::vector<std::string> env_s;
  for (const auto& [k, v] : env_map) env_s.push_back(k + "=" + v);
  std::vector<char*> envp;
  for (auto& e : env_s) envp.push_back(e.data());
  envp.push_back(nullptr);

  int log_fd = -1;
  if (!spec.log_file.empty()) {
    log_fd = open(spec.log_file.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (log_fd < 0) {
      return Error(ErrorCode::kIo, std::string("cannot open log file: ") + std::strerror(errno),
                   SourceLocation{spec.log_file.string()});
    }
  }
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) {
    const int e = errno;
    if (log_fd >= 0) close(log_fd);
    return Error(ErrorCode::kIo, std::string("fork: ") + std::strerror(e));
  }
  const bool detach = spec.detach;
  if (pid == 0) {
    // Child. Its own process group (signals reach its helpers; a terminal's Ctrl-C goes to the
    // supervisor, which stops children in order), default signal handling, and -- attached -- it
    // dies with the process that started it, so a crashed test or `tamp run` leaves no service
    // behind. Detached, it leads its own session and outlives the supervisor.
    if (detach) {
      setsid();
    } else {
      setpgid(0, 0);
    }
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    for (int sig = 1; sig < NSIG; ++sig) sigaction(sig, &dfl, nullptr);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    if (!detach) {
      prctl(PR_SET_PDEATHSIG, SIGTERM);
      if (getppid() != parent) _exit(127);  // the parent died before prctl took effect
    }
    if (log_fd >= 0) {
      dup2(log_fd, STDOUT_FILENO);
      dup2(log_fd, STDERR_FILENO);
    }
    // Only stdin/stdout/stderr survive: an inherited lock file or socket would otherwise stay
    // open as long as the service runs.
    syscall(SYS_close_range, 3U, ~0U, 0U);
    execve(argv[0], argv.data(), envp.data());
    const int e = errno;
    (void)!write(STDERR_FILENO, "tamp: exec failed\n", 18);
    _exit(e == ENOENT ? 127 : 126);  // seen by the supervisor as "exit 127/126"
  }
  // Also from the parent, so that the group exists as soon as spawn() returns (no race with a
  // signal sent right away); EACCES after the child's exec (or its setsid) is harmless.
  if (!detach) {
    setpgid(pid, pid);
  } else {
    // A session leader cannot be made a group leader by us (its setsid would fail): wait until
    // the child's own setsid() made the group, so a signal to -pid right away reaches it.
    for (int i = 0; i < 2000; ++i) {
      const pid_t group = getpgid(pid);
      if (group == pid || group < 0) break;
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  }
  if (log_fd >= 0) close(log_fd);
  return pid;
}

Supervisor::~Supervisor() { stopAll(); }

namespace {
std::chrono::steady_clock::duration seconds(double s) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(s));
}
}  // namespace

void Supervisor::emit(ProcessEventKind kind, const Child& c, std::string detail, double backoff_s) const {
  if (!handler_) return;
  ProcessEvent e;
  e.kind = kind;
  e.name = c.spec.name;
  e.pid = c.st.pid;
  e.restarts = c.st.restarts;
  e.backoff_s = backoff_s;
  e.detail = std::move(detail);
  handler_(e);
}

void Supervisor::checkUnique(const std::string& name) const {
  for (const auto& c : children_) require(c.spec.name != name, "duplicate process name '" + name + "'");
}

void Supervisor::add(ProcessSpec spec) {
  checkUnique(spec.name);
  Child c;
  c.st.name = spec.name;
  c.spec = std::move(spec);
  children_.push_back(std::move(c));
}

void Supervisor::adopt(ProcessSpec spec, pid_t pid) {
  checkUnique(spec.name);
  require(pid > 0, "adopt: bad pid " + std::to_string(pid) + " for '" + spec.name + "'");
  Child c;
  c.st.name = spec.name;
  c.st.pid = pid;
  c.st.phase = ProcessPhase::kRunning;
  c.st.adopted = true;
  c.st.started = std::chrono::steady_clock::now();
  c.spec = std::move(spec);
  children_.push_back(std::move(c));
  emit(ProcessEventKind::kAdopted, children_.back());
}

Status Supervisor::startAll() {
  Status first;
  for (auto& c : children_) {
    Status s = startChild(c);
    if (!s && first.ok()) first = s;
  }
  return first;
}

Status Supervisor::start(const std::string& name) {
  for (auto& c : children_) {
    if (c.spec.name == name) return startChild(c);
  }
  throw std::invalid_argument("Supervisor::start: no process '" + name + "'");
}

Status Supervisor::startChild(Child& c) {
  if (c.st.phase != ProcessPhase::kNotStarted) return Status::Ok();
  auto pid = spawn(c.spec);
  if (!pid) {
    c.st.phase = ProcessPhase::kFailed;
    c.st.last_exit = pid.error().toString();
    emit(ProcessEventKind::kStartFailed, c, c.st.last_exit);
    return pid.error();
  }
  c.st.pid = *pid;
  c.st.phase = ProcessPhase::kRunning;
  c.st.started = std::chrono::steady_clock::now();
  emit(ProcessEventKind::kStarted, c);
  return Status::Ok();
}

void Supervisor::onExit(Child& c, const std::string& how, int exit_code, bool clean) {
  c.st.last_exit = how;
  c.st.last_exit_code = exit_code;
  emit(ProcessEventKind::kExited, c, how);
  c.st.pid = -1;
  c.st.adopted = false;
  if (c.stopping || clean || !c.spec.restart) {
    c.st.phase = ProcessPhase::kExited;
    return;
  }
  const double ran_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - c.st.started).count();
  if (ran_s >= c.spec.stable_after_s) c.st.consecutive_restarts = 0;
  if (c.st.consecutive_restarts >= c.spec.max_restarts) {
    c.st.phase = ProcessPhase::kFailed;
    log::get("supervisor")->error("{} died ({}) and reached its restart limit ({})", c.spec.name, how,
                                  c.spec.max_restarts);
    emit(ProcessEventKind::kGaveUp, c, how + "; " + std::to_string(c.spec.max_restarts) + " consecutive restarts");
    return;
  }
  const double backoff = std::min(c.spec.restart_backoff_max_s,
                                  c.spec.restart_backoff_s * std::pow(2.0, std::min(c.st.consecutive_restarts, 30)));
  c.st.phase = ProcessPhase::kBackoff;
  c.restart_at = std::chrono::steady_clock::now() + seconds(backoff);
  log::get("supervisor")->warn("{} died ({}); restarting in {:.2f} s", c.spec.name, how, backoff);
  emit(ProcessEventKind::kRestartScheduled, c, how, backoff);
}

bool Supervisor::reap(Child& c, bool block, const std::string& cause, const std::string& note) {
  if (c.st.phase != ProcessPhase::kRunning || c.st.pid <= 0) return false;
  if (c.st.adopted) {
    // Not our child: its exit status went to whoever reaps orphans. Poll for its disappearance.
    if (block) {
      const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (processRunning(c.st.pid) && std::chrono::steady_clock::now() < end) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    }
    if (processRunning(c.st.pid)) return false;
    onExit(c, (!cause.empty() ? cause : c.stopping ? "stopped (adopted: exit status unknown)" : "ended (adopted: exit status unknown)") + note,
           -1, c.stopping);
    return true;
  }
  int wstatus = 0;
  if (waitpid(c.st.pid, &wstatus, block ? 0 : WNOHANG) != c.st.pid) return false;
  const int code = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
  onExit(c, (cause.empty() ? describeExit(wstatus) : cause) + note, code, WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0);
  return true;
}

void Supervisor::poll() {
  for (auto& c : children_) {
    (void)reap(c, false);
    if (c.st.phase == ProcessPhase::kBackoff && std::chrono::steady_clock::now() >= c.restart_at) {
      auto pid = spawn(c.spec);
      ++c.st.restarts;
      ++c.st.consecutive_restarts;
      if (!pid) {
        c.st.phase = ProcessPhase::kFailed;
        c.st.last_exit = pid.error().toString();
        emit(ProcessEventKind::kStartFailed, c, c.st.last_exit);
      } else {
        c.st.pid = *pid;
        c.st.phase = ProcessPhase::kRunning;
        c.st.started = std::chrono::steady_clock::now();
        log::get("supervisor")->info("{} restarted (pid {}, restart {})", c.spec.name, *pid, c.st.restarts);
        emit(ProcessEventKind::kRestarted, c, "after " + c.st.last_exit);
      }
    }
  }
}

bool Supervisor::declareDead(const std::string& name, const std::string& reason) {
  for (auto& c : children_) {
    if (c.spec.name != name || c.st.phase != ProcessPhase::kRunning || c.st.pid <= 0) continue;
    log::get("supervisor")->warn("{} (pid {}) declared dead: {}; SIGKILL", name, c.st.pid, reason);
    emit(ProcessEventKind::kKilled, c, reason);
    kill(-c.st.pid, SIGKILL);  // also ends a stopped (SIGSTOP) process
    // The exit is "signal 9" because we sent it; the cause is what the caller saw.
    return reap(c, true, "killed: " + reason);
  }
  return false;
}

void Supervisor::stopAll(double grace_s) {
  for (auto& c : children_) {
    c.stopping = true;
    if (c.st.phase == ProcessPhase::kBackoff) c.st.phase = ProcessPhase::kExited;
  }
  using Clock = std::chrono::steady_clock;
  const auto running = [](const Child& c) { return c.st.phase == ProcessPhase::kRunning && c.st.pid > 0; };
  const auto terminate = [](const Child& c) {
    kill(-c.st.pid, SIGTERM);
    kill(-c.st.pid, SIGCONT);  // a stopped process handles SIGTERM only once continued
  };
  // Waits for `c` until `end`, then kills it (its last exit noted "(did not stop within ...)").
  const auto awaitOrKill = [this, grace_s](Child& c, Clock::time_point end, const std::string& why) {
    while (!reap(c, false)) {
      if (Clock::now() >= end) {
        log::get("supervisor")->warn("{} did not stop within {:.1f} s{}: SIGKILL", c.spec.name, grace_s, why);
        kill(-c.st.pid, SIGKILL);
        (void)reap(c, true, {}, " (did not stop within " + formatNumber(grace_s) + " s" + why + ")");
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  };
  // One after the other, each with its grace, until twice the grace has gone by: services that
  // do not stop must not make the stop last as many graces as there are services.
  const auto in_turn_end = Clock::now() + 2 * seconds(grace_s);
  auto it = children_.rbegin();
  for (; it != children_.rend() && Clock::now() < in_turn_end; ++it) {
    if (!running(*it)) continue;
    terminate(*it);
    awaitOrKill(*it, Clock::now() + seconds(grace_s), "");
  }
  // The rest together, with one grace.
  std::vector<Child*> rest;
  for (; it != children_.rend(); ++it)
    if (running(*it)) rest.push_back(&*it);
  if (rest.empty()) return;
  log::get("supervisor")->warn("the stop took {:.1f} s: the last {} service(s) are stopped together", 2 * grace_s,
                               rest.size());
  for (Child* c : rest) terminate(*c);
  const auto end = Clock::now() + seconds(grace_s);
  for (Child* c : rest) awaitOrKill(*c, end, " of the stop's last phase");
}

void Supervisor::release() { children_.clear(); }

bool Supervisor::signal(const std::string& name, int sig) {
  for (auto& c : children_) {
    if (c.spec.name == name && c.st.phase == ProcessPhase::kRunning && c.st.pid > 0) {
      return kill(-c.st.pid, sig) == 0;
    }
  }
  return false;
}

std::vector<ProcessStatus> Supervisor::status() const {
  std::vector<ProcessStatus> out;
  for (const auto& c : children_) out.push_back(c.st);
  return out;
}

std::optional<ProcessStatus> Supervisor::status(const std::string& name) const {
  for (const auto& c : children_) {
    if (c.spec.name == name) return c.st;
  }
  return std::nullopt;
}

const ProcessSpec* Supervisor::spec(const std::string& name) const {
  for (const auto& c : children_) {
    if (c.spec.name == name) return &c.spec;
  }
  return nullptr;
}

}  // namespace tamp::process
