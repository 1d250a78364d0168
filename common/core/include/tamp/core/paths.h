#pragma once
/// @file
/// Where the project's data lives at run time. `configDir()` is `$TAMP_CONFIG_DIR` when set, else
/// the source tree's `config/` (compiled in), so binaries run from a build tree or an install.

#include <filesystem>
#include <string>

#include "tamp/core/error.h"

namespace tamp {

std::filesystem::path configDir();
/// The benchmark data shipped in the source tree (`tests/data/benchmarks/`: IPC PDDL sets, NAMO
/// worlds, TAMP benchmark problems; licences in its NOTICE.md), compiled in, or
/// `$TAMP_BENCHMARKS_DIR` when set.
std::filesystem::path benchmarksDir();
/// `relative` resolved against the directory of `base_file` (for paths inside config files);
/// absolute paths are returned unchanged.
std::filesystem::path resolveRelativeTo(const std::filesystem::path& base_file,
                                        const std::filesystem::path& relative);
/// Reads a whole file; a failure gives a kIo/kNotFound error naming the file.
Result<std::string> readTextFile(const std::filesystem::path& file);
/// Replaces `file` with `text` so that a crash at any instant leaves the old content or the new
/// one, never a torn file: written to `file.tmp`, fsynced, renamed over `file`, and the folder
/// fsynced. kIo naming the file (`what` says which file it is: "the mission journal") on failure.
Status writeFileAtomically(const std::filesystem::path& file, const std::string& text,
                           const std::string& what = "the file");

}  // namespace tamp
