#pragma once
// Missions end to end for the integration tests: `tamp run` with a deployment of the product's own
// services (a faster simulator, a fresh effort store), the report and the simulator's final world.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "integration_util.h"
#include "tamp/core/paths.h"

namespace tamp::integration {

namespace fs = std::filesystem;

struct Mission {
  int exit_code{-1};
  std::string output;
  nlohmann::json report;
  nlohmann::json truth;
  fs::path run_dir;  ///< OUT/RUN_ID of this run (empty when tamp run made none)
};

/// `deployment` (a file of its own, e.g. fastDeployment's) with `service`'s shipped configuration
/// copied beside it and the top-level `keys` set to the given values: each key must be in the
/// shipped file (a test of a setting that is not there fails here, not silently). A second call
/// for the same service starts again from the shipped file.
inline fs::path withServiceKeys(const fs::path& deployment, const std::string& service,
                                const std::map<std::string, std::string>& keys) {
  const fs::path dir = deployment.parent_path();
  std::string cfg = readFile(configDir() / "services" / (service + ".yaml"));
  for (const auto& [key, value] : keys) {
    const std::regex line("(^|\n)" + key + ": [^\n#]+");
    if (!std::regex_search(cfg, line)) throw std::invalid_argument(service + ".yaml has no top-level key " + key);
    cfg = std::regex_replace(cfg, line, "$1" + key + ": " + value + " ");
  }
  std::ofstream(dir / (service + ".yaml")) << cfg;
  std::string dep = readFile(deployment);
  dep = std::regex_replace(dep, std::regex("\\{config\\}/services/" + service + "\\.yaml"), (dir / (service + ".yaml")).string());
  std::ofstream(deployment) << dep;
  return deployment;
}

/// A deployment like config/deploy/local.yaml whose simulator runs `factor` times faster than
/// real time (the product's own services and parameters otherwise).
inline fs::path fastDeployment(const fs::path& dir, double factor) {
  fs::create_directories(dir);
  const fs::path deployment = dir / "deploy.yaml";
  std::ofstream(deployment) << readFile(configDir() / "deploy" / "local.yaml");
  withServiceKeys(deployment, "sim", {{"realtime_factor", std::to_string(factor)}});
  // A fresh effort-estimator store: the decisions under test start from the default time models,
  // not from whatever earlier runs on this machine taught the estimator.
  return withServiceKeys(deployment, "effort_estimator", {{"store_directory", (dir / "store").string()}});
}

/// `tamp run` of `scenario` with `deployment`, its run folder under `out` (kept: several runs may
/// share a deployment, and so an effort store).
inline Mission runWith(const fs::path& out, const fs::path& deployment, const std::string& scenario,
                       const std::vector<std::string>& extra = {}) {
  std::set<fs::path> before;
  if (fs::exists(out))
    for (const auto& entry : fs::directory_iterator(out)) before.insert(entry.path());
  std::vector<std::string> args{(configDir() / "scenarios" / scenario).string(), "--out", out.string(), "--domain",
                                std::to_string(isolatedDomain()), "--deployment", deployment.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  Mission m;
  std::tie(m.exit_code, m.output) = runCommand(binDir() / "tamp-run", args, 600.0);
  for (const auto& entry : fs::directory_iterator(out)) {
    if (entry.path().filename().string().rfind("run-", 0) != 0 || before.count(entry.path())) continue;
    m.run_dir = entry.path();
    if (fs::exists(entry.path() / "report.json"))
      m.report = nlohmann::json::parse(readFile(entry.path() / "report.json"), nullptr, false);
    if (fs::exists(entry.path() / "sim_final_world.json"))
      m.truth = nlohmann::json::parse(readFile(entry.path() / "sim_final_world.json"), nullptr, false);
  }
  return m;
}

/// `tamp run` of `scenario` in a folder of its own, with a deployment of its own (a 2x simulator,
/// an empty effort store).
inline Mission run(const std::string& scenario, const std::vector<std::string>& extra = {}) {
  std::string tag = fs::path(scenario).stem().string();
  for (const auto& a : extra) tag += "_" + fs::path(a).filename().string();
  const fs::path out = tempFile("tamp_mission_" + tag);
  fs::remove_all(out);
  fs::create_directories(out / "deploy" / "store");
  return runWith(out, fastDeployment(out / "deploy", 2.0), scenario, extra);
}

inline double distance(const nlohmann::json& p, double x, double y) {
  return std::hypot(p["x"].get<double>() - x, p["y"].get<double>() - y);
}

}  // namespace tamp::integration
