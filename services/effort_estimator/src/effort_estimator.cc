#include "tamp/effort_estimator/effort_estimator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <unordered_set>

#include "tamp/core/log.h"
#include "tamp/effort_estimator/store.h"

namespace tamp::effort_estimator {
namespace {

constexpr std::size_t kKinds = kAllActionKinds.size();

/// Index of a kind in kAllActionKinds (and in ModelSnapshot::models).
std::size_t indexOf(ActionKind kind) {
  const auto it = std::find(kAllActionKinds.begin(), kAllActionKinds.end(), kind);
  if (it == kAllActionKinds.end()) {
    throw std::invalid_argument("unknown action kind " + std::to_string(static_cast<int>(kind)));
  }
  return static_cast<std::size_t>(it - kAllActionKinds.begin());
}

}  // namespace

KindModel ModelSnapshot::model(ActionKind kind) && { return static_cast<const ModelSnapshot&>(*this).model(kind); }

const KindModel& ModelSnapshot::model(ActionKind kind) const& {
  const std::size_t i = indexOf(kind);
  if (i >= models.size() || models[i].kind != kind) {
    throw std::invalid_argument("snapshot has no model of '" + std::string(toString(kind)) + "'");
  }
  return models[i];
}

struct EffortEstimator::State {
  // Records, pending counts, ids, counters, worker wake-up.
  mutable std::mutex mu;
  std::condition_variable_any cv;
  bool wake{false};
  std::array<std::deque<FeatureRecord>, kKinds> records;
  std::array<std::size_t, kKinds> pending{};
  std::array<Clock::time_point, kKinds> oldest_pending{};
  std::array<bool, kKinds> urgent{};  // a surprising record: refit now
  std::unordered_set<std::string> ids;
  EstimatorCounters counters;

  std::mutex store_mu;  // the store is single-threaded
  std::unique_ptr<EffortStore> store;

  std::mutex fit_mu;      // one fit at a time (worker and refitNow)
  std::mutex publish_mu;  // snapshot read-modify-write

  // waitForVersion: the version of each kind whose publication (callback included) is complete.
  mutable std::mutex version_mu;
  mutable std::condition_variable version_cv;
  std::array<std::uint64_t, kKinds> done_version{};

