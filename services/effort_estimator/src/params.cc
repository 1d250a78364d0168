#include "tamp/core/format.h"
#include "tamp/effort_estimator/params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "tamp/config/schema.h"
#include "tamp/core/paths.h"
#include "tamp/effort_estimator/models.h"

namespace tamp::effort_estimator {
namespace {

using config::atLeast;
using config::Ends;
using config::inRange;
using config::nonNegative;
using config::positive;

/// The scalar fields; all at the top level of the file (the fit options too).
const config::Schema<EstimatorParams>& schema() {
  using P = EstimatorParams;
  static const config::Schema<P> kSchema = [] {
    config::Schema<P> s;
    s.root()
        .field("store_directory", &P::store_directory)
        .field("refit_batch_size", &P::refit_batch_size, atLeast(1))
        .field("refit_period_s", &P::refit_period_s, positive())
        .field("surprise_sigma", &P::surprise_sigma, nonNegative())
        .field("refit_time_budget_s", &P::refit_time_budget_s, positive())
        .field("max_records_per_kind", &P::max_records_per_kind, atLeast(1))
        .field("max_record_duration_s", &P::max_record_duration_s, positive());
    s.section("", &P::fit)
        .convert<std::string>(
            "loss", &FitOptions::loss,
            config::byName<LossKind>(lossKindFromString, "loss", "none, huber, cauchy, tukey"))
        .field("loss_scale", &FitOptions::loss_scale, positive())
        .field("prior_weight", &FitOptions::prior_weight, nonNegative())
        .field("prior_noise", &FitOptions::prior_noise,
               inRange(0, 2, Ends::kOpenClosed, "(stddev of log duration)"))
        .field("prior_noise_weight", &FitOptions::prior_noise_weight, nonNegative())
        .field("max_iterations", &FitOptions::max_iterations, atLeast(1));
    return s;
  }();
  return kSchema;
}

}  // namespace

const ModelPrior& EstimatorParams::prior(ActionKind kind) const {
  for (const auto& p : priors) {
    if (p.kind == kind) return p;
  }
  throw std::invalid_argument("EstimatorParams: no prior for kind " + std::to_string(static_cast<int>(kind)));
}

Status EstimatorParams::validate() const {
  std::vector<Error> errors = schema().errors(*this);
  for (std::size_t i = 0; i < priors.size(); ++i) {
    if (priors[i].kind != kAllActionKinds[i]) {
      errors.emplace_back(ErrorCode::kInvalidArgument, "priors must be in kAllActionKinds order",
                          SourceLocation{"", 0, 0, "defaults"});
    } else if (Status s = priors[i].validate(); !s) {
      Error e = s.error();
      e.where.field = "defaults." + e.where.field;
      errors.push_back(e);
    }
  }
  if (Status s = features.validate(); !s) {
    Error e = s.error();
    e.where.field = "arm_" + e.where.field;
    errors.push_back(e);
  }
  if (errors.empty()) return Status::Ok();
  return Error(ErrorCode::kInvalidArgument, "invalid effort estimator parameters:\n" + joinErrors(errors));
}

Result<EstimatorParams> parseEstimatorParams(const std::string& yaml_text, const std::string& name) {
  auto doc = config::parseYaml(yaml_text, name);
  if (!doc) return doc.error();
  EstimatorParams p;
  config::FieldReader r(*doc);
  schema().read(r, p);

  for (auto& [kind_name, kr] : r.entries("defaults", false)) {
    const auto kind = actionKindFromString(kind_name);
    if (!kind) {
      r.child("defaults").fail(kind_name, "unknown action kind '" + kind_name +
                                              "' (expected one of: move_base, move_arm, pick, place)");
      continue;
    }
    ModelPrior& prior = p.priors[static_cast<std::size_t>(std::find(kAllActionKinds.begin(), kAllActionKinds.end(), *kind) -
                                                          kAllActionKinds.begin())];
    const ModelSpec& spec = modelSpec(*kind);
    for (int i = 0; i < spec.size(); ++i) {
      const ParameterSpec& ps = spec.parameters[i];
      double v = prior.values[i];
      if (kr.optional(ps.name, v)) {
        if (kr.check(std::isfinite(v) && v >= ps.lower && v <= ps.upper, ps.name,
                     "must be within [" + formatNumber(ps.lower) + ", " + formatNumber(ps.upper) + "] " + ps.unit + ", got " + formatNumber(v))) {
          prior.values[i] = v;
        }
      }
    }
    kr.refuseUnknownKeys();
  }
  {
    config::FieldReader scales = r.child("arm_joint_scales", false);
    if (scales.isMap()) {
      for (auto it = scales.node().begin(); it != scales.node().end(); ++it) {
        const std::string joint = it->first.as<std::string>();
        double scale = 0.0;
        if (scales.required(joint, scale) &&
            scales.check(std::isfinite(scale) && scale > 0.0, joint, "must be positive, got " + formatNumber(scale))) {
          p.features.joint_scales[joint] = scale;
        }
      }
    }
  }
  r.refuseUnknownKeys();
  if (!r.ok()) return r.status().error();
  if (Status s = p.validate(); !s) return s.error();  // cannot happen after the checks above
  return p;
}

Result<EstimatorParams> loadEstimatorParams(const std::filesystem::path& file) {
  auto text = readTextFile(file);
  if (!text) return text.error();
  return parseEstimatorParams(*text, file.string());
}

std::filesystem::path dataDir() {
  auto env = [](const char* name) -> const char* {
    const char* v = std::getenv(name);
    return v != nullptr && *v != '\0' ? v : nullptr;
  };
  if (const char* d = env("TAMP_DATA_DIR")) return d;
  if (const char* d = env("XDG_STATE_HOME")) return std::filesystem::path(d) / "tamp";
  if (const char* d = env("HOME")) return std::filesystem::path(d) / ".local" / "state" / "tamp";
  return "/tmp/tamp-state";
}

std::filesystem::path resolveStoreDirectory(const std::string& store_directory) {
  if (store_directory.empty()) return {};
  const std::filesystem::path p(store_directory);
  return p.is_absolute() ? p : (dataDir() / p).lexically_normal();
}

}  // namespace tamp::effort_estimator
