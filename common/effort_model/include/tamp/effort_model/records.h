#pragma once
/// @file
/// Execution records: what the executive (or the simulator) reports after running an action, and
/// the validated, feature-reduced form the estimator stores and fits on.

#include <cstdint>
#include <string>

#include "tamp/core/error.h"
#include "tamp/effort_model/features.h"

namespace tamp::effort_model {

/// One executed action and how long it took. Maps field by field to an IDL struct.
struct ExecutionRecord {
  ActionDescription action;   ///< what was executed (kind, path or distances, object mass)
  double duration_s{0.0};     ///< measured execution time, s; must be finite and > 0
  double timestamp_s{0.0};    ///< when it finished, seconds since the Unix epoch; finite, >= 0
  std::string source;         ///< who measured it ("sim", "robot1/execution_monitor", ...)
  /// False for an action that failed or was aborted: its duration is not an execution time of
  /// the action, so the record is rejected (with that reason) rather than fitted.
  bool success{true};
  /// Optional unique id (e.g. the DDS sample's id). A record whose non-empty id was already
  /// accepted is ignored, so a re-delivered record is not counted twice.
  std::string record_id;
};

/// A validated record reduced to features (what the store keeps and the fits use).
struct FeatureRecord {
  ActionFeatures features;
  double duration_s{0.0};
  double timestamp_s{0.0};
  std::string source;
  std::string record_id;

  friend bool operator==(const FeatureRecord&, const FeatureRecord&) = default;
};

/// Largest duration a record may have unless configured otherwise (s): one hour.
inline constexpr double kDefaultMaxRecordDurationS = 3600.0;

/// Validates a record and extracts its features.
/// @param max_duration_s records longer than this are rejected (a stuck action is not an
///   execution time).
/// @param options robot-specific feature options (see extractFeatures).
/// @return the feature record, or a kInvalidArgument error whose message gives the reason and
///   whose `where.field` names the offending field ("duration_s", "action.path.waypoints[3]", ...).
Result<FeatureRecord> toFeatureRecord(const ExecutionRecord& record,
                                      double max_duration_s = kDefaultMaxRecordDurationS,
                                      const FeatureOptions& options = {});

/// Checks a feature record (e.g. one read back from a store) with the same rules.
Status validateFeatureRecord(const FeatureRecord& record,
                             double max_duration_s = kDefaultMaxRecordDurationS);

}  // namespace tamp::effort_model
