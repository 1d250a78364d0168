// Where the robot stands to grasp a blocking object (GraphManager::standBeside), against a
// scripted grasp service that records what it is asked: on the robot's own way in first, then
// facing the object at distances that follow the robot's footprint, then the service's samples.
#include <cmath>

#include <gtest/gtest.h>

#include "tamp/core/paths.h"
#include "tamp/graph_manager/graph_manager.h"
#include "tamp/world/scenario.h"

namespace tamp::graph_manager {
namespace {

/// Answers grasp queries from a single base pose when `accept` says so; a sampled query (no base)
/// gets `sampled`. Nothing else is asked in these tests.
class GraspOnly : public ServiceClients {
 public:
  std::function<bool(const Pose2D&)> accept = [](const Pose2D&) { return true; };
  std::vector<GraspOption> sampled;
  std::vector<GraspQuery> asked;

  TaskPlan plan(const TaskQuery&) override { return TaskPlan{}; }
  MotionAnswer motion(const MotionQuery&) override { return MotionAnswer{}; }
  Result<std::vector<PlacementOption>> placements(const PlacementQuery&) override {
    return std::vector<PlacementOption>{};
  }
  Result<std::vector<GraspOption>> grasps(const GraspQuery& q) override {
    asked.push_back(q);
    if (!q.base) return sampled;
    if (!accept(*q.base)) return std::vector<GraspOption>{};
    GraspOption g;
    g.base_pose = *q.base;
    return std::vector<GraspOption>{g};
  }
  std::vector<EffortAnswer> effort(const std::vector<EffortQuery>& qs) override {
    return std::vector<EffortAnswer>(qs.size());
  }
};

struct Fixture {
  world::Scenario sc;
  robot::RobotModel robot;
  GraphManagerParams params;
};

/// namo_corridor: the thin box (0.05 x 0.30 m) at (4.62, 1.2), the robot coming from the west.
Fixture corridor() {
  auto sc = world::loadScenario(configDir() / "scenarios" / "namo_corridor.yaml");
  if (!sc) throw std::runtime_error(sc.error().toString());
  auto robot = robot::RobotModel::loadDescription(sc->robot.description);
  if (!robot) throw std::runtime_error(robot.error().toString());
  return {*sc, *robot, GraphManagerParams{}};
}

double baseFront(const robot::RobotModel& r) {
  double x = 0.0;
  for (const auto& v : r.baseFootprint()) x = std::max(x, v.x());
  return x;
}

/// The lazy path's base poses from (1.5, 1.2) east, every 5 cm, heading `theta`.
std::vector<Pose2D> wayIn(double y, double theta) {
  std::vector<Pose2D> path;
  for (int i = 0; i <= 140; ++i) path.push_back(Pose2D{1.5 + 0.05 * i, y, theta});
  return path;
}

TEST(StandTest, TheRobotStandsOnItsWayInBackFromWhereItWouldTouchTheObject) {
  Fixture f = corridor();
  GraspOnly services;
  GraphManager gm(Abstraction(f.sc.plannerWorld(), f.robot), "(define (domain scripted))",
                  MissionGoal{{"(robot-at goal)"}}, services, f.params);
  const world::Object& box = f.sc.world.object("box");
  // Slightly off the corridor's axis, heading along it: a base facing the box would be turned.
  const std::vector<Pose2D> path = wayIn(1.26, -0.02);
  const Pose2D entry{4.25, 1.26, -0.02};
  auto g = gm.standBeside(box, entry, BranchContext{}, path);
  ASSERT_TRUE(g.has_value());
  ASSERT_EQ(services.asked.size(), 1u);
  // A pose of the way in, heading as the path does, before the contact.
  EXPECT_NEAR(g->base_pose.y, 1.26, 1e-9);
  EXPECT_NEAR(g->base_pose.theta, -0.02, 1e-9);
  EXPECT_LT(g->base_pose.x, entry.x);
  // The nearest such pose that keeps the base's radius and the margin off the box's face.
  const double d = std::hypot(g->base_pose.x - 4.62, g->base_pose.y - 1.2);
  const double clear = f.robot.baseRadius() + 0.025 + f.params.keep_clear_margin_m;
  EXPECT_GE(d, clear - 0.01);  // the box's extent towards a pose 1 cm off its axis: 2.5 cm at most
  EXPECT_LT(d, clear + 0.06);
}

TEST(StandTest, FacingPosesFollowTheRobotsFootprintThenTheServicesSamplesAreTaken) {
  Fixture f = corridor();
  GraspOnly services;
  services.accept = [](const Pose2D&) { return false; };
  GraspOption far, near;
  far.base_pose = Pose2D{5.4, 1.2, M_PI};
  near.base_pose = Pose2D{4.0, 1.25, 0.0};
  services.sampled = {far, near};
  GraphManager gm(Abstraction(f.sc.plannerWorld(), f.robot), "(define (domain scripted))",
                  MissionGoal{{"(robot-at goal)"}}, services, f.params);
  const world::Object& box = f.sc.world.object("box");
  auto g = gm.standBeside(box, Pose2D{3.0, 1.2, 0.0}, BranchContext{});
  ASSERT_TRUE(g.has_value());
  EXPECT_NEAR(g->base_pose.x, 4.0, 1e-9) << "the sample nearest to the way in";
  // Facing the box from the west: the base's front (from the robot's footprint) the margin off
  // the box's west face, then a step further each time; last the service's own samples.
  ASSERT_GE(services.asked.size(), 2u);
  const double first = baseFront(f.robot) + 0.025 + f.params.keep_clear_margin_m;
  for (std::size_t i = 0; i + 1 < services.asked.size(); ++i) {
    ASSERT_TRUE(services.asked[i].base.has_value());
    const Pose2D& b = *services.asked[i].base;
    EXPECT_NEAR(b.y, 1.2, 1e-9);
    EXPECT_NEAR(b.theta, 0.0, 1e-9);
    EXPECT_NEAR(4.62 - b.x, first + GraphManager::kStandStep_m * static_cast<double>(i), 1e-9) << i;
  }
  EXPECT_LE(services.asked.size() - 1, GraphManager::kStandSteps);
  EXPECT_FALSE(services.asked.back().base.has_value());
}

TEST(StandTest, AnObjectOutOfTheArmsReachIsLeftToTheServicesSamples) {
  Fixture f = corridor();
  GraspOnly services;
  GraphManager gm(Abstraction(f.sc.plannerWorld(), f.robot), "(define (domain scripted))",
                  MissionGoal{{"(robot-at goal)"}}, services, f.params);
  world::Object high = f.sc.world.object("box");
  high.pose.translation().z() = 10.0;  // far above the reach sphere
  auto g = gm.standBeside(high, Pose2D{3.0, 1.2, 0.0}, BranchContext{}, wayIn(1.2, 0.0));
  EXPECT_FALSE(g.has_value());
  ASSERT_EQ(services.asked.size(), 1u);
  EXPECT_FALSE(services.asked.front().base.has_value());
}


// hall_transport: the parcel at (2.8, 2.0) on one large floor region. A plan that meant to pick it
// from near_dock (5.45, 2.0), east of it, after driving from start (1.0, 2.0), west of it, is
// refuted; the refinement's stand is sought on the side the robot drives in from, not on the far
// side of where the refuted plan stood (a drive round the parcel and a half turn, 55 s against
// 37.5 s executed).
TEST(StandTest, ARefinedSlotIsReachedFromTheSideTheRobotDroveInFrom) {
  auto sc = world::loadScenario(configDir() / "scenarios" / "hall_transport.yaml");
  ASSERT_TRUE(sc) << sc.error().toString();
  auto robot = robot::RobotModel::loadDescription(sc->robot.description);
  ASSERT_TRUE(robot) << robot.error().toString();
  GraspOnly services;
  GraphManager gm(Abstraction(sc->plannerWorld(), *robot), "(define (domain scripted))",
                  MissionGoal{{"(on box dock)"}}, services, GraphManagerParams{});
  BranchContext ctx;
  ctx.state.base = Pose2D{5.45, 2.0, 0.0};  // where the refuted plan stood
  ctx.came_from = Pose2D{1.0, 2.0, 0.0};    // where its drive there started
  ASSERT_TRUE(gm.refineSupport("box", "hall", ctx));
  ASSERT_FALSE(services.asked.empty());
  ASSERT_TRUE(services.asked.front().base.has_value());
  const Pose2D& b = *services.asked.front().base;
  EXPECT_LT(b.x, 2.8) << "west of the parcel, facing it";
  EXPECT_NEAR(b.y, 2.0, 1e-6);
  EXPECT_NEAR(std::remainder(b.theta, 2 * M_PI), 0.0, 1e-6);

  // Without a drive in the branch, the side of where the branch stands.
  GraspOnly other;
  GraphManager gm2(Abstraction(sc->plannerWorld(), *robot), "(define (domain scripted))",
                   MissionGoal{{"(on box dock)"}}, other, GraphManagerParams{});
  ctx.came_from.reset();
  ASSERT_TRUE(gm2.refineSupport("box", "hall", ctx));
  ASSERT_FALSE(other.asked.empty());
  ASSERT_TRUE(other.asked.front().base.has_value());
  EXPECT_GT(other.asked.front().base->x, 2.8);
}

}  // namespace
}  // namespace tamp::graph_manager
