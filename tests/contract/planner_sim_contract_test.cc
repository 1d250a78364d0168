// Contract between the motion planner and the robot (the simulator stands in for it): a
// full-mode arm path that the planner returns as collision-free is executed without the robot
// being stopped before a contact. The simulator sweeps every commanded motion at its own
// resolution (a bound on any point's displacement, 1 cm) and stops before the first contact,
// including the floor's; the planner must not hand it a path that clips an object between two of
// its own checks. Each case: the graspable objects of shipped scenarios, the robot at a stand
// pose that the planner's grasp generator chose.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tamp/collision/scene.h"
#include "tamp/motion_planner/motion_planner.h"
#include "tamp/motion_planner/params.h"
#include "tamp/sim/setup.h"
#include "tamp/sim/simulator.h"
#include "tamp/world/scenario.h"

namespace tamp {
namespace {

namespace mp = motion_planner;

/// The first contact along `path` from `start` in a scene of `w`, every 1 mrad: tells in a
/// failure message whether the path's own states touch the object or only the robot's sweep.
std::string denseContact(const world::World& w, const robot::RobotModel& model, const robot::RobotState& start,
                         const JointPath& path) {
  collision::Scene scene(w);
  scene.setRobot(model.collisionGeometry());
  std::vector<Eigen::Isometry3d> poses;
  for (std::size_t i = 0; i + 1 < path.waypoints.size(); ++i) {
    const auto& a = path.waypoints[i];
    const auto& b = path.waypoints[i + 1];
    double d = 0;
    for (std::size_t j = 0; j < a.size(); ++j) d = std::max(d, std::abs(b[j] - a[j]));
    const int n = std::max(1, static_cast<int>(std::ceil(d / 0.001)));
    for (int k = 0; k <= n; ++k) {
      std::vector<double> q(a.size());
      for (std::size_t j = 0; j < a.size(); ++j) q[j] = a[j] + (b[j] - a[j]) * k / n;
      auto s = model.fromJointValues(path.joint_names, q, start);
      if (!s.ok()) return s.error().message;
      model.linkPoses(*s, poses);
      scene.setLinkPoses(poses);
      const auto c = scene.robotCollisions();
      if (!c.empty()) return "segment " + std::to_string(i) + " touches " + c.front() + " at " + std::to_string(k) + "/" + std::to_string(n);
    }
  }
  return "no contact of the path's states";
}

/// Runs `sim` until the action in progress ends.
sim::ActionResult runToEnd(sim::Simulator& s) {
  for (int i = 0; i < 100000; ++i) {
    auto ev = s.step(0.05);
    if (!ev.results.empty()) return ev.results.front();
  }
  sim::ActionResult r;
  r.reason = "never ended";
  return r;
}

sim::ActionResult executeArm(sim::Simulator& s, const std::string& id, const Trajectory& traj) {
  sim::ActionCommand c;
  c.command_id = id;
  c.kind = ActionKind::kMoveArm;
  c.trajectory = traj;
  if (Status st = s.submit(c); !st) {
    sim::ActionResult r;
    r.reason = "refused: " + st.error().message;
    return r;
  }
  return runToEnd(s);
}

/// A trajectory through `waypoints` at `speed` rad/s (as the graph manager times a pick).
Trajectory timed(const std::vector<std::string>& names, const std::vector<std::vector<double>>& waypoints, double speed) {
  Trajectory t;
  t.joint_names = names;
  double time = 0.0;
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    if (i > 0) {
      double d = 0.0;
      for (std::size_t j = 0; j < waypoints[i].size(); ++j) d = std::max(d, std::abs(waypoints[i][j] - waypoints[i - 1][j]));
      time += std::max(0.2, d / speed);
    }
    t.points.push_back(TrajectoryPoint{time, waypoints[i], {}});
  }
  return t;
}

/// One graspable object of a scenario, the robot at a stand pose the grasp generator chose.
struct Case {
  std::string name;
  const world::Scenario* scenario;
  std::string object;
  robot::RobotState at;       ///< stand pose, the scenario's start arm configuration
  std::vector<mp::Grasp> grasps;
};

class PlannerSimContract : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    mp::seedRandomness(7);
    for (const char* name : {"namo_corridor_slippery", "occluded_can", "holding_start"}) {
      auto sc = world::loadScenario(std::string(TAMP_SOURCE_DIR) + "/config/scenarios/" + name + ".yaml");
      ASSERT_TRUE(sc.ok()) << sc.error().toString();
      scenarios_.push_back(std::make_unique<world::Scenario>(std::move(*sc)));
    }
    auto m = robot::RobotModel::loadDescription(scenarios_.front()->robot.description);
    ASSERT_TRUE(m.ok()) << m.error().toString();
    model_ = std::make_unique<robot::RobotModel>(std::move(*m));
    for (const auto& sc : scenarios_) {
      mp::MotionPlanner planner(*model_, mp::MotionPlannerParams{});
      const world::World view = sc->plannerWorld();
      planner.setWorld(view);
      robot::RobotState start = model_->defaultState(sc->robot.start);
      if (!sc->robot.arm.empty()) start.arm = sc->robot.arm;
      start.gripper = sc->robot.gripper;
      for (const auto& o : view.objects()) {
        if (o.kind != world::ObjectKind::kMovable || !o.graspable || (view.held() && view.held()->object_id == o.id))
          continue;
        mp::GraspRequest g;
        g.object_id = o.id;
        g.start_arm = start.arm;
        g.max_grasps = 2;
        auto grasps = planner.generateGrasps(g, Termination::after(10.0));
        if (!grasps.ok() || grasps->empty()) continue;
        Case c{sc->name + "/" + o.id, sc.get(), o.id, start, {}};
        c.at.base = grasps->front().base_pose;
        for (const auto& gr : *grasps)
          if (std::abs(gr.base_pose.x - c.at.base.x) + std::abs(gr.base_pose.y - c.at.base.y) < 1e-9) c.grasps.push_back(gr);
        cases_.push_back(std::move(c));
      }
    }
    ASSERT_GE(cases_.size(), 3u) << "too few graspable objects with grasps in the scenarios";
  }
  static void TearDownTestSuite() {
    cases_.clear();
    scenarios_.clear();
    model_.reset();
  }

  static std::vector<std::unique_ptr<world::Scenario>> scenarios_;
  static std::unique_ptr<robot::RobotModel> model_;
  static std::vector<Case> cases_;
};
std::vector<std::unique_ptr<world::Scenario>> PlannerSimContract::scenarios_;
std::unique_ptr<robot::RobotModel> PlannerSimContract::model_;
std::vector<Case> PlannerSimContract::cases_;

