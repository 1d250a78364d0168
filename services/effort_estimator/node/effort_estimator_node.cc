#include "effort_estimator_node.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#include "tamp/core/log.h"
#include "tamp/core/paths.h"
#include "tamp/dds/convert.h"

namespace tamp::effort_estimator {
namespace {

Error inputError(const std::string& field, const std::string& what) {
  return Error(ErrorCode::kInvalidArgument, what, SourceLocation{"", 0, 0, field});
}

Result<ActionKind> kindFromMsg(msg::ActionKind kind, const std::string& field) {
  const auto k = static_cast<long long>(kind);
  if (k < static_cast<long long>(msg::ACTION_MOVE_BASE) ||
      k > static_cast<long long>(msg::ACTION_PLACE)) {
    return inputError(field, "unknown action kind " + std::to_string(k));
  }
  return dds::fromMsg(kind);
}

/// `e` with its field renamed to the IDL field under `prefix`.
Error withIdlField(Error e, const std::string& prefix) {
  e.where.field = idlField(e.where.field, prefix);
  return e;
}

}  // namespace

std::string idlField(const std::string& library_field, const std::string& prefix) {
  std::string f = library_field;
  if (f.rfind(prefix + ".", 0) == 0 || f == prefix) return f;  // already an IDL path
  if (f.rfind("action.", 0) == 0) f = f.substr(7);
  if (f == "action") f.clear();
  if (f == "object_mass_kg") f = "object_mass";
  if (f == "timestamp_s") f = "stamp_ns";
  return f.empty() ? prefix : prefix + "." + f;
}

Result<ActionDescription> fromMsg(const msg::EffortQuery& m, const std::string& field) {
  ActionDescription a;
  auto kind = kindFromMsg(m.kind(), field + ".kind");
  if (!kind) return kind.error();
  a.kind = *kind;
  auto path = dds::fromMsg(m.path(), field + ".path");
  if (!path) return path.error();
  a.path = std::move(*path);
  a.object_mass_kg = m.object_mass();
  a.approach_m = m.approach_m();
  a.retreat_m = m.retreat_m();
  return a;
}

Result<ExecutionRecord> fromMsg(const msg::ExecutionRecord& m, const std::string& field) {
  ExecutionRecord r;
  auto kind = kindFromMsg(m.kind(), field + ".kind");
  if (!kind) return kind.error();
  r.action.kind = *kind;
  auto path = dds::fromMsg(m.path(), field + ".path");
  if (!path) return path.error();
  r.action.path = std::move(*path);
  r.action.object_mass_kg = m.object_mass();
  r.action.approach_m = m.approach_m();
  r.action.retreat_m = m.retreat_m();
  r.duration_s = m.duration_s();
  r.timestamp_s = static_cast<double>(m.stamp_ns()) * 1e-9;
  r.source = m.source();
  r.success = m.success();
  r.record_id = m.record_id();
  return r;
}

msg::EffortQuery toMsg(const ActionDescription& a) {
  msg::EffortQuery m;
  m.kind(dds::toMsg(a.kind));
  m.path(dds::toMsg(a.path));
  m.object_mass(a.object_mass_kg);
  m.approach_m(a.approach_m);
  m.retreat_m(a.retreat_m);
  return m;
}

msg::ExecutionRecord toMsg(const ExecutionRecord& r) {
  msg::ExecutionRecord m;
  m.record_id(r.record_id);
  m.kind(dds::toMsg(r.action.kind));
  m.path(dds::toMsg(r.action.path));
  m.object_mass(r.action.object_mass_kg);
  m.approach_m(r.action.approach_m);
  m.retreat_m(r.action.retreat_m);
  m.duration_s(r.duration_s);
  m.success(r.success);
  m.stamp_ns(static_cast<int64_t>(std::llround(r.timestamp_s * 1e9)));
  m.source(r.source);
  return m;
}

msg::EffortModelSnapshot toMsg(const ModelSnapshot& s, const std::string& model_id) {
  msg::EffortModelSnapshot m;
  m.model_id(model_id);
  m.version(s.version);
  m.stamp_ns(dds::nowNs());
  std::vector<msg::ActionTimeModel> models;
  models.reserve(s.models.size());
  for (const KindModel& k : s.models) {
    msg::ActionTimeModel t;
    t.kind(dds::toMsg(k.kind));
    t.parameter_names(k.parameter_names);
    t.values(k.values);
    t.log_covariance(k.log_covariance);
    t.noise_log_stddev(k.noise_log_stddev);
    t.version(k.version);
    t.record_count(static_cast<uint32_t>(std::min<std::uint64_t>(k.record_count, UINT32_MAX)));
    models.push_back(std::move(t));
  }
  m.models(std::move(models));
  return m;
}

Result<std::unique_ptr<dds::ServiceNode>> EffortEstimatorNode::create(
    const dds::ServiceArgs& args) {
  const std::filesystem::path file = args.config_file.empty()
                                         ? configDir() / "services" / "effort_estimator.yaml"
                                         : std::filesystem::path(args.config_file);
  auto params = loadEstimatorParams(file);
  if (!params) return params.error();
  // `tamp run --fresh`: a store of the run's own (the default models), whatever the config says.
  if (const char* fresh = std::getenv("TAMP_EFFORT_STORE"); fresh != nullptr && *fresh != '\0') {
    if (!std::filesystem::path(fresh).is_absolute()) {
      return Error(ErrorCode::kInvalidArgument, std::string("$TAMP_EFFORT_STORE must be an absolute directory, got '") +
                                                    fresh + "'");
    }
    params->store_directory = fresh;
  }
  return std::unique_ptr<dds::ServiceNode>(
      std::make_unique<EffortEstimatorNode>(args, std::move(*params)));
}

EffortEstimatorNode::EffortEstimatorNode(const dds::ServiceArgs& args, EstimatorParams params)
    : ServiceNode(args) {
  model_writer_ = std::make_unique<dds::Writer<msg::EffortModelSnapshot>>(
      participant(), dds::topics::kEffortModel);
  estimator_ = std::make_unique<EffortEstimator>(std::move(params));
  estimator_->setModelUpdateCallback(
      [this](std::shared_ptr<const ModelSnapshot> snapshot) { publishSnapshot(snapshot); });
  // The start-up snapshot (stored models or priors); a refit of records loaded from the store may
  // already have published a newer one, which publishSnapshot() keeps.
  publishSnapshot(estimator_->snapshotPtr());
  ack_writer_ = std::make_unique<dds::Writer<msg::RecordAck>>(participant(), dds::topics::kRecordAcks);
  record_reader_ = std::make_unique<dds::Reader<msg::ExecutionRecord>>(
      participant(), dds::topics::kExecutionRecords,
      [this](const msg::ExecutionRecord& m, const dds::SampleMeta&) { onRecord(m); });
  server_ = std::make_unique<dds::RpcServer<msg::EffortRequest, msg::EffortReply>>(
      participant(), dds::services::kEffort,
      [this](const msg::EffortRequest& req, const dds::RequestContext& ctx) {
        return handle(req, ctx);
      });
}

EffortEstimatorNode::~EffortEstimatorNode() {
  server_.reset();
  record_reader_.reset();
  ack_writer_.reset();
  estimator_.reset();  // joins the refit worker, whose callback publishes with model_writer_
  model_writer_.reset();
}

msg::EffortReply EffortEstimatorNode::handle(const msg::EffortRequest& req,
                                             const dds::RequestContext&) {
  if (Status bad = msgv::validateEnvelope(req); !bad.ok()) {
    rejects_.reject(dds::services::kEffort.name, bad.error());
    msg::EffortReply rep;
    rep.header().code(msg::STATUS_INVALID_ARGUMENT);
    rep.header().message(bad.error().message);
    return rep;
  }
  const auto& queries = req.queries();
  std::vector<msg::EffortEstimate> out(queries.size());
  std::vector<ActionDescription> actions;
  std::vector<size_t> index;
  actions.reserve(queries.size());
  index.reserve(queries.size());
  auto fail = [&out](size_t i, const Error& e) {
    out[i].code(dds::toMsg(e.code));
    out[i].message(e.toString());
  };
  for (size_t i = 0; i < queries.size(); ++i) {
    if (Status bad = msgv::validateQuery(queries[i], i); !bad.ok()) {
      rejects_.reject(dds::services::kEffort.name, bad.error());
      out[i].code(msg::STATUS_INVALID_ARGUMENT);
      out[i].message(bad.error().message);  // "EffortRequest.queries[i].<field>: <what>"
      continue;
    }
    auto a = fromMsg(queries[i], "queries[" + std::to_string(i) + "]");
    if (!a) {
      fail(i, a.error());
      continue;
    }
    actions.push_back(std::move(*a));
    index.push_back(i);
  }
  const BatchEstimate batch = estimator_->estimateBatch(actions);
  for (size_t j = 0; j < index.size(); ++j) {
    const size_t i = index[j];
    const Result<Estimate>& e = batch.estimates[j];
    if (!e) {
      fail(i, withIdlField(e.error(), "queries[" + std::to_string(i) + "]"));
      continue;
    }
    out[i].mean_s(e->mean_s);
    out[i].stddev_s(e->stddev_s);
    out[i].code(msg::STATUS_OK);
  }
  msg::EffortReply rep;
  rep.estimates(std::move(out));
  rep.model_version(batch.snapshot_version);
  rep.header().code(msg::STATUS_OK);
  return rep;
}

Status EffortEstimatorNode::handleRecord(const msg::ExecutionRecord& m) {
  if (Status bad = msgv::screen(m, dds::topics::kExecutionRecords.name, rejects_); !bad.ok()) {
    ++records_rejected_;
    return bad;
  }
  auto record = fromMsg(m, "record");
  Status s = record ? estimator_->addRecord(*record) : Status(record.error());
  if (s) return s;
  ++records_rejected_;
  Error e = withIdlField(s.error(), "record");
  tamp::log::get("effort_estimator")
      ->warn("rejected execution record '{}' from '{}': {}", m.record_id(), m.source(),
             e.toString());
  return e;
}

void EffortEstimatorNode::onRecord(const msg::ExecutionRecord& m) {
  const Status held = handleRecord(m);  // ok: stored now or before
  if (m.record_id().empty() || m.record_id().size() > msgv::Limits{}.max_id_length) return;
  msg::RecordAck ack;
  ack.record_id(m.record_id());
  ack.estimator(name());
  ack.stored(held.ok());
  if (Status s = ack_writer_->write(ack); !s) {
    tamp::log::get("effort_estimator")
        ->warn("acknowledgement of record '{}' not sent (it will come again): {}", m.record_id(),
               s.error().toString());
  }
}

void EffortEstimatorNode::publishSnapshot(const std::shared_ptr<const ModelSnapshot>& snapshot) {
  std::lock_guard lk(publish_mu_);
  if (published_any_ && snapshot->version <= published_version_) return;  // a newer one is out
  if (Status s = model_writer_->write(toMsg(*snapshot, name())); !s) {
    tamp::log::get("effort_estimator")
        ->error("cannot publish effort model v{}: {}", snapshot->version, s.error().toString());
    return;
  }
  published_any_ = true;
  published_version_ = snapshot->version;
}

std::uint64_t EffortEstimatorNode::recordsRejected() const { return records_rejected_.load(); }

std::uint64_t EffortEstimatorNode::publishedVersion() const {
  std::lock_guard lk(publish_mu_);
  return published_version_;
}

std::pair<uint64_t, uint64_t> EffortEstimatorNode::requestCounters() const {
  auto base = ServiceNode::requestCounters();
  if (!server_) return base;
  return {base.first + server_->served(), base.second + server_->failed() + server_->rejected()};
}

}  // namespace tamp::effort_estimator
