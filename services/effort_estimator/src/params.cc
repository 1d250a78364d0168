#include "tamp/core/format.h"
#include "tamp/effort_estimator/params.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <vector>

#include "tamp/config/yaml_reader.h"
#include "tamp/core/paths.h"
#include "tamp/effort_estimator/models.h"

namespace tamp::effort_estimator {
namespace {

/// One rule per scalar field: (field name, ok?, message). Shared by validate() and the loader,
/// which attaches the YAML location of the field.
struct Rule {
  const char* field;
  bool ok;
  std::string message;
};

std::vector<Rule> scalarRules(const EstimatorParams& p) {
  const FitOptions& f = p.fit;
  return {
      {"refit_batch_size", p.refit_batch_size >= 1, "must be >= 1, got " + std::to_string(p.refit_batch_size)},
      {"refit_period_s", std::isfinite(p.refit_period_s) && p.refit_period_s > 0,
       "must be positive, got " + formatNumber(p.refit_period_s)},
      {"refit_time_budget_s", std::isfinite(p.refit_time_budget_s) && p.refit_time_budget_s > 0,
       "must be positive, got " + formatNumber(p.refit_time_budget_s)},
      {"max_records_per_kind", p.max_records_per_kind >= 1,
       "must be >= 1, got " + std::to_string(p.max_records_per_kind)},
      {"max_record_duration_s", std::isfinite(p.max_record_duration_s) && p.max_record_duration_s > 0,
       "must be positive, got " + formatNumber(p.max_record_duration_s)},
      {"loss_scale", std::isfinite(f.loss_scale) && f.loss_scale > 0, "must be positive, got " + formatNumber(f.loss_scale)},
      {"prior_weight", std::isfinite(f.prior_weight) && f.prior_weight >= 0,
       "must be >= 0, got " + formatNumber(f.prior_weight)},
      {"prior_noise", std::isfinite(f.prior_noise) && f.prior_noise > 0 && f.prior_noise <= 2.0,
       "must be in (0, 2] (stddev of log duration), got " + formatNumber(f.prior_noise)},
      {"prior_noise_weight", std::isfinite(f.prior_noise_weight) && f.prior_noise_weight >= 0,
       "must be >= 0, got " + formatNumber(f.prior_noise_weight)},
      {"max_iterations", f.max_iterations >= 1, "must be >= 1, got " + std::to_string(f.max_iterations)},
  };
}

}  // namespace

const ModelPrior& EstimatorParams::prior(ActionKind kind) const {
  for (const auto& p : priors) {
    if (p.kind == kind) return p;
  }
  throw std::invalid_argument("EstimatorParams: no prior for kind " + std::to_string(static_cast<int>(kind)));
}

Status EstimatorParams::validate() const {
  std::vector<Error> errors;
  for (const Rule& r : scalarRules(*this)) {
    if (!r.ok) errors.emplace_back(ErrorCode::kInvalidArgument, r.message, SourceLocation{"", 0, 0, r.field});
  }
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
  r.optional("store_directory", p.store_directory);
  r.optional("refit_batch_size", p.refit_batch_size);
  r.optional("refit_period_s", p.refit_period_s);
  r.optional("refit_time_budget_s", p.refit_time_budget_s);
  r.optional("max_records_per_kind", p.max_records_per_kind);
  r.optional("max_record_duration_s", p.max_record_duration_s);
  std::string loss(toString(p.fit.loss));
  if (r.optional("loss", loss)) {
    if (auto l = lossKindFromString(loss)) {
      p.fit.loss = *l;
    } else {
      r.fail("loss", "unknown loss '" + loss + "' (expected one of: none, huber, cauchy, tukey)");
    }
  }
  r.optional("loss_scale", p.fit.loss_scale);
  r.optional("prior_weight", p.fit.prior_weight);
  r.optional("prior_noise", p.fit.prior_noise);
  r.optional("prior_noise_weight", p.fit.prior_noise_weight);
  r.optional("max_iterations", p.fit.max_iterations);
  for (const Rule& rule : scalarRules(p)) r.check(rule.ok, rule.field, rule.message);

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
