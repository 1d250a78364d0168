// Arm and whole-body groups of the mobile manipulator: configuration and end-effector goals
// (through IK), paths re-checked densely in a fresh collision scene, IK goals reached.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tamp/motion_planner/motion_planner.h"
#include "test_worlds.h"

namespace tamp::motion_planner {
namespace {

class ArmTest : public ::testing::Test {
 protected:
  void SetUp() override {
    seedRandomness(42);
    auto m = robot::RobotModel::loadDefault();
    ASSERT_TRUE(m.ok()) << m.error().toString();
    model_ = std::make_unique<robot::RobotModel>(std::move(*m));
    world_ = world::World("arm_world");
    world::Object table = testing::box("table", 1.2, 0.0, 0.6, 1.0, false, 0.75);
    ASSERT_TRUE(world_.addObject(table).ok());
    world::Object post = testing::box("post", 0.6, 0.9, 0.15, 0.15, false, 1.6);
    ASSERT_TRUE(world_.addObject(post).ok());
    world_.setWorkspace(Aabb{Eigen::Vector3d(-3, -3, 0), Eigen::Vector3d(4, 3, 2)});
  }

  MotionPlanner planner() {
    MotionPlanner mp(*model_, MotionPlannerParams{});
    mp.setWorld(world_);
    return mp;
  }

  /// Dense re-check of a path over `names` in a scene built here (not the planner's).
  void expectCollisionFree(const JointPath& path, const robot::RobotState& start, double step = 0.005) {
    collision::Scene scene(world_);
    scene.setRobot(model_->collisionGeometry());
    std::vector<Eigen::Isometry3d> poses;
    for (std::size_t i = 0; i + 1 < path.waypoints.size(); ++i) {
      const auto& a = path.waypoints[i];
      const auto& b = path.waypoints[i + 1];
      double d = 0;
      for (std::size_t j = 0; j < a.size(); ++j) d = std::max(d, std::abs(b[j] - a[j]));
      const int n = std::max(1, static_cast<int>(std::ceil(d / step)));
      for (int k = 0; k <= n; ++k) {
        std::vector<double> q(a.size());
        for (std::size_t j = 0; j < a.size(); ++j) q[j] = a[j] + (b[j] - a[j]) * k / n;
        auto s = model_->fromJointValues(path.joint_names, q, start);
        ASSERT_TRUE(s.ok()) << s.error().toString();
        ASSERT_TRUE(model_->withinLimits(s->arm, 1e-6));
        model_->linkPoses(*s, poses);
        scene.setLinkPoses(poses);
        ASSERT_FALSE(scene.robotInCollision()) << "segment " << i << " step " << k << ": "
                                               << scene.robotCollisions().front();
        ASSERT_TRUE(scene.selfCollisions().empty()) << "self-collision at segment " << i << " step " << k;
      }
    }
  }

  /// A random collision-free arm configuration (fixed seed), checked in a scene built here.
  std::vector<double> freeConfiguration(const Pose2D& base, unsigned seed) {
    collision::Scene scene(world_);
    scene.setRobot(model_->collisionGeometry());
    std::mt19937 rng(seed);
    std::vector<Eigen::Isometry3d> poses;
    for (int i = 0; i < 1000; ++i) {
      robot::RobotState s = model_->defaultState(base);
      s.arm = model_->randomArmConfiguration(rng);
      model_->linkPoses(s, poses);
      scene.setLinkPoses(poses);
      if (!scene.robotInCollision() && scene.selfCollisions().empty()) return s.arm;
    }
    ADD_FAILURE() << "no free configuration";
    return model_->defaultState(base).arm;
  }

