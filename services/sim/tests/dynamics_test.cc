// The simulator's own dynamics (dynamics.h) and the oracle's nominal duration.
#include <algorithm>
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

double trapezoid(double L, double v, double a) {
  return L >= v * v / a ? L / v + v / a : 2.0 * std::sqrt(L / a);
}

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

/// An arc in the plane of the first two arm joints: radius `r` (rad), `n` segments of `step` rad of
/// bend each, from the upright arm.
std::vector<std::vector<double>> armArc(double r, int n, double step) {
  std::vector<std::vector<double>> out;
  for (int i = 0; i <= n; ++i) {
    std::vector<double> q(robotModel().armDof(), 0.0);
    q[0] = r * std::sin(i * step);
    q[1] = r * (1.0 - std::cos(i * step));
    out.push_back(q);
  }
  return out;
}

double distanceToPolyline(const std::vector<double>& x,
                          const std::vector<std::vector<double>>& poly) {
  double best = 1e300;
  for (std::size_t k = 1; k < poly.size(); ++k) {
    double dd = 0.0, xd = 0.0;
    for (std::size_t j = 0; j < x.size(); ++j) {
      const double d = poly[k][j] - poly[k - 1][j];
      dd += d * d;
      xd += (x[j] - poly[k - 1][j]) * d;
    }
    const double w = dd > 0.0 ? std::clamp(xd / dd, 0.0, 1.0) : 0.0;
    double e = 0.0;
    for (std::size_t j = 0; j < x.size(); ++j) {
      const double p = poly[k - 1][j] + w * (poly[k][j] - poly[k - 1][j]) - x[j];
      e += p * p;
    }
    best = std::min(best, std::sqrt(e));
  }
  return best;
}

TEST(ArmRunsTest, GentleBendsAreOneRunThroughEveryWaypointAndCornersStop) {
  const ArmDynamics arm;  // corner_threshold_rad 0.05
  const auto speeds = armSpeedLimits(robotModel());
  const auto names = robotModel().armJointNames();
  // 45 bends of 0.02 rad: one run through all 46 waypoints (not a chord of them).
  const auto arc = armArc(1.0, 45, 0.02);
  const auto runs = armRuns(arc, names, speeds, arm, 1.0);
  ASSERT_EQ(runs.size(), 1u);
  ASSERT_EQ(runs[0].points.size(), arc.size());
  for (std::size_t k = 0; k < arc.size(); ++k) EXPECT_EQ(runs[0].points[k], k);
  for (std::size_t k = 1; k < runs[0].u.size(); ++k) EXPECT_GT(runs[0].u[k], runs[0].u[k - 1]);
  // Bends of 0.1 rad stop at every waypoint.
  EXPECT_EQ(armRuns(armArc(1.0, 6, 0.1), names, speeds, arm, 1.0).size(), 6u);
  // One straight segment: u is the slowest joint's time at its speed limit; a load divides the
  // speed and acceleration limits, not the jerk.
  std::vector<std::vector<double>> line{std::vector<double>(names.size(), 0.0),
                                        std::vector<double>(names.size(), 0.0)};
  line[1][0] = 0.4;
  line[1][1] = -0.2;
  const double w0 = std::min(arm.max_speed, arm.speed_fraction * speeds.at(names[0]));
  const double w1 = std::min(arm.max_speed, arm.speed_fraction * speeds.at(names[1]));
  const auto one = armRuns(line, names, speeds, arm, 1.0);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_NEAR(one[0].length(), std::max(0.4 / w0, 0.2 / w1), 1e-12);
  const auto loaded = armRuns(line, names, speeds, arm, 2.0);
  EXPECT_NEAR(loaded[0].limits.speed, 0.5 * one[0].limits.speed, 1e-12);
  EXPECT_NEAR(loaded[0].limits.accel, 0.5 * one[0].limits.accel, 1e-12);
  EXPECT_NEAR(loaded[0].limits.jerk, one[0].limits.jerk, 1e-12);
}

// The simulator's timing is its own, its geometry the commanded one: through gentle bends the
// arm does not stop, and every state it passes lies on the commanded polyline (a chord of the
// arc would leave it by 0.1 rad, into whatever the planner went round).
TEST(SimulatorDynamicsTest, TheArmFollowsTheCommandedPolylineThroughGentleBends) {
  const auto arc = armArc(1.0, 45, 0.02);
  std::vector<double> chord_mid(arc.front().size());
  for (std::size_t j = 0; j < chord_mid.size(); ++j)
    chord_mid[j] = 0.5 * (arc.front()[j] + arc.back()[j]);
  ASSERT_GT(distanceToPolyline(chord_mid, arc), 0.09);  // the premise: the chord cuts the arc
  Simulator sim(emptyRoom(), robotModel(), upright(), exactParams());
  ASSERT_TRUE(sim.submit(testing::armCommand("arc", ActionKind::kMoveArm, arc)));
  double worst = 0.0;
  int samples = 0;
  while (sim.busy()) {
    const StepEvents e = sim.step(0.01);
    for (const auto& r : e.results) EXPECT_EQ(r.outcome, Outcome::kSucceeded) << r.reason;
    worst = std::max(worst, distanceToPolyline(sim.robotState().state.arm, arc));
    ++samples;
  }
  EXPECT_GT(samples, 50);
  EXPECT_LT(worst, 1e-9);
  for (std::size_t j = 0; j < arc.back().size(); ++j)
    EXPECT_NEAR(sim.robotState().state.arm[j], arc.back()[j], 1e-9);
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
  EXPECT_GT(*nominalDuration(d, speeds, baseQuery(3.0)),
            *nominalDuration(d, speeds, baseQuery(0.0)) + 0.1);
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

// The robot executes a command's trajectory, which samples a turn in place every sample period:
// as long as the same turn commanded by its two ends, not one rest-to-rest turn per sample (a
// 1.2 rad turn sampled 40 times took 40 S-curves, 2.7 times the prediction, in a NAMO mission).
TEST(NominalDurationTest, ATurnInPlaceTakesAsLongHoweverFinelyItIsSampled) {
  const DynamicsParams d;
  NominalQuery two;
  two.kind = ActionKind::kMoveBase;
  two.path.joint_names = {"base_x", "base_y", "base_theta"};
  two.path.waypoints = {{0, 0, -M_PI / 2}, {0, 0, -M_PI / 2 - 1.2}, {1, 0, 0}};
  NominalQuery sampled = two;
  sampled.path.waypoints.clear();
  for (int i = 0; i <= 40; ++i) sampled.path.waypoints.push_back({0, 0, -M_PI / 2 - 1.2 * i / 40.0});
  sampled.path.waypoints.push_back({1, 0, 0});
  EXPECT_NEAR(*nominalDuration(d, {}, sampled), *nominalDuration(d, {}, two), 1e-9);
}

TEST(NominalDurationTest, MalformedQueriesNameTheField) {
  const DynamicsParams d;
  NominalQuery q = baseQuery(0.0);
  q.path.waypoints[1].pop_back();
  auto r = nominalDuration(d, {}, q);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().toString().find("path.waypoints[1]"), std::string::npos)
      << r.error().toString();
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
