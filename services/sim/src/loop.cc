#include "tamp/sim/loop.h"

#include <chrono>
#include <cmath>
#include <vector>

#include "tamp/core/log.h"

namespace tamp::sim {
namespace {

template <typename Fn, typename... Args>
void safeCall(const Fn& fn, const char* what, Args&&... args) {
  if (!fn) return;
  try {
    fn(std::forward<Args>(args)...);
  } catch (const std::exception& e) {
    tamp::log::get("sim")->error("{} callback threw: {}", what, e.what());
  } catch (...) {
    tamp::log::get("sim")->error("{} callback threw", what);
  }
}

}  // namespace

SimulationLoop::SimulationLoop(Simulator& sim, LoopCallbacks callbacks)
    : sim_(sim), cb_(std::move(callbacks)) {
  epoch_ns_ = std::llround(sim.epoch() * 1e9);
  next_cloud_ = sim.time();
}

SimulationLoop::~SimulationLoop() { stop(); }

void SimulationLoop::start() {
  std::lock_guard lock(mutex_);
  if (thread_.joinable()) return;
  stop_ = false;
  thread_ = std::thread([this] { run(); });
}

void SimulationLoop::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable() && thread_.get_id() != std::this_thread::get_id()) thread_.join();
}

std::int64_t SimulationLoop::stampNs(double t) const {
  return epoch_ns_ + static_cast<std::int64_t>(t * 1e9);
}

double SimulationLoop::simTime() const {
  std::lock_guard lock(mutex_);
  return sim_.time();
}

bool SimulationLoop::busy() const {
  std::lock_guard lock(mutex_);
  return sim_.busy();
}

void SimulationLoop::withSimulator(const std::function<void(Simulator&)>& fn) {
  std::lock_guard lock(mutex_);
  fn(sim_);
}

Status SimulationLoop::submit(const ActionCommand& command) {
  Status s;
  {
    std::lock_guard lock(mutex_);
    s = sim_.submit(command);
  }
  if (!s) {
    ActionResult r;
    r.command_id = command.command_id;
    r.outcome = Outcome::kFailed;
    r.reason = "rejected: " + s.error().message;
    safeCall(cb_.on_result, "on_result", r);
  }
  cv_.notify_all();
  return s;
}

Status SimulationLoop::cancel(const std::string& command_id) {
  std::lock_guard lock(mutex_);
  return sim_.cancel(command_id);
}

Status SimulationLoop::inject(Fault fault) {
  std::lock_guard lock(mutex_);
  return sim_.inject(std::move(fault));
}

void SimulationLoop::requestCloud() {
  cloud_requested_ = true;
  cv_.notify_all();
}

void SimulationLoop::tick() {
  StepEvents ev;
  RobotStateSample state;
  std::vector<PointCloudFrame> clouds;
  {
    std::lock_guard lock(mutex_);
    const SimParams& p = sim_.params();
    ev = sim_.step(p.state_period_s);
    state = sim_.robotState();
    bool cloud = cloud_requested_.exchange(false) || !ev.results.empty();
    if (p.cloud_period_s > 0.0 && sim_.time() + 1e-9 >= next_cloud_) {
      cloud = true;
      while (next_cloud_ <= sim_.time() + 1e-9) next_cloud_ += p.cloud_period_s;
    }
    if (cloud && (cb_.on_cloud)) clouds.push_back(sim_.captureCloud(stampNs(sim_.time())));
  }
  for (const auto& f : ev.faults) safeCall(cb_.on_fault, "on_fault", f);
  safeCall(cb_.on_state, "on_state", state, stampNs(state.time_s));
  for (const auto& r : ev.records) safeCall(cb_.on_record, "on_record", r);
  for (const auto& r : ev.results) safeCall(cb_.on_result, "on_result", r);
  for (const auto& c : clouds) safeCall(cb_.on_cloud, "on_cloud", c);
}

void SimulationLoop::run() {
  using Clock = std::chrono::steady_clock;
  const double factor = sim_.params().realtime_factor;
  const double period = sim_.params().state_period_s;
  auto wall_anchor = Clock::now();
  double sim_anchor = simTime();
  for (;;) {
    tick();
    const bool fast = factor == 0.0 && busy();
    std::unique_lock lock(mutex_);
    if (stop_) return;
    if (fast) {
      // As fast as possible: re-anchor so that pacing resumes from here when idle.
      wall_anchor = Clock::now();
      sim_anchor = sim_.time();
      continue;
    }
    const double rate = factor > 0.0 ? factor : 1.0;
    const auto due = wall_anchor + std::chrono::duration_cast<Clock::duration>(
                                       std::chrono::duration<double>((sim_.time() - sim_anchor) / rate));
    cv_.wait_until(lock, due, [&] { return stop_ || (factor == 0.0 && sim_.busy()) || cloud_requested_; });
    if (stop_) return;
    if (Clock::now() > due + std::chrono::duration<double>(10 * period)) {
      // Fell behind (slow callbacks, a loaded machine): do not try to catch up in a burst.
      wall_anchor = Clock::now();
      sim_anchor = sim_.time();
    }
  }
}

}  // namespace tamp::sim