  std::unique_ptr<robot::RobotModel> model_;
  world::World world_;
};

TEST_F(ArmTest, ArmConfigurationGoalIsReachedOnACollisionFreePath) {
  MotionPlanner mp = planner();
  MotionRequest req;
  req.group = PlanningGroup::kArm;
  req.mode = MotionMode::kFull;
  req.start = model_->defaultState(Pose2D{0, 0, 0});
  const std::vector<double> goal = freeConfiguration(req.start.base, 3);
  req.goal = MotionGoal::configurationGoal(goal);
  const MotionResult r = mp.plan(req, Termination::after(10.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason << " checks " << r.stats.validity_checks;
  EXPECT_EQ(r.path.joint_names, model_->armJointNames());
  for (std::size_t j = 0; j < goal.size(); ++j) EXPECT_NEAR(r.path.waypoints.back()[j], goal[j], 0.02);
  expectCollisionFree(r.path, req.start);
  EXPECT_NO_THROW(r.trajectory.validate());
}

TEST_F(ArmTest, ANearbyFreeConfigurationIsReachedByTheDirectMotion) {
  MotionPlannerParams p;
  p.sampling.direct_first = true;
  MotionPlanner mp(*model_, p);
  mp.setWorld(world_);
  MotionRequest req;
  req.group = PlanningGroup::kArm;
  req.mode = MotionMode::kFull;
  req.start = model_->defaultState(Pose2D{0, 0, 0});
  std::vector<double> goal = req.start.arm;
  goal[0] += 0.3;  // the first joint turned a little: free all the way (checked below)
  req.goal = MotionGoal::configurationGoal(goal);
  const MotionResult r = mp.plan(req, Termination::after(10.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_TRUE(r.stats.direct);
  EXPECT_EQ(r.path.waypoints.size(), 2u);
  expectCollisionFree(r.path, req.start);
  for (std::size_t j = 0; j < goal.size(); ++j) EXPECT_NEAR(r.path.waypoints.back()[j], goal[j], 1e-9);
}

// A block placed just beyond the direct motion's sweep (found by moving it out from the tool, at
// the motion's middle, until the direct motion with no clearance is free): the direct motion
// passes it by millimetres, and with `direct_clearance` it is not taken; the motion is sampled
// and still solved.
TEST_F(ArmTest, TheDirectMotionKeepsItsClearanceOrIsNotTaken) {
  MotionPlannerParams p;
  p.sampling.direct_first = true;
  p.sampling.direct_clearance = 0.0;
  const robot::RobotState start = model_->defaultState(Pose2D{0, 0, 0});
  std::vector<double> goal = start.arm;
  goal[0] += 0.3;
  robot::RobotState mid = start;
  mid.arm[0] += 0.15;
  const Eigen::Vector3d tool = model_->toolPoseInWorld(mid).translation();
  const Eigen::Vector3d out = Eigen::Vector3d(tool.x(), tool.y(), 0.0).normalized();
  MotionRequest req;
  req.group = PlanningGroup::kArm;
  req.mode = MotionMode::kFull;
  req.start = start;
  req.goal = MotionGoal::configurationGoal(goal);
  auto withBlock = [&](double d) {
    world::World w = world_;
    world::Object block = testing::box("block", 0, 0, 0.03, 0.03, true, 0.03, 0.1);
    block.pose.translation() = tool + d * out;
    EXPECT_TRUE(w.addObject(block).ok());
    return w;
  };
  double d = 0.0;
  for (; d < 0.3; d += 0.004) {
    MotionPlanner plain(*model_, p);
    plain.setWorld(withBlock(d));
    const MotionResult r = plain.plan(req, Termination::after(10.0));
    if (r.ok() && r.stats.direct) break;  // (near the tool the goal itself touches the block)
  }
  ASSERT_LT(d, 0.3) << "the direct motion was never free";
  ASSERT_GT(d, 0.0) << "the block did not touch the direct motion at the tool";
  p.sampling.direct_clearance = MotionPlannerParams{}.sampling.direct_clearance;
  ASSERT_GT(p.sampling.direct_clearance, 0.01);
  MotionPlanner careful(*model_, p);
  careful.setWorld(withBlock(d));
  const MotionResult r = careful.plan(req, Termination::after(10.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_FALSE(r.stats.direct) << "taken " << d << " m out from the tool";
  MotionPlanner far(*model_, p);
  far.setWorld(withBlock(d + 0.1));
  EXPECT_TRUE(far.plan(req, Termination::after(10.0)).stats.direct) << "a block 10 cm further out";
}

// The margin of a held object keeps it off the world, not off the robot that holds it: a small
// block in the hand, grown by 12 cm into the wrist and fingers, still moves (its contacts with
// the robot are checked as modelled). Grown into the table, the start is left first.
TEST_F(ArmTest, AHeldObjectsMarginIsNotAContactWithTheRobotHoldingIt) {
  world::Object block = testing::box("block", -2.5, -2.5, 0.04, 0.04, true, 0.04, 0.2);
  ASSERT_TRUE(world_.addObject(block).ok());
  MotionPlanner mp = planner();
  MotionRequest req;
  req.group = PlanningGroup::kArm;
  req.mode = MotionMode::kFull;
  req.start = model_->defaultState(Pose2D{0, 0, 0});
  std::vector<double> goal = req.start.arm;
  goal[0] += 0.3;
  req.goal = MotionGoal::configurationGoal(goal);
  req.held_object = "block";
  req.held_grasp = HeldGrasp{"", Eigen::Isometry3d::Identity()};  // at the tool's origin
  const MotionResult plain = mp.plan(req, Termination::after(10.0));
  ASSERT_EQ(plain.status, MotionStatus::kSolved) << plain.reason;
  req.held_padding_m = 0.12;
  const MotionResult padded = mp.plan(req, Termination::after(10.0));
  ASSERT_EQ(padded.status, MotionStatus::kSolved) << padded.reason;
}

TEST_F(ArmTest, EndEffectorGoalThroughIkIsReachedWithinTolerance) {
  MotionPlanner mp = planner();
  // A reachable pose in front of the robot, the tool pointing down.
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  target.translation() = Eigen::Vector3d(0.55, 0.1, 0.85);  // wrist centre 0.6 m from the shoulder
  MotionRequest req;
  req.group = PlanningGroup::kArm;
  req.mode = MotionMode::kFull;
  req.start = model_->defaultState(Pose2D{0, 0, 0});
  req.goal = MotionGoal::endEffectorGoal(target);
  const MotionResult r = mp.plan(req, Termination::after(10.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  auto s = model_->fromJointValues(r.path.joint_names, r.path.waypoints.back(), req.start);
  ASSERT_TRUE(s.ok());
  const Eigen::Isometry3d got = model_->toolPoseInWorld(*s);
  EXPECT_LT((got.translation() - target.translation()).norm(), 1e-3);
  EXPECT_LT(Eigen::AngleAxisd(got.linear().transpose() * target.linear()).angle(), 1e-2);
  expectCollisionFree(r.path, req.start);
}

TEST_F(ArmTest, WholeBodyEndEffectorGoalMovesTheBaseAndReachesThePose) {
  MotionPlanner mp = planner();
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  target.translation() = Eigen::Vector3d(1.0, 0.0, 0.9);  // above the table, 0.1 m from its edge
  MotionRequest req;
  req.group = PlanningGroup::kWholeBody;
  req.mode = MotionMode::kFull;
  req.start = model_->defaultState(Pose2D{-2.0, 1.5, 0.3});
  req.goal = MotionGoal::endEffectorGoal(target);
  const MotionResult r = mp.plan(req, Termination::after(20.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  ASSERT_EQ(r.path.joint_names.size(), 3 + model_->armDof());
  auto s = model_->fromJointValues(r.path.joint_names, r.path.waypoints.back(), req.start);
  ASSERT_TRUE(s.ok());
  const Eigen::Isometry3d got = model_->toolPoseInWorld(*s);
  EXPECT_LT((got.translation() - target.translation()).norm(), 1e-3);
  EXPECT_LT(Eigen::AngleAxisd(got.linear().transpose() * target.linear()).angle(), 1e-2);
  expectCollisionFree(r.path, req.start);
}

TEST_F(ArmTest, UnreachableEndEffectorGoalIsNoPathWithReason) {
  MotionPlanner mp = planner();
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.translation() = Eigen::Vector3d(0.3, 0.0, 5.0);
  MotionRequest req;
  req.group = PlanningGroup::kArm;
  req.mode = MotionMode::kFull;
  req.start = model_->defaultState(Pose2D{0, 0, 0});
  req.goal = MotionGoal::endEffectorGoal(target);
  const MotionResult r = mp.plan(req, Termination::after(5.0));
  EXPECT_EQ(r.status, MotionStatus::kNoPath);
  EXPECT_NE(r.reason.find("goal.end_effector"), std::string::npos) << r.reason;
}

TEST_F(ArmTest, ArmGoalOutsideJointLimitsIsInvalid) {
  MotionPlanner mp = planner();
  MotionRequest req;
  req.group = PlanningGroup::kArm;
  req.start = model_->defaultState(Pose2D{0, 0, 0});
  std::vector<double> goal = req.start.arm;
  goal[2] = 9.0;
  req.goal = MotionGoal::configurationGoal(goal);
  const MotionResult r = mp.plan(req, Termination::after(1.0));
  EXPECT_EQ(r.status, MotionStatus::kInvalidRequest);
  EXPECT_NE(r.reason.find("goal.configuration[2]"), std::string::npos) << r.reason;
}

TEST_F(ArmTest, BaseGroupOfTheManipulatorReportsTheBlockingObject) {
  world_ = testing::corridorWorld(true);
  MotionPlanner mp = planner();
  MotionRequest req;
  req.group = PlanningGroup::kBase;
  req.mode = MotionMode::kLazy;
  req.start = model_->defaultState(Pose2D{2, 2, 0});
  req.goal = MotionGoal::basePoseGoal(Pose2D{8, 2, 0});
  const MotionResult r = mp.plan(req, Termination::after(10.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  ASSERT_EQ(r.blocking.size(), 1u);
  EXPECT_EQ(r.blocking[0].object_id, "crate");
  // Full mode is a proven no path (the base's inscribed disc cannot pass the crate).
  req.mode = MotionMode::kFull;
  const MotionResult f = mp.plan(req, Termination::after(10.0));
  EXPECT_EQ(f.status, MotionStatus::kNoPath) << f.reason;
}

}  // namespace
}  // namespace tamp::motion_planner
