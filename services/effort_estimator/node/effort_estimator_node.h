#pragma once
/// @file
/// The effort estimator as a DDS service: a thin adapter around
/// `tamp::effort_estimator::EffortEstimator` (idl/effort.idl).
///
/// - Serves `services::kEffort` ("tamp/effort_estimator/estimate"): a batch of queries
///   (msg::EffortRequest) is priced against one model snapshot (`estimateBatch`), each query with
///   its own mean, stddev and status. A malformed query (kind out of range, path values not a
///   multiple of its joints, negative mass, a path given to pick/place, ...) gets
///   STATUS_INVALID_ARGUMENT in its `EffortEstimate::code` and a message naming the IDL field
///   ("queries[2].path.values: ..."); the other queries are answered and the reply header is OK.
///   Estimates read an immutable snapshot: they never wait for a refit.
/// - Reads `topics::kExecutionRecords` ("tamp/execution/record"): each record is validated by the
///   library; a rejected one is logged with the reason and counted (`counters()`), an accepted one
///   is stored (SQLite under the params' `store_directory`) and queued. The library's worker thread
///   refits in batches (`refit_batch_size` records of a kind, or `refit_period_s`), never on a DDS
///   thread.
/// - Acknowledges every record with an id on `topics::kRecordAcks` once it holds it (stored now,
///   or before: the store keeps an id once) or refuses it for good (invalid): the execution
///   monitor sends a record again until then, so records arrive exactly once across restarts.
/// - Publishes `topics::kEffortModel` ("tamp/effort/model", RELIABLE + TRANSIENT_LOCAL, keyed by
///   `model_id` = the node name): once at start-up (the models loaded from the store, or the
///   priors) and after every refit, from the refit worker. Late joiners get the current snapshot.
///   Snapshots go out in version order (an older one is never published after a newer one).

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "tamp/dds/service_node.h"
#include "tamp/msg_validation/validate.h"
#include "tamp/effort_estimator/effort_estimator.h"

namespace tamp::effort_estimator {

/// msg::EffortQuery -> ActionDescription. Checks what the IDL cannot (the kind's range, the path's
/// shape); the rest is checked by the estimator. Errors are kInvalidArgument and `where.field`
/// names the IDL field under `field` (e.g. "queries[3].path.values").
Result<ActionDescription> fromMsg(const msg::EffortQuery& m, const std::string& field = "query");
/// msg::ExecutionRecord -> ExecutionRecord (stamp_ns -> timestamp_s). Errors as above.
Result<ExecutionRecord> fromMsg(const msg::ExecutionRecord& m, const std::string& field = "record");
/// ActionDescription -> msg::EffortQuery (for clients and tests).
msg::EffortQuery toMsg(const ActionDescription& a);
/// ExecutionRecord -> msg::ExecutionRecord (for publishers and tests).
msg::ExecutionRecord toMsg(const ExecutionRecord& r);
/// A model snapshot as published; `model_id` is the instance key, `stamp_ns` the publication time.
msg::EffortModelSnapshot toMsg(const ModelSnapshot& s, const std::string& model_id);
/// The library's field path of an error ("action.object_mass_kg", "timestamp_s", ...) as the IDL
/// field it came from ("object_mass", "stamp_ns", ...), prefixed with `prefix` + ".".
std::string idlField(const std::string& library_field, const std::string& prefix);

class EffortEstimatorNode : public dds::ServiceNode {
 public:
  /// For serviceMain: parameters from `args.config_file` (default:
  /// configDir()/services/effort_estimator.yaml); errors name file, line, column and field.
  static Result<std::unique_ptr<dds::ServiceNode>> create(const dds::ServiceArgs& args);
  /// With parameters in hand (tests, embedded use). Throws std::invalid_argument if
  /// `params.validate()` fails and std::runtime_error when DDS fails.
  EffortEstimatorNode(const dds::ServiceArgs& args, EstimatorParams params);
  ~EffortEstimatorNode() override;

  /// The request handler (public for tests and benchmarks).
  msg::EffortReply handle(const msg::EffortRequest& req, const dds::RequestContext& ctx);
  /// The record handler (what the topic's callback calls): ok, or why the record was rejected.
  Status handleRecord(const msg::ExecutionRecord& m);

  const EffortEstimator& estimator() const { return *estimator_; }
  EffortEstimator& estimator() { return *estimator_; }
  /// Records that failed conversion or validation (logged with the reason), since start.
  std::uint64_t recordsRejected() const;
  /// Snapshot version last published on tamp/effort/model.
  std::uint64_t publishedVersion() const;

 protected:
  std::pair<uint64_t, uint64_t> requestCounters() const override;

 private:
  msgv::RejectLog rejects_{"effort_estimator"};  // malformed input: logged once per kind, rate-limited
  void publishSnapshot(const std::shared_ptr<const ModelSnapshot>& snapshot);
  /// The record topic's callback: handleRecord, then the acknowledgement.
  void onRecord(const msg::ExecutionRecord& m);

  // Destroyed in reverse order: the server and the record reader first (their threads call the
  // estimator), then the estimator (its worker calls publishSnapshot), then the writer.
  std::unique_ptr<dds::Writer<msg::EffortModelSnapshot>> model_writer_;
  mutable std::mutex publish_mu_;  // orders snapshots; guards published_version_/published_any_
  std::uint64_t published_version_{0};
  bool published_any_{false};
  std::atomic<std::uint64_t> records_rejected_{0};
  std::unique_ptr<EffortEstimator> estimator_;
  std::unique_ptr<dds::Writer<msg::RecordAck>> ack_writer_;
  std::unique_ptr<dds::Reader<msg::ExecutionRecord>> record_reader_;
  std::unique_ptr<dds::RpcServer<msg::EffortRequest, msg::EffortReply>> server_;
};

}  // namespace tamp::effort_estimator
