#include "launcher.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <map>
#include <random>
#include <thread>

#include <nlohmann/json.hpp>

#include "tamp/core/log.h"
#include "tamp/core/termination.h"
#include "tamp/dds/discovery.h"
#include "tamp/dds/heartbeat.h"
#include "tamp/dds/participant.h"

namespace fs = std::filesystem;

namespace tamp::launch {
namespace {

std::string utcNow() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[40];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%S", &tm);
  char out[48];
  std::snprintf(out, sizeof(out), "%s.%03dZ", buf, static_cast<int>(ms));
  return out;
}

std::string thisHost() {
  char buf[256] = {};
  if (gethostname(buf, sizeof(buf) - 1) != 0) return "unknown";
  return buf;
}

/// What identifies how a service was started: a changed deployment means a replaced process.
std::string commandLine(const process::ProcessSpec& s) {
  std::string out = s.executable.string();
  for (const auto& a : s.args) out += " " + a;
  for (const auto& [k, v] : s.env) out += " " + k + "=" + v;
  return out;
}

void writeAtomically(const fs::path& file, const std::string& text) {
  const fs::path tmp = file.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << text;
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
  if (ec) log::get("launch")->warn("cannot write {}: {}", file.string(), ec.message());
}

}  // namespace

std::string makeRunId(const std::string& prefix) {
  char stamp[32];
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  localtime_r(&now, &tm);
  std::strftime(stamp, sizeof(stamp), "%Y%m%d-%H%M%S", &tm);
  std::random_device rd;
  char suffix[8];
  std::snprintf(suffix, sizeof(suffix), "%04x",
                static_cast<unsigned>((rd() ^ static_cast<unsigned>(::getpid())) & 0xffff));
  return prefix + "-" + stamp + "-" + suffix;
}

void printUncleanEnds(const char* tool, const process::Supervisor& sup) {
  for (const auto& st : sup.status()) {
    if (st.last_exit != "exit 0" && st.last_exit.rfind("signal 15", 0) != 0 &&
        st.last_exit.rfind("stopped", 0) != 0) {
      std::printf("%s: %s ended with %s\n", tool, st.name.c_str(), st.last_exit.c_str());
    }
  }
}

Launcher::Launcher(LaunchOptions options) : o_(std::move(options)) {
  require(o_.deployment.host(o_.host) != nullptr, "Launcher: unknown host '" + o_.host + "'");
  sup_.onEvent([this](const process::ProcessEvent& e) { logEvent(e); });
}

Launcher::~Launcher() {
  if (!stopped_) stop(3.0);
  if (lock_fd_ >= 0) close(lock_fd_);
}

std::vector<std::string> Launcher::services() const {
  std::vector<std::string> out;
  for (const auto* s : o_.deployment.servicesOn(o_.host)) out.push_back(s->name);
  return out;
}

process::ProcessSpec Launcher::specOf(const deploy::ServiceSpec& s) const {
  const auto& d = o_.deployment;
  process::ProcessSpec spec;
  spec.name = s.name;
  spec.executable = deploy::resolveExecutable(s, o_.bin_dir);
  spec.args = {"--name",
               s.name,
               "--domain",
               std::to_string(o_.domain),
               "--heartbeat-period",
               std::to_string(d.heartbeat_period_s),
               "--stall-timeout",
               std::to_string(d.stall_timeout_s)};
  if (!o_.run_id.empty()) spec.args.insert(spec.args.end(), {"--run-id", o_.run_id});
  if (!o_.profile.empty()) spec.args.insert(spec.args.end(), {"--profile", o_.profile});
  if (o_.detach && d.orphan_timeout_s > 0) {
    spec.args.insert(spec.args.end(),
                     {"--supervisor-lease", (o_.run_dir / "supervisor.lease").string(),
                      "--orphan-timeout", std::to_string(d.orphan_timeout_s)});
  }
  const auto extra =
      deploy::expandArgs(s, deploy::Placeholders{o_.scenario, o_.config_dir.string(),
                                                 o_.run_dir.string(), o_.run_id, o_.host});
  spec.args.insert(spec.args.end(), extra.begin(), extra.end());
  auto addEnv = [&](const std::vector<std::string>& env) {
    for (const auto& kv : env) {
      const auto eq = kv.find('=');
      spec.env[kv.substr(0, eq)] = kv.substr(eq + 1);
    }
  };
  // Discovery of the deployment (multicast: an inherited server list is cleared); the host's and
  // the service's env may still override it.
  spec.env["TAMP_DDS_DISCOVERY_SERVERS"] = d.discovery.serversEnv();
  // The run folder, where services keep what must survive their restart (the execution
  // monitor's journal of commands sent to the robot).
  spec.env["TAMP_RUN_DIR"] = o_.run_dir.string();
  addEnv(d.host(o_.host)->env);
  addEnv(s.env);
  spec.log_file = logFile(s.name);
  spec.restart = o_.restart && s.restart;
  spec.max_restarts = d.restart.max_restarts;
  spec.restart_backoff_s = d.restart.backoff_s;
  spec.restart_backoff_max_s = d.restart.backoff_max_s;
  spec.stable_after_s = d.restart.stable_after_s;
  spec.detach = o_.detach;
  return spec;
}

