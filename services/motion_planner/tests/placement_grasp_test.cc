// Placements (stable, collision-free, clear of the swept volume, reachable) and grasps (boxes
// and cylinders, top and side, approach/retreat through IK).
#include <gtest/gtest.h>

#include <cmath>

#include "tamp/motion_planner/motion_planner.h"
#include "test_worlds.h"

namespace tamp::motion_planner {
namespace {

class ManipulationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    seedRandomness(42);
    auto m = robot::RobotModel::loadDefault();
    ASSERT_TRUE(m.ok()) << m.error().toString();
    model_ = std::make_unique<robot::RobotModel>(std::move(*m));
    world_ = world::World("kitchen");
    // A low table (0.55 m): this arm reaches top-down tool poses up to ~0.8 m high (0.35-0.8 m
    // from the base), so top grasps with a 0.1 m approach fit there.
    add(testing::box("table", 2.0, 0.0, 1.2, 0.8, false, 0.55));
    world::Object can;
    can.id = "can";
    can.label = "can";
    can.kind = world::ObjectKind::kMovable;
    can.shape = world::Shape::cylinder(0.033, 0.12);
    can.pose.translation() = Eigen::Vector3d(1.5, 0.1, 0.55 + 0.06);
    can.mass = 0.35;
    can.graspable = true;
    can.region = "table_top";
    add(can);
    world::Object cube = testing::box("cube", 1.5, -0.2, 0.05, 0.06, true, 0.1, 0.2);
    cube.pose.translation().z() = 0.55 + 0.05;
    add(cube);
    world::Object wide = testing::box("wide", 2.3, 0.2, 0.3, 0.3, true, 0.2, 2.0);
    wide.pose.translation().z() = 0.55 + 0.1;
    add(wide);
    world::Object tri;
    tri.id = "wedge";
    tri.kind = world::ObjectKind::kMovable;
    tri.shape = world::Shape::prism({{0, 0}, {0.05, 0}, {0, 0.05}}, 0.05);
    tri.pose.translation() = Eigen::Vector3d(2.4, -0.25, 0.575);
    tri.mass = 0.1;
    tri.graspable = true;
    add(tri);
    world::Region top;
    top.id = "table_top";
    top.kind = world::RegionKind::kTable;
    top.polygon = {{1.4, -0.4}, {2.6, -0.4}, {2.6, 0.4}, {1.4, 0.4}};
    top.height = 0.55;
    ASSERT_TRUE(world_.addRegion(top).ok());
    world::Region floor;
    floor.id = "floor";
    floor.polygon = {{-2, -2}, {4, -2}, {4, 2}, {-2, 2}};
    ASSERT_TRUE(world_.addRegion(floor).ok());
  }
  void add(const world::Object& o) { ASSERT_TRUE(world_.addObject(o).ok()) << o.id; }
  MotionPlanner planner() {
    MotionPlanner mp(*model_, MotionPlannerParams{});
    mp.setWorld(world_);
    return mp;
  }
  Eigen::Isometry3d fk(const Pose2D& base, const std::vector<double>& arm) const {
    robot::RobotState s = model_->defaultState(base);
    s.arm = arm;
    return model_->toolPoseInWorld(s);
  }
  /// Up to six grasps of the can from a base pose in front of the table.
  Result<std::vector<Grasp>> canGrasps(MotionPlanner& mp) const {
    GraspRequest req;
    req.object_id = "can";
    req.base_pose = Pose2D{1.05, 0.1, 0.0};
    req.max_grasps = 6;
    return mp.generateGrasps(req, Termination::after(20.0));
  }
  static double poseError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
    return (a.translation() - b.translation()).norm();
  }
  static double angleError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
    return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
  }
  std::unique_ptr<robot::RobotModel> model_;
  world::World world_;
};

