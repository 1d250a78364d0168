#pragma once
// Test helpers: an isolated DDS domain per test process, and a participant on it.
#include <unistd.h>

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

}  // namespace tamp::dds::testing
