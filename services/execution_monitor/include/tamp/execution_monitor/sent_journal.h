#pragma once
/// @file
/// What the execution monitor sent to the robot, kept on disk across its restarts (issue 13,
/// part 3): one command id per line, appended and fsynced before the command goes out. A
/// restarted monitor reads it back (`ExecutionMonitor::resume`) so that a command it sent is
/// never executed as new again. A torn last line (a crash in the middle of a write) is dropped:
/// that command had not been sent yet.

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "tamp/core/append_file.h"
#include "tamp/core/error.h"

namespace tamp::execution_monitor {

class SentJournal {
 public:
  /// Opens (creating if missing) the journal at `path` and reads the ids already in it.
  /// kIo naming the file when it cannot be read or opened for appending.
  static Result<SentJournal> open(const std::filesystem::path& path);
  SentJournal(SentJournal&& other) noexcept = default;
  SentJournal& operator=(SentJournal&& other) noexcept = default;
  SentJournal(const SentJournal&) = delete;
  SentJournal& operator=(const SentJournal&) = delete;
  ~SentJournal() = default;

  /// The ids in the journal when it was opened, in order.
  const std::vector<std::string>& previous() const { return previous_; }
  /// Appends `command_id` (no newline in it) and fsyncs; a no-op for an id already in it.
  /// kIo when the write or the fsync fails (the caller must not send the command then).
  Status append(const std::string& command_id);
  const std::filesystem::path& path() const { return file_.path(); }

 private:
  SentJournal(AppendFile file, std::vector<std::string> previous);
  AppendFile file_;
  std::vector<std::string> previous_;
  std::set<std::string> ids_;
};

}  // namespace tamp::execution_monitor
