#pragma once
/// @file
/// Effort queries and answers to and from their messages, shared by the effort estimator's client
/// (dds_clients.cc) and the oracle's (oracle_clients.cc), which ask the same queries.

#include <string>
#include <vector>

#include "tamp/dds/topics.h"
#include "tamp/dds/convert.h"
#include "tamp/graph_manager/clients.h"

namespace tamp::graph_manager {

inline msg::EffortQuery toEffortMsg(const EffortQuery& q) {
  msg::EffortQuery m;
  m.kind(dds::toMsg(q.kind));
  if (!q.path.empty()) m.path(dds::toMsg(q.path));
  m.object_mass(q.object_mass);
  m.approach_m(q.approach_m);
  m.retreat_m(q.retreat_m);
  return m;
}

/// One answer per query, from the reply's estimates in order; answers without an estimate keep
/// `ok` false.
inline void fillEffortAnswers(const std::vector<msg::EffortEstimate>& estimates, std::vector<EffortAnswer>& out) {
  for (std::size_t i = 0; i < out.size() && i < estimates.size(); ++i) {
    const auto& e = estimates[i];
    out[i].ok = e.code() == msg::StatusCode::STATUS_OK;
    out[i].mean_s = e.mean_s();
    out[i].stddev_s = e.stddev_s();
    out[i].message = e.message();
  }
}

}  // namespace tamp::graph_manager
