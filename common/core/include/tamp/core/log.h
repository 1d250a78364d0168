#pragma once
/// @file
/// Logging through spdlog. One named logger per component ("symbolic_planner", "dds", ...), all
/// writing to stderr with the same pattern; level from `TAMP_LOG_LEVEL` (trace, debug, info, warn,
/// error, off; default info) or `setLevel()`.
///
///   auto log = tamp::log::get("motion_planner");
///   log->info("solved in {:.1f} ms, {} objects in the way", ms, n);

#include <memory>
#include <string>

#include <spdlog/spdlog.h>

namespace tamp::log {

/// The logger for `component`, created on first use. Thread-safe.
std::shared_ptr<spdlog::logger> get(const std::string& component);

/// Sets the level of every existing and future logger ("trace".."off"); unknown names throw
/// std::invalid_argument.
void setLevel(const std::string& level);

}  // namespace tamp::log
