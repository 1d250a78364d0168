// tamp estimate show|fit|predict: inspect an effort estimator store, refit its models from the
// stored execution records, or price one action with them (issue 5).
// Exit codes: 0 ok, 20 fit timed out, 30 input error (bad config, store, request), 39 fit failed.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "tamp/core/log.h"
#include "tamp/core/paths.h"
#include "tamp/effort_estimator/effort_estimator.h"

namespace ee = tamp::effort_estimator;
using nlohmann::json;

namespace {

json modelJson(const ee::KindModel& m) {
  const ee::ModelSpec& spec = ee::modelSpec(m.kind);
  const std::vector<double> sd = m.stddevs();
  json params = json::array();
  for (int i = 0; i < m.size(); ++i) {
    params.push_back({{"name", m.parameter_names[i]},
                      {"unit", spec.parameters[i].unit},
                      {"value", m.values[i]},
                      {"stddev", sd[i]},
                      {"default", spec.parameters[i].default_value}});
  }
  return {{"kind", std::string(tamp::toString(m.kind))},
          {"version", m.version},
          {"record_count", m.record_count},
          {"noise_log_stddev", m.noise_log_stddev},
          {"fitted_at_s", m.fitted_at_s},
          {"parameters", params},
          {"log_covariance", m.log_covariance},
          {"fit",
           {{"converged", m.summary.converged},
            {"iterations", m.summary.iterations},
            {"outliers", m.summary.outliers},
            {"rms_log_residual", m.summary.rms_log_residual},
            {"covariance_ok", m.summary.covariance_ok}}}};
}

void printModel(const ee::KindModel& m, std::size_t held) {
  const ee::ModelSpec& spec = ee::modelSpec(m.kind);
  const std::vector<double> sd = m.stddevs();
  std::printf("%s: version %llu, fitted on %llu records (%zu held), noise %.1f %%%s\n",
              std::string(tamp::toString(m.kind)).c_str(), static_cast<unsigned long long>(m.version),
              static_cast<unsigned long long>(m.record_count), held, 100.0 * m.noise_log_stddev,
              m.version == 0 ? " (defaults)" : "");
  for (int i = 0; i < m.size(); ++i) {
    std::printf("  %-18s %10.4g +- %-10.3g %-8s (default %g)\n", m.parameter_names[i].c_str(), m.values[i], sd[i],
                spec.parameters[i].unit.c_str(), spec.parameters[i].default_value);
  }
}

/// "x,y,theta; x,y,theta; ..." -> waypoints.
bool parseWaypoints(const std::string& text, std::vector<std::vector<double>>& out, std::string& why) {
  std::stringstream rows(text);
  std::string row;
  while (std::getline(rows, row, ';')) {
    if (row.find_first_not_of(" \t") == std::string::npos) continue;
    std::vector<double> w;
    std::stringstream cols(row);
    std::string c;
    while (std::getline(cols, c, ',')) {
      try {
        std::size_t used = 0;
        w.push_back(std::stod(c, &used));
        if (c.find_first_not_of(" \t", used) != std::string::npos) throw std::invalid_argument(c);
      } catch (const std::exception&) {
        why = "not a number: '" + c + "' in waypoint " + std::to_string(out.size());
        return false;
      }
    }
    out.push_back(std::move(w));
  }
  return true;
}

/// Everything `tamp estimate`'s command line sets, with its defaults. Validated by the checks each
/// option is declared with (CLI11 refuses a value outside them).
struct EstimateCli {
  std::string config = (tamp::configDir() / "services" / "effort_estimator.yaml").string();
  std::string store;  // empty: the config's store_directory
  bool as_json = false;
  // fit
  bool all = false;
  double timeout = 60.0;
  // predict
  std::string kind_name, waypoints, joints;
  double approach = 0.0, retreat = 0.0, mass = 0.0;
};

/// The subcommands, to tell after parsing which one was given.
struct Subcommands {
  CLI::App* show;
  CLI::App* fit;
  CLI::App* predict;
};

constexpr const char* kAbout =
    "Inspect, refit or query the effort estimator's execution-time models.\n"
    "Exit codes: 0 ok, 20 fit timed out, 30 input error, 39 fit failed.";

/// `predict`'s options: the action to price.
void addPredictOptions(CLI::App& predict, EstimateCli& o) {
  predict.add_option("--kind", o.kind_name, "move_base, move_arm, pick or place")
      ->required()
      ->check(CLI::IsMember({"move_base", "move_arm", "pick", "place"}));
  predict.add_option("--waypoints", o.waypoints,
                     "path as 'v1,v2,...; v1,v2,...' (move_base: x,y,theta; move_arm: one value per --joints)");
  predict.add_option("--joints", o.joints, "move_arm joint names, comma-separated");
  predict.add_option("--approach", o.approach, "pick/place approach distance, m");
  predict.add_option("--retreat", o.retreat, "pick/place retreat distance, m");
  predict.add_option("--mass", o.mass, "object mass, kg");
}

/// Declares every option and subcommand of `tamp estimate` on `app`, bound to `o`, in the order
/// --help lists them; exactly one subcommand is required.
Subcommands defineOptions(CLI::App& app, EstimateCli& o) {
  app.require_subcommand(1);
  app.fallthrough();  // --config/--store/--json also after the subcommand
  app.add_option("--config", o.config, "service parameters (YAML)");
  app.add_option("--store", o.store, "store directory (overrides store_directory of the config)");
  app.add_flag("--json", o.as_json, "print JSON");

  Subcommands sub{};
  sub.show = app.add_subcommand("show", "print the stored models and record counts");
  sub.fit = app.add_subcommand("fit", "refit the models from the stored records and save them");
  sub.fit->add_flag("--all", o.all, "refit every kind with records, not only those with new records");
  sub.fit->add_option("--timeout", o.timeout, "time limit per kind, seconds")->check(CLI::Range(0.001, 1e6));
  sub.predict = app.add_subcommand("predict", "price one action with the stored models");
  addPredictOptions(*sub.predict, o);
  return sub;
}

/// The estimator's parameters (--config, --store, --timeout) and the store directory they name.
struct StoreParams {
  ee::EstimatorParams params;
  std::filesystem::path dir;
};

/// The parameters and their store, which must be an existing directory; an input error otherwise.
tamp::Result<StoreParams> storeParams(const EstimateCli& o) {
  auto params = ee::loadEstimatorParams(o.config);
  if (!params) return params.error();
  if (!o.store.empty()) params->store_directory = o.store;
  const std::filesystem::path dir = ee::resolveStoreDirectory(params->store_directory);
  if (dir.empty() || !std::filesystem::is_directory(dir)) {
    return tamp::Error(tamp::ErrorCode::kNotFound,
                       "no effort store directory at '" + dir.string() + "'");
  }
  params->refit_time_budget_s = o.timeout;
  return StoreParams{std::move(*params), dir};
}

/// `fit`: refits the models (every kind with records with --all), one entry of `reports` each;
/// the exit code of the last fit that failed (kExitTimeout, or 39), else kExitOk.
int refit(ee::EffortEstimator& est, const EstimateCli& o, json& reports) {
  int code = tamp::cli::kExitOk;
  for (const ee::RefitReport& r : est.refitNow(tamp::Termination::after(o.timeout * 4), o.all)) {
    const std::string k(tamp::toString(r.kind));
    if (!r.status.ok()) {
      std::cerr << "fit of " << k << " failed: " << r.status.error().toString() << "\n";
      code = r.status.error().code == tamp::ErrorCode::kTimeout ? tamp::cli::kExitTimeout
                                                                : tamp::cli::kExitInputError + 9;
    }
    reports.push_back(
        {{"kind", k}, {"ok", r.status.ok()}, {"version", r.version}, {"records", r.record_count}});
  }
  return code;
}

/// `show` and `fit`: the store's models, refitted first with `fit`, on stdout (with --json, the
/// refits too); the exit code.
int showModels(ee::EffortEstimator& est, const EstimateCli& o, const std::filesystem::path& dir,
               bool fit) {
  json reports = json::array();
  const int code = fit ? refit(est, o, reports) : tamp::cli::kExitOk;
  const ee::ModelSnapshot snap = est.snapshot();
  if (o.as_json) {
    json models = json::array();
    for (const auto& m : snap.models) models.push_back(modelJson(m));
    json out{{"store", dir.string()}, {"version", snap.version}, {"models", models}};
    if (fit) out["refits"] = reports;
    std::cout << out.dump(2) << "\n";
  } else {
    std::printf("store %s, snapshot version %llu\n", dir.string().c_str(),
                static_cast<unsigned long long>(snap.version));
    for (const auto& m : snap.models) printModel(m, est.recordCount(m.kind));
  }
  return code;
}

/// The path's joint names: the base's for move_base, else --joints (comma-separated).
std::vector<std::string> jointNames(tamp::ActionKind kind, const std::string& joints) {
  if (kind == tamp::ActionKind::kMoveBase) return {"base_x", "base_y", "base_theta"};
  std::vector<std::string> names;
  std::stringstream ss(joints);
  std::string j;
  while (std::getline(ss, j, ',')) names.push_back(j);
  return names;
}

/// `predict`'s request; an input error for a waypoint that is not numbers.
tamp::Result<ee::EstimateRequest> predictRequest(const EstimateCli& o) {
  ee::EstimateRequest req;
  req.kind = *tamp::actionKindFromString(o.kind_name);
  req.approach_m = o.approach;
  req.retreat_m = o.retreat;
  req.object_mass_kg = o.mass;
  if (!o.waypoints.empty()) {
    std::string why;
    if (!parseWaypoints(o.waypoints, req.path.waypoints, why)) {
      return tamp::Error(tamp::ErrorCode::kInvalidArgument, "--waypoints: " + why);
    }
    req.path.joint_names = jointNames(req.kind, o.joints);
  }
  return req;
}

/// The estimate on stdout, as JSON with --json.
void printEstimate(const EstimateCli& o, const ee::Estimate& e) {
  if (o.as_json) {
    std::cout << json{{"kind", o.kind_name},
                      {"mean_s", e.mean_s},
                      {"stddev_s", e.stddev_s},
                      {"nominal_s", e.nominal_s},
                      {"parameter_stddev_s", e.parameter_stddev_s},
                      {"model_version", e.model_version}}
                     .dump(2)
              << "\n";
  } else {
    std::printf(
        "%s: %.3f s +- %.3f s (model %.3f s, parameter part +- %.3f s, model version %llu)\n",
        o.kind_name.c_str(), e.mean_s, e.stddev_s, e.nominal_s, e.parameter_stddev_s,
        static_cast<unsigned long long>(e.model_version));
  }
}

/// `predict`: prices the action with the stored models; the exit code.
int predict(const ee::EffortEstimator& est, const EstimateCli& o) {
  const tamp::Result<ee::EstimateRequest> req = predictRequest(o);
  if (!req) return tamp::cli::fail("error", req.error(), tamp::cli::kExitInputError);
  const auto e = est.estimate(*req);
  if (!e) return tamp::cli::fail("error", e.error(), tamp::cli::kExitInputError);
  printEstimate(o, *e);
  return tamp::cli::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  EstimateCli o;
  CLI::App app{kAbout, "tamp estimate"};
  const Subcommands sub = defineOptions(app, o);
  CLI11_PARSE(app, argc, argv);
  tamp::log::setLevel("warn");
  const tamp::Result<StoreParams> store = storeParams(o);
  if (!store) return tamp::cli::fail("error", store.error(), tamp::cli::kExitInputError);
  ee::EffortEstimator est(store->params, /*start_worker=*/false);
  for (const auto& w : est.startupWarnings()) std::cerr << "warning: " << w << "\n";
  if (sub.show->parsed() || sub.fit->parsed())
    return showModels(est, o, store->dir, sub.fit->parsed());
  return predict(est, o);
}