// Out to random tool poses round the object (towards it, level, turned up to 0.6 rad, up to 30 cm
// off, down to 5 cm below its centre) and back to the start configuration.
TEST_F(PlannerSimContract, ArmMotionsRoundAnObjectAreNotStopped) {
  int executed = 0;
  std::vector<std::string> stopped;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> off(-0.30, 0.30), up(-0.05, 0.30), turn(-0.6, 0.6);
  for (const Case& c : cases_) {
    mp::MotionPlanner planner(*model_, mp::MotionPlannerParams{});
    planner.setWorld(c.scenario->plannerWorld());
    const world::Object& o = c.scenario->world.object(c.object);
    const Eigen::Vector2d to = (o.pose.translation() - c.at.base.toIsometry().translation()).head<2>();
    const double yaw = std::atan2(to.y(), to.x());
    for (int trial = 0; trial < 14; ++trial) {
      Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
      target.translation() = o.pose.translation() + Eigen::Vector3d(off(rng), off(rng), up(rng));
      target.linear() = (Eigen::AngleAxisd(yaw + turn(rng), Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()))
                            .toRotationMatrix();
      mp::MotionRequest req;
      req.group = mp::PlanningGroup::kArm;
      req.mode = mp::MotionMode::kFull;
      req.start = c.at;
      req.goal = mp::MotionGoal::endEffectorGoal(target);
      sim::SimParams params;
      params.duration_noise = 0.0;
      sim::Simulator s(c.scenario->world, *model_, c.at, params);
      for (const char* leg : {"out", "back"}) {
        const auto r = planner.plan(req, Termination::after(5.0));
        if (!r.ok()) break;
        const sim::ActionResult done = executeArm(s, leg, r.trajectory);
        ++executed;
        if (done.outcome != sim::Outcome::kSucceeded) {
          stopped.push_back(c.name + " trial " + std::to_string(trial) + " " + leg + ": " + done.reason + " (" +
                            denseContact(c.scenario->world, *model_, req.start, r.path) + "; " +
                            std::to_string(r.path.waypoints.size()) + " waypoints, " +
                            std::to_string(r.stats.swept_repairs) + " segments re-planned)");
          break;
        }
        req.start = s.robotState().state;
        req.goal = mp::MotionGoal::configurationGoal(c.at.arm);
      }
    }
  }
  EXPECT_GT(executed, 40);
  EXPECT_TRUE(stopped.empty()) << stopped.size() << " of " << executed << " stopped; first: " << stopped.front();
}

