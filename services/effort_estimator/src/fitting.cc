#include "tamp/core/format.h"
#include "tamp/effort_estimator/fitting.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <stdexcept>

#include "tamp/effort_model/model_math.h"
#include "tamp/effort_estimator/models.h"

namespace tamp::effort_estimator {
namespace {

Error invalidField(const std::string& field, const std::string& message) {
  return Error(ErrorCode::kInvalidArgument, message, SourceLocation{"", 0, 0, field});
}

/// Noise-normalised log residual of one record: (log T(exp(theta); f) - log y) / sigma.
template <int N>
struct LogResidual {
  const ActionFeatures* features;
  double log_duration;
  double inv_sigma;

  template <typename T>
  bool operator()(const T* theta, T* residual) const {
    using std::exp;
    using std::log;
    std::array<T, N> p;
    for (int i = 0; i < N; ++i) p[i] = exp(theta[i]);
    const T t = effort_model::detail::duration<T>(*features, p.data());
    if (!(effort_model::detail::scalarOf(t) > 0.0)) return false;  // cannot happen with positive parameters
    residual[0] = (log(t) - log_duration) * inv_sigma;
    return true;
  }
};

/// sqrt(w) * (theta - mu) / s: the Gaussian prior on log parameters, as N residuals.
template <int N>
struct PriorResidual {
  std::array<double, N> mu;
  std::array<double, N> scale;  // sqrt(w) / s

  template <typename T>
  bool operator()(const T* theta, T* residual) const {
    for (int i = 0; i < N; ++i) residual[i] = (theta[i] - mu[i]) * scale[i];
    return true;
  }
};

class TerminationCallback : public ceres::IterationCallback {
 public:
  explicit TerminationCallback(const Termination& t) : term_(t) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return term_() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }

 private:
  const Termination& term_;
};

/// The q-quantile of v (linear interpolation between order statistics), 0 <= q <= 1.
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(pos);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

/// Robust scale of residuals from the lower quartile of |r|: for Gaussian noise the 25 % quantile
/// of |r| is 0.31864 sigma. Its breakdown point is 75 %, so a burst of stalls (40 % of the records
/// of a short window have been seen in simulation) cannot inflate it, where the median absolute
/// residual (50 % breakdown) doubles sigma with every pass and ends up accepting the stalls.
double lowerQuartileScale(const std::vector<double>& abs_res) { return quantile(abs_res, 0.25) / 0.31864; }

Error stopError(const Termination& term) {
  return term.reason() == StopReason::kStopRequested
             ? Error(ErrorCode::kCancelled, "fit cancelled by a stop request")
             : Error(ErrorCode::kTimeout, "fit stopped at its deadline");
}

template <int N>
Result<KindModel> fitImpl(const KindModel& start, std::span<const FeatureRecord> records,
                          const ModelPrior& prior, const FitOptions& opt, const Termination& term) {
  const Stopwatch watch;
  const ModelSpec& spec = modelSpec(start.kind);
  std::array<double, N> lo{}, hi{}, theta{};
  PriorResidual<N> prior_res;
  const double sqrt_w = std::sqrt(opt.prior_weight);
  for (int i = 0; i < N; ++i) {
    lo[i] = std::log(spec.parameters[i].lower);
    hi[i] = std::log(spec.parameters[i].upper);
    // Start strictly inside the bounds (Ceres requires a feasible start).
    const double margin = 1e-9 * (hi[i] - lo[i]);
    theta[i] = std::clamp(std::log(start.values[i]), lo[i] + margin, hi[i] - margin);
    prior_res.mu[i] = std::log(prior.values[i]);
    prior_res.scale[i] = sqrt_w / prior.log_stddev[i];
  }
  std::vector<double> log_y(records.size());
  for (std::size_t i = 0; i < records.size(); ++i) log_y[i] = std::log(records[i].duration_s);

  // The noise estimate starts from the model's previous one (a refit) and is pooled with the prior.
  double sigma = start.noise_log_stddev > 0 ? start.noise_log_stddev : opt.prior_noise;
  KindModel out = start;
  out.summary = FitSummary{};
  std::vector<double> residuals(records.size());
  std::array<double, N * N> cov{};
  constexpr int kMaxPasses = 4;

  for (int pass = 1; pass <= kMaxPasses; ++pass) {
    // Graduated non-convexity: the Cauchy loss is not convex, and from a start far from the
    // truth (defaults off by 2x are ~15 noise stddevs) it can settle on a subset of the records
    // and call the rest outliers. The first pass uses the convex Huber loss to reach the right
    // basin; later passes use the configured loss from there.
    const bool convex = opt.loss == LossKind::kNone || opt.loss == LossKind::kHuber;
    const LossKind loss_now = pass == 1 && !convex ? LossKind::kHuber : opt.loss;
    if (term()) return stopError(term);
    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    for (std::size_t i = 0; i < records.size(); ++i) {
      auto* cost = new ceres::AutoDiffCostFunction<LogResidual<N>, 1, N>(
          new LogResidual<N>{&records[i].features, log_y[i], 1.0 / sigma});
      ceres::LossFunction* loss = nullptr;
      if (loss_now == LossKind::kHuber) loss = new ceres::HuberLoss(opt.loss_scale);
      if (loss_now == LossKind::kCauchy) loss = new ceres::CauchyLoss(opt.loss_scale);
      if (loss_now == LossKind::kTukey) loss = new ceres::TukeyLoss(opt.loss_scale);
      problem.AddResidualBlock(cost, loss, theta.data());
    }
    if (opt.prior_weight > 0.0 || records.empty()) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<PriorResidual<N>, N, N>(new PriorResidual<N>(prior_res)),
          nullptr, theta.data());
    }
    for (int i = 0; i < N; ++i) {
      problem.SetParameterLowerBound(theta.data(), i, lo[i]);
      problem.SetParameterUpperBound(theta.data(), i, hi[i]);
    }

    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    so.max_num_iterations = opt.max_iterations;
    so.function_tolerance = 1e-10;
    so.gradient_tolerance = 1e-12;
    so.parameter_tolerance = 1e-10;
    so.num_threads = 1;
    if (!term.deadline().isNever()) {
      so.max_solver_time_in_seconds = std::max(1e-3, term.deadline().secondsLeft());
    }
    TerminationCallback callback(term);
    so.callbacks.push_back(&callback);
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    if (summary.termination_type == ceres::USER_FAILURE || term()) return stopError(term);
    if (summary.termination_type == ceres::FAILURE || !summary.IsSolutionUsable()) {
      return Error(ErrorCode::kInternal, "Ceres failed to fit the " +
                                             std::string(toString(start.kind)) +
                                             " model: " + summary.message);
    }
    out.summary.iterations += static_cast<int>(summary.iterations.size());
    out.summary.passes = pass;
    out.summary.converged = summary.termination_type == ceres::CONVERGENCE;
    out.summary.message = summary.message;

    // Posterior covariance of theta (Laplace approximation) with the current sigma.
    ceres::Covariance::Options co;
    co.algorithm_type = ceres::DENSE_SVD;
    co.null_space_rank = -1;
    co.num_threads = 1;
    ceres::Covariance covariance(co);
    std::vector<const double*> blocks{theta.data()};
    out.summary.covariance_ok =
        covariance.Compute(blocks, &problem) && covariance.GetCovarianceBlock(theta.data(), theta.data(), cov.data());
    if (!out.summary.covariance_ok) {
      cov.fill(0.0);
      for (int i = 0; i < N; ++i) {
        const double s = prior.log_stddev[i] / std::max(sqrt_w, 1e-6);
        cov[i * N + i] = s * s;
      }
    }

