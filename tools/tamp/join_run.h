#pragma once
/// @file
/// `tamp mission`'s own DDS participant in a running deployment: one that hears every service
/// the deployment requires, ready.

#include <memory>
#include <string>

#include "tamp/deploy/deployment.h"
#include "tamp/dds/participant.h"

namespace tamp::runner {

struct JoinedRun {
  std::shared_ptr<dds::Participant> participant;  ///< null on failure
  int exit_code{0};                               ///< cli exit code on failure
  std::string error;                              ///< what is missing, on failure
  int new_participants{0};                        ///< participants made again (below)
};

/// Joins run `run_id` on `domain` and waits (up to the deployment's readyWait()) until every
/// required service is heard ready. Debian's Fast DDS 2.9.1 under DDS Security now and then
/// leaves a pair of participants unmatched for good (docs/reliability.md): when a required
/// service has not been heard at all for `ready_timeout_s` while others have, the participant is
/// made again (a new one matches every other anew), at most `ready_restarts` times, each said on
/// stderr. A service heard but not ready is its supervisor's to restart, not a reason for that.
JoinedRun joinRun(const deploy::Deployment& deployment, int domain, const std::string& run_id);

}  // namespace tamp::runner