TEST_F(ManipulationTest, CylinderGraspsReachTheirPosesThroughIk) {
  MotionPlanner mp = planner();
  auto grasps = canGrasps(mp);
  ASSERT_TRUE(grasps.ok()) << grasps.error().toString();
  ASSERT_FALSE(grasps->empty());
  bool top = false;
  const Eigen::Isometry3d obj = world_.object("can").pose;
  for (const Grasp& g : *grasps) {
    top |= g.type == GraspType::kTop;
    EXPECT_LT(poseError(g.world_T_tool, obj * g.gripper_in_object), 1e-9);
    // IK solutions reach their targets (FK check, within the IK tolerances).
    const Eigen::Isometry3d grasp = fk(g.base_pose, g.grasp_configuration);
    EXPECT_LT(poseError(grasp, g.world_T_tool), 1e-3);
    EXPECT_LT(angleError(grasp, g.world_T_tool), 1e-2);
    const Eigen::Isometry3d pre = fk(g.base_pose, g.pregrasp_configuration);
    const Eigen::Isometry3d pre_target = g.world_T_tool * Eigen::Translation3d(0, 0, -mp.params().grasp.approach_distance);
    EXPECT_LT(poseError(pre, pre_target), 1e-3);
    const Eigen::Isometry3d ret = fk(g.base_pose, g.retreat_configuration);
    EXPECT_NEAR(ret.translation().z() - g.world_T_tool.translation().z(), mp.params().grasp.retreat_distance, 1e-3);
    EXPECT_TRUE(model_->withinLimits(g.grasp_configuration, 1e-6));
    // The fingers open wider than the can, within the gripper's range; the tool centre point is
    // inside the can's extent (the fingers close on it).
    EXPECT_GT(g.opening, 0.033);
    EXPECT_LE(g.opening, model_->gripperLimits().upper + 1e-12);
    const Eigen::Vector3d local = g.gripper_in_object.translation();
    EXPECT_LE(std::hypot(local.x(), local.y()), 0.033 + 1e-9);
    EXPECT_LE(std::abs(local.z()), 0.06 + 1e-9);
    if (g.type == GraspType::kTop) {
      EXPECT_GT(-g.world_T_tool.linear().col(2).z(), 0.999);  // approach straight down
    } else {
      EXPECT_LT(std::abs(g.world_T_tool.linear().col(2).z()), 1e-9);  // horizontal approach
    }
  }
  EXPECT_TRUE(top);
}

TEST_F(ManipulationTest, BoxGraspsWithSampledBasePosesAreCollisionFree) {
  MotionPlanner mp = planner();
  GraspRequest req;
  req.object_id = "cube";
  req.max_grasps = 8;
  auto grasps = mp.generateGrasps(req, Termination::after(30.0));
  ASSERT_TRUE(grasps.ok()) << grasps.error().toString();
  ASSERT_FALSE(grasps->empty());
  bool side = false, top = false;
  collision::Scene scene(world_);
  scene.setRobot(model_->collisionGeometry());
  std::vector<Eigen::Isometry3d> poses;
  for (const Grasp& g : *grasps) {
    (g.type == GraspType::kTop ? top : side) = true;
    EXPECT_LT(poseError(fk(g.base_pose, g.grasp_configuration), g.world_T_tool), 1e-3);
    // Pre-grasp: free of every object; grasp: free of everything but the cube.
    robot::RobotState s = model_->defaultState(g.base_pose);
    s.arm = g.pregrasp_configuration;
    s.gripper = g.opening;
    model_->linkPoses(s, poses);
    scene.setLinkPoses(poses);
    EXPECT_FALSE(scene.robotInCollision());
    s.arm = g.grasp_configuration;
    model_->linkPoses(s, poses);
    scene.setLinkPoses(poses);
    EXPECT_FALSE(scene.robotInCollision(collision::Filter::allBut({"cube"})));
  }
  EXPECT_TRUE(top);
  (void)side;
}