    // Re-estimate the noise from the residuals. A rough robust scale (lower quartile of |r|,
    // breakdown 75 %) sets a 3-sigma cut; the records inside it give the estimate, as the
    // posterior mode of an inverse-gamma prior worth `prior_noise_weight` records at
    // `prior_noise`: sigma^2 = (nu0 sigma0^2 + sum_in r^2) / (nu0 + n_in - p_eff), where
    // p_eff = p - trace(C * prior precision) is the number of parameters the data determine (the
    // residuals of a fit with as many parameters as records say nothing about the noise).
    std::array<double, N> p;
    for (int i = 0; i < N; ++i) p[i] = std::exp(theta[i]);
    std::vector<double> abs_res(records.size());
    double sum_sq = 0.0;
    for (std::size_t i = 0; i < records.size(); ++i) {
      residuals[i] = std::log(effort_model::detail::duration<double>(records[i].features, p.data())) - log_y[i];
      abs_res[i] = std::abs(residuals[i]);
      sum_sq += residuals[i] * residuals[i];
    }
    const double n = static_cast<double>(records.size());
    out.summary.rms_log_residual = records.empty() ? 0.0 : std::sqrt(sum_sq / n);
    double new_sigma = opt.prior_noise;
    if (!records.empty()) {
      double p_eff = N;
      for (int i = 0; i < N; ++i) p_eff -= cov[i * N + i] * prior_res.scale[i] * prior_res.scale[i];
      p_eff = std::clamp(p_eff, 0.0, static_cast<double>(N));
      const double cut = 3.0 * lowerQuartileScale(abs_res);
      double in_sq = 0.0;
      double n_in = 0.0;
      for (double a : abs_res) {
        if (a <= cut) {
          in_sq += a * a;
          n_in += 1.0;
        }
      }
      const double nu0 = opt.prior_noise_weight;
      const double dof = std::max(n_in - p_eff, 0.0);
      new_sigma = nu0 + dof > 0.0 ? std::sqrt((nu0 * opt.prior_noise * opt.prior_noise + in_sq) / (nu0 + dof))
                                  : opt.prior_noise;
      new_sigma = std::max(new_sigma, 1e-4);
    }
    // The fit and its covariance used `sigma`; keep them consistent: stop when the new estimate
    // agrees within 10 % (or at the pass cap), otherwise refit with the new noise level.
    if (std::getenv("TAMP_EFFORT_DEBUG")) {
      std::fprintf(stderr, "pass %d loss %d sigma %.4f -> %.4f theta:", pass, static_cast<int>(loss_now), sigma, new_sigma);
      for (int i = 0; i < N; ++i) std::fprintf(stderr, " %.3f", std::exp(theta[i]));
      std::fprintf(stderr, "\n  res:");
      for (double r : residuals) std::fprintf(stderr, " %.3f", r);
      std::fprintf(stderr, "\n");
    }
    // The Huber warm-up is pulled toward stalls: its residuals do not re-estimate the noise (an
    // inflated sigma would stop the Cauchy passes from rejecting the stalls).
    if (loss_now != opt.loss) continue;
    const bool settled = std::abs(new_sigma / sigma - 1.0) < 0.1;
    if (settled || pass == kMaxPasses) break;
    sigma = new_sigma;
  }

  int outliers = 0;
  for (double r : residuals) outliers += std::abs(r) > 3.0 * sigma ? 1 : 0;
  out.summary.outliers = outliers;
  out.values.assign(N, 0.0);
  for (int i = 0; i < N; ++i) out.values[i] = std::exp(theta[i]);
  out.log_covariance.assign(cov.begin(), cov.end());
  out.noise_log_stddev = sigma;
  out.version = start.version + 1;
  out.record_count = records.size();
  out.fitted_at_s =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  out.summary.solve_time_s = watch.seconds();
  return out;
}

}  // namespace

std::string_view toString(LossKind loss) {
  switch (loss) {
    case LossKind::kNone: return "none";
    case LossKind::kHuber: return "huber";
    case LossKind::kCauchy: return "cauchy";
    case LossKind::kTukey: return "tukey";
  }
  return "unknown";
}

std::optional<LossKind> lossKindFromString(std::string_view name) {
  for (LossKind k : {LossKind::kNone, LossKind::kHuber, LossKind::kCauchy, LossKind::kTukey}) {
    if (toString(k) == name) return k;
  }
  return std::nullopt;
}

