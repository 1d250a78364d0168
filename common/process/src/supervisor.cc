#include "tamp/process/supervisor.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <thread>

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
  if (pid == 0) {
    // Child. Its own process group (signals reach its helpers; a terminal's Ctrl-C goes to the
    // supervisor, which stops children in order), default signal handling, and it dies with the
    // process that started it, so a crashed test or supervisor leaves no service behind.
    setpgid(0, 0);
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    for (int sig = 1; sig < NSIG; ++sig) sigaction(sig, &dfl, nullptr);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);  // the parent died before prctl took effect
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
  // signal sent right away); EACCES after the child's exec is harmless.
  setpgid(pid, pid);
  if (log_fd >= 0) close(log_fd);
  return pid;
}

Supervisor::~Supervisor() { stopAll(); }

void Supervisor::add(ProcessSpec spec) {
  for (const auto& c : children_) {
    require(c.spec.name != spec.name, "duplicate process name '" + spec.name + "'");
  }
  Child c;
  c.st.name = spec.name;
  c.spec = std::move(spec);
  children_.push_back(std::move(c));
}

Status Supervisor::startAll() {
  Status first;
  for (auto& c : children_) {
    if (c.st.phase != ProcessPhase::kNotStarted) continue;
    auto pid = spawn(c.spec);
    if (!pid) {
      c.st.phase = ProcessPhase::kFailed;
      c.st.last_exit = pid.error().toString();
      if (first.ok()) first = pid.error();
      continue;
    }
    c.st.pid = *pid;
    c.st.phase = ProcessPhase::kRunning;
  }
  return first;
}

void Supervisor::onExit(Child& c, int wstatus) {
  c.st.last_exit = describeExit(wstatus);
  c.st.last_exit_code = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
  c.st.pid = -1;
  const bool clean = WIFEXITED(wstatus) && WEXITSTATUS(wstatus) == 0;
  if (c.stopping || clean || !c.spec.restart) {
    c.st.phase = ProcessPhase::kExited;
    return;
  }
  if (c.st.restarts >= c.spec.max_restarts) {
    c.st.phase = ProcessPhase::kFailed;
    log::get("supervisor")->error("{} died ({}) and reached its restart limit ({})", c.spec.name, c.st.last_exit,
                                  c.spec.max_restarts);
    return;
  }
  const double backoff = std::min(8.0, c.spec.restart_backoff_s * (1 << std::min(c.st.restarts, 4)));
  c.st.phase = ProcessPhase::kBackoff;
  c.restart_at = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                        std::chrono::duration<double>(backoff));
  log::get("supervisor")->warn("{} died ({}); restarting in {:.1f} s", c.spec.name, c.st.last_exit, backoff);
}

void Supervisor::poll() {
  for (auto& c : children_) {
    if (c.st.phase == ProcessPhase::kRunning && c.st.pid > 0) {
      int wstatus = 0;
      if (waitpid(c.st.pid, &wstatus, WNOHANG) == c.st.pid) onExit(c, wstatus);
    }
    if (c.st.phase == ProcessPhase::kBackoff && std::chrono::steady_clock::now() >= c.restart_at) {
      auto pid = spawn(c.spec);
      ++c.st.restarts;
      if (!pid) {
        c.st.phase = ProcessPhase::kFailed;
        c.st.last_exit = pid.error().toString();
      } else {
        c.st.pid = *pid;
        c.st.phase = ProcessPhase::kRunning;
        log::get("supervisor")->info("{} restarted (pid {}, restart {})", c.spec.name, *pid, c.st.restarts);
      }
    }
  }
}

void Supervisor::stopAll(double grace_s) {
  for (auto& c : children_) {
    c.stopping = true;
    if (c.st.phase == ProcessPhase::kBackoff) c.st.phase = ProcessPhase::kExited;
    if (c.st.phase == ProcessPhase::kRunning && c.st.pid > 0) kill(-c.st.pid, SIGTERM);
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                          std::chrono::duration<double>(grace_s));
  while (true) {
    bool any = false;
    for (auto& c : children_) {
      if (c.st.phase != ProcessPhase::kRunning || c.st.pid <= 0) continue;
      int wstatus = 0;
      if (waitpid(c.st.pid, &wstatus, WNOHANG) == c.st.pid) {
        onExit(c, wstatus);
      } else {
        any = true;
      }
    }
    if (!any) break;
    if (std::chrono::steady_clock::now() >= end) {
      for (auto& c : children_) {
        if (c.st.phase == ProcessPhase::kRunning && c.st.pid > 0) {
          log::get("supervisor")->warn("{} did not stop within {:.1f} s: SIGKILL", c.spec.name, grace_s);
          kill(-c.st.pid, SIGKILL);
          int wstatus = 0;
          waitpid(c.st.pid, &wstatus, 0);
          onExit(c, wstatus);
        }
      }
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

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

}  // namespace tamp::process