Status Launcher::startDiscoveryServers() {
  const auto& dc = o_.deployment.discovery;
  for (std::size_t i : dc.serversOn(o_.host)) {
    auto address = dds::parseDiscoveryServer(dc.servers[i]);
    if (!address) return address.error();
    auto server = dds::DiscoveryServer::start(*address, static_cast<int>(i));
    if (!server) return server.error();
    discovery_servers_.push_back(std::move(*server));
  }
  return Status::Ok();
}

Status Launcher::start() {
  // DDS first: a failure here must not touch the run folder of services we could have adopted.
  dds::ParticipantOptions po;
  po.domain_id = o_.domain;
  if (!o_.profile.empty()) po.profile = o_.profile;
  po.name = "tamp/launch/" + o_.host;
  // This process and what it spawns (tamp-status) discover as the services do.
  setenv("TAMP_DDS_DISCOVERY_SERVERS", o_.deployment.discovery.serversEnv().c_str(), 1);
  if (Status s = startDiscoveryServers(); !s.ok()) return s;
  auto p = dds::Participant::create(po, o_.run_id);
  if (!p) return p.error();
  participant_ = *p;
  monitor_ = std::make_unique<dds::HeartbeatMonitor>(participant_);
  std::error_code ec;
  fs::create_directories(o_.run_dir, ec);
  if (ec)
    return Error(ErrorCode::kIo, "cannot create the run folder: " + ec.message(),
                 SourceLocation{o_.run_dir.string()});
  const fs::path lock = o_.run_dir / "launch.lock";
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0 || flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    std::string holder;
    std::ifstream(lock) >> holder;
    return Error(ErrorCode::kUnavailable,
                 "another tamp launch (pid " + (holder.empty() ? std::string("?") : holder) +
                     ") supervises host '" + o_.host + "' of this run",
                 SourceLocation{lock.string()});
  }
  owns_run_dir_ = true;
  (void)!ftruncate(lock_fd_, 0);
  const std::string me = std::to_string(::getpid()) + "\n";
  (void)!write(lock_fd_, me.data(), me.size());
  touchLease();

  note("launch_started", "pid " + std::to_string(::getpid()) + ", domain " +
                             std::to_string(o_.domain) + ", deployment " + o_.deployment.file);
  // Services recorded by an earlier supervisor of this run and host: adopt the ones still running
  // as they were started, replace the ones started otherwise (rebuilt binary, edited deployment).
  std::map<std::string, nlohmann::json> recorded;
  if (o_.adopt && fs::exists(o_.run_dir / "launch.pids")) {
    std::ifstream in(o_.run_dir / "launch.pids");
    const auto j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_object() && j.contains("services") && j["services"].is_array()) {
      for (const auto& s : j["services"]) {
        if (s.is_object() && s.contains("name")) recorded[s.value("name", "")] = s;
      }
    }
  }
  for (const auto* s : o_.deployment.servicesOn(o_.host)) {
    process::ProcessSpec spec = specOf(*s);
    auto it = recorded.find(s->name);
    if (it != recorded.end()) {
      const pid_t pid = it->second.value("pid", -1);
      const auto start_time = process::processStartTime(pid);
      const bool same_process = start_time && process::processRunning(pid) &&
                                *start_time == it->second.value("start_time", 0ULL);
      if (same_process) {
        std::error_code e2;
        const fs::path exe = fs::read_symlink("/proc/" + std::to_string(pid) + "/exe", e2);
        const bool same_start = !e2 && fs::equivalent(exe, spec.executable, e2) &&
                                it->second.value("command", "") == commandLine(spec);
        if (same_start) {
          sup_.adopt(spec, pid);
          adopted_.push_back(s->name);
          continue;
        }
        writeEvent(s->name, "replaced", pid, 0, 0,
                   "started differently by an earlier supervisor: stopped");
        kill(-pid, SIGTERM);
        kill(-pid, SIGCONT);
        const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
        while (process::processRunning(pid) && std::chrono::steady_clock::now() < end) {
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        if (process::processRunning(pid)) kill(-pid, SIGKILL);
      }
    }
    sup_.add(spec);
  }
  Status st = participant_->securityIdentity().empty() ? sup_.startAll() : startOneByOne();
  pids_dirty_ = true;
  writePidFile();
  return st;
}