Status FitOptions::validate() const {
  if (!lossKindFromString(toString(loss))) return invalidField("loss", "unknown loss");
  if (!(std::isfinite(loss_scale) && loss_scale > 0)) {
    return invalidField("loss_scale", "must be positive, got " + formatNumber(loss_scale));
  }
  if (!(std::isfinite(prior_weight) && prior_weight >= 0)) {
    return invalidField("prior_weight", "must be >= 0, got " + formatNumber(prior_weight));
  }
  if (!(std::isfinite(prior_noise) && prior_noise > 0 && prior_noise <= 2.0)) {
    return invalidField("prior_noise", "must be in (0, 2], got " + formatNumber(prior_noise));
  }
  if (!(std::isfinite(prior_noise_weight) && prior_noise_weight >= 0)) {
    return invalidField("prior_noise_weight", "must be >= 0, got " + formatNumber(prior_noise_weight));
  }
  if (max_iterations < 1) {
    return invalidField("max_iterations", "must be >= 1, got " + std::to_string(max_iterations));
  }
  return Status::Ok();
}

ModelPrior ModelPrior::defaults(ActionKind kind) {
  const ModelSpec& spec = modelSpec(kind);
  ModelPrior p;
  p.kind = kind;
  for (const auto& ps : spec.parameters) {
    p.values.push_back(ps.default_value);
    p.log_stddev.push_back(ps.prior_log_stddev);
  }
  return p;
}

Status ModelPrior::validate() const {
  const ModelSpec& spec = modelSpec(kind);
  const std::string k(toString(kind));
  if (static_cast<int>(values.size()) != spec.size() || static_cast<int>(log_stddev.size()) != spec.size()) {
    return invalidField(k, "prior needs " + std::to_string(spec.size()) + " values");
  }
  for (int i = 0; i < spec.size(); ++i) {
    const auto& ps = spec.parameters[i];
    if (!(values[i] >= ps.lower && values[i] <= ps.upper)) {
      return invalidField(k + "." + ps.name, "must be within [" + formatNumber(ps.lower) + ", " + formatNumber(ps.upper) +
                                                 "] " + ps.unit + ", got " + formatNumber(values[i]));
    }
    if (!(std::isfinite(log_stddev[i]) && log_stddev[i] > 0)) {
      return invalidField(k + "." + ps.name, "prior log stddev must be positive");
    }
  }
  return Status::Ok();
}

std::vector<double> KindModel::stddevs() const {
  std::vector<double> out(values.size(), 0.0);
  const std::size_t n = values.size();
  if (log_covariance.size() != n * n) return out;
  for (std::size_t i = 0; i < n; ++i) out[i] = values[i] * std::sqrt(std::max(0.0, log_covariance[i * n + i]));
  return out;
}

Status KindModel::validate() const {
  const ModelSpec& spec = modelSpec(kind);
  const std::string k(toString(kind));
  if (parameter_names != spec.names()) {
    std::string got;
    for (const auto& s : parameter_names) got += (got.empty() ? "" : ", ") + s;
    return invalidField(k + ".parameter_names", "expected the parameters of the current model, got [" + got + "]");
  }
  const std::size_t n = static_cast<std::size_t>(spec.size());
  if (values.size() != n) return invalidField(k + ".values", "expected " + std::to_string(n) + " values");
  for (std::size_t i = 0; i < n; ++i) {
    const auto& ps = spec.parameters[i];
    // A small tolerance: values are exp(log bound) after a fit.
    if (!(std::isfinite(values[i]) && values[i] >= ps.lower * (1 - 1e-9) && values[i] <= ps.upper * (1 + 1e-9))) {
      return invalidField(k + ".values." + ps.name, "outside [" + formatNumber(ps.lower) + ", " + formatNumber(ps.upper) + "]: " +
                                                        formatNumber(values[i]));
    }
  }
  if (log_covariance.size() != n * n) {
    return invalidField(k + ".log_covariance", "expected " + std::to_string(n * n) + " entries");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!(std::isfinite(log_covariance[i * n + i]) && log_covariance[i * n + i] >= 0)) {
      return invalidField(k + ".log_covariance", "diagonal must be finite and >= 0");
    }
    for (std::size_t j = 0; j < n; ++j) {
      const double a = log_covariance[i * n + j];
      const double b = log_covariance[j * n + i];
      if (!std::isfinite(a) || std::abs(a - b) > 1e-9 * (1 + std::abs(a))) {
        return invalidField(k + ".log_covariance", "must be finite and symmetric");
      }
    }
  }
  if (!(std::isfinite(noise_log_stddev) && noise_log_stddev > 0)) {
    return invalidField(k + ".noise_log_stddev", "must be positive, got " + formatNumber(noise_log_stddev));
  }
  return Status::Ok();
}

