#include "join_run.h"

#include <cstdio>
#include <vector>

#include "cli_common.h"
#include "tamp/core/termination.h"
#include "tamp/dds/heartbeat.h"

namespace tamp::runner {
namespace {

/// The required services not heard ready (yet), and of those the ones not heard at all.
struct Missing {
  std::vector<std::string> not_ready, unheard;
  std::string why;  // the first one's, for the message
  bool any_heard{false};
};

Missing waitForServices(const dds::HeartbeatMonitor& monitor, const deploy::Deployment& d, const Termination& until) {
  Missing m;
  for (const auto& s : d.services) {
    if (s.optional || monitor.waitFor(s.name, 1, until, /*ready=*/true)) continue;
    bool heard = false;
    std::string why = "no heartbeat";
    for (const auto& info : monitor.services()) {
      if (info.name != s.name) continue;
      heard = true;
      if (info.alive) why = "alive but not ready (" + info.detail + ")";
    }
    if (m.not_ready.empty()) m.why = "service '" + s.name + "': " + why;
    m.not_ready.push_back(s.name);
    if (!heard) m.unheard.push_back(s.name);
  }
  m.any_heard = !monitor.services().empty();
  return m;
}

}  // namespace

JoinedRun joinRun(const deploy::Deployment& d, int domain, const std::string& run_id) {
  JoinedRun r;
  // The services' supervisors (tamp launch) restart one that stays not ready: wait that long.
  const Termination overall = Termination::after(d.readyWait());
  while (true) {
    auto p = dds::Participant::create({domain, dds::kProfileDefault, "tamp/mission", {}}, run_id);
    if (!p) {
      r.exit_code = cli::kExitServiceError;
      r.error = p.error().toString();
      return r;
    }
    const dds::HeartbeatMonitor monitor(*p);
    const bool may_renew = r.new_participants < d.ready_restarts;
    const Termination window = may_renew ? overall.tightened(Deadline::in(d.ready_timeout_s)) : overall;
    Missing m = waitForServices(monitor, d, window);
    // Not heard at all while others are: this participant's pairs, not the services.
    const bool renew = may_renew && !m.unheard.empty() && m.any_heard && !overall();
    if (!renew && !m.not_ready.empty() && !overall()) m = waitForServices(monitor, d, overall);
    if (m.not_ready.empty()) {
      r.participant = *p;
      return r;
    }
    if (!renew) {
      r.exit_code = cli::kExitServiceError;
      r.error = m.why + " within " + std::to_string(static_cast<int>(d.readyWait())) + " s (tamp status)";
      return r;
    }
    ++r.new_participants;
    std::string names;
    for (const auto& n : m.unheard) names += (names.empty() ? "'" : ", '") + n + "'";
    std::fprintf(stderr,
                 "tamp mission: %s not heard in %.0f s while other services are: a new DDS participant (%d of %d)\n",
                 names.c_str(), d.ready_timeout_s, r.new_participants, d.ready_restarts);
  }
}

}  // namespace tamp::runner
