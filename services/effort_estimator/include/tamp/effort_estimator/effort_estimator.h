#pragma once
/// @file
/// The effort estimator: predicted execution time (the paper's "effort") of robot actions, with
/// its uncertainty, from physical time models refitted online to measured executions.
///
/// Design overview
/// ---------------
/// In "Conditional Task and Motion Planning through an Effort-Based Approach"
/// (spec/conditional-tamp-effort-based.tex) the plan choice minimises the effort of the
/// reachability graph's branches, and the effort of an action is the execution time of its
/// trajectory, Effort(t_i | a_i). This library prices every edge the graph manager asks about and
/// learns from every action the robot executes (the paper's loop step 5, docs/architecture.md).
///
/// - **Models** (`models.h`): one small physical model per action kind (move_base stop-and-turn
///   with trapezoidal profiles, move_arm synchronized joint trapezoids, pick/place approach +
///   gripper + retreat with a payload slowdown), with named parameters, defaults and bounds, and
///   exposed as pure functions of (features, parameters) so that the simulator computes "true"
///   durations with its own parameters, which the fits never see.
/// - **Features** (`features.h`): a path is reduced once to sorted move lengths with prefix sums;
///   a prediction is then O(log n) and allocation-free (`estimate(ActionFeatures)` ~ 0.1-1 us,
///   see docs/benchmarks.md).
/// - **Fits** (`fitting.h`): Ceres, MAP in log-parameters with bounds, a robust loss (Cauchy or
///   Huber) on log-time residuals, a Gaussian prior toward the defaults (so few or unexciting
///   records give sane values), a robust noise estimate, and ceres::Covariance; every estimate
///   has a stddev from the parameter covariance (propagated through the model's gradient) plus
///   the execution noise.
/// - **Online refit**: `addRecord()` validates, persists and queues a record; a background worker
///   refits a kind when `refit_batch_size` records of it are pending or the oldest pending record
///   is `refit_period_s` old. Estimates read an immutable `ModelSnapshot` through an atomic
///   shared_ptr: they never wait for a fit, and a refit publishes a whole new snapshot whose kind
///   version (and the snapshot version) is one higher.
/// - **Persistence** (`store.h`): records and models in SQLite under a configurable directory;
///   a corrupt or missing store is a clear warning and the service starts from defaults.
///
/// The library knows nothing of DDS. The request/record/snapshot types are flat value types that
/// map field by field to IDL messages, and every call is safe from any thread, so the DDS node is
/// a thin mapping: estimate requests -> `estimate()`, execution records -> `addRecord()`,
/// `setModelUpdateCallback()` -> publish the snapshot (transient-local).

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <stop_token>
#include <string>
#include <thread>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/termination.h"
#include "tamp/effort_estimator/features.h"
#include "tamp/effort_estimator/fitting.h"
#include "tamp/effort_estimator/models.h"
#include "tamp/effort_estimator/params.h"
#include "tamp/effort_estimator/records.h"

namespace tamp::effort_estimator {

/// An estimate request: the action to price (kind, path or approach/retreat, object mass).
using EstimateRequest = ActionDescription;

/// All kinds' models at one moment. Immutable once published.
struct ModelSnapshot {
  /// +1 per published refit of any kind; equals the sum of the kinds' versions, so it keeps
  /// increasing across restarts.
  std::uint64_t version{0};
  /// One per kind, in `kAllActionKinds` order.
  std::vector<KindModel> models;