// Right after a release the fingers still touch the can (here 3 mm into it on each side). The
// arm leaves it first by a straight motion that goes no deeper into it than
// `start_escape_depth`: a way out sliding a finger across the can would push it (the robot is
// stopped before it). Checked from several grasps, each escape sampled every 2 mrad of joint
// motion against the can made that much smaller, less the planner's sweep resolution
// (`arm_swept_step`: a point moves no more between two of its checks).
TEST_F(ManipulationTest, AnArmStartingAgainstAnObjectLeavesItWithoutGoingDeeper) {
  MotionPlanner mp = planner();
  auto grasps = canGrasps(mp);
  ASSERT_TRUE(grasps.ok()) << grasps.error().toString();
  ASSERT_GE(grasps->size(), 3u);
  const double depth = mp.params().sampling.start_escape_depth;
  ASSERT_GT(depth, 0.003);
  world::World smaller = world_;
  world::Object can = smaller.object("can");
  can.shape = world::shrunk(can.shape, depth + mp.params().sampling.arm_swept_step);
  ASSERT_TRUE(smaller.updateObject(can).ok());
  collision::Scene scene(smaller);
  scene.setRobot(model_->collisionGeometry());
  std::vector<Eigen::Isometry3d> poses;
  int escapes = 0;
  for (const Grasp& g : *grasps) {
    MotionRequest req;
    req.group = PlanningGroup::kArm;
    req.mode = MotionMode::kFull;
    req.start = model_->defaultState(g.base_pose);
    req.start.arm = g.grasp_configuration;
    req.start.gripper = 0.5 * g.width - 0.003;
    req.goal = MotionGoal::configurationGoal(g.pregrasp_configuration);
    const MotionResult r = mp.plan(req, Termination::after(10.0));
    if (!r.ok()) continue;  // no way out of this grasp: not what is tested
    ASSERT_EQ(r.start_contacts, std::vector<std::string>{"can"}) << "the start does not touch the can";
    ++escapes;
    ASSERT_GE(r.path.waypoints.size(), 2u);
    const auto& a = r.path.waypoints[0];
    const auto& b = r.path.waypoints[1];
    double d = 0;
    for (std::size_t j = 0; j < a.size(); ++j) d = std::max(d, std::abs(b[j] - a[j]));
    const int n = std::max(1, static_cast<int>(std::ceil(d / 0.002)));
    for (int k = 1; k <= n; ++k) {
      std::vector<double> q(a.size());
      for (std::size_t j = 0; j < a.size(); ++j) q[j] = a[j] + (b[j] - a[j]) * k / n;
      auto s = model_->fromJointValues(r.path.joint_names, q, req.start);
      ASSERT_TRUE(s.ok()) << s.error().toString();
      model_->linkPoses(*s, poses);
      scene.setLinkPoses(poses);
      ASSERT_FALSE(scene.robotInCollision(collision::Filter::objects({"can"})))
          << "the way out goes deeper into the can, grasp " << escapes << ", step " << k << " of " << n;
    }
  }
  EXPECT_GE(escapes, 3);
}

TEST_F(ManipulationTest, GraspErrorsNameTheProblem) {
  MotionPlanner mp = planner();
  GraspRequest req;
  req.object_id = "nothing";
  auto r = mp.generateGrasps(req);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kNotFound);
  req.object_id = "table";
  r = mp.generateGrasps(req);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
  req.object_id = "wedge";
  r = mp.generateGrasps(req);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kUnsupported);
  req.object_id = "can";
  req.base_pose = Pose2D{NAN, 0, 0};
  r = mp.generateGrasps(req);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("base_pose"), std::string::npos);
  // Too wide for the gripper in every direction: no grasps, not an error.
  req.object_id = "wide";
  req.base_pose = Pose2D{1.3, 0.2, 0.0};
  r = mp.generateGrasps(req, Termination::after(5.0));
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r->empty());
}

