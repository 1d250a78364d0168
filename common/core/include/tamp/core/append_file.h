#pragma once
/// @file
/// The file primitives shared by the append-only journals of the run folder (the execution
/// monitor's sent journal and record outbox) and by `writeFileAtomically` (paths.h): a file
/// opened for appending whole lines, each write completed across short writes and optionally
/// fdatasynced before returning; reading a file that may not exist yet; syncing a folder so that
/// a file just created or renamed in it survives a crash.
///
/// Every error is kIo naming the file, with the `what` given at open ("the execution monitor's
/// journal") and the system's reason: "cannot append to the execution monitor's journal: No space
/// left on device".

#include <cstddef>
#include <filesystem>
#include <string>

#include "tamp/core/error.h"

namespace tamp {

/// A file opened with O_APPEND (created 0644 if missing); owns the descriptor, move-only. A
/// default-constructed one is closed: `append` is a no-op that succeeds (an in-memory journal).
class AppendFile {
 public:
  AppendFile() = default;
  /// Opens `file` for appending, creating it if missing. kIo "cannot open <what> for appending"
  /// naming `file` (a missing folder, no permission).
  static Result<AppendFile> open(const std::filesystem::path& file, const std::string& what);
  AppendFile(AppendFile&& other) noexcept;
  AppendFile& operator=(AppendFile&& other) noexcept;
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;
  ~AppendFile();

  bool isOpen() const { return fd_ >= 0; }
  const std::filesystem::path& path() const { return path_; }

  /// Appends all of `text` (write() repeated over short and interrupted writes); with `sync`,
  /// fdatasync before returning, so that the text survives a crash once this returns ok. kIo
  /// "cannot append to <what>" / "cannot sync <what>". Ok without doing anything when closed.
  Status append(const std::string& text, bool sync);
  /// Cuts the file to its first `size` bytes (a torn last line). kIo "cannot cut the torn last
  /// line off <what>". Precondition: open.
  Status truncate(std::size_t size);

 private:
  AppendFile(std::filesystem::path path, std::string what, int fd);

  std::filesystem::path path_;
  std::string what_;
  int fd_{-1};
};

/// The whole content of `file`, or "" when it does not exist (a journal not written yet). kIo
/// "cannot read <what>" naming the file when it exists but cannot be opened.
Result<std::string> readFileIfExists(const std::filesystem::path& file, const std::string& what);

/// fsyncs the folder `dir` ("" is the working folder), so that a file created, truncated or
/// renamed in it is found after a crash. kIo "cannot open the folder of <what>" / "cannot sync
/// the folder of <what>" naming `dir`. Journals that can live without it ignore the status.
Status syncDirectory(const std::filesystem::path& dir, const std::string& what);

/// write() repeated until all of `text` is written to `fd` (short and EINTR-interrupted writes
/// resumed). false on an error, with errno set.
bool writeAll(int fd, const std::string& text);

}  // namespace tamp