  /// @throws std::invalid_argument for a kind not in the snapshot.
  const KindModel& model(ActionKind kind) const&;
  /// On a temporary (`est.snapshot().model(k)`) a copy, so that no reference dangles.
  KindModel model(ActionKind kind) &&;
};

/// Estimates of many requests against one snapshot (the graph manager prices many edges at once).
struct BatchEstimate {
  std::vector<Result<Estimate>> estimates;  ///< one per request, in order
  std::uint64_t snapshot_version{0};        ///< ModelSnapshot::version all estimates used
};

/// Result of one kind's refit (for logs, the CLI and tests).
struct RefitReport {
  ActionKind kind{ActionKind::kMoveBase};
  Status status;               ///< ok, or why the fit failed (the previous model is kept)
  std::uint64_t version{0};    ///< the kind's version after the refit
  std::size_t record_count{0};
};

/// Whether `measured_s` is more than `sigma` of `e`'s stddevs (at least 5 % of its mean) from its
/// mean: the robot showed the model wrong (EstimatorParams::surprise_sigma). False for sigma <= 0.
bool surprising(const Estimate& e, double measured_s, double sigma);

/// Counters for the node's heartbeat.
struct EstimatorCounters {
  std::uint64_t estimates{0};
  std::uint64_t records_accepted{0};
  std::uint64_t records_rejected{0};
  std::uint64_t records_duplicate{0};
  std::uint64_t refits{0};
  std::uint64_t surprises{0};  ///< records refitted at once (EstimatorParams::surprise_sigma)
  std::uint64_t refit_failures{0};
  std::uint64_t store_write_failures{0};
};

class EffortEstimator {
 public:
  /// Opens the store (`resolveStoreDirectory(params.store_directory)`), loads its records and
  /// models (kinds without a valid stored model start from their prior), and, if `start_worker`,
  /// starts the background refit worker. Problems with the store do not fail construction: they
  /// are in `startupWarnings()` (and logged) and the estimator runs from defaults.
  /// Records loaded without a model newer than them are refitted by the worker (or refitNow()).
  /// @throws std::invalid_argument if `params.validate()` fails (misuse: load params first).
  explicit EffortEstimator(EstimatorParams params, bool start_worker = true);
  /// Stops the worker (a fit in progress is cancelled through its stop token).
  ~EffortEstimator();
  EffortEstimator(const EffortEstimator&) = delete;
  EffortEstimator& operator=(const EffortEstimator&) = delete;

  /// Predicted execution time of an action. Thread-safe, lock-free with respect to fits.
  /// @return the estimate, or kInvalidArgument naming what is wrong with the request.
  Result<Estimate> estimate(const EstimateRequest& request) const;
  /// Estimates every request against the same snapshot (consistent even while a refit
  /// publishes). Thread-safe; a bad request gives its own error and does not affect the others.
  BatchEstimate estimateBatch(std::span<const EstimateRequest> requests) const;
  /// Same from precomputed features (validated by `extractFeatures`): the cheap path for callers
  /// that price the same edge again after a refit.
  Estimate estimate(const ActionFeatures& features) const;

  /// Validates, stores and queues an execution record for the next refit of its kind; a
  /// surprising one (`surprising` against the current model) has its kind refitted at once.
  /// @return ok (also for a duplicate `record_id`, which is ignored), or kInvalidArgument with
  ///   the reason and `where.field` naming the bad field. Never blocks on a fit.
  Status addRecord(const ExecutionRecord& record);

  /// Refits, synchronously, every kind with records newer than its model (or every kind with
  /// records when `all`), under `termination`. Serialised with the worker.
  std::vector<RefitReport> refitNow(const Termination& termination = {}, bool all = false);

  /// The current models (a copy; cheap enough for a message).
  ModelSnapshot snapshot() const { return *snapshotPtr(); }
  std::shared_ptr<const ModelSnapshot> snapshotPtr() const { return snapshot_.load(); }

  /// Called (from the worker or refitNow's thread) after each published refit, with the new
  /// snapshot. For the node to publish it. Exceptions from the callback are caught and logged.
  void setModelUpdateCallback(std::function<void(std::shared_ptr<const ModelSnapshot>)> callback);

  /// Blocks until `kind`'s model version is at least `version` (published, and the update
  /// callback for it has returned) or `deadline` passes; true if reached. For tests and tools.
  bool waitForVersion(ActionKind kind, std::uint64_t version, Deadline deadline) const;

  /// Messages about the store found at construction (corrupt file moved aside, ...).
  const std::vector<std::string>& startupWarnings() const { return startup_warnings_; }
  /// True when records and models are written to disk.
  bool persistent() const;
  /// Records held for `kind` (loaded + accepted since start; capped at max_records_per_kind for fits).
  std::size_t recordCount(ActionKind kind) const;
  /// Records of `kind` accepted since its model was last fitted.
  std::size_t pendingCount(ActionKind kind) const;
  EstimatorCounters counters() const;
  const EstimatorParams& params() const { return params_; }

 private:
  struct State;
  void workerLoop(std::stop_token stop);
  RefitReport refitKind(std::size_t kind_index, const Termination& termination);
  void publish(const KindModel& model);

  EstimatorParams params_;
  std::vector<std::string> startup_warnings_;
  std::unique_ptr<State> state_;
  std::atomic<std::shared_ptr<const ModelSnapshot>> snapshot_;
  mutable std::atomic<std::uint64_t> estimates_{0};
  std::jthread worker_;  // last: stopped and joined before the members it uses are destroyed
};

}  // namespace tamp::effort_estimator
