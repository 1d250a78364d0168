// The simulator's own dynamics (dynamics.h) and the oracle's nominal duration.
#include <cmath>

#include <gtest/gtest.h>

#include "sim_test_util.h"
#include "tamp/sim/dynamics.h"

namespace tamp::sim {
namespace {

using testing::exactParams;
using testing::moveBase;
using testing::robotModel;
using testing::runToEnd;
using testing::upright;

double trapezoid(double L, double v, double a) { return L >= v * v / a ? L / v + v / a : 2.0 * std::sqrt(L / a); }

TEST(MotionProfileTest, ReachesTheLengthAndRespectsTheLimits) {
  for (double L : {0.01, 0.3, 1.0, 7.5}) {
    const auto p = MotionProfile::restToRest(L, 0.5, 0.4, 0.9);
    EXPECT_NEAR(p.positionAt(p.duration()), L, 1e-9);
    EXPECT_NEAR(p.positionAt(p.duration() - 1e-9), L, 1e-6);
    // Speed within the limit, position monotone.
    double last = 0.0;
    const int n = 400;
    for (int i = 1; i <= n; ++i) {
      const double t = p.duration() * i / n;
      const double s = p.positionAt(t);
      EXPECT_GE(s, last - 1e-12);
      EXPECT_LE((s - last) / (p.duration() / n), 0.5 + 1e-6);
      last = s;
    }
    EXPECT_NEAR(p.positionAt(p.timeAt(0.4 * L)), 0.4 * L, 1e-6 * std::max(1.0, L));
  }
}

TEST(MotionProfileTest, JerkLimitedTakesLongerThanTheTrapezoidAndApproachesItForHighJerk) {
  for (double L : {0.05, 0.5, 3.0}) {
    const double trap = trapezoid(L, 0.5, 0.4);
    EXPECT_GT(MotionProfile::restToRest(L, 0.5, 0.4, 0.9).duration(), trap + 1e-3) << L;
    EXPECT_NEAR(MotionProfile::restToRest(L, 0.5, 0.4, 1e6).duration(), trap, 1e-2 * trap) << L;
  }
  EXPECT_EQ(MotionProfile::restToRest(0.0, 1, 1, 1).duration(), 0.0);
  EXPECT_THROW(MotionProfile::restToRest(1.0, 0.0, 1, 1), std::invalid_argument);
  EXPECT_THROW(MotionProfile::restToRest(-1.0, 1, 1, 1), std::invalid_argument);
}

TEST(BaseRunsTest, StopsAndTurnsOnlyAtCornersAboveTheThreshold) {
  // A bend of 0.03 rad is driven through, a right angle stops and turns.
  const std::vector<Pose2D> gentle{{0, 0, 0}, {1, 0, 0}, {2, 0.03, 0}};
  EXPECT_EQ(baseRuns(gentle, 0.05).size(), 1u);
  EXPECT_GT(baseRuns(gentle, 0.01).size(), 1u);
  const auto corner = baseRuns({{0, 0, 0}, {1, 0, 0}, {1, 1, M_PI / 2}}, 0.05);
  ASSERT_EQ(corner.size(), 3u);
  EXPECT_EQ(corner[1].kind, BaseRun::Kind::kTurn);
  EXPECT_NEAR(corner[1].amount, M_PI / 2, 1e-9);
}

NominalQuery baseQuery(double mass) {
  NominalQuery q;
  q.kind = ActionKind::kMoveBase;
  q.path.joint_names = {"base_x", "base_y", "base_theta"};
  q.path.waypoints = {{0, 0, 0}, {2, 0, 0}, {2, 1, M_PI / 2}};
  q.object_mass_kg = mass;
  return q;
}

TEST(NominalDurationTest, ALoadSlowsEveryKind) {
  const DynamicsParams d;
  const auto speeds = armSpeedLimits(robotModel());
  EXPECT_GT(*nominalDuration(d, speeds, baseQuery(3.0)), *nominalDuration(d, speeds, baseQuery(0.0)) + 0.1);
  NominalQuery arm;
  arm.kind = ActionKind::kMoveArm;
  arm.path.joint_names = robotModel().armJointNames();
  arm.path.waypoints = {std::vector<double>(arm.path.joint_names.size(), 0.0),
                        std::vector<double>(arm.path.joint_names.size(), 0.5)};
  const double light = *nominalDuration(d, speeds, arm);
  arm.object_mass_kg = 2.0;
  EXPECT_GT(*nominalDuration(d, speeds, arm), light + 0.05);
  NominalQuery pick;
  pick.kind = ActionKind::kPick;
  pick.approach_m = pick.retreat_m = 0.1;
  const double empty = *nominalDuration(d, speeds, pick);
  pick.object_mass_kg = 2.0;
  EXPECT_GT(*nominalDuration(d, speeds, pick), empty + 0.05);
  EXPECT_GE(empty, d.hand.close_s);
}

TEST(NominalDurationTest, MalformedQueriesNameTheField) {
  const DynamicsParams d;
  NominalQuery q = baseQuery(0.0);
  q.path.waypoints[1].pop_back();
  auto r = nominalDuration(d, {}, q);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().toString().find("path.waypoints[1]"), std::string::npos) << r.error().toString();
  q = baseQuery(-1.0);
  EXPECT_FALSE(nominalDuration(d, {}, q));
  q = baseQuery(0.0);
  q.path.joint_names[2] = "yaw";
  EXPECT_FALSE(nominalDuration(d, {}, q));
  DynamicsParams bad;
  bad.stall.max_s = 0.1;  // below min_s
  auto v = bad.validate();
  ASSERT_FALSE(v);
  EXPECT_NE(v.error().toString().find("dynamics.stall.max_s"), std::string::npos);
}

// The simulator executes with exactly the oracle's nominal duration when noise and stalls are off
// (the oracle's contract), and a stall only ever adds time.
TEST(SimulatorDynamicsTest, ExecutionMatchesTheOracleWithoutNoiseAndStallsAddTime) {
  const std::vector<Pose2D> path{{0, 0, 0}, {1.5, 0, 0}, {1.5, 1.0, 1.0}};
  SimParams p = exactParams();
  Simulator exact(emptyRoom(), robotModel(), upright(), p);
  const auto cmd = moveBase("b", path);
  auto oracle = exact.nominalDuration(cmd);
  ASSERT_TRUE(oracle) << oracle.error().toString();
  ASSERT_TRUE(exact.submit(cmd));
  const auto e = runToEnd(exact);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_NEAR(e.results[0].duration_s, *oracle, 1e-9);
  EXPECT_NEAR(testing::trueTime(e.records.at(0), p), *oracle, 1e-9);

  p.dynamics.stall.probability = 1.0;
  p.dynamics.stall.min_s = p.dynamics.stall.max_s = 0.7;
  Simulator stalling(emptyRoom(), robotModel(), upright(), p);
  EXPECT_NEAR(*stalling.nominalDuration(cmd), *oracle, 1e-9);  // the oracle knows no stalls
  ASSERT_TRUE(stalling.submit(cmd));
  const auto s = runToEnd(stalling);
  ASSERT_EQ(s.results.size(), 1u);
  // Three motions (turn, drive, turn, drive, turn: at least 3), each followed by a 0.7 s stall.
  EXPECT_GE(s.results[0].duration_s, *oracle + 3 * 0.7 - 1e-9);
}

TEST(SimulatorDynamicsTest, DeterministicForASeedAndDifferentForAnother) {
  auto run = [](std::uint64_t seed) {
    SimParams p = exactParams();
    p.duration_noise = 0.05;
    p.dynamics.stall.probability = 0.5;
    p.seed = seed;
    Simulator sim(emptyRoom(), robotModel(), upright(), p);
    std::vector<double> out;
    Pose2D at{};
    for (int i = 0; i < 4; ++i) {
      const Pose2D next{at.x + 1.0, at.y + 0.5 * (i % 2), 0.0};
      EXPECT_TRUE(sim.submit(moveBase("m" + std::to_string(i), {at, next})));
      const auto e = runToEnd(sim);
      out.push_back(e.results.at(0).duration_s);
      at = sim.robotState().state.base;
    }
    return out;
  };
  EXPECT_EQ(run(3), run(3));
  EXPECT_NE(run(3), run(4));
}

}  // namespace
}  // namespace tamp::sim
