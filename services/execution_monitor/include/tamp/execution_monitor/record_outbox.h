#pragma once
/// @file
/// Execution records on their way to the effort estimator, kept until it acknowledges them
/// (issue 13, part 3: records reach the estimator exactly once, never lost when it restarts).
///
/// The monitor adds each record it forwards (appended and fsynced before the record goes out),
/// sends it again every `resend_period` until the estimator acknowledges its id, and drops it
/// then. The estimator stores a record id once and acknowledges every copy, so a resend is
/// harmless. With a file (a restarted monitor reads it back) the records not yet acknowledged
/// survive a restart of the monitor as well as of the estimator; without one (no run folder)
/// they survive the estimator's restarts only.
///
/// File: one line per event, `r <record id> <payload in hex>` when a record is added and
/// `a <record id>` when it is acknowledged. A torn last line (a crash in the middle of a write)
/// is dropped: a torn `r` line's record had not been sent yet, a torn `a` line costs one resend.
/// The payload is opaque here (the node keeps the serialized message in it).

#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "tamp/core/append_file.h"
#include "tamp/core/error.h"

namespace tamp::execution_monitor {

class RecordOutbox {
 public:
  struct Entry {
    std::string record_id;
    std::string payload;   ///< opaque bytes (the serialized record)
    double last_sent{0.0}; ///< s, the caller's clock; -inf before the first send
    int sends{0};
  };

  /// In memory only.
  RecordOutbox() = default;
  /// Opens (creating if missing) the outbox at `path` and reads back the records it holds that
  /// were never acknowledged (due at once). kIo naming the file when it cannot be read or opened;
  /// kParseError naming the file and line for a complete line that is not an event.
  static Result<RecordOutbox> open(const std::filesystem::path& path);
  RecordOutbox(RecordOutbox&& other) noexcept = default;
  RecordOutbox& operator=(RecordOutbox&& other) noexcept = default;
  RecordOutbox(const RecordOutbox&) = delete;
  RecordOutbox& operator=(const RecordOutbox&) = delete;
  ~RecordOutbox() = default;

  /// Keeps `record_id` (non-empty, no whitespace; throws std::invalid_argument otherwise) until it
  /// is acknowledged; with a file, durably before returning. false (nothing done) for an id
  /// already kept or acknowledged. kIo when the write or the fsync fails: the caller must not
  /// count on it then.
  Result<bool> add(const std::string& record_id, const std::string& payload);
  /// The estimator holds `record_id`: it is not sent again. True when it was waiting. An
  /// acknowledgement that cannot be written is only logged by the caller: the record is resent
  /// after a restart, and de-duplicated.
  bool acknowledge(const std::string& record_id);
  /// The records to send now: never sent, or last sent at or before `now - resend_period_s`
  /// (oldest first). Each is marked sent at `now`.
  std::vector<Entry> due(double now, double resend_period_s);
  /// Records waiting for an acknowledgement.
  std::size_t pending() const { return pending_.size(); }
  bool isPending(const std::string& record_id) const { return pending_.count(record_id) > 0; }
  /// Records acknowledged since the outbox was opened (read back from the file included).
  std::size_t acknowledged() const { return acked_.size(); }
  /// Empty when in memory.
  const std::filesystem::path& path() const { return file_.path(); }

 private:
  explicit RecordOutbox(AppendFile file) : file_(std::move(file)) {}

  AppendFile file_;  // closed when in memory
  std::map<std::string, Entry> pending_;
  std::vector<std::string> order_;  // ids in the order added (pending ones are sent in it)
  std::set<std::string> acked_;
};

}  // namespace tamp::execution_monitor
