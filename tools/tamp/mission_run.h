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
  std::filesystem::path out_dir;
};

/// Loads the scenario (and its robot): the error (file:line: field) or nothing.
std::optional<std::string> checkScenario(const std::string& file);

/// Runs the mission and returns the exit code (0, 10, 20, 30, 40). `poll` is called while
/// waiting; it returns true to abort.
int runMission(const std::shared_ptr<dds::Participant>& participant, const MissionOptions& options,
               const std::function<bool()>& poll);

}  // namespace tamp::runner