KindModel priorModel(const ModelPrior& prior, const FitOptions& options) {
  if (Status s = prior.validate(); !s) throw std::invalid_argument("priorModel: " + s.error().toString());
  const ModelSpec& spec = modelSpec(prior.kind);
  const std::size_t n = static_cast<std::size_t>(spec.size());
  KindModel m;
  m.kind = prior.kind;
  m.parameter_names = spec.names();
  m.values = prior.values;
  m.log_covariance.assign(n * n, 0.0);
  const double w = std::max(options.prior_weight, 1e-6);
  for (std::size_t i = 0; i < n; ++i) m.log_covariance[i * n + i] = prior.log_stddev[i] * prior.log_stddev[i] / w;
  m.noise_log_stddev = options.prior_noise;
  return m;
}

Result<KindModel> fitModel(const KindModel& start, std::span<const FeatureRecord> records,
                           const ModelPrior& prior, const FitOptions& options, const Termination& termination) {
  if (Status s = start.validate(); !s) throw std::invalid_argument("fitModel: start model: " + s.error().toString());
  if (Status s = prior.validate(); !s) throw std::invalid_argument("fitModel: prior: " + s.error().toString());
  if (Status s = options.validate(); !s) throw std::invalid_argument("fitModel: options: " + s.error().toString());
  require(prior.kind == start.kind, "fitModel: prior and start model are of different kinds");
  for (std::size_t i = 0; i < records.size(); ++i) {
    if (records[i].features.kind != start.kind) {
      return invalidField("records[" + std::to_string(i) + "]",
                          "record of kind '" + std::string(toString(records[i].features.kind)) +
                              "' in a fit of '" + std::string(toString(start.kind)) + "'");
    }
    if (Status s = validateFeatureRecord(records[i], std::numeric_limits<double>::infinity()); !s) {
      Error e = s.error();
      e.where.field = "records[" + std::to_string(i) + "]." + e.where.field;
      return e;
    }
  }
  if (records.empty() && options.prior_weight == 0.0) {
    return Error(ErrorCode::kInvalidArgument, "no records and no prior: nothing to fit");
  }
  try {
    switch (modelSpec(start.kind).size()) {
      case 4: return fitImpl<4>(start, records, prior, options, termination);
      case 5: return fitImpl<5>(start, records, prior, options, termination);
      case 6: return fitImpl<6>(start, records, prior, options, termination);
      case 7: return fitImpl<7>(start, records, prior, options, termination);
      default: break;
    }
  } catch (const std::exception& e) {
    return Error(ErrorCode::kInternal, std::string("fit failed: ") + e.what());
  }
  return Error(ErrorCode::kInternal, "no fit for a model of this size");
}

Estimate predict(const KindModel& model, const ActionFeatures& features) {
  require(model.kind == features.kind, "predict: model of '" + std::string(toString(model.kind)) +
                                           "' asked about a '" + std::string(toString(features.kind)) + "'");
  const std::size_t n = model.values.size();
  require(model.log_covariance.size() == n * n, "predict: malformed model covariance");
  std::array<double, kMaxModelParameters> g{};
  const double t = predictDurationWithLogGradient(features, model.values, g);
  double var_param = 0.0;  // variance of log T from the parameters: g' C g / t^2
  for (std::size_t i = 0; i < n; ++i) {
    double row = 0.0;
    for (std::size_t j = 0; j < n; ++j) row += model.log_covariance[i * n + j] * g[j];
    var_param += g[i] * row;
  }
  var_param = std::max(0.0, var_param) / (t * t);
  const double var_total = var_param + model.noise_log_stddev * model.noise_log_stddev;
  Estimate e;
  e.kind = model.kind;
  e.nominal_s = t;
  e.mean_s = t * std::exp(0.5 * var_total);
  e.stddev_s = e.mean_s * std::sqrt(std::expm1(var_total));
  e.parameter_stddev_s = t * std::exp(0.5 * var_param) * std::sqrt(std::expm1(var_param));
  e.model_version = model.version;
  return e;
}

}  // namespace tamp::effort_estimator
