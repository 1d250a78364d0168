// The planner on real NAMO benchmark worlds (tests/data/benchmarks/namo, shipped in the repository).
#include <gtest/gtest.h>

#include <filesystem>

#include "tamp/core/paths.h"
#include "tamp/motion_planner/motion_planner.h"
#include "tamp/world/namo.h"

namespace tamp::motion_planner {
namespace {

std::filesystem::path namoDir() { return std::filesystem::path(TAMP_BENCHMARKS_DIR) / "namo"; }

class NamoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    seedRandomness(42);
    ASSERT_TRUE(std::filesystem::exists(namoDir())) << "no NAMO worlds at " << namoDir();
  }
};

/// Movables a disc touches along the path (5 mm steps), re-checked in a scene built here.
std::vector<std::string> recheck(const world::World& w, double radius, const JointPath& path) {
  collision::Scene scene(w);
  scene.setRobot(collision::RobotGeometry::disc(radius, 1.0));
  std::vector<std::string> out;
  for (std::size_t i = 0; i + 1 < path.waypoints.size(); ++i) {
    const auto& a = path.waypoints[i];
    const auto& b = path.waypoints[i + 1];
    const int n = std::max(1, static_cast<int>(std::ceil(std::hypot(b[0] - a[0], b[1] - a[1]) / 0.005)));
    for (int k = 0; k <= n; ++k) {
      const double t = static_cast<double>(k) / n;
      scene.setBasePose(Pose2D{a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), 0.0});
      EXPECT_FALSE(scene.robotInCollision(collision::Filter::staticOnly())) << "static contact, segment " << i;
      for (const auto& id : scene.robotCollisions(collision::Filter::movableOnly())) out.push_back(id);
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

TEST_F(NamoTest, MoghaddamWorldLazyPathReportsWhatItCrossesAndFullModeProvesNoPath) {
  auto loaded = world::loadNamo(namoDir() / "moghaddam_planning_2016_benchmark" /
                                "moghaddam_planning_2016_benchmark_05.svg");
  ASSERT_TRUE(loaded.ok()) << loaded.error().toString();
  const auto& nw = *loaded;
  ASSERT_FALSE(nw.goals.empty());
  MotionPlanner mp(collision::RobotGeometry::disc(nw.robot_radius, 1.0));
  mp.setWorld(nw.world);
  MotionRequest req;
  req.start.base = nw.start;
  req.goal = MotionGoal::basePoseGoal(nw.goals[0].pose, !nw.goals[0].has_orientation);
  const MotionResult lazy = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(lazy.status, MotionStatus::kSolved) << lazy.reason;
  std::vector<std::string> reported;
  for (const auto& b : lazy.blocking) reported.push_back(b.object_id);
  std::sort(reported.begin(), reported.end());
  EXPECT_EQ(recheck(nw.world, nw.robot_radius, lazy.path), reported);
  EXPECT_FALSE(reported.empty());  // no collision-free path exists in these worlds
  EXPECT_LE(lazy.cost_s, lazy.stats.raw_cost_s + 1e-9);

  req.mode = MotionMode::kFull;
  const MotionResult full = mp.plan(req, Termination::after(30.0));
  EXPECT_EQ(full.status, MotionStatus::kNoPath) << full.reason;
  EXPECT_NE(full.reason.find("proven"), std::string::npos) << full.reason;
}

TEST_F(NamoTest, JsonWorldWithoutMovablesIsSolvedCollisionFreeInBothModes) {
  auto loaded = world::loadNamo(namoDir() / "s-namo_cases" / "01_basic" / "01_basic_no_movables_omniscient.json");
  ASSERT_TRUE(loaded.ok()) << loaded.error().toString();
  const auto& nw = *loaded;
  MotionPlanner mp(collision::RobotGeometry::disc(nw.robot_radius, 1.0));
  mp.setWorld(nw.world);
  for (MotionMode mode : {MotionMode::kLazy, MotionMode::kFull}) {
    MotionRequest req;
    req.mode = mode;
    req.start.base = nw.start;
    req.goal = MotionGoal::basePoseGoal(nw.goals[0].pose, !nw.goals[0].has_orientation);
    const MotionResult r = mp.plan(req, Termination::after(10.0));
    ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
    EXPECT_TRUE(r.blocking.empty());
    EXPECT_TRUE(recheck(nw.world, nw.robot_radius, r.path).empty());
  }
}

// The clearance grid (sampling.clearance_grid_resolution) answers a share of the lazy mode's
// static checks without FCL, and its paths stay free of static contact (checked at 5 mm here).
// (That it changes no path is measured across processes by tamp_motion_planner_namo_bench:
// OMPL's samplers are seeded once per process, so two planners in one process differ anyway.)
TEST_F(NamoTest, TheClearanceGridAnswersStaticChecksAndItsPathsTouchNoWall) {
  const std::vector<std::filesystem::path> worlds{
      namoDir() / "moghaddam_planning_2016_benchmark" / "moghaddam_planning_2016_benchmark_05.svg",
      namoDir() / "s-namo_cases" / "04_after_the_feast" / "04_after_the_feast.json"};
  for (const auto& file : worlds) {
    auto loaded = world::loadNamo(file);
    ASSERT_TRUE(loaded.ok()) << loaded.error().toString();
    const auto& nw = *loaded;
    for (double h : {0.05, 0.0}) {
      MotionPlannerParams params;
      params.sampling.clearance_grid_resolution = h;
      MotionPlanner mp(collision::RobotGeometry::disc(nw.robot_radius, 1.0), params);
      mp.setWorld(nw.world);
      std::uint64_t answered = 0, checks = 0;
      // There and back, then there again (the roadmap answers the later ones).
      const std::vector<std::pair<Pose2D, Pose2D>> legs{
          {nw.start, nw.goals[0].pose}, {nw.goals[0].pose, nw.start}, {nw.start, nw.goals[0].pose}};
      for (const auto& [from, to] : legs) {
        MotionRequest req;
        req.start.base = from;
        req.goal = MotionGoal::basePoseGoal(to, true);
        const MotionResult r = mp.plan(req, Termination::after(30.0));
        ASSERT_EQ(r.status, MotionStatus::kSolved) << file << ": " << r.reason;
        std::vector<std::string> reported;
        for (const auto& b : r.blocking) reported.push_back(b.object_id);
        std::sort(reported.begin(), reported.end());
        EXPECT_EQ(recheck(nw.world, nw.robot_radius, r.path), reported) << file;
        answered += r.stats.grid_answers;
        checks += r.stats.validity_checks;
      }
      if (h > 0.0)
        EXPECT_GT(answered, checks / 10) << file << ": the grid answered " << answered << " of " << checks << " checks";
      else
        EXPECT_EQ(answered, 0U) << file;
    }
  }
}

}  // namespace
}  // namespace tamp::motion_planner