TEST_F(ManipulationTest, PlacementsAreStableClearAndReachable) {
  MotionPlanner mp = planner();
  PlacementRequest req;
  req.object_id = "can";
  req.region_id = "table_top";
  // A swept base path along the table's near half (y = -0.1 .. 0.1 at x = 1.8 .. 2.2).
  for (double x = 1.8; x <= 2.2 + 1e-9; x += 0.05) req.keep_clear_path.push_back(Pose2D{x, 0.0, 0.0});
  req.keep_clear_radius = 0.25;
  req.max_placements = 5;
  auto r = mp.samplePlacements(req, Termination::after(30.0));
  ASSERT_TRUE(r.ok()) << r.error().toString();
  ASSERT_FALSE(r->empty());
  const double radius = 0.033, half = 0.06;
  collision::Scene scene(world_);
  scene.setRobot(model_->collisionGeometry());
  std::vector<Eigen::Isometry3d> poses;
  double last = -1;
  for (const Placement& p : *r) {
    const Eigen::Vector3d c = p.object_pose.translation();
    // Stable: upright, resting on the top, footprint inside it (with the margin).
    EXPECT_NEAR(c.z(), 0.55 + half, 1e-9);
    EXPECT_GT(p.object_pose.linear().col(2).z(), 1.0 - 1e-9);
    EXPECT_GE(c.x() - radius, 1.4 + 0.009);
    EXPECT_LE(c.x() + radius, 2.6 - 0.009);
    EXPECT_GE(c.y() - radius, -0.4 + 0.009);
    EXPECT_LE(c.y() + radius, 0.4 - 0.009);
    // Clear of the swept path.
    for (const Pose2D& s : req.keep_clear_path) EXPECT_GT(std::hypot(c.x() - s.x, c.y() - s.y) - radius, 0.25);
    // Clear of the other objects on the table (independent: footprints apart).
    EXPECT_GT(std::hypot(c.x() - 1.5, c.y() + 0.2), radius);  // cube centre outside the can
    EXPECT_FALSE(std::abs(c.x() - 2.3) < 0.15 + radius && std::abs(c.y() - 0.2) < 0.15 + radius);
    EXPECT_GE(p.clearance, 0.0);
    // Reachable: the arm configuration puts the tool over the placement, from a free base pose.
    ASSERT_EQ(p.arm_configuration.size(), model_->armDof());
    const Eigen::Isometry3d tool = fk(p.base_pose, p.arm_configuration);
    EXPECT_LT(std::hypot(tool.translation().x() - c.x(), tool.translation().y() - c.y()), 0.04);
    robot::RobotState s = model_->defaultState(p.base_pose);
    model_->linkPoses(s, poses);
    scene.setLinkPoses(poses);
    EXPECT_FALSE(scene.robotInCollision());
    EXPECT_GE(p.transfer_distance, last);  // sorted: shortest transfer first
    last = p.transfer_distance;
  }
}

TEST_F(ManipulationTest, AHeldGraspAlongTheObjectAxisPlacesTheObjectOnItsTopWithTheToolDown) {
  // A held grasp given as the identity rotation (the object's z along the tool's approach axis):
  // upright, the tool would point up from under the table top; the object stands on its top face.
  MotionPlanner mp = planner();
  PlacementRequest req;
  req.object_id = "can";
  req.region_id = "table_top";
  req.base = Pose2D{1.0, 0.0, 0.0};
  Eigen::Isometry3d object_T_tool = Eigen::Isometry3d::Identity();
  object_T_tool.translation() = Eigen::Vector3d(0.0, 0.0, -0.03);
  req.held_object_T_tool = object_T_tool;
  req.approach = 0.05;
  req.max_placements = 3;
  auto r = mp.samplePlacements(req, Termination::after(30.0));
  ASSERT_TRUE(r.ok()) << r.error().toString();
  ASSERT_FALSE(r->empty());
  for (const Placement& p : *r) {
    EXPECT_NEAR(p.object_pose.translation().z(), 0.55 + 0.06, 1e-9);
    EXPECT_LT(p.object_pose.linear().col(2).z(), -1.0 + 1e-9);  // on its top face
    const Eigen::Isometry3d tool = fk(p.base_pose, p.arm_configuration);
    EXPECT_LT(tool.linear().col(2).z(), -0.99);  // the tool points down
    EXPECT_LT((tool.translation() - (p.object_pose * object_T_tool).translation()).norm(), 0.01);
  }
}

