// Missions end to end over real processes: `tamp run` (the product's main job) starts every service
// of the default deployment on its own DDS domain, executes the scenario's mission in the
// simulator and writes the report. Each test judges the mission by the simulator's ground truth at
// the end (sim_final_world.json) and by the report, never by what the planner believes.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration_util.h"
#include "tamp/core/paths.h"

namespace tamp::integration {
namespace {

namespace fs = std::filesystem;

struct Mission {
  int exit_code{-1};
  std::string output;
  nlohmann::json report;
  nlohmann::json truth;
};

/// A deployment like config/deploy/local.yaml whose simulator runs `factor` times faster than
/// real time (the product's own services and parameters otherwise).
fs::path fastDeployment(const fs::path& dir, double factor) {
  fs::create_directories(dir);
  std::string sim = readFile(configDir() / "services" / "sim.yaml");
  sim = std::regex_replace(sim, std::regex("realtime_factor: [0-9.]+"), "realtime_factor: " + std::to_string(factor));
  std::ofstream(dir / "sim.yaml") << sim;
  std::string dep = readFile(configDir() / "deploy" / "local.yaml");
  dep = std::regex_replace(dep, std::regex("\\{config\\}/services/sim.yaml"), (dir / "sim.yaml").string());
  // A fresh effort-estimator store: the decisions under test start from the default time models,
  // not from whatever earlier runs on this machine taught the estimator.
  std::string est = readFile(configDir() / "services" / "effort_estimator.yaml");
  est = std::regex_replace(est, std::regex("store_directory: [^\\n#]+"), "store_directory: " + (dir / "store").string() + " ");
  std::ofstream(dir / "effort_estimator.yaml") << est;
  dep = std::regex_replace(dep, std::regex("\\{config\\}/services/effort_estimator.yaml"),
                           (dir / "effort_estimator.yaml").string());
  std::ofstream(dir / "deploy.yaml") << dep;
  return dir / "deploy.yaml";
}

Mission run(const std::string& scenario, const std::vector<std::string>& extra = {}) {
  std::string tag = fs::path(scenario).stem().string();
  for (const auto& a : extra) tag += "_" + fs::path(a).filename().string();
  const fs::path out = tempFile("tamp_mission_" + tag);
  fs::remove_all(out);
  fs::create_directories(out / "deploy" / "store");
  const fs::path deployment = fastDeployment(out / "deploy", 2.0);
  std::vector<std::string> args{(configDir() / "scenarios" / scenario).string(), "--out", out.string(), "--domain",
                                std::to_string(isolatedDomain()), "--deployment", deployment.string()};
  args.insert(args.end(), extra.begin(), extra.end());
  Mission m;
  std::tie(m.exit_code, m.output) = runCommand(binDir() / "tamp-run", args, 600.0);
  for (const auto& entry : fs::directory_iterator(out)) {
    if (entry.path().filename().string().rfind("run-", 0) != 0) continue;
    if (fs::exists(entry.path() / "report.json"))
      m.report = nlohmann::json::parse(readFile(entry.path() / "report.json"), nullptr, false);
    if (fs::exists(entry.path() / "sim_final_world.json"))
      m.truth = nlohmann::json::parse(readFile(entry.path() / "sim_final_world.json"), nullptr, false);
  }
  return m;
}

double distance(const nlohmann::json& p, double x, double y) {
  return std::hypot(p["x"].get<double>() - x, p["y"].get<double>() - y);
}

bool insideCorridor(const nlohmann::json& p) {
  const double x = p["x"].get<double>(), y = p["y"].get<double>();
  return x > 4.3 && x < 6.7 && y > 0.85 && y < 1.55;
}

TEST(MissionTest, CorridorEffortPolicyMovesTheLightBoxAndReachesTheGoal) {
  const Mission m = run("namo_corridor.yaml", {"--policy", "effort"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  EXPECT_LT(distance(m.truth["robot"], 8.5, 1.2), 0.10) << m.truth.dump();
  EXPECT_FALSE(insideCorridor(m.truth["objects"]["box"])) << m.truth["objects"]["box"].dump();
  EXPECT_EQ(m.report["status"], "succeeded");
  EXPECT_EQ(m.report["objects_moved"], nlohmann::json::array({"box"})) << m.report.dump(1);
  // The detour was priced and lost: a decision lists it with a larger (or cut) effort.
  bool detour_seen = false;
  for (const auto& d : m.report["decisions"])
    for (const auto& a : d["alternatives"])
      if (a["alternative"].get<std::string>().find("[around]") != std::string::npos && !a["chosen"].get<bool>())
        detour_seen = true;
  EXPECT_TRUE(detour_seen) << m.report["decisions"].dump(1);
  // Every action the report lists was measured by the robot, and they add up.
  double measured = 0.0;
  for (const auto& a : m.report["actions"]) measured += a["measured_s"].get<double>();
  EXPECT_NEAR(measured, m.report["executed_effort_s"].get<double>(), 1e-6);
}

TEST(MissionTest, CorridorInfeasibilityPolicyGoesRoundAndLeavesTheBox) {
  const Mission m = run("namo_corridor.yaml", {"--policy", "infeasible"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  EXPECT_LT(distance(m.truth["robot"], 8.5, 1.2), 0.10) << m.truth.dump();
  EXPECT_LT(distance(m.truth["objects"]["box"], 4.62, 1.2), 0.02) << "the box was not to be touched";
  EXPECT_TRUE(m.report["objects_moved"].empty());
}

TEST(MissionTest, CorridorHeavyBoxAboveThePayloadIsGoneRound) {
  const Mission m = run("namo_corridor_heavy.yaml");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  EXPECT_LT(distance(m.truth["robot"], 8.5, 1.2), 0.10) << m.truth.dump();
  EXPECT_LT(distance(m.truth["objects"]["box"], 4.62, 1.2), 0.02);
  EXPECT_EQ(m.report["grasp_calls"], 0) << "a box above the payload offers no removal to price";
}

TEST(MissionTest, CorridorShortDetourIsTakenInsteadOfMovingTheBox) {
  const Mission m = run("namo_corridor_short.yaml");
  ASSERT_EQ(m.exit_code, 0) << m.output;
  EXPECT_LT(distance(m.truth["robot"], 8.5, 1.2), 0.10) << m.truth.dump();
  EXPECT_LT(distance(m.truth["objects"]["box"], 4.62, 1.2), 0.02);
}

// The DDS Security profile (deploy/security/): every service with its own certificate and
// permissions, everything encrypted; the mission must still succeed. A topic a node uses but the
// access table does not grant it makes that node fail to start (or the call fail), so this is
// also the check that deploy/security/access.txt covers the code.
TEST(MissionTest, SecuredCorridorMissionSucceeds) {
  const fs::path pki = tempFile("tamp_mission_pki");
  fs::remove_all(pki);
  const std::string cmd = std::string("bash ") + TAMP_SOURCE_DIR + "/deploy/security/make_certs.sh '" + pki.string() +
                          "' > '" + pki.string() + ".log' 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << readFile(pki.string() + ".log");
  Mission m = run("namo_corridor.yaml", {"--policy", "effort", "--security", pki.string()});
  if (m.exit_code != 0) {
    // Known weakness, docs/benchmarks.md: secured, 2 corridor runs of 6 failed on this loaded VM
    // (a service pair not matched within the graph manager's 10 s, a lost reply). One more try,
    // the first failure shown; two failures in a row fail the test.
    std::cerr << "secured mission failed once (exit " << m.exit_code << "), trying again:\n" << m.output << "\n";
    RecordProperty("secured_first_attempt_failed", "true");
    m = run("namo_corridor.yaml", {"--policy", "effort", "--security", pki.string()});
  }
  fs::remove_all(pki);
  ASSERT_EQ(m.exit_code, 0) << m.output;
  EXPECT_NE(m.output.find("ok"), std::string::npos) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  EXPECT_LT(distance(m.truth["robot"], 8.5, 1.2), 0.10) << m.truth.dump();
  EXPECT_EQ(m.report["status"], "succeeded") << m.report.dump(1);
  EXPECT_EQ(m.report["objects_moved"], nlohmann::json::array({"box"})) << m.report.dump(1);
}

TEST(MissionTest, ABadScenarioIsAnInputErrorBeforeAnyServiceStarts) {
  const fs::path bad = tempFile("tamp_bad_scenario") += ".yaml";
  std::ofstream(bad) << "name: bad\npddl:\n  domain: nowhere.pddl\nrobot: {start: start}\n";
  const auto [code, out] = runCommand(binDir() / "tamp-run", {bad.string(), "--domain", std::to_string(isolatedDomain())}, 60.0);
  EXPECT_EQ(code, 30) << out;
  EXPECT_NE(out.find(bad.string()), std::string::npos) << "the error names the file: " << out;
  EXPECT_EQ(out.find("SERVICE"), std::string::npos) << "no service was started: " << out;
}

}  // namespace
}  // namespace tamp::integration
