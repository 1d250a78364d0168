// Pushes in the simulator: a move_base command that names an object drives the base into it and
// carries it ahead; the object ends where the base left it, less the gap before contact, and
// slips by the simulator's own error. A push out of reach is refused; one into a wall stops.
#include <cmath>

#include <gtest/gtest.h>

#include "sim_test_util.h"

namespace tamp::sim {
namespace {

using namespace tamp::sim::testing;

/// A 0.6 m crate on the floor, its near face `gap` m ahead of the base's front (0.30 m).
world::World crateAhead(double gap, double mass = 30.0) {
  world::World w = emptyRoom();
  world::Object crate = box("crate", 0.6, 0.6, 0.5, at(0.30 + gap + 0.30, 0.0, 0.25), true);
  crate.mass = mass;
  crate.region = "floor";
  EXPECT_TRUE(w.addObject(crate));
  return w;
}

/// Exact, and the push without slip.
SimParams noSlip() {
  SimParams p = exactParams();
  p.push.lateral_slip = 0.0;
  p.push.yaw_slip_rad_per_m = 0.0;
  return p;
}

ActionCommand push(const std::string& id, double distance) {
  ActionCommand c = moveBase(id, {{0.0, 0.0, 0.0}, {distance, 0.0, 0.0}});
  c.object_id = "crate";
  return c;
}

TEST(PushTest, ThePushedObjectEndsAheadOfTheBaseByTheDistanceDrivenPastContact) {
  const SimParams p = noSlip();
  Simulator sim(crateAhead(0.03), robotModel(), upright(), p);
  ASSERT_TRUE(sim.submit(push("push", 1.03)));
  const StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].outcome, Outcome::kSucceeded) << e.results[0].reason;
  EXPECT_TRUE(e.world_changed);
  const Eigen::Vector3d c = sim.world().object("crate").pose.translation();
  EXPECT_NEAR(c.x(), 0.63 + 1.0, 0.015);  // 1.03 m driven, 0.03 m of it before contact, 1 cm slide
  EXPECT_GT(c.x() - 0.30 - (sim.robotState().state.base.x + 0.30), 0.005) << "the base is left clear of the object";
  EXPECT_NEAR(c.y(), 0.0, 1e-6);
  EXPECT_NEAR(c.z(), 0.25, 1e-6);
  EXPECT_NEAR(sim.robotState().state.base.x, 1.03, 0.01);
  // The record: a move_base slowed by the pushed mass.
  ASSERT_EQ(e.records.size(), 1u);
  EXPECT_EQ(e.records[0].action.kind, ActionKind::kMoveBase);
  EXPECT_DOUBLE_EQ(e.records[0].action.object_mass_kg, 30.0);
}

TEST(PushTest, ThePushSlipsSidewaysByTheSimulatorsOwnError) {
  SimParams p = exactParams();
  p.push.lateral_slip = 0.05;
  Simulator sim(crateAhead(0.03), robotModel(), upright(), p);
  ASSERT_TRUE(sim.submit(push("push", 1.03)));
  const StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  ASSERT_EQ(e.results[0].outcome, Outcome::kSucceeded) << e.results[0].reason;
  const Eigen::Isometry3d pose = sim.world().object("crate").pose;
  EXPECT_NEAR(pose.translation().x(), 1.63, 0.015);
  EXPECT_GT(std::abs(pose.translation().y()), 1e-6);  // slipped: the planner cannot know where exactly
  EXPECT_LT(std::abs(pose.translation().y()), 0.25);  // 5 sigma
}

TEST(PushTest, ABaseBackingOffAfterThePushLeavesTheObjectWhereItWasPushed) {
  const SimParams p = noSlip();
  Simulator sim(crateAhead(0.03), robotModel(), upright(), p);
  ActionCommand c = moveBase("push", {{0.0, 0.0, 0.0}, {1.03, 0.0, 0.0}, {0.88, 0.0, 0.0}});
  c.object_id = "crate";
  ASSERT_TRUE(sim.submit(c));
  const StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  ASSERT_EQ(e.results[0].outcome, Outcome::kSucceeded) << e.results[0].reason;
  EXPECT_NEAR(sim.robotState().state.base.x, 0.88, 0.01);
  EXPECT_NEAR(sim.world().object("crate").pose.translation().x(), 1.63, 0.015) << "not pulled back";
}

TEST(PushTest, AnObjectOutOfReachIsNotPushedAndTheCommandIsRefused) {
  Simulator sim(crateAhead(0.5), robotModel(), upright(), exactParams());
  const Status s = sim.submit(push("push", 1.0));
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("not within"), std::string::npos) << s.error().message;
  EXPECT_FALSE(sim.busy());
  EXPECT_NEAR(sim.world().object("crate").pose.translation().x(), 1.1, 1e-9);
}

TEST(PushTest, AStaticObjectOrAnUnknownOneCannotBePushed) {
  world::World w = crateAhead(0.03);
  ASSERT_TRUE(w.addObject(box("pillar", 0.2, 0.2, 1.0, at(-2.0, 0.0, 0.5))));
  Simulator sim(std::move(w), robotModel(), upright(), exactParams());
  ActionCommand c = push("p1", 1.0);
  c.object_id = "pillar";
  EXPECT_FALSE(sim.submit(c));
  c.object_id = "ghost";
  EXPECT_FALSE(sim.submit(c));
}

TEST(PushTest, APushIntoAWallStopsBeforeTheObjectTouchesIt) {
  world::World w = crateAhead(0.03);
  ASSERT_TRUE(w.addObject(box("wall", 0.2, 3.0, 1.0, at(1.6, 0.0, 0.5))));  // its face at x = 1.5
  const SimParams p = noSlip();
  Simulator sim(std::move(w), robotModel(), upright(), p);
  ASSERT_TRUE(sim.submit(push("push", 1.03)));
  const StepEvents e = runToEnd(sim);
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].outcome, Outcome::kBlocked);
  EXPECT_EQ(e.results[0].blocking_object_id, "wall");
  const double x = sim.world().object("crate").pose.translation().x();
  EXPECT_LE(x + 0.30, 1.5 + 1e-6);  // not into the wall
  EXPECT_GT(x, 0.63 + 0.3);         // but pushed most of the way
}

}  // namespace
}  // namespace tamp::sim
