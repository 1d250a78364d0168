#pragma once
/// @file
/// Persistence of execution records and fitted models in one SQLite file,
/// `<directory>/effort_store.sqlite` (WAL journal), so that both survive a restart.
///
/// Opening never fails the service: a missing directory is created; a file that is not a
/// database of this schema (corrupt, truncated, foreign) is moved aside to
/// `<file>.corrupt-<unix seconds>` and a fresh store is created; a directory that cannot be
/// created or written leaves the store in memory only. Every such case is a clear message in
/// `StoreOpenResult::warnings`, and the estimator starts from its default models. Rows that fail
/// validation (e.g. edited by hand) are skipped, each with a warning naming the row.

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/effort_estimator/fitting.h"
#include "tamp/effort_estimator/records.h"

namespace tamp::effort_estimator {

class EffortStore;

/// What opening a store found.
struct StoreOpenResult {
  std::unique_ptr<EffortStore> store;  ///< never null
  std::vector<FeatureRecord> records;  ///< valid stored records, oldest first
  std::vector<KindModel> models;       ///< valid stored models (at most one per kind)
  std::vector<std::string> warnings;   ///< what went wrong and what was done about it
  std::size_t rows_skipped{0};         ///< invalid record/model rows ignored
};

/// The SQLite store. Not thread-safe: one owner (the estimator serialises access).
class EffortStore {
 public:
  /// File name inside the store directory.
  static constexpr const char* kFileName = "effort_store.sqlite";
  /// Schema version written to the store's meta table; another version is treated as foreign.
  static constexpr int kSchemaVersion = 1;

  /// Opens (or creates) the store in `directory` and reads it back. See the file comment for
  /// what happens on a missing directory or a corrupt file. `max_record_duration_s` is the limit
  /// applied when validating stored records.
  static StoreOpenResult open(const std::filesystem::path& directory,
                              double max_record_duration_s = kDefaultMaxRecordDurationS);
  /// A store that keeps nothing.
  static std::unique_ptr<EffortStore> inMemory();

  ~EffortStore();
  EffortStore(const EffortStore&) = delete;
  EffortStore& operator=(const EffortStore&) = delete;

  /// True when records and models are written to disk.
  bool persistent() const;
  /// The database file (empty when in memory only).
  const std::filesystem::path& file() const { return file_; }

  /// Appends a record (durably, before returning). kIo on a write failure; a no-op in memory.
  Status appendRecord(const FeatureRecord& record);
  /// Replaces the stored model of `model.kind`. kIo on a write failure; a no-op in memory.
  Status saveModel(const KindModel& model);

 private:
  struct Impl;
  explicit EffortStore(std::unique_ptr<Impl> impl, std::filesystem::path file);
  std::unique_ptr<Impl> impl_;
  std::filesystem::path file_;
};

}  // namespace tamp::effort_estimator
