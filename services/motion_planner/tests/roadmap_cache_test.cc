// The roadmap cache of the lazy mode: reused across requests while only movables change, with the
// same quality; a changed static world or held object selects another roadmap.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "tamp/motion_planner/motion_planner.h"
#include "test_worlds.h"

namespace tamp::motion_planner {
namespace {

using testing::baseRequest;
using testing::blockingIds;
using testing::discClearance;
using testing::discTouches;

constexpr double kRadius = testing::kDiscRadius;

MotionPlannerParams params() { return testing::untimedParams(); }
MotionPlanner planner(const world::World& w, const MotionPlannerParams& p = params()) { return testing::discPlanner(w, p); }

class RoadmapCacheTest : public ::testing::Test {
 protected:
  void SetUp() override { seedRandomness(42); }
};

TEST_F(RoadmapCacheTest, ReuseGivesTheSameQualityAndMovablesDoNotInvalidate) {
  world::World w = testing::twoDoorWorld();
  MotionPlanner mp = planner(w, params());
  const MotionRequest req = baseRequest({2, 0.9, 0}, {8, 0.9, 0});
  const MotionResult cold = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(cold.status, MotionStatus::kSolved) << cold.reason;
  EXPECT_FALSE(cold.stats.roadmap_reused);
  EXPECT_TRUE(cold.stats.lazy_planner_used);  // a new roadmap is seeded by lazy KPIECE
  EXPECT_EQ(blockingIds(cold.blocking), std::vector<std::string>{"light"});
  EXPECT_EQ(mp.roadmapCacheSize(), 1u);

  // Another query from elsewhere, then the same query again: the roadmap answers.
  const MotionResult other = mp.plan(baseRequest({1, 3, 0}, {9, 1, 0}), Termination::after(5.0));
  ASSERT_EQ(other.status, MotionStatus::kSolved) << other.reason;
  EXPECT_TRUE(other.stats.roadmap_reused);
  EXPECT_GT(discClearance(w, other.path, kRadius, 0.005, {}, /*movables=*/false), -1e-3);
  EXPECT_EQ(discTouches(w, other.path, kRadius, 0.005), blockingIds(other.blocking));
  const MotionResult warm = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(warm.status, MotionStatus::kSolved) << warm.reason;
  EXPECT_TRUE(warm.stats.roadmap_reused);
  EXPECT_FALSE(warm.stats.lazy_planner_used);
  EXPECT_EQ(blockingIds(warm.blocking), blockingIds(cold.blocking));
  EXPECT_EQ(discTouches(w, warm.path, kRadius, 0.005), blockingIds(warm.blocking));
  EXPECT_GT(discClearance(w, warm.path, kRadius, 0.005, {}, false), -1e-3);
  EXPECT_LE(warm.cost_s, cold.cost_s * 1.05) << "cold " << cold.cost_s << " warm " << warm.cost_s;

  // Movables change: the light box leaves door B. Same roadmap, and the path is now free.
  Eigen::Isometry3d p = w.object("light").pose;
  p.translation().x() = 8.5;
  p.translation().y() = 3.5;
  ASSERT_TRUE(w.setObjectPose("light", p).ok());
  mp.setWorld(w);
  const MotionResult moved = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(moved.status, MotionStatus::kSolved) << moved.reason;
  EXPECT_TRUE(moved.stats.roadmap_reused);
  EXPECT_TRUE(moved.blocking.empty()) << moved.blocking.front().object_id;
  EXPECT_TRUE(discTouches(w, moved.path, kRadius, 0.005).empty());
  EXPECT_EQ(mp.roadmapCacheSize(), 1u);
}

TEST_F(RoadmapCacheTest, StaticWorldChangeInvalidates) {
  world::World w = testing::twoDoorWorld();
  MotionPlanner mp = planner(w, params());
  const MotionRequest req = baseRequest({2, 0.9, 0}, {8, 0.9, 0});
  const MotionResult first = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(first.status, MotionStatus::kSolved) << first.reason;
  ASSERT_EQ(blockingIds(first.blocking), std::vector<std::string>{"light"});  // through door B
  ASSERT_TRUE(mp.plan(req, Termination::after(5.0)).stats.roadmap_reused);

  // A static wall closes door B: the cached roadmap's edges through it are no longer valid.
  ASSERT_TRUE(w.addObject(testing::box("door_b_closed", 5.0, 3.1, 0.2, 1.0, false)).ok());
  ASSERT_TRUE(w.removeObject("light").ok());
  mp.setWorld(w);
  const MotionResult closed = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(closed.status, MotionStatus::kSolved) << closed.reason;
  // Not the cached roadmap: one made from it, whose edges near the new wall are checked again
  // (the new static world only adds an obstacle to the cached one's).
  EXPECT_TRUE(closed.stats.roadmap_derived);
  EXPECT_GT(discClearance(w, closed.path, kRadius, 0.005, {}, /*movables=*/false), -1e-3);
  EXPECT_EQ(blockingIds(closed.blocking), (std::vector<std::string>{"heavy_a", "heavy_b"}));

  // A moved static object invalidates too.
  world::World w2 = w;
  Eigen::Isometry3d p = w2.object("door_b_closed").pose;
  p.translation().x() = 1.0;
  ASSERT_TRUE(w2.setObjectPose("door_b_closed", p).ok());
  mp.setWorld(w2);
  const MotionResult reopened = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(reopened.status, MotionStatus::kSolved) << reopened.reason;
  // Not the closed world's roadmap (its wall stood elsewhere); made from the first world's again.
  EXPECT_TRUE(reopened.stats.roadmap_derived);
  EXPECT_GT(discClearance(w2, reopened.path, kRadius, 0.005, {}, false), -1e-3);
  EXPECT_TRUE(reopened.blocking.empty());  // door B is open and free now

  // Back to the first static world: its roadmap is still cached (LRU), and still right.
  mp.setWorld(w);
  const MotionResult again = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(again.status, MotionStatus::kSolved) << again.reason;
  EXPECT_TRUE(again.stats.roadmap_reused);
  EXPECT_GT(discClearance(w, again.path, kRadius, 0.005, {}, false), -1e-3);

  mp.clearRoadmapCache();
  EXPECT_EQ(mp.roadmapCacheSize(), 0u);
  EXPECT_FALSE(mp.plan(req, Termination::after(5.0)).stats.roadmap_reused);
}

TEST_F(RoadmapCacheTest, HeldObjectChangeInvalidates) {
  world::World w = testing::twoDoorWorld();
  ASSERT_TRUE(w.addObject(testing::box("parcel", 2.0, 1.35, 0.2, 0.2, true, 0.3, 1.0)).ok());
  MotionPlanner mp = planner(w, params());
  MotionRequest req = baseRequest({2, 0.9, 0}, {8, 0.9, 0});
  ASSERT_TRUE(mp.plan(req, Termination::after(5.0)).ok());
  ASSERT_TRUE(mp.plan(req, Termination::after(5.0)).stats.roadmap_reused);

  req.held_object = "parcel";  // the robot carries it: its static free space is smaller
  const MotionResult held = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(held.status, MotionStatus::kSolved) << held.reason;
  EXPECT_FALSE(held.stats.roadmap_reused);
  EXPECT_EQ(std::count(held.stats.raw_blocking.begin(), held.stats.raw_blocking.end(), "parcel"), 0);
  EXPECT_EQ(mp.roadmapCacheSize(), 2u);
  EXPECT_TRUE(mp.plan(req, Termination::after(5.0)).stats.roadmap_reused);

  // Held at another place on the robot (the start differs relative to the parcel): another roadmap.
  MotionRequest req2 = req;
  req2.start.base = Pose2D{2.0, 0.85, 0.0};
  const MotionResult regrasped = mp.plan(req2, Termination::after(5.0));
  ASSERT_EQ(regrasped.status, MotionStatus::kSolved) << regrasped.reason;
  EXPECT_FALSE(regrasped.stats.roadmap_reused);

  // Put down again: the first roadmap is still cached.
  req.held_object.clear();
  EXPECT_TRUE(mp.plan(req, Termination::after(5.0)).stats.roadmap_reused);
}

}  // namespace
}  // namespace tamp::motion_planner

