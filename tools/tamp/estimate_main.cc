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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Inspect, refit or query the effort estimator's execution-time models.\n"
               "Exit codes: 0 ok, 20 fit timed out, 30 input error, 39 fit failed.",
               "tamp estimate"};
  app.require_subcommand(1);
  app.fallthrough();  // --config/--store/--json also after the subcommand
  std::string config = (tamp::configDir() / "services" / "effort_estimator.yaml").string();
  std::string store;
  bool as_json = false;
  app.add_option("--config", config, "service parameters (YAML)");
  app.add_option("--store", store, "store directory (overrides store_directory of the config)");
  app.add_flag("--json", as_json, "print JSON");

  CLI::App* show = app.add_subcommand("show", "print the stored models and record counts");
  CLI::App* fit = app.add_subcommand("fit", "refit the models from the stored records and save them");
  bool all = false;
  double timeout = 60.0;
  fit->add_flag("--all", all, "refit every kind with records, not only those with new records");
  fit->add_option("--timeout", timeout, "time limit per kind, seconds")->check(CLI::Range(0.001, 1e6));
  CLI::App* predict = app.add_subcommand("predict", "price one action with the stored models");
  std::string kind_name, waypoints, joints;
  double approach = 0.0, retreat = 0.0, mass = 0.0;
  predict->add_option("--kind", kind_name, "move_base, move_arm, pick or place")
      ->required()
      ->check(CLI::IsMember({"move_base", "move_arm", "pick", "place"}));
  predict->add_option("--waypoints", waypoints,
                      "path as 'v1,v2,...; v1,v2,...' (move_base: x,y,theta; move_arm: one value per --joints)");
  predict->add_option("--joints", joints, "move_arm joint names, comma-separated");
  predict->add_option("--approach", approach, "pick/place approach distance, m");
  predict->add_option("--retreat", retreat, "pick/place retreat distance, m");
  predict->add_option("--mass", mass, "object mass, kg");
  CLI11_PARSE(app, argc, argv);
  tamp::log::setLevel("warn");

  auto params = ee::loadEstimatorParams(config);
  if (!params) {
    std::cerr << "error: " << params.error().toString() << "\n";
    return tamp::cli::kExitInputError;
  }
  if (!store.empty()) params->store_directory = store;
  const std::filesystem::path dir = ee::resolveStoreDirectory(params->store_directory);
  if (dir.empty() || !std::filesystem::is_directory(dir)) {
    std::cerr << "error: no effort store directory at '" << dir.string() << "'\n";
    return tamp::cli::kExitInputError;
  }
  params->refit_time_budget_s = timeout;
  ee::EffortEstimator est(*params, /*start_worker=*/false);
  for (const auto& w : est.startupWarnings()) std::cerr << "warning: " << w << "\n";

  if (show->parsed() || fit->parsed()) {
    int code = tamp::cli::kExitOk;
    json reports = json::array();
    if (fit->parsed()) {
      for (const ee::RefitReport& r : est.refitNow(tamp::Termination::after(timeout * 4), all)) {
        const std::string k(tamp::toString(r.kind));
        if (!r.status.ok()) {
          std::cerr << "fit of " << k << " failed: " << r.status.error().toString() << "\n";
          code = r.status.error().code == tamp::ErrorCode::kTimeout ? tamp::cli::kExitTimeout
                                                                     : tamp::cli::kExitInputError + 9;
        }
        reports.push_back({{"kind", k}, {"ok", r.status.ok()}, {"version", r.version}, {"records", r.record_count}});
      }
    }
    const ee::ModelSnapshot snap = est.snapshot();
    if (as_json) {
      json models = json::array();
      for (const auto& m : snap.models) models.push_back(modelJson(m));
      json out{{"store", dir.string()}, {"version", snap.version}, {"models", models}};
      if (fit->parsed()) out["refits"] = reports;
      std::cout << out.dump(2) << "\n";
    } else {
      std::printf("store %s, snapshot version %llu\n", dir.string().c_str(),
                  static_cast<unsigned long long>(snap.version));
      for (const auto& m : snap.models) printModel(m, est.recordCount(m.kind));
    }
    return code;
  }

  ee::EstimateRequest req;
  req.kind = *tamp::actionKindFromString(kind_name);
  req.approach_m = approach;
  req.retreat_m = retreat;
  req.object_mass_kg = mass;
  if (!waypoints.empty()) {
    std::string why;
    if (!parseWaypoints(waypoints, req.path.waypoints, why)) {
      std::cerr << "error: --waypoints: " << why << "\n";
      return tamp::cli::kExitInputError;
    }
    if (req.kind == tamp::ActionKind::kMoveBase) {
      req.path.joint_names = {"base_x", "base_y", "base_theta"};
    } else {
      std::stringstream ss(joints);
      std::string j;
      while (std::getline(ss, j, ',')) req.path.joint_names.push_back(j);
    }
  }
  auto e = est.estimate(req);
  if (!e) {
    std::cerr << "error: " << e.error().toString() << "\n";
    return tamp::cli::kExitInputError;
  }
  if (as_json) {
    std::cout << json{{"kind", kind_name},
                      {"mean_s", e->mean_s},
                      {"stddev_s", e->stddev_s},
                      {"nominal_s", e->nominal_s},
                      {"parameter_stddev_s", e->parameter_stddev_s},
                      {"model_version", e->model_version}}
                     .dump(2)
              << "\n";
  } else {
    std::printf("%s: %.3f s +- %.3f s (model %.3f s, parameter part +- %.3f s, model version %llu)\n",
                kind_name.c_str(), e->mean_s, e->stddev_s, e->nominal_s, e->parameter_stddev_s,
                static_cast<unsigned long long>(e->model_version));
  }
  return tamp::cli::kExitOk;
}
