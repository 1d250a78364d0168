#pragma once
/// @file
/// The mission report as JSON (schema: docs/report_schema.md).

#include <string>

#include "tamp/graph_manager/graph_manager.h"

namespace tamp::graph_manager {

/// `report.json`: status, reason, efforts, timings, counters, moved objects, decisions, actions.
/// `scenario` and `policy` are copied in for the reader.
std::string reportJson(const MissionReport& report, const std::string& scenario, const std::string& policy,
                       std::uint32_t seed);

}  // namespace tamp::graph_manager
