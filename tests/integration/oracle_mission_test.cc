// Policy oracle end to end over real processes (issue 12 part 4): `tamp run --policy oracle`
// makes the simulator serve its truth, the graph manager prices every action with the
// simulator's true nominal durations and evaluates remove-or-avoid exhaustively. Judged by the
// simulator's final world and by the report.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mission_util.h"

namespace tamp::integration {
namespace {

TEST(OracleMissionTest, CorridorOracleReachesTheGoalPricingBothRemovalAndDetourInFull) {
  const Mission m = run("namo_corridor.yaml", {"--policy", "oracle"});
  ASSERT_EQ(m.exit_code, 0) << m.output;
  ASSERT_TRUE(m.truth.is_object()) << m.output;
  // The robot is at the corridor's goal (8.5, 1.2) in the simulator's world.
  EXPECT_LT(distance(m.truth["robot"], 8.5, 1.2), 0.10) << m.truth.dump();
  EXPECT_EQ(m.report["policy"], "oracle") << m.report.dump(1);
  EXPECT_EQ(m.report["status"], "succeeded");
  EXPECT_NE(m.output.find("policy oracle"), std::string::npos) << m.output;

  // Exhaustive: no alternative of any decision was cut on its bound, and the chosen one is the
  // least effort of its decision.
  ASSERT_FALSE(m.report["decisions"].empty()) << m.report.dump(1);
  for (const auto& d : m.report["decisions"]) {
    if (d["what"].get<std::string>().rfind("observation", 0) == 0) continue;
    double least = std::numeric_limits<double>::infinity(), chosen = -1.0;
    for (const auto& a : d["alternatives"]) {
      EXPECT_FALSE(a["cut"].get<bool>()) << d.dump(1);
      if (a["effort_s"].is_null()) continue;
      least = std::min(least, a["effort_s"].get<double>());
      if (a["chosen"].get<bool>()) chosen = a["effort_s"].get<double>();
    }
    EXPECT_NEAR(chosen, least, 1e-6) << d.dump(1);
  }
  // At the start, both ways were priced in full: the detour and the removal of the box.
  const auto& first = m.report["decisions"][0];
  bool around = false, removal = false;
  for (const auto& a : first["alternatives"]) {
    const std::string what = a["alternative"].get<std::string>();
    if (a["effort_s"].is_null()) continue;
    around = around || what.find("[around]") != std::string::npos;
    removal = removal || what.find("sub-task: move box") != std::string::npos;
  }
  EXPECT_TRUE(around && removal) << first.dump(1);

  // The true durations: each action took what the oracle predicted, up to the simulator's
  // execution noise (3 % log-normal) and one stall (at most 1.5 s).
  for (const auto& a : m.report["actions"]) {
    if (a["outcome"] != "succeeded") continue;
    const double predicted = a["predicted_s"].get<double>(),
                 measured = a["measured_s"].get<double>();
    EXPECT_NEAR(measured, predicted, 0.15 * predicted + 1.6) << a.dump();
  }
}

}  // namespace
}  // namespace tamp::integration