namespace tamp::motion_planner {
namespace {

// prepare() builds the roadmap ahead of requests: the first request after it reuses it (no lazy
// KPIECE), with the same report as a cold request; a second prepare() finds it cached and only
// evaluates the edges the request added; an interrupted prepare() keeps what it did.
TEST_F(RoadmapCacheTest, PrepareBuildsTheRoadmapTheNextRequestReuses) {
  world::World w = testing::twoDoorWorld();
  MotionPlanner mp = planner(w, params());
  const MotionRequest req = baseRequest({2, 0.9, 0}, {8, 0.9, 0});

  auto stopped = mp.prepare(PlanningGroup::kBase, req.start, {}, Termination::after(-1.0));
  ASSERT_TRUE(stopped.ok()) << stopped.error().toString();
  EXPECT_TRUE(stopped->built);
  EXPECT_FALSE(stopped->completed);

  // The next call completes what the interrupted one left.
  auto prep = mp.prepare(PlanningGroup::kBase, req.start, {}, Termination::after(30.0));
  ASSERT_TRUE(prep.ok()) << prep.error().toString();
  EXPECT_FALSE(prep->built);
  EXPECT_TRUE(prep->completed);
  EXPECT_GE(prep->roadmap_nodes, static_cast<std::size_t>(mp.params().lazy.roadmap_samples));
  EXPECT_EQ(prep->edges_evaluated, prep->roadmap_edges);  // every edge's static validity known
  EXPECT_GT(prep->edges_invalid, 0u);                     // the walls cut some
  EXPECT_EQ(mp.roadmapCacheSize(), 1u);

  const MotionResult r = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_TRUE(r.stats.roadmap_reused);
  EXPECT_FALSE(r.stats.lazy_planner_used);
  EXPECT_EQ(blockingIds(r.blocking), std::vector<std::string>{"light"});
  EXPECT_EQ(discTouches(w, r.path, kRadius, 0.005), blockingIds(r.blocking));
  EXPECT_GT(discClearance(w, r.path, kRadius, 0.005, {}, /*movables=*/false), -1e-3);
  EXPECT_EQ(mp.roadmapCacheSize(), 1u);

  // Again: cached; only the edges of the request's start and goal and of the samples it added
  // around the movables its path crossed (at most each of the 3 once) are new.
  auto again = mp.prepare(PlanningGroup::kBase, req.start, {}, Termination::after(30.0));
  ASSERT_TRUE(again.ok());
  EXPECT_FALSE(again->built);
  EXPECT_TRUE(again->completed);
  const auto& lazy = mp.params().lazy;
  EXPECT_LE(again->edges_evaluated,
            static_cast<std::size_t>((2 + 3 * lazy.object_ring_samples) * lazy.roadmap_neighbors));

  // Only a movable changes: still the same roadmap.
  Eigen::Isometry3d p = w.object("light").pose;
  p.translation().x() = 8.5;
  p.translation().y() = 3.5;
  ASSERT_TRUE(w.setObjectPose("light", p).ok());
  mp.setWorld(w);
  auto moved = mp.prepare(PlanningGroup::kBase, req.start, {}, Termination::after(30.0));
  ASSERT_TRUE(moved.ok());
  EXPECT_FALSE(moved->built);
  EXPECT_EQ(moved->edges_evaluated, 0u);

  // Bad input.
  EXPECT_FALSE(mp.prepare(PlanningGroup::kArm, req.start).ok());
  robot::RobotState bad = req.start;
  bad.arm = {0.1};
  EXPECT_FALSE(mp.prepare(PlanningGroup::kBase, bad).ok());
}

// The movables touched along roadmap edges are cached across requests and dropped near objects
// that moved: door A's edges learnt free while the heavy boxes were away must see them again when
// they come back (a stale entry would send the robot through them instead of the light box).
TEST_F(RoadmapCacheTest, MovableCacheFollowsMovedObjects) {
  world::World w = testing::twoDoorWorld();
  MotionPlanner mp = planner(w, params());
  const MotionRequest req = baseRequest({2, 0.9, 0}, {8, 0.9, 0});
  ASSERT_TRUE(mp.prepare(PlanningGroup::kBase, req.start, {}, Termination::after(30.0)).ok());
  const MotionResult first = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(first.status, MotionStatus::kSolved) << first.reason;
  EXPECT_EQ(blockingIds(first.blocking), std::vector<std::string>{"light"});

  const world::World original = w;
  auto place = [&](const std::string& id, double x, double y) {
    Eigen::Isometry3d p = w.object(id).pose;
    p.translation().x() = x;
    p.translation().y() = y;
    ASSERT_TRUE(w.setObjectPose(id, p).ok());
  };
  place("heavy_a", 0.8, 3.3);
  place("heavy_b", 9.2, 3.3);
  mp.setWorld(w);
  const MotionResult away = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(away.status, MotionStatus::kSolved) << away.reason;
  EXPECT_TRUE(away.blocking.empty());  // door A is free now
  EXPECT_FALSE(away.stats.lazy_planner_used);

  mp.setWorld(original);
  const MotionResult back = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(back.status, MotionStatus::kSolved) << back.reason;
  EXPECT_EQ(blockingIds(back.blocking), std::vector<std::string>{"light"});
  EXPECT_EQ(discTouches(original, back.path, kRadius, 0.005), blockingIds(back.blocking));
  EXPECT_LE(back.cost_s, first.cost_s * 1.05) << "first " << first.cost_s << " back " << back.cost_s;
}

// The same on an open room, where a stale entry would show: the straight path learnt free while
// the box was away must be seen blocked when the box returns (a detour is far cheaper than
// moving it).
TEST_F(RoadmapCacheTest, MovableCacheDropsEntriesWhereAnObjectReturns) {
  world::World w = testing::openRoomWorld();
  const world::World original = w;
  MotionPlanner mp(collision::RobotGeometry::disc(kRadius, 1.0), params());
  const MotionRequest req = baseRequest({2, 3, 0}, {8, 3, 0});
  Eigen::Isometry3d p = w.object("obstacle").pose;
  p.translation().x() = 1.0;
  p.translation().y() = 5.2;
  ASSERT_TRUE(w.setObjectPose("obstacle", p).ok());
  mp.setWorld(w);
  ASSERT_TRUE(mp.prepare(PlanningGroup::kBase, req.start, {}, Termination::after(30.0)).ok());
  const MotionResult away = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(away.status, MotionStatus::kSolved) << away.reason;
  EXPECT_TRUE(away.blocking.empty());
  EXPECT_FALSE(away.stats.lazy_planner_used);

  mp.setWorld(original);
  const MotionResult back = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(back.status, MotionStatus::kSolved) << back.reason;
  EXPECT_TRUE(back.blocking.empty()) << back.blocking.front().object_id;
  EXPECT_TRUE(discTouches(original, back.path, kRadius, 0.005).empty());
}

// A long mission asks many queries: their starts and goals join the roadmap, and the least
// recently used are removed beyond roadmap_max_request_nodes, without breaking later searches
// (indices, edges and the movable cache are remapped).
TEST_F(RoadmapCacheTest, RequestNodesArePrunedAndLaterSearchesStayCorrect) {
  world::World w = testing::twoDoorWorld();
  MotionPlannerParams p = params();
  p.lazy.roadmap_max_request_nodes = 10;
  p.lazy.roadmap_growth_samples = 0;
  MotionPlanner mp = planner(w, p);
  const MotionRequest req = baseRequest({2, 0.9, 0}, {8, 0.9, 0});
  const auto prep = mp.prepare(PlanningGroup::kBase, req.start, {}, Termination::after(30.0));
  ASSERT_TRUE(prep.ok());
  const MotionResult first = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(first.status, MotionStatus::kSolved) << first.reason;

  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(0.6, 9.4), uy(0.6, 3.4);
  std::size_t pruned = 0, max_nodes = 0;
  int solved = 0, fallbacks = 0;
  for (int i = 0; i < 40; ++i) {
    const MotionRequest q = baseRequest({ux(rng), uy(rng), 0}, {ux(rng), uy(rng), 0});
    const MotionResult r = mp.plan(q, Termination::after(5.0));
    if (r.status != MotionStatus::kSolved) continue;  // a sample inside a wall or a box
    ++solved;
    pruned += r.stats.roadmap_pruned;
    fallbacks += r.stats.lazy_planner_used;
    if (!r.stats.lazy_planner_used) max_nodes = std::max(max_nodes, r.stats.roadmap_nodes);
    EXPECT_GT(discClearance(w, r.path, kRadius, 0.005, {}, /*movables=*/false), -1e-3) << "query " << i;
    EXPECT_EQ(discTouches(w, r.path, kRadius, 0.005), blockingIds(r.blocking)) << "query " << i;
  }
  EXPECT_GE(solved, 20);
  EXPECT_GT(pruned, 0u);
  // Samples, the first request's path and at most 10 request nodes (+ the current request's);
  // kept: the samples around crossed movables (each of the 3 once: they do not move here) and the
  // paths of lazy KPIECE fallbacks.
  EXPECT_LE(max_nodes, first.stats.roadmap_nodes + 12 + 3 * static_cast<std::size_t>(p.lazy.object_ring_samples) +
                           40 * static_cast<std::size_t>(fallbacks));
  // The first query again, after all that pruning: same objects, no worse.
  const MotionResult again = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(again.status, MotionStatus::kSolved) << again.reason;
  EXPECT_EQ(blockingIds(again.blocking), blockingIds(first.blocking));
  EXPECT_LE(again.cost_s, first.cost_s * 1.05) << "first " << first.cost_s << " again " << again.cost_s;
}

}  // namespace
}  // namespace tamp::motion_planner