// A pick that fails part-way ("the box slips out of the fingers") leaves the fingers beside the
// object, or the object fallen back below them: the arm motion back to the start configuration
// is planned from where the robot stopped, and the robot must not be stopped on it
// (namo_corridor_slippery, CI of 2026-12-05: stopped before the box, then before the wall).
TEST_F(PlannerSimContract, TheArmLeavesAPickThatFailedPartWayWithoutBeingStopped) {
  int retreats = 0;
  std::vector<std::string> stopped;
  for (const Case& c : cases_) {
    if (c.scenario->world.held()) continue;  // the hand is not free to pick
    mp::MotionPlanner planner(*model_, mp::MotionPlannerParams{});
    planner.setWorld(c.scenario->plannerWorld());
    for (std::size_t g = 0; g < c.grasps.size(); ++g) {
      const mp::Grasp& grasp = c.grasps[g];
      for (double fraction : {0.2, 0.45, 0.7, 0.9}) {
        robot::RobotState pre = c.at;
        pre.arm = grasp.pregrasp_configuration;
        pre.gripper = grasp.opening;
        sim::SimParams params;
        params.duration_noise = 0.0;
        sim::Fault slip;
        slip.id = "slip";
        slip.type = sim::FaultType::kFailAction;
        slip.trigger.step = 0;
        slip.trigger.fraction = fraction;
        slip.action = ActionKind::kPick;
        sim::Simulator s(c.scenario->world, *model_, pre, params, {slip});
        sim::ActionCommand pick;
        pick.command_id = "pick";
        pick.kind = ActionKind::kPick;
        pick.object_id = c.object;
        pick.object_pose = c.scenario->world.object(c.object).pose;
        pick.trajectory = timed(model_->armJointNames(),
                                {grasp.pregrasp_configuration, grasp.grasp_configuration, grasp.pregrasp_configuration}, 0.5);
        ASSERT_TRUE(s.submit(pick).ok());
        const sim::ActionResult failed = runToEnd(s);
        ASSERT_EQ(failed.outcome, sim::Outcome::kFailed) << failed.reason;
        ASSERT_EQ(s.robotState().held_object_id, "") << c.name << " grasp " << g << " fraction " << fraction << ": the failed pick still holds the object (" << failed.reason << ")";
        // The planner's world: the object where the simulator has it now.
        world::World view = c.scenario->plannerWorld();
        ASSERT_TRUE(view.setObjectPose(c.object, s.world().object(c.object).pose).ok());
        planner.setWorld(view);
        mp::MotionRequest req;
        req.group = mp::PlanningGroup::kArm;
        req.mode = mp::MotionMode::kFull;
        req.start = s.robotState().state;
        req.goal = mp::MotionGoal::configurationGoal(c.at.arm);
        const auto back = planner.plan(req, Termination::after(5.0));
        ASSERT_TRUE(back.ok()) << c.name << " grasp " << g << " fraction " << fraction << ": " << back.reason;
        const sim::ActionResult done = executeArm(s, "back", back.trajectory);
        ++retreats;
        if (done.outcome != sim::Outcome::kSucceeded)
          stopped.push_back(c.name + " grasp " + std::to_string(g) + " fraction " + std::to_string(fraction) + ": " +
                            done.reason + " (" + denseContact(view, *model_, req.start, back.path) + ")");
      }
    }
  }
  EXPECT_GE(retreats, 12);
  EXPECT_TRUE(stopped.empty()) << stopped.size() << " of " << retreats << " stopped; first: " << stopped.front();
}

