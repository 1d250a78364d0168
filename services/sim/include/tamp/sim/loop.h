#pragma once
/// @file
/// Runs a `Simulator` on its own thread, paced against the wall clock, and reports what happens
/// through callbacks (the DDS node maps them to topics; tests can use them directly).
///
/// Every tick advances simulated time by `SimParams::state_period_s` and reports the robot state.
/// Pacing: with `realtime_factor` r > 0, simulated time runs r times faster than the wall clock
/// (1 = real time). With r = 0, actions run as fast as the machine allows, and while idle the
/// simulated time advances in real time (so a waiting simulator does not spin a core and timed
/// faults still fire).
///
/// Point clouds: every `cloud_period_s` of simulated time (0 = never periodically), after every
/// finished action, and on `requestCloud()`.
///
/// Thread safety: `submit`, `cancel`, `inject`, `requestCloud`, `stop` and the accessors may be
/// called from any thread. Callbacks run on the loop thread, without the simulator's lock held,
/// and must not throw (a throwing callback is logged and ignored).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>

#include "tamp/sim/simulator.h"

namespace tamp::sim {

struct LoopCallbacks {
  std::function<void(const RobotStateSample&, std::int64_t stamp_ns)> on_state;
  std::function<void(const ActionResult&)> on_result;
  std::function<void(const effort_model::ExecutionRecord&)> on_record;
  std::function<void(const FaultEvent&)> on_fault;
  std::function<void(const PointCloudFrame&)> on_cloud;
};

class SimulationLoop {
 public:
  /// The loop drives `sim` (which must outlive it); nothing runs before `start()`.
  SimulationLoop(Simulator& sim, LoopCallbacks callbacks);
  ~SimulationLoop();  ///< stops the thread
  SimulationLoop(const SimulationLoop&) = delete;
  SimulationLoop& operator=(const SimulationLoop&) = delete;

  void start();
  void stop();

  /// One tick on the caller's thread (no pacing): step, then report. For tests and tools.
  void tick();

  /// Thread-safe entry points (see Simulator). A rejected command is also reported through
  /// `on_result` as kFailed with the rejection's message, so a remote sender gets an answer.
  Status submit(const ActionCommand& command);
  Status cancel(const std::string& command_id);
  Status inject(Fault fault);
  void requestCloud();

  /// Stamp (ns since the Unix epoch) of simulated time `t`: `Simulator::epoch()` (the wall-clock
  /// time at simulated time 0) plus `t`.
  std::int64_t stampNs(double t) const;
  double simTime() const;
  bool busy() const;
  /// Runs `fn` with the simulator locked (e.g. to read the world).
  void withSimulator(const std::function<void(Simulator&)>& fn);

 private:
  void run();

  Simulator& sim_;
  LoopCallbacks cb_;
  std::int64_t epoch_ns_{0};
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::thread thread_;
  bool stop_{false};
  std::atomic<bool> cloud_requested_{false};
  double next_cloud_{0.0};
};

}  // namespace tamp::sim