// Secured, every new participant runs an authentication handshake and a crypto-token exchange
// with every other one. On Fast DDS 2.9.1, eight participants started at once left one pair
// unmatched for more than 30 s in about one secured run of four (docs/reliability.md); started one
// by one, each waiting for the previous one's heartbeat, they match. A service that sends no
// heartbeat within startup_timeout_s does not hold the others back any longer.
Status Launcher::startOneByOne() {
  Status first;
  for (const auto& name : services()) {
    const auto before = sup_.status(name);
    if (!before || before->phase != process::ProcessPhase::kNotStarted) continue;
    Status s = sup_.start(name);
    if (!s) {
      if (first.ok()) first = s;
      continue;
    }
    const auto started = sup_.status(name);
    const Termination until = Termination::after(o_.deployment.startup_timeout_s);
    while (!until()) {
      sup_.poll();
      const auto now = sup_.status(name);
      if (!now || now->phase != process::ProcessPhase::kRunning || now->pid != started->pid) break;
      bool heard = false;
      for (const auto& seen : monitor_->services())
        heard = heard || (seen.name == name && seen.pid == static_cast<uint32_t>(now->pid));
      if (heard) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  return first;
}

void Launcher::poll() {
  sup_.poll();
  if (o_.restart && o_.liveness) checkLiveness();
  if (o_.restart) checkReadiness();
  touchLease();
  if (pids_dirty_) writePidFile();
}

void Launcher::checkLiveness() {
  const auto services = monitor_->services();
  const std::string host = thisHost();
  const auto now = std::chrono::steady_clock::now();
  const double timeout = o_.deployment.livenessTimeout();
  for (const auto& st : sup_.status()) {
    if (st.phase != process::ProcessPhase::kRunning || st.pid <= 0) continue;
    const dds::ServiceInfo* seen = nullptr;
    for (const auto& s : services) {
      if (s.name == st.name && s.pid == static_cast<uint32_t>(st.pid) && s.host == host) seen = &s;
    }
    const double since_start = std::chrono::duration<double>(now - st.started).count();
    if (seen == nullptr) {
      if (since_start > o_.deployment.startup_timeout_s) {
        char why[160];
        std::snprintf(why, sizeof(why),
                      "no heartbeat within startup_timeout_s (%.1f s) of its start",
                      o_.deployment.startup_timeout_s);
        (void)sup_.declareDead(st.name, why);
      }
      continue;
    }
    if (seen->age_s > timeout) {
      char why[160];
      std::snprintf(why, sizeof(why), "no heartbeat for %.1f s (%d periods of %.2f s)", seen->age_s,
                    o_.deployment.liveness_periods, o_.deployment.heartbeat_period_s);
      (void)sup_.declareDead(st.name, why);
    }
  }
}

namespace {

/// The heartbeat of `st`'s current process on `host`, if heard.
const dds::ServiceInfo* heardFrom(const std::vector<dds::ServiceInfo>& services, const process::ProcessStatus& st,
                                  const std::string& host) {
  for (const auto& s : services)
    if (s.alive && s.name == st.name && s.pid == static_cast<uint32_t>(st.pid) && s.host == host) return &s;
  return nullptr;
}

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// The heartbeat of `st`'s current process on `host` when it is alive but still starting (not
/// ready) more than `ready_timeout_s` after the process started; null otherwise.
const dds::ServiceInfo* notReadyInTime(const std::vector<dds::ServiceInfo>& services,
                                       const process::ProcessStatus& st, const std::string& host,
                                       double ready_timeout_s) {
  const dds::ServiceInfo* seen = heardFrom(services, st, host);
  if (seen == nullptr || seen->state != msg::SERVICE_STARTING) return nullptr;
  return secondsSince(st.started) > ready_timeout_s ? seen : nullptr;
}

}  // namespace

bool Launcher::readinessRestartsLeft(const std::string& name) const {
  const process::ProcessSpec* spec = sup_.spec(name);
  if (spec == nullptr || !spec->restart) return false;
  const auto used = ready_restarts_.find(name);
  return (used == ready_restarts_.end() ? 0 : used->second) < o_.deployment.ready_restarts;
}

// A new process is a new participant, which authenticates and matches with every other one
// anew: what cures a pair that never matched (Fast DDS 2.9.1, secured: docs/reliability.md).
void Launcher::checkReadiness() {
  const auto services = monitor_->services();
  const std::string host = thisHost();
  const int limit = o_.deployment.ready_restarts;
  for (const auto& st : sup_.status()) {
    if (st.phase != process::ProcessPhase::kRunning || st.pid <= 0) continue;
    if (!readinessRestartsLeft(st.name)) continue;
    const dds::ServiceInfo* seen =
        notReadyInTime(services, st, host, o_.deployment.ready_timeout_s);
    if (seen == nullptr) continue;
    const int n = ++ready_restarts_[st.name];
    char why[512];
    std::snprintf(why, sizeof(why), "not ready within ready_timeout_s (%.1f s) of its start (%s): restarted, %d of %d",
                  o_.deployment.ready_timeout_s, seen->detail.c_str(), n, limit);
    (void)sup_.declareDead(st.name, why);
  }
}

bool Launcher::readinessGivenUp(const std::string& name) const {
  const auto st = sup_.status(name);
  if (!st || st->phase != process::ProcessPhase::kRunning) return false;
  if (o_.restart && readinessRestartsLeft(name)) return false;
  return notReadyInTime(monitor_->services(), *st, thisHost(), o_.deployment.ready_timeout_s) !=
         nullptr;
}

void Launcher::stop(double grace_s) {
  if (stopped_) return;
  stopped_ = true;
  if (!owns_run_dir_) return;  // another supervisor's run folder and services
  sup_.stopAll(grace_s);
  std::error_code ec;
  fs::remove(o_.run_dir / "launch.pids", ec);
  note("launch_stopped", "every service stopped");
}

void Launcher::touchLease() {
  if (!o_.detach) return;  // attached services die with us: no lease to renew
  const auto now = std::chrono::steady_clock::now();
  if (now - lease_touched_ < std::chrono::duration<double>(o_.deployment.heartbeat_period_s))
    return;
  lease_touched_ = now;
  const fs::path lease = o_.run_dir / "supervisor.lease";
  std::error_code ec;
  if (!fs::exists(lease, ec)) std::ofstream(lease) << "renewed by tamp launch\n";
  fs::last_write_time(lease, fs::file_time_type::clock::now(), ec);
}

void Launcher::writePidFile() {
  pids_dirty_ = false;
  nlohmann::json services = nlohmann::json::array();
  for (const auto& st : sup_.status()) {
    if (st.phase != process::ProcessPhase::kRunning || st.pid <= 0) continue;
    const auto t = process::processStartTime(st.pid);
    const process::ProcessSpec* spec = sup_.spec(st.name);
    services.push_back({{"name", st.name},
                        {"pid", st.pid},
                        {"start_time", t.value_or(0)},
                        {"command", spec ? commandLine(*spec) : ""},
                        {"restarts", st.restarts}});
  }
  nlohmann::json j{{"run_id", o_.run_id},
                   {"host", o_.host},
                   {"domain", o_.domain},
                   {"supervisor_pid", ::getpid()},
                   {"services", services}};
  writeAtomically(o_.run_dir / "launch.pids", j.dump(2) + "\n");
}

void Launcher::note(const std::string& event, const std::string& detail) {
  writeEvent("", event, ::getpid(), 0, 0, detail);
}

void Launcher::logEvent(const process::ProcessEvent& e) {
  pids_dirty_ = true;
  writeEvent(e.name, process::toString(e.kind), e.pid, e.restarts, e.backoff_s, e.detail);
}

void Launcher::writeEvent(const std::string& service, const std::string& event, pid_t pid,
                          int restarts, double backoff_s, const std::string& detail) {
  nlohmann::json j{{"time", utcNow()},    {"run_id", o_.run_id}, {"host", o_.host},
                   {"service", service},  {"event", event},      {"pid", pid},
                   {"restarts", restarts}};
  if (backoff_s > 0) j["backoff_s"] = backoff_s;
  if (!detail.empty()) j["detail"] = detail;
  // One write() per line with O_APPEND: lines of concurrent writers do not interleave.
  const std::string line = j.dump() + "\n";
  const int fd = ::open(eventsFile().c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) {
    log::get("launch")->warn("cannot write {}: {}", eventsFile().string(), std::strerror(errno));
    return;
  }
  (void)!::write(fd, line.data(), line.size());
  ::close(fd);
}

}  // namespace tamp::launch