  std::mutex callback_mu;
  std::function<void(std::shared_ptr<const ModelSnapshot>)> callback;
};

EffortEstimator::EffortEstimator(EstimatorParams params, bool start_worker)
    : params_(std::move(params)), state_(std::make_unique<State>()) {
  if (Status s = params_.validate(); !s) throw std::invalid_argument(s.error().toString());
  auto log = tamp::log::get("effort_estimator");

  StoreOpenResult opened =
      EffortStore::open(resolveStoreDirectory(params_.store_directory), params_.max_record_duration_s);
  startup_warnings_ = std::move(opened.warnings);
  for (const auto& w : startup_warnings_) log->warn("{}", w);
  state_->store = std::move(opened.store);

  auto snap = std::make_shared<ModelSnapshot>();
  for (std::size_t k = 0; k < kKinds; ++k) snap->models.push_back(priorModel(params_.priors[k], params_.fit));
  for (auto& m : opened.models) snap->models[indexOf(m.kind)] = std::move(m);

  std::array<std::size_t, kKinds> totals{};
  const auto now = Clock::now();
  for (auto& r : opened.records) {
    const std::size_t k = indexOf(r.features.kind);
    ++totals[k];
    if (!r.record_id.empty()) state_->ids.insert(r.record_id);
    state_->records[k].push_back(std::move(r));
    if (state_->records[k].size() > static_cast<std::size_t>(params_.max_records_per_kind)) {
      state_->records[k].pop_front();
    }
  }
  snap->version = 0;
  for (std::size_t k = 0; k < kKinds; ++k) {
    const KindModel& m = snap->models[k];
    snap->version += m.version;
    // Records not covered by the stored model (e.g. accepted just before a crash) are refitted.
    state_->pending[k] = totals[k] - std::min<std::size_t>(totals[k], m.record_count);
    if (state_->pending[k] > 0) state_->oldest_pending[k] = now;
  }
  for (std::size_t k = 0; k < kKinds; ++k) state_->done_version[k] = snap->models[k].version;
  snapshot_.store(snap);
  log->info("effort estimator: store {}, {} records loaded, model versions {}/{}/{}/{}",
            state_->store->persistent() ? state_->store->file().string() : std::string("(memory only)"),
            opened.records.size(), snap->models[0].version, snap->models[1].version, snap->models[2].version,
            snap->models[3].version);
  if (start_worker) worker_ = std::jthread([this](std::stop_token stop) { workerLoop(std::move(stop)); });
}

EffortEstimator::~EffortEstimator() {
  if (worker_.joinable()) {
    worker_.request_stop();
    state_->cv.notify_all();
    worker_.join();
  }
}

Result<Estimate> EffortEstimator::estimate(const EstimateRequest& request) const {
  auto features = extractFeatures(request, params_.features);
  if (!features) return features.error();
  return estimate(*features);
}

BatchEstimate EffortEstimator::estimateBatch(std::span<const EstimateRequest> requests) const {
  const std::shared_ptr<const ModelSnapshot> snap = snapshot_.load();
  BatchEstimate out;
  out.snapshot_version = snap->version;
  out.estimates.reserve(requests.size());
  for (const EstimateRequest& r : requests) {
    auto features = extractFeatures(r, params_.features);
    if (!features) {
      out.estimates.emplace_back(features.error());
    } else {
      out.estimates.emplace_back(predict(snap->models[indexOf(features->kind)], *features));
    }
  }
  estimates_.fetch_add(requests.size(), std::memory_order_relaxed);
  return out;
}

Estimate EffortEstimator::estimate(const ActionFeatures& features) const {
  const std::shared_ptr<const ModelSnapshot> snap = snapshot_.load();
  estimates_.fetch_add(1, std::memory_order_relaxed);
  return predict(snap->models[indexOf(features.kind)], features);
}

bool surprising(const Estimate& e, double measured_s, double sigma) {
  if (!(sigma > 0) || !(e.mean_s > 0) || !std::isfinite(measured_s)) return false;
  return std::abs(measured_s - e.mean_s) > sigma * std::max(e.stddev_s, 0.05 * e.mean_s);
}

Status EffortEstimator::addRecord(const ExecutionRecord& record) {
  auto log = tamp::log::get("effort_estimator");
  auto fr = toFeatureRecord(record, params_.max_record_duration_s, params_.features);
  if (!fr) {
    std::lock_guard lk(state_->mu);
    ++state_->counters.records_rejected;
    return fr.error();
  }
  const std::size_t k = indexOf(fr->features.kind);
  if (!fr->record_id.empty()) {
    std::lock_guard lk(state_->mu);
    if (!state_->ids.insert(fr->record_id).second) {
      ++state_->counters.records_duplicate;
      return Status::Ok();
    }
  }
  {
    std::lock_guard lk(state_->store_mu);
    if (Status s = state_->store->appendRecord(*fr); !s) {
      log->warn("record kept in memory only: {}", s.error().toString());
      std::lock_guard lk2(state_->mu);
      ++state_->counters.store_write_failures;
    }
  }
  // Against the model the robot was just priced with: far off, the kind is refitted at once.
  const Estimate before = predict(snapshot_.load()->models[k], fr->features);
  const bool surprise = surprising(before, fr->duration_s, params_.surprise_sigma);
  if (surprise) {
    log->info("record '{}' ({}): {:.2f} s against {:.2f} +- {:.2f} s estimated: refitting now", fr->record_id,
              toString(fr->features.kind), fr->duration_s, before.mean_s, before.stddev_s);
  }
  {
    std::lock_guard lk(state_->mu);
    auto& recs = state_->records[k];
    if (surprise) {
      state_->urgent[k] = true;
      ++state_->counters.surprises;
    }
    recs.push_back(std::move(*fr));
    if (recs.size() > static_cast<std::size_t>(params_.max_records_per_kind)) recs.pop_front();
    if (state_->pending[k]++ == 0) state_->oldest_pending[k] = Clock::now();
    ++state_->counters.records_accepted;
    state_->wake = true;
  }
  state_->cv.notify_all();
  return Status::Ok();
}

void EffortEstimator::workerLoop(std::stop_token stop) {
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(params_.refit_period_s));
  const auto batch = static_cast<std::size_t>(params_.refit_batch_size);
  std::unique_lock lk(state_->mu);
  while (!stop.stop_requested()) {
    const auto now = Clock::now();
    std::vector<std::size_t> due;
    std::optional<Clock::time_point> next_wake;
    for (std::size_t k = 0; k < kKinds; ++k) {
      if (state_->pending[k] == 0) continue;
      const auto when = state_->oldest_pending[k] + period;
      if (state_->pending[k] >= batch || now >= when || state_->urgent[k]) {
        state_->urgent[k] = false;
        due.push_back(k);
      } else if (!next_wake || when < *next_wake) {
        next_wake = when;
      }
    }
    if (due.empty()) {
      auto woken = [this] { return std::exchange(state_->wake, false); };
      if (next_wake) {
        state_->cv.wait_until(lk, stop, *next_wake, woken);
      } else {
        state_->cv.wait(lk, stop, woken);
      }
      continue;
    }
    lk.unlock();
    for (std::size_t k : due) {
      if (stop.stop_requested()) break;
      refitKind(k, Termination(Deadline::in(params_.refit_time_budget_s), stop));
    }
    lk.lock();
  }
}

