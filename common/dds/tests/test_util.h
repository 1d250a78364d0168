#pragma once
// Test helpers: an isolated DDS domain per test process, a participant on it, and an inbox that
// collects what a reader callback receives.
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

#include "tamp/dds/participant.h"

namespace tamp::dds::testing {

/// A domain id unlikely to be shared with a test running in parallel (ctest runs each test in
/// its own process).
inline int isolatedDomain() { return 20 + static_cast<int>(::getpid() % 200); }

inline std::shared_ptr<Participant> makeParticipant(int domain = isolatedDomain(),
                                                    const std::string& profile = kProfileDefault) {
  auto p = Participant::create(ParticipantOptions{domain, profile, "test", {}});
  if (!p) ADD_FAILURE() << p.error().toString();
  return p ? *p : nullptr;
}

/// Collects samples from reader callbacks (any thread) for a test to wait on.
template <typename T>
class Inbox {
 public:
  void push(const T& v) {
    std::lock_guard l(m_);
    items_.push_back(v);
    cv_.notify_all();
  }
  /// Waits (bounded, so that a broken service fails the test instead of hanging it) for an item
  /// matching `pred`; the first match.
  std::optional<T> waitFor(const std::function<bool(const T&)>& pred, double seconds = 30.0) {
    std::unique_lock l(m_);
    std::optional<T> found;
    cv_.wait_for(l, std::chrono::duration<double>(seconds), [&] {
      for (const auto& x : items_) {
        if (pred(x)) {
          found = x;
          return true;
        }
      }
      return false;
    });
    return found;
  }
  std::size_t size() {
    std::lock_guard l(m_);
    return items_.size();
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  std::vector<T> items_;
};

}  // namespace tamp::dds::testing
