#pragma once
/// @file
/// Deadlines and stop requests for every long call (planning, search, fitting, RPC).
///
/// A `Termination` combines a steady-clock deadline with a `std::stop_token`, in the spirit of
/// OMPL's `PlannerTerminationCondition`: long loops run `while (!term())`. It is cheap to copy and
/// to query (one clock read; callers in hot loops may check every N iterations).

#include <chrono>
#include <limits>
#include <stop_token>

namespace tamp {

using Clock = std::chrono::steady_clock;

/// A point in time on the steady clock after which work should stop. `never()` does not expire.
class Deadline {
 public:
  static Deadline never() { return Deadline(Clock::time_point::max()); }
  static Deadline at(Clock::time_point t) { return Deadline(t); }
  /// A deadline `seconds` from now; non-positive values give an already-expired deadline.
  static Deadline in(double seconds);
  template <class Rep, class Period>
  static Deadline in(std::chrono::duration<Rep, Period> d) {
    return Deadline(Clock::now() + std::chrono::duration_cast<Clock::duration>(d));
  }

  bool expired() const { return t_ != Clock::time_point::max() && Clock::now() >= t_; }
  bool isNever() const { return t_ == Clock::time_point::max(); }
  Clock::time_point time() const { return t_; }
  /// Seconds left (negative once expired; +inf for never()).
  double secondsLeft() const;
  /// The earlier of the two.
  Deadline min(const Deadline& other) const { return t_ < other.t_ ? *this : other; }

 private:
  explicit Deadline(Clock::time_point t) : t_(t) {}
  Clock::time_point t_;
};

/// Why a long call stopped early.
enum class StopReason { kNone, kDeadline, kStopRequested };

/// Deadline + stop token. `operator()` is true when the work should stop.
class Termination {
 public:
  Termination() : deadline_(Deadline::never()) {}
  explicit Termination(Deadline d, std::stop_token token = {}) : deadline_(d), token_(std::move(token)) {}
  static Termination after(double seconds) { return Termination(Deadline::in(seconds)); }

  bool operator()() const { return reason() != StopReason::kNone; }
  StopReason reason() const {
    if (token_.stop_requested()) return StopReason::kStopRequested;
    if (deadline_.expired()) return StopReason::kDeadline;
    return StopReason::kNone;
  }
  const Deadline& deadline() const { return deadline_; }
  const std::stop_token& token() const { return token_; }
  /// The same stop token with a deadline no later than `d` (for a sub-call with its own budget).
  Termination tightened(Deadline d) const { return Termination(deadline_.min(d), token_); }

 private:
  Deadline deadline_;
  std::stop_token token_;
};

/// Wall-clock stopwatch for measurements and logs.
class Stopwatch {
 public:
  Stopwatch() : start_(Clock::now()) {}
  void reset() { start_ = Clock::now(); }
  double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
  double millis() const { return seconds() * 1e3; }

 private:
  Clock::time_point start_;
};

}  // namespace tamp