RefitReport EffortEstimator::refitKind(std::size_t k, const Termination& termination) {
  auto log = tamp::log::get("effort_estimator");
  std::lock_guard fit_lock(state_->fit_mu);
  std::vector<FeatureRecord> records;
  std::size_t taken = 0;
  {
    std::lock_guard lk(state_->mu);
    records.assign(state_->records[k].begin(), state_->records[k].end());
    taken = state_->pending[k];
  }
  const std::shared_ptr<const ModelSnapshot> snap = snapshot_.load();
  const KindModel& current = snap->models[k];
  RefitReport report{kAllActionKinds[k], Status::Ok(), current.version, records.size()};
  if (records.empty()) return report;

  // Every refit starts from the prior (values and noise), not from the previous fit: the result
  // is then a function of the record set alone (reproducible, independent of the order and the
  // batching of records), and a poor early fit (e.g. a stall on the only loaded record of the
  // first five, taken for a payload effect, with an inflated noise estimate that then stops the
  // robust loss from rejecting stalls) cannot lock later fits into its basin. Fits take ~1 ms.
  KindModel start = priorModel(params_.priors[k], params_.fit);
  start.version = current.version;
  Result<KindModel> fitted = fitModel(start, records, params_.priors[k], params_.fit, termination);
  {
    std::lock_guard lk(state_->mu);
    // A cancelled fit leaves its records pending for the next run; any other outcome consumes
    // them (a failing fit is not retried in a tight loop; the next record triggers it again).
    if (fitted.ok() || fitted.error().code != ErrorCode::kCancelled) {
      state_->pending[k] -= std::min(state_->pending[k], taken);
      if (state_->pending[k] > 0) state_->oldest_pending[k] = Clock::now();
    }
    if (fitted.ok()) {
      ++state_->counters.refits;
    } else {
      ++state_->counters.refit_failures;
    }
  }
  if (!fitted) {
    log->warn("refit of '{}' failed, keeping version {}: {}", toString(kAllActionKinds[k]), current.version,
              fitted.error().toString());
    report.status = fitted.error();
    return report;
  }
  log->info("refit '{}' v{} on {} records: {} iterations, rms log residual {:.4f}, noise {:.4f}, {} outliers, {:.1f} ms",
            toString(fitted->kind), fitted->version, fitted->record_count, fitted->summary.iterations,
            fitted->summary.rms_log_residual, fitted->noise_log_stddev, fitted->summary.outliers,
            fitted->summary.solve_time_s * 1e3);
  {
    std::lock_guard lk(state_->store_mu);
    if (Status s = state_->store->saveModel(*fitted); !s) {
      log->warn("model kept in memory only: {}", s.error().toString());
      std::lock_guard lk2(state_->mu);
      ++state_->counters.store_write_failures;
    }
  }
  report.version = fitted->version;
  publish(*fitted);
  return report;
}

void EffortEstimator::publish(const KindModel& model) {
  std::shared_ptr<const ModelSnapshot> next;
  {
    std::lock_guard lk(state_->publish_mu);
    auto copy = std::make_shared<ModelSnapshot>(*snapshot_.load());
    copy->models[indexOf(model.kind)] = model;
    ++copy->version;
    next = copy;
    snapshot_.store(next);
  }
  std::function<void(std::shared_ptr<const ModelSnapshot>)> cb;
  {
    std::lock_guard lk(state_->callback_mu);
    cb = state_->callback;
  }
  if (cb) {
    try {
      cb(next);
    } catch (const std::exception& e) {
      tamp::log::get("effort_estimator")->error("model update callback threw: {}", e.what());
    } catch (...) {
      tamp::log::get("effort_estimator")->error("model update callback threw a non-standard exception");
    }
  }
  {
    std::lock_guard lk(state_->version_mu);
    state_->done_version[indexOf(model.kind)] = model.version;
  }
  state_->version_cv.notify_all();
}

std::vector<RefitReport> EffortEstimator::refitNow(const Termination& termination, bool all) {
  std::vector<RefitReport> out;
  for (std::size_t k = 0; k < kKinds; ++k) {
    bool due = false;
    {
      std::lock_guard lk(state_->mu);
      due = all ? !state_->records[k].empty() : state_->pending[k] > 0;
    }
    if (due) out.push_back(refitKind(k, termination));
  }
  return out;
}

void EffortEstimator::setModelUpdateCallback(std::function<void(std::shared_ptr<const ModelSnapshot>)> callback) {
  std::lock_guard lk(state_->callback_mu);
  state_->callback = std::move(callback);
}

bool EffortEstimator::waitForVersion(ActionKind kind, std::uint64_t version, Deadline deadline) const {
  const std::size_t k = indexOf(kind);
  std::unique_lock lk(state_->version_mu);
  auto reached = [&] { return state_->done_version[k] >= version; };
  if (deadline.isNever()) {
    state_->version_cv.wait(lk, reached);
    return true;
  }
  return state_->version_cv.wait_until(lk, deadline.time(), reached);
}

bool EffortEstimator::persistent() const {
  std::lock_guard lk(state_->store_mu);
  return state_->store->persistent();
}

std::size_t EffortEstimator::recordCount(ActionKind kind) const {
  std::lock_guard lk(state_->mu);
  return state_->records[indexOf(kind)].size();
}

std::size_t EffortEstimator::pendingCount(ActionKind kind) const {
  std::lock_guard lk(state_->mu);
  return state_->pending[indexOf(kind)];
}

EstimatorCounters EffortEstimator::counters() const {
  EstimatorCounters c;
  {
    std::lock_guard lk(state_->mu);
    c = state_->counters;
  }
  c.estimates = estimates_.load(std::memory_order_relaxed);
  return c;
}

}  // namespace tamp::effort_estimator
