#include "tamp/core/format.h"
#include "tamp/effort_model/records.h"

#include <cmath>
#include <cstdio>
#include <string>

namespace tamp::effort_model {
namespace {

Status checkScalars(double duration_s, double timestamp_s, double max_duration_s) {
  auto bad = [](std::string msg, std::string field) {
    return Error(ErrorCode::kInvalidArgument, std::move(msg), SourceLocation{"", 0, 0, std::move(field)});
  };
  if (std::isnan(duration_s)) return bad("duration is NaN", "duration_s");
  if (std::isinf(duration_s)) return bad("duration is infinite", "duration_s");
  if (duration_s <= 0.0) return bad("duration must be positive, got " + formatNumber(duration_s) + " s", "duration_s");
  if (duration_s > max_duration_s) {
    return bad("duration " + formatNumber(duration_s) + " s exceeds the limit of " + formatNumber(max_duration_s) + " s",
               "duration_s");
  }
  if (!std::isfinite(timestamp_s) || timestamp_s < 0.0) {
    return bad("timestamp must be finite and >= 0, got " + formatNumber(timestamp_s), "timestamp_s");
  }
  return Status::Ok();
}

}  // namespace

Result<FeatureRecord> toFeatureRecord(const ExecutionRecord& record, double max_duration_s,
                                      const FeatureOptions& options) {
  if (!record.success) {
    return Error(ErrorCode::kInvalidArgument,
                 "the action failed (success = false): its duration is not an execution time and is not fitted",
                 SourceLocation{"", 0, 0, "success"});
  }
  if (Status s = checkScalars(record.duration_s, record.timestamp_s, max_duration_s); !s) return s.error();
  auto features = extractFeatures(record.action, options);
  if (!features) {
    Error e = features.error();
    e.where.field = e.where.field.empty() ? "action" : "action." + e.where.field;
    return e;
  }
  return FeatureRecord{std::move(*features), record.duration_s, record.timestamp_s, record.source,
                       record.record_id};
}

Status validateFeatureRecord(const FeatureRecord& record, double max_duration_s) {
  if (Status s = checkScalars(record.duration_s, record.timestamp_s, max_duration_s); !s) return s;
  return validateFeatures(record.features);
}

}  // namespace tamp::effort_model
