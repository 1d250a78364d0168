// Lazy mode: the objects in the way, where contact starts and ends, and effort-aware improvement.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "tamp/motion_planner/motion_planner.h"
#include "test_worlds.h"

namespace tamp::motion_planner {
namespace {

using testing::baseRequest;
using testing::blockingIds;
using testing::discClearance;
using testing::discTouches;
using testing::untimedParams;

constexpr double kRadius = testing::kDiscRadius;

class LazyTest : public ::testing::Test {
 protected:
  void SetUp() override { seedRandomness(42); }
  static MotionPlanner planner(const world::World& w, const MotionPlannerParams& p = testing::untimedParams()) {
    return testing::discPlanner(w, p);
  }
};

TEST_F(LazyTest, ReportsExactlyTheObjectThatBlocksTheDoor) {
  const world::World w = testing::corridorWorld(true);
  MotionPlanner mp = planner(w);
  const MotionResult r = mp.plan(baseRequest({2, 2, 0}, {8, 2, 0}), Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_EQ(blockingIds(r.blocking), std::vector<std::string>{"crate"});
  // The path avoids static geometry (independent 2-D check, 5 mm steps) ...
  EXPECT_GT(discClearance(w, r.path, kRadius, 0.005, {}, /*movables=*/false), -1e-3);
  // ... and the independent check sees exactly the reported movables.
  EXPECT_EQ(discTouches(w, r.path, kRadius, 0.005), blockingIds(r.blocking));
  // Start and goal as requested.
  ASSERT_GE(r.path.waypoints.size(), 2u);
  EXPECT_NEAR(r.path.waypoints.front()[0], 2.0, 1e-9);
  EXPECT_NEAR(r.path.waypoints.back()[0], 8.0, 0.011);
  EXPECT_NEAR(r.path.waypoints.back()[1], 2.0, 0.011);
}

TEST_F(LazyTest, ContactIntervalMatchesTheGeometry) {
  const world::World w = testing::corridorWorld(true);
  MotionPlanner mp = planner(w);
  const MotionResult r = mp.plan(baseRequest({2, 2, 0}, {8, 2, 0}), Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  ASSERT_EQ(r.blocking.size(), 1u);
  const BlockingObject& b = r.blocking[0];
  EXPECT_EQ(b.mass, 8.0);
  EXPECT_GT(b.effort_s, 0.0);
  ASSERT_EQ(b.intervals.size(), 1u);
  EXPECT_LT(b.enter_fraction, b.exit_fraction);
  EXPECT_LE(b.enter_waypoint, b.exit_waypoint);
  EXPECT_LT(b.exit_waypoint, r.path.waypoints.size());
  ASSERT_FALSE(b.swept_base.empty());
  EXPECT_EQ(b.swept_base.size(), b.swept_configurations.size());
  // Every swept pose is in contact with the crate: the disc centre is within radius of the box
  // (crate: x in [4.8, 5.2], y in [1.5, 2.5]); the first and last are near the boundary.
  for (const Pose2D& p : b.swept_base) {
    const double dx = std::max(std::abs(p.x - 5.0) - 0.2, 0.0), dy = std::max(std::abs(p.y - 2.0) - 0.5, 0.0);
    EXPECT_LE(std::hypot(dx, dy), kRadius + 0.02) << p;
  }
  // The contact starts where the disc reaches x = 4.8 - r along the path (and ends past 5.2 + r),
  // up to the bisection tolerance; compute the fractions independently from the waypoints.
  std::vector<double> cum{0.0};
  for (std::size_t i = 1; i < r.path.waypoints.size(); ++i) {
    const auto& a = r.path.waypoints[i - 1];
    const auto& c = r.path.waypoints[i];
    cum.push_back(cum.back() + std::hypot(c[0] - a[0], c[1] - a[1]) + 0.5 * std::abs(c[2] - a[2]));
  }
  auto at = [&](double f) {  // base position at path fraction f (space metric)
    const double s = f * cum.back();
    for (std::size_t i = 1; i < cum.size(); ++i) {
      if (s <= cum[i] || i + 1 == cum.size()) {
        const double t = cum[i] > cum[i - 1] ? (s - cum[i - 1]) / (cum[i] - cum[i - 1]) : 0.0;
        const auto& a = r.path.waypoints[i - 1];
        const auto& c = r.path.waypoints[i];
        return Eigen::Vector2d(a[0] + t * (c[0] - a[0]), a[1] + t * (c[1] - a[1]));
      }
    }
    return Eigen::Vector2d(r.path.waypoints.back()[0], r.path.waypoints.back()[1]);
  };
  auto dist = [](const Eigen::Vector2d& p) {
    const double dx = std::max(std::abs(p.x() - 5.0) - 0.2, 0.0), dy = std::max(std::abs(p.y() - 2.0) - 0.5, 0.0);
    return std::hypot(dx, dy);
  };
  EXPECT_NEAR(dist(at(b.enter_fraction)), kRadius, 0.02);
  EXPECT_NEAR(dist(at(b.exit_fraction)), kRadius, 0.02);
}

TEST_F(LazyTest, GoesAroundALightObjectWhenTheDetourIsCheaper) {
  const world::World w = testing::openRoomWorld();
  MotionPlanner mp = planner(w);
  const MotionResult r = mp.plan(baseRequest({2, 3, 0}, {8, 3, 0}), Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_TRUE(r.blocking.empty()) << "crossed " << r.blocking.front().object_id;
  EXPECT_TRUE(discTouches(w, r.path, kRadius, 0.005).empty());
  // The detour is short: the straight line is 6 m, going around a 0.6 m box with r = 0.3 costs little.
  EXPECT_LT(r.path_length, 6.0 * 1.15);
}

TEST_F(LazyTest, PrefersOneLightObjectOverTwoHeavyOnes) {
  const world::World w = testing::twoDoorWorld();
  MotionPlanner mp = planner(w);
  const MotionResult r = mp.plan(baseRequest({2, 0.9, 0}, {8, 0.9, 0}), Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_EQ(blockingIds(r.blocking), std::vector<std::string>{"light"});
  EXPECT_EQ(discTouches(w, r.path, kRadius, 0.005), std::vector<std::string>{"light"});
  // Its cost is below that of crossing both heavy objects on the straight line.
  double heavy = 0.0;
  for (const auto& o : w.objects()) {
    if (o.id == "heavy_a" || o.id == "heavy_b") heavy += defaultObjectEffort(o, mp.params().cost);
  }
  EXPECT_LT(r.cost_s, heavy + 6.0 / mp.params().cost.base_speed);
  EXPECT_LE(r.cost_s, r.stats.raw_cost_s + 1e-9);
}

TEST_F(LazyTest, ReportMatchesIndependentCheckForAnyCostScale) {
  const world::World w = testing::twoDoorWorld();
  for (double scale : {0.0, 0.2, 1.0, 10.0}) {
    MotionPlanner mp = planner(w);
    MotionRequest req = baseRequest({2, 0.9, 0}, {8, 0.9, 0});
    req.object_cost_scale = scale;
    const MotionResult r = mp.plan(req, Termination::after(5.0));
    ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
    EXPECT_EQ(discTouches(w, r.path, kRadius, 0.005), blockingIds(r.blocking)) << "scale " << scale;
    EXPECT_GT(discClearance(w, r.path, kRadius, 0.005, {}, false), -1e-3) << "scale " << scale;
  }
}

// A perceived object the caller can neither carry nor push, estimated 3 cm into where the robot
// stands, is fixed for the next question: the start touches a static object for that request.
// It is left as a movable would be in full mode (a short way out first), not `start in collision`.
TEST_F(LazyTest, AStartTouchingAFixedObjectLeavesItFirst) {
  const world::World w = testing::openRoomWorld();  // `obstacle`: x in [4.7, 5.3], y in [2.7, 3.3]
  MotionPlanner mp = planner(w);
  const Pose2D from{4.7 - kRadius + 0.03, 3.0, 0.0};
  MotionRequest req = baseRequest(from, {2.0, 3.0, 0.0});
  req.fixed_objects = {"obstacle"};
  const MotionResult r = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_EQ(r.start_contacts, std::vector<std::string>{"obstacle"});
  ASSERT_GE(r.path.waypoints.size(), 2u);
  EXPECT_NEAR(r.path.waypoints.front()[0], from.x, 1e-9);
  // After the start (and the turn in place there that the path states), off the object it stood in.
  JointPath rest = r.path;
  while (rest.waypoints.size() > 1 &&
         std::hypot(rest.waypoints.front()[0] - from.x, rest.waypoints.front()[1] - from.y) < 1e-9)
    rest.waypoints.erase(rest.waypoints.begin());
  EXPECT_TRUE(discTouches(w, rest, kRadius, 0.005).empty());
  // Touching a wall as well, there is no way out: start in collision, as before.
  world::World walled = w;
  ASSERT_TRUE(walled.addObject(testing::box("pillar", from.x - 0.3, 3.0, 0.1, 0.1, false)).ok());
  MotionPlanner mp2 = planner(walled);
  EXPECT_EQ(mp2.plan(req, Termination::after(5.0)).status, MotionStatus::kStartInCollision);
}

// A goal walled off by statics and an object the request fixes: the proof's first turn answers
// before any slice of the sampling planner (lazy KPIECE's first slice is 0.25 s).
TEST_F(LazyTest, AGoalWalledOffByAFixedObjectIsProvenBeforeAnySampling) {
  const world::World w = testing::pocketWorld();  // the crate closes the pocket's door
  MotionPlanner mp = planner(w);
  MotionRequest req = baseRequest({2, 2, 0}, {25, 25, 0});
  req.fixed_objects = {"crate"};
  const MotionResult r = mp.plan(req, Termination::after(10.0));
  EXPECT_EQ(r.status, MotionStatus::kNoPath) << r.reason;
  EXPECT_EQ(r.stats.sampling_slices, 0) << r.stats.proof_trace;
  EXPECT_GT(r.stats.proof_cells, 0u);
  // The crate free to move: the lazy path crosses it.
  req.fixed_objects.clear();
  const MotionResult o = mp.plan(req, Termination::after(10.0));
  ASSERT_EQ(o.status, MotionStatus::kSolved) << o.reason;
  EXPECT_EQ(blockingIds(o.blocking), std::vector<std::string>{"crate"});
}

TEST_F(LazyTest, FixedObjectsAreObstaclesOfTheLazyPath) {
  const world::World w = testing::twoDoorWorld();
  // The pure static-only path takes door A, through the two heavy objects.
  MotionRequest req = baseRequest({2, 0.9, 0}, {8, 0.9, 0});
  req.object_cost_scale = 0.0;
  {
    MotionPlanner mp = planner(w);
    const MotionResult r = mp.plan(req, Termination::after(5.0));
    ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
    EXPECT_EQ(blockingIds(r.blocking), (std::vector<std::string>{"heavy_a", "heavy_b"}));
  }
  // The robot cannot move them: the path goes through door B, whatever the cost scale, and
  // the planner's world is the same afterwards.
  req.fixed_objects = {"heavy_a", "heavy_b"};
  ASSERT_TRUE(w.object("light").graspable);  // fixed below too: fixing a graspable object is fine
  for (double scale : {0.0, 1.0}) {
    MotionPlanner mp = planner(w);
    req.object_cost_scale = scale;
    const MotionResult r = mp.plan(req, Termination::after(5.0));
    ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
    EXPECT_EQ(blockingIds(r.blocking), std::vector<std::string>{"light"}) << "scale " << scale;
    EXPECT_EQ(discTouches(w, r.path, kRadius, 0.005), std::vector<std::string>{"light"}) << "scale " << scale;
  }
  {
    // The planner's world is its own again after such a request.
    MotionPlanner mp = planner(w);
    (void)mp.plan(req, Termination::after(5.0));
    MotionRequest plain = baseRequest({2, 0.9, 0}, {8, 0.9, 0});
    plain.object_cost_scale = 0.0;
    const MotionResult r = mp.plan(plain, Termination::after(5.0));
    ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
    EXPECT_EQ(blockingIds(r.blocking), (std::vector<std::string>{"heavy_a", "heavy_b"}));
  }
  // Nothing can be moved: no lazy path.
  req.fixed_objects = {"heavy_a", "heavy_b", "light"};
  MotionPlanner mp = planner(w);
  const MotionResult r = mp.plan(req, Termination::after(3.0));
  EXPECT_TRUE(r.status == MotionStatus::kNoPath || r.status == MotionStatus::kTimeout)
      << toString(r.status) << ": " << r.reason;
}

// The roadmap of a world with fixed objects is made from the cached one of the world without
// them (the fixed objects' boxes checked again), not sampled anew behind lazy KPIECE: the
// request is answered from the roadmap, and its path is as independent checks require.
TEST_F(LazyTest, AFixedObjectsRoadmapIsDerivedFromTheCachedOne) {
  const world::World w = testing::twoDoorWorld();
  MotionPlanner mp = planner(w);
  MotionRequest req = baseRequest({2, 0.9, 0}, {8, 0.9, 0});
  req.object_cost_scale = 0.0;
  const MotionResult first = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(first.status, MotionStatus::kSolved) << first.reason;
  EXPECT_FALSE(first.stats.roadmap_derived);
  for (int k = 0; k < 2; ++k) {  // the second: the derived roadmap is cached itself
    MotionRequest fixed = req;
    fixed.fixed_objects = {"heavy_a", "heavy_b"};
    const MotionResult r = mp.plan(fixed, Termination::after(5.0));
    ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
    EXPECT_EQ(r.stats.roadmap_derived, k == 0) << k;
    EXPECT_TRUE(r.stats.roadmap_reused) << k;
    EXPECT_FALSE(r.stats.lazy_planner_used) << "answered from the roadmap, " << k;
    EXPECT_EQ(blockingIds(r.blocking), std::vector<std::string>{"light"}) << k;
    EXPECT_EQ(discTouches(w, r.path, kRadius, 0.005), std::vector<std::string>{"light"}) << k;
    EXPECT_GT(discClearance(w, r.path, kRadius, 0.005, {}, /*movables=*/false), -1e-3) << k;
  }
  // The world without them is the cached one still: the same answer as the first.
  const MotionResult again = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(again.status, MotionStatus::kSolved) << again.reason;
  EXPECT_EQ(blockingIds(again.blocking), blockingIds(first.blocking));
}

TEST_F(LazyTest, FixedObjectsMustBeMovablesOfTheWorld) {
  const world::World w = testing::twoDoorWorld();
  MotionPlanner mp = planner(w);
  MotionRequest req = baseRequest({2, 0.9, 0}, {8, 0.9, 0});
  req.fixed_objects = {"heavy_a", "no_such_thing"};
  MotionResult r = mp.plan(req, Termination::after(5.0));
  EXPECT_EQ(r.status, MotionStatus::kInvalidRequest);
  EXPECT_NE(r.reason.find("fixed_objects[1]: no object 'no_such_thing'"), std::string::npos) << r.reason;
  req.fixed_objects = {"wall_mid_a"};
  r = mp.plan(req, Termination::after(5.0));
  EXPECT_EQ(r.status, MotionStatus::kInvalidRequest);
  EXPECT_NE(r.reason.find("fixed_objects[0]: object 'wall_mid_a' is static"), std::string::npos) << r.reason;
}

TEST_F(LazyTest, IgnoredObjectsAreNeitherObstaclesNorReported) {
  const world::World w = testing::corridorWorld(true);
  MotionPlanner mp = planner(w);
  MotionRequest req = baseRequest({2, 2, 0}, {8, 2, 0});
  req.ignored_objects = {"crate"};
  const MotionResult r = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_TRUE(r.blocking.empty());
}

TEST_F(LazyTest, GoalInsideAMovableIsAllowedAndReported) {
  const world::World w = testing::corridorWorld(true);
  MotionPlanner mp = planner(w);
  const MotionResult r = mp.plan(baseRequest({2, 2, 0}, {8.8, 3.4, 0}), Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  const auto got = blockingIds(r.blocking);
  EXPECT_NE(std::find(got.begin(), got.end(), "far_box"), got.end());
  EXPECT_NEAR(r.blocking.back().exit_fraction, 1.0, 1e-9);
}

TEST_F(LazyTest, StaticCollisionAtStartOrGoalNamesTheObject) {
  const world::World w = testing::corridorWorld(true);
  MotionPlanner mp = planner(w);
  MotionResult r = mp.plan(baseRequest({5, 0.5, 0}, {8, 2, 0}), Termination::after(2.0));
  EXPECT_EQ(r.status, MotionStatus::kStartInCollision);
  EXPECT_EQ(r.colliding_object, "wall_mid_low");
  r = mp.plan(baseRequest({2, 2, 0}, {5, 3.5, 0}), Termination::after(2.0));
  EXPECT_EQ(r.status, MotionStatus::kGoalInCollision);
  EXPECT_EQ(r.colliding_object, "wall_mid_high");
}

TEST_F(LazyTest, TrajectoryFollowsThePath) {
  const world::World w = testing::corridorWorld(true);
  MotionPlanner mp = planner(w);
  const MotionResult r = mp.plan(baseRequest({2, 2, 0}, {8, 2, 0}), Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  ASSERT_FALSE(r.trajectory.empty());
  EXPECT_EQ(r.trajectory.joint_names, r.path.joint_names);
  EXPECT_NO_THROW(r.trajectory.validate());
  EXPECT_EQ(r.trajectory.points.front().positions, r.path.waypoints.front());
  for (std::size_t j = 0; j < 3; ++j) {
    EXPECT_NEAR(r.trajectory.points.back().positions[j], r.path.waypoints.back()[j], 1e-9);
  }
  EXPECT_GT(r.trajectory.duration(), r.path_length / mp.params().timing.base_linear_speed);
}

TEST_F(LazyTest, WorldUpdatesBetweenCallsAreApplied) {
  world::World w = testing::corridorWorld(true);
  MotionPlanner mp = planner(w);
  MotionResult r = mp.plan(baseRequest({2, 2, 0}, {8, 2, 0}), Termination::after(5.0));
  ASSERT_EQ(blockingIds(r.blocking), std::vector<std::string>{"crate"});
  // Move the crate out of the door: the next call sees it.
  Eigen::Isometry3d p = w.object("crate").pose;
  p.translation().x() = 2.0;
  p.translation().y() = 3.4;
  ASSERT_TRUE(w.setObjectPose("crate", p).ok());
  mp.setWorld(w);
  r = mp.plan(baseRequest({2, 1.0, 0}, {8, 2, 0}), Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_TRUE(r.blocking.empty()) << r.blocking.front().object_id;
}

// Samples around a crossed movable find the gap beside it that a sparse roadmap misses: a door
// half filled by a heavy crate, with room for the robot beside it (0.7 m for a 0.6 m disc).
TEST_F(LazyTest, SamplesAroundACrossedObjectFindTheGapBesideIt) {
  world::World w("half_door");
  for (const auto& o : {testing::box("wall_south", 5, -0.1, 10.4, 0.2, false), testing::box("wall_north", 5, 4.1, 10.4, 0.2, false),
                        testing::box("wall_west", -0.1, 2, 0.2, 4, false), testing::box("wall_east", 10.1, 2, 0.2, 4, false),
                        testing::box("wall_mid_low", 5, 0.5, 0.2, 1.0, false), testing::box("wall_mid_high", 5, 3.5, 0.2, 1.0, false),
                        testing::box("crate", 5, 1.65, 0.4, 1.3, true, 1.0, 120.0)}) {
    ASSERT_TRUE(w.addObject(o).ok());
  }
  MotionPlannerParams p = untimedParams();
  // A roadmap of lazy KPIECE's path alone (it crosses the door anywhere in its 2 m, statically
  // free), and no shortcutting: what the samples around the crate add is all that can find the gap.
  p.lazy.roadmap_samples = 0;
  p.lazy.roadmap_bridge_samples = 0;
  p.lazy.roadmap_growth_samples = 0;
  p.lazy.shortcut_attempts = 0;
  const MotionRequest req = baseRequest({2, 1.0, 0}, {8, 1.0, 0});
  auto run = [&](int ring) {
    p.lazy.object_ring_samples = ring;
    MotionPlanner mp = planner(w, p);
    return mp.plan(req, Termination::after(10.0));
  };
  const MotionResult with = run(48);
  ASSERT_EQ(with.status, MotionStatus::kSolved) << with.reason;
  EXPECT_TRUE(with.blocking.empty()) << "crossed " << with.blocking.front().object_id;
  EXPECT_TRUE(discTouches(w, with.path, kRadius, 0.005).empty());
  EXPECT_GT(discClearance(w, with.path, kRadius, 0.005, {}, /*movables=*/false), -1e-3);
  // Without them, on this seed, the path crosses the crate (cost ~392 s against ~17 s; recorded,
  // not asserted: it depends on lazy KPIECE's random path).
  const MotionResult without = run(0);
  ASSERT_EQ(without.status, MotionStatus::kSolved) << without.reason;
  RecordProperty("crossed_without_ring_samples", static_cast<int>(without.blocking.size()));
  EXPECT_LE(with.cost_s, without.cost_s + 1e-9);
}

// (Last in the file: SamplesAroundACrossedObjectFindTheGapBesideIt compares two random lazy
// paths and failed when this test ran before it; seedRandomness does not reset every random state.)
// A 0.6 x 0.5 m stop-and-turn base drives north to a pose facing east, 4 cm short of a crate
// beside the goal: it turns in place there, and its corner (0.39 m out) sweeps 5 cm into the
// crate. The report must hold what the robot sweeps (an independent rectangle test, 2 mrad and
// 1 mm apart), or the execution monitor refuses a path the graph manager believed clear. The
// segment's end yaws agree, so its SE(2) distance is the drive alone: the report now samples by
// the swept length (turns at the circumradius), about 1.5 times denser here. (This graze is deep
// enough that the sparser samples caught it too; the refusals seen in the NAMO worlds at push
// start poses are not reproduced by this test.)
TEST_F(LazyTest, AStopAndTurnBaseReportsWhatItsTurnInPlaceSweeps) {
  world::World w("room");
  ASSERT_TRUE(w.addObject(testing::box("crate", 0.3 + 0.04 + 0.2, 3.0, 0.4, 0.4, true, 0.5)).ok());
  MotionPlannerParams p = testing::untimedParams();
  p.sampling.base_turn_in_place = true;
  MotionPlanner mp(collision::RobotGeometry::box(0.6, 0.5, 0.35), p);
  mp.setWorld(w);
  const MotionResult r = mp.plan(baseRequest({0.0, 0.0, 0.0}, {0.0, 3.0, 0.0}), Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  const double hx = 0.3, hy = 0.25;
  auto touchesCrate = [&](double x, double y, double th) {
    const double c = std::cos(th), s = std::sin(th);
    const double dx = 0.54 - x, dy = 3.0 - y;
    const double tx = 0.2 * std::abs(c) + 0.2 * std::abs(s);
    return std::abs(dx) < hx * std::abs(c) + hy * std::abs(s) + 0.2 && std::abs(dy) < hx * std::abs(s) + hy * std::abs(c) + 0.2 &&
           std::abs(dx * c + dy * s) < hx + tx && std::abs(-dx * s + dy * c) < hy + tx;
  };
  auto wrap = [](double a) { return std::remainder(a, 2.0 * M_PI); };
  bool touched = false;
  const auto& wp = r.path.waypoints;
  double heading = wp.front()[2];
  auto turn = [&](double x, double y, double to) {
    const double d = wrap(to - heading);
    const int n = std::max(1, static_cast<int>(std::ceil(std::abs(d) / 0.002)));
    for (int k = 0; k <= n; ++k) touched = touched || touchesCrate(x, y, heading + d * k / n);
    heading = to;
  };
  for (std::size_t i = 0; i + 1 < wp.size(); ++i) {
    const double dx = wp[i + 1][0] - wp[i][0], dy = wp[i + 1][1] - wp[i][1], len = std::hypot(dx, dy);
    if (len >= 1e-6) {
      double h = std::atan2(dy, dx);
      if (std::abs(wrap(h + M_PI - wp[i][2])) < std::abs(wrap(h - wp[i][2]))) h = wrap(h + M_PI);
      turn(wp[i][0], wp[i][1], h);
      const int n = std::max(1, static_cast<int>(std::ceil(len / 0.001)));
      for (int k = 0; k <= n; ++k) touched = touched || touchesCrate(wp[i][0] + dx * k / n, wp[i][1] + dy * k / n, h);
    }
    turn(wp[i + 1][0], wp[i + 1][1], wp[i + 1][2]);
  }
  EXPECT_TRUE(touched) << "the scene should make the final turn sweep the crate";
  EXPECT_EQ(blockingIds(r.blocking), touched ? std::vector<std::string>{"crate"} : std::vector<std::string>{});
}

}  // namespace
}  // namespace tamp::motion_planner