// Base motions of the mobile manipulator in NAMO scenario worlds, planned in full mode with the
// shipped planner parameters (the clearance grid on: most static checks are answered by a distance
// grid, not FCL) between random free stands, executed by the simulator: none is stopped before a
// wall or an object. Namo worlds: walls that are one outline round the map, corridors a robot's
// width wide.
// Session 18: it failed, 1 of 30 legs (namo_moghaddam_07's 7th: the simulator stopped the robot
// before wall_03 on a path whose states were free), with or without the clearance grid: the
// executor turned from its drive heading straight to the next drive's, the other way round from
// the turn the planner had checked through an inner waypoint's heading (explicitBaseTurns).
TEST(PlannerSimBaseContract, BaseMotionsPlannedWithTheClearanceGridAreNotStopped) {
  mp::seedRandomness(11);
  auto params = mp::loadMotionPlannerParams(std::string(TAMP_SOURCE_DIR) + "/config/services/motion_planner.yaml", {"node"});
  ASSERT_TRUE(params.ok()) << params.error().toString();
  ASSERT_GT(params->sampling.clearance_grid_resolution, 0.0);
  int executed = 0;
  std::vector<std::string> stopped;
  for (const char* name : {"namo_big_crossing", "namo_moghaddam_07"}) {
    auto sc = world::loadScenario(std::string(TAMP_SOURCE_DIR) + "/config/scenarios/" + name + ".yaml");
    ASSERT_TRUE(sc.ok()) << sc.error().toString();
    auto model = robot::RobotModel::loadDescription(sc->robot.description);
    ASSERT_TRUE(model.ok()) << model.error().toString();
    const world::World view = sc->plannerWorld();
    mp::MotionPlanner planner(*model, *params);
    planner.setWorld(view);
    robot::RobotState at = model->defaultState(sc->robot.start);
    if (!sc->robot.arm.empty()) at.arm = sc->robot.arm;
    at.gripper = sc->robot.gripper;
    // Free stands: the robot 1 cm clear of everything (robots park beside walls and objects).
    collision::Scene scene(view);
    scene.setRobot(model->collisionGeometry());
    const Aabb bounds = view.bounds();
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> ux(bounds.min.x(), bounds.max.x()), uy(bounds.min.y(), bounds.max.y()),
        yaw(-M_PI, M_PI);
    sim::SimParams sim_params;
    sim_params.duration_noise = 0.0;
    sim::Simulator s(sc->world, *model, at, sim_params);
    std::vector<Eigen::Isometry3d> poses;
    int legs = 0;
    for (int tries = 0; tries < 2000 && legs < 15; ++tries) {
      robot::RobotState goal = at;
      goal.base = Pose2D{ux(rng), uy(rng), yaw(rng)};
      model->linkPoses(goal, poses);
      scene.setLinkPoses(poses);
      if (scene.robotDistance().distance < 0.01) continue;
      mp::MotionRequest req;
      req.group = mp::PlanningGroup::kBase;
      req.mode = mp::MotionMode::kFull;
      req.start = s.robotState().state;
      req.goal = mp::MotionGoal::basePoseGoal(goal.base, false);
      const auto r = planner.plan(req, Termination::after(5.0));
      if (!r.ok()) continue;
      ++legs;
      sim::ActionCommand c;
      c.command_id = std::string(name) + "-" + std::to_string(legs);
      c.kind = ActionKind::kMoveBase;
      c.trajectory = r.trajectory;
      ASSERT_TRUE(s.submit(c).ok()) << c.command_id;
      const sim::ActionResult done = runToEnd(s);
      ++executed;
      if (done.outcome != sim::Outcome::kSucceeded) {
        stopped.push_back(c.command_id + ": " + done.reason + " (" + denseContact(view, *model, req.start, r.path) + ")");
        if (std::getenv("PROBE")) {
          const auto st = s.robotState().state;
          std::printf("stopped at (%.4f %.4f %.4f) relaxed %d\n", st.base.x, st.base.y, st.base.theta, int(r.stats.clearance_relaxed));
          for (const auto& w : r.path.waypoints) {
            robot::RobotState q = req.start; q.base = Pose2D{w[0], w[1], w[2]};
            model->linkPoses(q, poses); scene.setLinkPoses(poses);
            std::printf(" path (%.4f %.4f %.4f) dist %.4f\n", w[0], w[1], w[2], scene.robotDistance(collision::Filter::staticOnly()).distance);
          }
          model->linkPoses(st, poses); scene.setLinkPoses(poses);
          std::printf(" stop dist %.4f\n", scene.robotDistance(collision::Filter::staticOnly()).distance);
          for (const auto& pt : r.trajectory.points) std::printf(" traj t=%.2f (%.4f %.4f %.4f)\n", pt.time_from_start, pt.positions[0], pt.positions[1], pt.positions[2]);
        }
      }
    }
  }
  EXPECT_GE(executed, 20);
  EXPECT_TRUE(stopped.empty()) << stopped.size() << " of " << executed << " stopped; first: " << stopped.front();
}

}  // namespace
}  // namespace tamp
