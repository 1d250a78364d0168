#pragma once
/// @file
/// Parameters of the effort estimator service, loaded from YAML
/// (`config/services/effort_estimator.yaml`, every key optional):
///
///   store_directory: effort_estimator  # relative to the data dir (see resolveStoreDirectory); "" = none
///   refit_batch_size: 10       # new records of one kind that trigger a refit of that kind
///   refit_period_s: 30         # a pending record waits at most this long for its refit
///   surprise_sigma: 3          # a record this many stddevs off the model's estimate is refitted at once (0: never)
///   refit_time_budget_s: 5     # deadline of one kind's refit
///   max_records_per_kind: 5000 # the most recent records a refit uses
///   max_record_duration_s: 3600
///   loss: cauchy               # none | huber | cauchy
///   loss_scale: 2.0            # in noise stddevs
///   prior_weight: 1.0
///   prior_noise: 0.05          # stddev of log(duration) before any record (5 %)
///   prior_noise_weight: 5      # records' worth of prior_noise
///   max_iterations: 100
///   defaults:                  # robot-specific prior centres, by kind and parameter name
///     move_base: {max_linear_speed: 0.6}
///   arm_joint_scales:          # relative per-joint arm limits (URDF velocity limits), default 1
///     arm_joint_5: 1.2

#include <array>
#include <filesystem>
#include <string>

#include "tamp/core/error.h"
#include "tamp/effort_estimator/fitting.h"

namespace tamp::effort_estimator {

struct EstimatorParams {
  /// Directory of the SQLite store. A relative path is resolved by `resolveStoreDirectory`.
  /// Empty: no persistence.
  std::string store_directory{"effort_estimator"};
  int refit_batch_size{10};               ///< >= 1
  double refit_period_s{30.0};            ///< > 0
  /// A record whose duration is more than this many of the estimate's stddevs (at least 5 % of
  /// its mean, the graph manager's overrun rule) from the current model's estimate is refitted
  /// at once, without waiting for a batch or the period: the robot just showed the model wrong,
  /// and the next decisions should not wait for it. 0: never (batches and periods only). >= 0.
  double surprise_sigma{3.0};
  double refit_time_budget_s{5.0};        ///< > 0
  int max_records_per_kind{5000};         ///< >= 1
  double max_record_duration_s{kDefaultMaxRecordDurationS};  ///< > 0; longer records are rejected
  FitOptions fit;                         ///< loss, prior weight, prior noise, iterations
  /// Per-joint arm limit scales used to reduce paths (records and requests alike). Changing them
  /// does not re-reduce records already stored.
  FeatureOptions features;
  /// Prior per kind, in `kAllActionKinds` order; defaults from `modelSpec`, centres overridable.
  std::array<ModelPrior, 4> priors{ModelPrior::defaults(ActionKind::kMoveBase),
                                   ModelPrior::defaults(ActionKind::kMoveArm),
                                   ModelPrior::defaults(ActionKind::kPick),
                                   ModelPrior::defaults(ActionKind::kPlace)};

  const ModelPrior& prior(ActionKind kind) const;
  /// Ok, or one kInvalidArgument error naming every bad field.
  Status validate() const;
};

/// Loads parameters from a YAML file; every error names file, line, column and field, unknown
/// keys are refused. A missing file is kNotFound naming it.
Result<EstimatorParams> loadEstimatorParams(const std::filesystem::path& file);
/// Same, from YAML text; `name` is used as the file name in messages.
Result<EstimatorParams> parseEstimatorParams(const std::string& yaml_text, const std::string& name);

/// The directory a relative `store_directory` lives under: `$TAMP_DATA_DIR` if set, else
/// `$XDG_STATE_HOME/tamp`, else `$HOME/.local/state/tamp`, else `/tmp/tamp-state`.
std::filesystem::path dataDir();
/// `store_directory` made absolute against `dataDir()` (empty stays empty: no persistence).
std::filesystem::path resolveStoreDirectory(const std::string& store_directory);

}  // namespace tamp::effort_estimator
