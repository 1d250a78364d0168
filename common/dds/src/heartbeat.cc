#include "tamp/dds/heartbeat.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include "tamp/dds/convert.h"
#include "tamp/dds/rpc.h"

namespace tamp::dds {

const char* toString(msg::ServiceState state) {
  switch (state) {
    case msg::SERVICE_STARTING: return "starting";
    case msg::SERVICE_READY: return "ready";
    case msg::SERVICE_BUSY: return "busy";
    case msg::SERVICE_DEGRADED: return "degraded";
    case msg::SERVICE_STOPPING: return "stopping";
  }
  return "unknown";
}

HeartbeatPublisher::HeartbeatPublisher(std::shared_ptr<Participant> p, const std::string& name, double period_s)
    : participant_(p), writer_(p, topics::kHeartbeat), period_s_(period_s) {
  require(!name.empty(), "HeartbeatPublisher needs a service name");
  require(period_s > 0, "heartbeat period must be positive, got " + std::to_string(period_s));
  const std::string host = detail::hostName();
  service_id_ = name + "@" + host + ":" + std::to_string(::getpid());
  beat_.service_id(service_id_);
  beat_.name(name);
  beat_.host(host);
  beat_.pid(static_cast<uint32_t>(::getpid()));
  beat_.state(msg::SERVICE_STARTING);
  beat_.start_time_ns(nowNs());
  beat_.period_s(period_s);
  beat_.version(TAMP_VERSION);
  publish();
  thread_ = std::jthread([this](std::stop_token st) {
    std::unique_lock lock(mutex_);
    while (!st.stop_requested()) {
      cv_.wait_for(lock, st, std::chrono::duration<double>(period_s_), [] { return false; });
      if (st.stop_requested()) break;
      lock.unlock();
      beat();
      lock.lock();
    }
  });
}

HeartbeatPublisher::~HeartbeatPublisher() {
  thread_.request_stop();
  thread_ = {};
  setState(msg::SERVICE_STOPPING);
  msg::Heartbeat key;
  key.service_id(service_id_);
  (void)writer_.unregister(key);
}

void HeartbeatPublisher::setState(msg::ServiceState state) {
  {
    std::lock_guard lock(mutex_);
    if (beat_.state() == state) return;
    beat_.state(state);
  }
  publish();
}

void HeartbeatPublisher::setDetail(const std::string& detail) {
  std::lock_guard lock(mutex_);
  beat_.detail(detail);
}

void HeartbeatPublisher::setCounters(std::function<std::pair<uint64_t, uint64_t>()> served_failed) {
  std::lock_guard lock(mutex_);
  counters_ = std::move(served_failed);
}

void HeartbeatPublisher::setStallLimit(double limit_s) {
  require(std::isfinite(limit_s) && limit_s >= 0.0,
          "heartbeat stall limit must be finite and not negative, got " + std::to_string(limit_s));
  kick();
  stall_limit_ns_.store(static_cast<int64_t>(limit_s * 1e9));
}

void HeartbeatPublisher::kick() { last_kick_ns_.store(nowNs(), std::memory_order_relaxed); }

double HeartbeatPublisher::stalledFor() const {
  if (stall_limit_ns_.load() <= 0) return 0.0;
  return static_cast<double>(nowNs() - last_kick_ns_.load(std::memory_order_relaxed)) * 1e-9;
}

void WorkWatch::busy() {
  last_kick_ns_.store(nowNs(), std::memory_order_relaxed);
  busy_.store(true);
}

void WorkWatch::kick() { last_kick_ns_.store(nowNs(), std::memory_order_relaxed); }

void WorkWatch::idle() { busy_.store(false); }

double WorkWatch::stalledFor() const {
  if (!busy_.load()) return 0.0;
  return static_cast<double>(nowNs() - last_kick_ns_.load(std::memory_order_relaxed)) * 1e-9;
}

std::shared_ptr<WorkWatch> HeartbeatPublisher::watchWorker(const std::string& name) {
  require(!name.empty(), "a watched worker needs a name");
  auto w = std::make_shared<WorkWatch>(name);
  std::lock_guard lock(mutex_);
  workers_.push_back(w);
  return w;
}

std::pair<std::string, double> HeartbeatPublisher::stalled(int64_t limit_ns) const {
  const double limit_s = static_cast<double>(limit_ns) * 1e-9;
  if (const double s = stalledFor(); s > limit_s) return {"its main loop has not run", s};
  std::lock_guard lock(mutex_);
  for (const auto& w : workers_)
    if (const double s = w->stalledFor(); s > limit_s) return {"its worker '" + w->name() + "' has not moved on", s};
  return {};
}

void HeartbeatPublisher::beat() {
  const int64_t limit = stall_limit_ns_.load();
  if (limit > 0) {
    if (const auto [what, for_s] = stalled(limit); !what.empty()) {
      if (!withheld_)
        log::get("dds")->error("{}: {} for {:.1f} s (stall limit {:.1f} s): heartbeats withheld, so that it counts as "
                               "dead",
                               service_id_, what, for_s, static_cast<double>(limit) * 1e-9);
      withheld_ = true;
      return;
    }
  }
  if (withheld_) log::get("dds")->warn("{}: its work goes on again: heartbeats resumed", service_id_);
  withheld_ = false;
  publish();
}

void HeartbeatPublisher::publish() {
  msg::Heartbeat b;
  {
    std::lock_guard lock(mutex_);
    if (counters_) {
      auto [served, failed] = counters_();
      beat_.requests_served(served);
      beat_.requests_failed(failed);
    }
    beat_.stamp_ns(nowNs());
    b = beat_;
  }
  if (Status s = writer_.write(b); !s.ok()) log::get("dds")->warn("heartbeat: {}", s.error().toString());
}

HeartbeatMonitor::HeartbeatMonitor(std::shared_ptr<Participant> p)
    : reader_(p, topics::kHeartbeat, [this](const msg::Heartbeat& hb, const SampleMeta& m) { onBeat(hb, m); }) {}

void HeartbeatMonitor::onBeat(const msg::Heartbeat& hb, const SampleMeta& meta) {
  std::lock_guard lock(mutex_);
  Entry& e = entries_[hb.service_id()];
  e.beat = hb;
  e.received = Clock::now();
  e.gone = !meta.alive;
}

std::vector<ServiceInfo> HeartbeatMonitor::services() const {
  std::vector<ServiceInfo> out;
  const int64_t now = nowNs();
  std::lock_guard lock(mutex_);
  for (const auto& [id, e] : entries_) {
    ServiceInfo s;
    s.service_id = id;
    s.name = e.beat.name();
    s.host = e.beat.host();
    s.pid = e.beat.pid();
    s.state = e.beat.state();
    s.uptime_s = static_cast<double>(now - e.beat.start_time_ns()) * 1e-9;
    s.age_s = std::chrono::duration<double>(Clock::now() - e.received).count();
    s.period_s = e.beat.period_s() > 0 ? e.beat.period_s() : 1.0;
    s.served = e.beat.requests_served();
    s.failed = e.beat.requests_failed();
    s.version = e.beat.version();
    s.detail = e.beat.detail();
    s.alive = !e.gone && s.state != msg::SERVICE_STOPPING && s.age_s < 3.0 * s.period_s;
    out.push_back(std::move(s));
  }
  std::sort(out.begin(), out.end(), [](const ServiceInfo& a, const ServiceInfo& b) {
    if (a.alive != b.alive) return a.alive;
    if (a.name != b.name) return a.name < b.name;
    return a.service_id < b.service_id;
  });
  return out;
}

bool HeartbeatMonitor::waitFor(const std::string& name, int count, const Termination& until, bool ready) const {
  while (true) {
    int n = 0;
    for (const auto& s : services())
      n += (s.alive && s.name == name && (!ready || s.state != msg::SERVICE_STARTING)) ? 1 : 0;
    if (n >= count) return true;
    if (until()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace tamp::dds
