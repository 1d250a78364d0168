#pragma once
/// @file
/// The mission part of `tamp run`: sends a MissionCommand to the graph manager, follows its
/// MissionStatus with one line per action and a progress bar, and writes the run's artefacts
/// (report.json, graph.dot/.svg, world.png/.svg).

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "tamp/dds/participant.h"

namespace tamp::runner {

struct MissionOptions {
  std::string scenario;  ///< absolute path
  std::string policy{"effort"};
  unsigned seed{0};
  double timeout_s{900.0};
  std::filesystem::path out_dir;  ///< this run's folder: report.json, graph, pictures
  /// When set (tamp run's --out), the run's report is also left at `latest_dir/report.json` and
  /// `latest_dir/latest` links to `out_dir`, so a script finds the last run without its id.
  std::filesystem::path latest_dir;
};

/// Loads the scenario (and its robot): the error (file:line: field) or nothing.
std::optional<std::string> checkScenario(const std::string& file);

/// Runs the mission and returns the exit code (0, 10, 20, 30, 40; 50 when its report could not be
/// written). `poll` is called while
/// waiting; it returns true to abort.
int runMission(const std::shared_ptr<dds::Participant>& participant, const MissionOptions& options,
               const std::function<bool()>& poll);

}  // namespace tamp::runner