TEST_F(ManipulationTest, PlacementErrorsNameTheField) {
  MotionPlanner mp = planner();
  PlacementRequest req;
  req.object_id = "can";
  req.region_id = "nowhere";
  auto r = mp.samplePlacements(req);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kNotFound);
  EXPECT_NE(r.error().message.find("region_id"), std::string::npos);
  req.region_id = "table_top";
  req.object_id = "table";
  r = mp.samplePlacements(req);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
  req.object_id = "can";
  req.keep_clear_radius = -1;
  r = mp.samplePlacements(req);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("keep_clear_radius"), std::string::npos);
}

TEST(PlanarPlacementTest, FloorPlacementsForTheDiscRobotAvoidTheSweptPath) {
  seedRandomness(42);
  const world::World w = testing::corridorWorld(true);
  MotionPlanner mp(collision::RobotGeometry::disc(0.3, 1.0));
  mp.setWorld(w);
  PlacementRequest req;
  req.object_id = "crate";
  req.region_id = "floor";
  for (double x = 2.0; x <= 8.0 + 1e-9; x += 0.1) req.keep_clear_path.push_back(Pose2D{x, 2.0, 0.0});
  req.keep_clear_radius = 0.3;
  req.max_placements = 6;
  auto r = mp.samplePlacements(req, Termination::after(10.0));
  ASSERT_TRUE(r.ok()) << r.error().toString();
  ASSERT_FALSE(r->empty());
  for (const Placement& p : *r) {
    const Eigen::Vector3d c = p.object_pose.translation();
    EXPECT_NEAR(c.z(), 0.4, 1e-9);
    // The crate (0.4 x 1.0) rotated by its yaw keeps > 0.3 m from every pose of the swept path
    // (exact point-rectangle distance in the crate's frame).
    const double yaw = std::atan2(p.object_pose.linear()(1, 0), p.object_pose.linear()(0, 0));
    for (const Pose2D& s : req.keep_clear_path) {
      const double dx = s.x - c.x(), dy = s.y - c.y();
      const double lx = std::cos(yaw) * dx + std::sin(yaw) * dy, ly = -std::sin(yaw) * dx + std::cos(yaw) * dy;
      const double ex = std::max(std::abs(lx) - 0.2, 0.0), ey = std::max(std::abs(ly) - 0.5, 0.0);
      EXPECT_GT(std::hypot(ex, ey), 0.3) << c.transpose();
    }
    double miny = 1e9, maxy = -1e9;
    for (double sx : {-0.2, 0.2})
      for (double sy : {-0.5, 0.5}) {
        const double y = c.y() + std::sin(yaw) * sx + std::cos(yaw) * sy;
        miny = std::min(miny, y);
        maxy = std::max(maxy, y);
      }
    // Inside the room (floor region [0,10] x [0,4]).
    EXPECT_GT(miny, 0.0);
    EXPECT_LT(maxy, 4.0);
    // A collision-free base pose within reach.
    EXPECT_LE(std::hypot(p.base_pose.x - c.x(), p.base_pose.y - c.y()), mp.params().placement.planar_reach + 1e-9);
    EXPECT_GE(testing::discClearance(w, JointPath{{"base_x", "base_y", "base_theta"},
                                                  {{p.base_pose.x, p.base_pose.y, 0.0}}},
                                     0.3, 0.01, {"crate"}),
              0.0);
  }
}

}  // namespace
}  // namespace tamp::motion_planner
