#pragma once
/// @file
/// Fitting one action kind's time model to execution records (Ceres), and predicting with it.
///
/// The fit is a maximum-a-posteriori estimate of theta = log(parameters):
///   minimise  sum_i rho( ((log T(theta; f_i) - log y_i) / sigma)^2 )            (records)
///           + prior_weight * sum_j ((theta_j - log default_j) / prior_log_stddev_j)^2   (prior)
///   subject to log(lower_j) <= theta_j <= log(upper_j)
/// with rho a robust loss (Huber or Cauchy, bending at `loss_scale` noise stddevs). Residuals in
/// log time make the noise model multiplicative (an x % error weighs the same on a 2 s and on a
/// 60 s action). The prior keeps parameters that the records do not excite (only short moves say
/// nothing about the cruise speed) at their defaults with their prior uncertainty, so few records
/// give sane estimates. sigma, the noise stddev of log(duration), is estimated robustly from the
/// residuals (from the lower quartile of |r|, which tolerates up to 75 % stalls, corrected for the
/// effective number of parameters) and pooled
/// with `prior_noise` worth `prior_noise_weight` records; the fit is repeated until sigma settles.
/// With a non-convex loss (Cauchy, Tukey) the first pass uses the convex Huber loss to reach the
/// right basin from a start that may be far off (graduated non-convexity).
/// The covariance of theta is the inverse of the Gauss-Newton Hessian at the optimum
/// (ceres::Covariance, robustified Jacobian), i.e. the Laplace approximation of the posterior.
///
/// A prediction then has log-normal uncertainty: log T ~ N(log T(theta_hat), g' C g + sigma^2)
/// with g = d log T / d theta, which gives the mean and stddev of `Estimate`.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/termination.h"
#include "tamp/core/trajectory.h"
#include "tamp/effort_estimator/features.h"
#include "tamp/effort_estimator/records.h"

namespace tamp::effort_estimator {

/// Robust loss on the noise-normalised log residuals: none (least squares), Huber (convex,
/// bounded influence), Cauchy (influence decays as 1/r), Tukey (biweight: influence zero beyond
/// loss_scale, cost capped; the most aggressive against bursts of stalls).
enum class LossKind { kNone, kHuber, kCauchy, kTukey };
/// "none", "huber", "cauchy", "tukey".
std::string_view toString(LossKind loss);
std::optional<LossKind> lossKindFromString(std::string_view name);

/// Options of one fit. Defaults are the service defaults (config/services/effort_estimator.yaml).
struct FitOptions {
  LossKind loss{LossKind::kCauchy};
  double loss_scale{2.0};          ///< where the robust loss bends, in noise stddevs; > 0
  double prior_weight{1.0};        ///< scales the prior's information; >= 0 (0 = no prior)
  double prior_noise{0.05};        ///< stddev of log(duration) assumed before any record; > 0
  double prior_noise_weight{5.0};  ///< how many records prior_noise is worth; >= 0
  int max_iterations{100};         ///< Levenberg-Marquardt iterations per pass; >= 1

  /// Ok, or kInvalidArgument naming the bad field.
  Status validate() const;
};

/// How a fit went (diagnostics; published with the model).
struct FitSummary {
  bool converged{false};       ///< Ceres reported convergence in the final pass
  int iterations{0};           ///< LM iterations over all passes
  int passes{0};               ///< solver passes (noise re-estimation, Huber then Cauchy; 1-4)
  int outliers{0};             ///< records whose |log residual| exceeds 3 sigma
  double rms_log_residual{0};  ///< RMS of log(predicted / measured) over the records
  double solve_time_s{0};      ///< wall time of the whole fit, s
  bool covariance_ok{false};   ///< false: ceres::Covariance failed, the prior covariance is used
  std::string message;         ///< Ceres' termination message of the final pass
};

/// The prior of one kind's model: centre (physical units) and stddev of log(value) per parameter.
struct ModelPrior {
  ActionKind kind{ActionKind::kMoveBase};
  std::vector<double> values;
  std::vector<double> log_stddev;

  /// The defaults of `modelSpec(kind)`.
  static ModelPrior defaults(ActionKind kind);
  /// Ok, or kInvalidArgument when sizes differ or a value is outside its bounds.
  Status validate() const;
};

/// One kind's model state: fitted (or prior) parameters with their uncertainty. A value type,
/// mapped one to one to a DDS message.
struct KindModel {
  ActionKind kind{ActionKind::kMoveBase};
  std::vector<std::string> parameter_names;  ///< modelSpec(kind) order
  std::vector<double> values;                ///< physical units (modelSpec(kind).parameters[i].unit)
  /// Covariance of log(values), row-major n x n (dimensionless; sqrt of a diagonal entry is the
  /// relative stddev of that parameter).
  std::vector<double> log_covariance;
  double noise_log_stddev{0.05};  ///< stddev of log(measured / model duration)
  std::uint64_t version{0};       ///< 0 = prior (never fitted); +1 per successful refit
  std::uint64_t record_count{0};  ///< records the last fit used
  double fitted_at_s{0.0};        ///< Unix time of the last fit, s (0 = never)
  FitSummary summary;

  int size() const { return static_cast<int>(values.size()); }
  /// Approximate stddev of each parameter in its unit: value * sqrt(log variance).
  std::vector<double> stddevs() const;
  /// Ok, or kInvalidArgument naming what is inconsistent (names/sizes vs modelSpec, non-finite
  /// or out-of-bounds values, covariance not symmetric with a positive diagonal, bad noise).
  Status validate() const;
};

/// The model at its prior: values = prior centre, covariance = prior covariance, version 0.
KindModel priorModel(const ModelPrior& prior, const FitOptions& options);

/// Fits `start.kind`'s model to `records` (all of that kind), starting from `start.values` and its
/// noise estimate. The result has `start.version + 1` and `record_count = records.size()`.
/// @return the fitted model; kCancelled/kTimeout when `termination` fired (nothing is returned
///   half-fitted), kInvalidArgument when a record has another kind or is invalid, kInternal when
///   Ceres fails.
/// @throws std::invalid_argument if `start`, `prior` or `options` fail validate() (misuse).
Result<KindModel> fitModel(const KindModel& start, std::span<const FeatureRecord> records,
                           const ModelPrior& prior, const FitOptions& options,
                           const Termination& termination = {});

/// A predicted execution time with its uncertainty. Maps one to one to a DDS message.
struct Estimate {
  ActionKind kind{ActionKind::kMoveBase};
  double mean_s{0.0};              ///< expected execution time, s (log-normal mean)
  double stddev_s{0.0};            ///< total stddev, s: parameter uncertainty and execution noise
  double nominal_s{0.0};           ///< the model at the fitted parameters, s (predictive median)
  double parameter_stddev_s{0.0};  ///< the part of the stddev due to parameter uncertainty, s
  std::uint64_t model_version{0};  ///< KindModel::version used
};

/// Prediction of `model` for `features` (same kind). Cheap: O(log n) in the number of moves.
/// @throws std::invalid_argument if the kinds differ or the model is malformed (misuse).
Estimate predict(const KindModel& model, const ActionFeatures& features);

}  // namespace tamp::effort_estimator
