#include "tamp/robot/robot_model.h"

#include <fstream>
#include <random>

#include <gtest/gtest.h>
#include <kdl/chain.hpp>

namespace tamp::robot {
namespace {

const RobotModel& robot() {
  static const RobotModel m = [] {
    auto r = RobotModel::loadFile(std::filesystem::path(TAMP_SOURCE_DIR) /
                                  "config/robots/mobile_manipulator.urdf");
    if (!r) throw std::runtime_error(r.error().toString());
    return std::move(r).value();
  }();
  return m;
}

Eigen::Isometry3d pose(double x, double y, double z, const Eigen::Matrix3d& R) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

// Gripper pointing down (approach -z), fingers closing along world y.
Eigen::Matrix3d topDown() {
  return Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
}
// Gripper pointing forward (approach +x).
Eigen::Matrix3d forward() {
  return Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

double rotationAngle(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

TEST(RobotModelTest, LoadsTheShippedRobot) {
  const RobotModel& r = robot();
  EXPECT_EQ(r.name(), "mobile_manipulator");
  EXPECT_EQ(r.armJointNames(),
            (std::vector<std::string>{"arm_joint_1", "arm_joint_2", "arm_joint_3", "arm_joint_4",
                                      "arm_joint_5", "arm_joint_6"}));
  EXPECT_EQ(r.gripperJointName(), "gripper_finger_left_joint");
  EXPECT_DOUBLE_EQ(r.gripperLimits().upper, 0.04);
  EXPECT_DOUBLE_EQ(r.armLimits()[2].lower, -2.6);
  EXPECT_EQ(r.linkNames().front(), "base_link");
  EXPECT_EQ(r.fullJointNames().size(), 10u);
  EXPECT_EQ(r.fullJointNames()[0], "base_x");
  // Footprint: the 0.6 x 0.5 base box.
  ASSERT_EQ(r.baseFootprint().size(), 4u);
  EXPECT_NEAR(world::signedArea(r.baseFootprint()), 0.30, 1e-12);
  EXPECT_NEAR(r.baseRadius(), std::hypot(0.3, 0.25), 1e-12);
  EXPECT_EQ(r.collisionGeometry().links.size(), r.linkNames().size());
  EXPECT_GE(r.collisionGeometry().parts.size(), 11u);
}

TEST(RobotModelTest, ForwardKinematicsByHand) {
  const RobotModel& r = robot();
  // Zero: arm straight up; pedestal top 0.50, shoulder 0.60, +0.36 +0.33 +0.17 = 1.46.
  const Eigen::Isometry3d T0 = r.toolPose(std::vector<double>(6, 0.0));
  EXPECT_NEAR(T0.translation().x(), 0.15, 1e-12);
  EXPECT_NEAR(T0.translation().y(), 0.0, 1e-12);
  EXPECT_NEAR(T0.translation().z(), 1.46, 1e-12);
  EXPECT_NEAR(rotationAngle(T0.linear(), Eigen::Matrix3d::Identity()), 0.0, 1e-12);
  // Shoulder pitched forward by pi/2: the arm lies along +x at the shoulder height.
  const Eigen::Isometry3d T1 = r.toolPose(std::vector<double>{0, M_PI / 2, 0, 0, 0, 0});
  EXPECT_NEAR(T1.translation().x(), 0.15 + 0.86, 1e-12);
  EXPECT_NEAR(T1.translation().z(), 0.60, 1e-12);
  EXPECT_NEAR(rotationAngle(T1.linear(), forward()), 0.0, 1e-12);
  // Plus a base yaw of pi/2 at (1, 2): the arm points along +y in the world.
  RobotState s = r.defaultState({1, 2, M_PI / 2});
  s.arm = {0, M_PI / 2, 0, 0, 0, 0};
  const Eigen::Isometry3d W = r.toolPoseInWorld(s);
  EXPECT_NEAR(W.translation().x(), 1.0, 1e-12);
  EXPECT_NEAR(W.translation().y(), 2.0 + 1.01, 1e-12);
  EXPECT_THROW((void)r.toolPose(std::vector<double>(5, 0.0)), std::invalid_argument);
}

TEST(RobotModelTest, KdlChainAgreesWithTheTreeWalk) {
  const RobotModel& r = robot();
  std::mt19937 rng(17);
  std::vector<Eigen::Isometry3d> P;
  const int tool = r.linkIndex("gripper_tcp");
  ASSERT_GE(tool, 0);
  for (int i = 0; i < 200; ++i) {
    RobotState s = r.defaultState({0.3, -0.2, 0.7});
    s.arm = r.randomArmConfiguration(rng);
    r.linkPoses(s, P);
    const Eigen::Isometry3d a = P[static_cast<size_t>(tool)];
    const Eigen::Isometry3d b = r.toolPoseInWorld(s);
    EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), 1e-12) << "sample " << i;
  }
}

TEST(RobotModelTest, IkRoundTripsAtRandomSeeds) {
  const RobotModel& r = robot();
  std::mt19937 rng(2024);
  int solved = 0;
  const int n = 200;
  for (int i = 0; i < n; ++i) {
    const std::vector<double> q = r.randomArmConfiguration(rng);
    const Eigen::Isometry3d target = r.toolPose(q);
    IkOptions opt;
    opt.seed = static_cast<std::uint32_t>(i + 1);
    const std::vector<double> seed = r.randomArmConfiguration(rng);
    const IkResult res = r.inverseKinematics(target, seed, opt);
    if (!res.ok()) continue;
    ++solved;
    ASSERT_TRUE(r.withinLimits(res.q));
    const Eigen::Isometry3d got = r.toolPose(res.q);  // independent check of the reported error
    EXPECT_LT((got.translation() - target.translation()).norm(), 1e-4) << "sample " << i;
    EXPECT_LT(rotationAngle(got.linear(), target.linear()), 1e-3) << "sample " << i;
    EXPECT_NEAR(res.position_error, (got.translation() - target.translation()).norm(), 1e-12);
  }
  EXPECT_GE(solved, n * 97 / 100) << "solved " << solved << " of " << n;
}

TEST(RobotModelTest, IkReachesTableTopsAndTheFloorInFront) {
  const RobotModel& r = robot();
  collision::Scene scene;
  scene.setRobot(r.collisionGeometry());
  std::vector<Eigen::Isometry3d> P;
  struct Case {
    const char* what;
    Eigen::Isometry3d target;
  };
  const std::vector<Case> cases{
      {"top grasp over a 0.75 m table, 0.25 m beyond the base front",
       pose(0.55, 0.0, 0.85, topDown())},
      {"top grasp over a 0.75 m table, 0.15 m to the side", pose(0.50, 0.15, 0.85, topDown())},
      {"side grasp at table height", pose(0.60, 0.0, 0.82, forward())},
      {"top grasp on the floor, 0.3 m beyond the base front", pose(0.60, 0.0, 0.06, topDown())},
      {"top grasp on the floor, 0.4 m beyond the base front", pose(0.70, 0.0, 0.06, topDown())},
  };
  for (const auto& c : cases) {
    IkOptions opt;
    opt.accept = [&](const std::vector<double>& q) {  // no self-collision
      RobotState s = r.defaultState();
      s.arm = q;
      s.gripper = 0.04;
      r.linkPoses(s, P);
      scene.setLinkPoses(P);
      return scene.selfCollisions().empty();
    };
    const IkResult res = r.inverseKinematics(c.target, r.defaultState().arm, opt);
    EXPECT_TRUE(res.ok()) << c.what << ": " << toString(res.status);
  }
}

TEST(RobotModelTest, TheReachSphereHoldsTheToolInEveryConfiguration) {
  const RobotModel& r = robot();
  const RobotModel::ReachSphere reach = r.armReach();
  ASSERT_TRUE(std::isfinite(reach.radius));
  std::mt19937 rng(7);
  double farthest = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const double d = (r.toolPose(r.randomArmConfiguration(rng)).translation() - reach.centre).norm();
    ASSERT_LE(d, reach.radius + 1e-9) << "sample " << i;
    farthest = std::max(farthest, d);
  }
  // A bound, not a guess: random configurations come close to it (this arm's axes meet).
  EXPECT_GT(farthest, 0.9 * reach.radius) << "farthest " << farthest << " of " << reach.radius;
  // Just inside the sphere along the stretched arm, IK still finds a solution: the cut is no
  // tighter than the arm.
  const Eigen::Isometry3d stretched = r.toolPose(std::vector<double>(r.armDof(), 0.0));
  IkOptions opt;
  EXPECT_TRUE(r.inverseKinematics(stretched, r.defaultState().arm, opt).ok());
}

TEST(RobotModelTest, IkStatuses) {
  const RobotModel& r = robot();
  const auto seed = r.defaultState().arm;
  IkOptions few;
  few.max_attempts = 5;
  const IkResult far = r.inverseKinematics(pose(2.5, 0, 0.8, topDown()), seed, few);
  EXPECT_EQ(far.status, IkStatus::kNoSolution);
  EXPECT_EQ(far.attempts, 0) << "2.5 m is beyond the arm's reach: no attempt can succeed";
  Eigen::Isometry3d nan = Eigen::Isometry3d::Identity();
  nan.translation().x() = std::nan("");
  EXPECT_EQ(r.inverseKinematics(nan, seed).status, IkStatus::kInvalidInput);
  EXPECT_EQ(r.inverseKinematics(pose(0.5, 0, 0.8, topDown()), std::vector<double>(3, 0.0)).status,
            IkStatus::kInvalidInput);
  EXPECT_EQ(
      r.inverseKinematics(pose(0.5, 0, 0.8, topDown()), seed, {}, Termination::after(-1)).status,
      IkStatus::kTimeout);
  IkOptions reject = few;
  reject.accept = [](const std::vector<double>&) { return false; };
  EXPECT_EQ(r.inverseKinematics(pose(0.55, 0, 0.85, topDown()), seed, reject).status,
            IkStatus::kNoSolution);
}

TEST(RobotModelTest, CameraLooksForwardAndDown) {
  const RobotModel& r = robot();
  const RobotState s = r.defaultState({0, 0, 0});
  const Eigen::Isometry3d C = r.linkPoseInWorld("camera_optical_frame", s).value();
  const Eigen::Vector3d z = C.linear().col(2);  // optical axis
  EXPECT_NEAR(z.x(), std::cos(0.6), 1e-9);
  EXPECT_NEAR(z.y(), 0.0, 1e-9);
  EXPECT_NEAR(z.z(), -std::sin(0.6), 1e-9);
  EXPECT_NEAR(C.linear().col(0).y(), -1.0, 1e-9);  // image x to the robot's right
  EXPECT_NEAR(C.translation().z(), 0.35 + 1.10, 1e-9);
  EXPECT_FALSE(r.linkPoseInWorld("nope", s).ok());
}

TEST(RobotModelTest, GripperFingersAreSymmetric) {
  const RobotModel& r = robot();
  RobotState s = r.defaultState();
  s.gripper = 0.03;
  std::vector<Eigen::Isometry3d> P;
  r.linkPoses(s, P);
  const Eigen::Isometry3d tcp = P[static_cast<size_t>(r.linkIndex("gripper_tcp"))];
  const Eigen::Vector3d l =
      tcp.inverse() * P[static_cast<size_t>(r.linkIndex("gripper_finger_left_link"))].translation();
  const Eigen::Vector3d rr =
      tcp.inverse() *
      P[static_cast<size_t>(r.linkIndex("gripper_finger_right_link"))].translation();
  EXPECT_NEAR(l.y(), 0.03, 1e-12);
  EXPECT_NEAR(rr.y(), -0.03, 1e-12);
}

TEST(RobotModelTest, SelfCollisionModel) {
  const RobotModel& r = robot();
  collision::Scene scene;
  scene.setRobot(r.collisionGeometry());
  std::vector<Eigen::Isometry3d> P;
  RobotState s = r.defaultState();
  for (double g : {0.0, 0.04}) {
    s.gripper = g;
    r.linkPoses(s, P);
    scene.setLinkPoses(P);
    EXPECT_TRUE(scene.selfCollisions().empty()) << "gripper " << g;
  }
  // Property: whenever the wrist centre is inside the base box, the model reports a self-collision.
  std::mt19937 rng(5);
  const int wrist = r.linkIndex("arm_link_5");
  int inside = 0;
  for (int i = 0; i < 20000; ++i) {
    s.arm = r.randomArmConfiguration(rng);
    r.linkPoses(s, P);
    const Eigen::Vector3d w = P[static_cast<size_t>(wrist)].translation();
    if (std::abs(w.x()) > 0.3 || std::abs(w.y()) > 0.25 || w.z() > 0.35) continue;
    ++inside;
    scene.setLinkPoses(P);
    EXPECT_FALSE(scene.selfCollisions().empty()) << "sample " << i;
  }
  EXPECT_GT(inside, 10);
}

TEST(RobotModelTest, HeldObjectFollowsTheTool) {
  const RobotModel& r = robot();
  RobotState s = r.defaultState({1, 1, 0});
  s.arm = {0, 0.8, 1.2, 0, 1.1, 0};
  Eigen::Isometry3d obj = r.toolPoseInWorld(s);
  obj.translation() += obj.linear() * Eigen::Vector3d(0, 0, 0.02);
  const world::HeldObject h = r.hold("cup", s, obj);
  EXPECT_EQ(h.link, "gripper_tcp");
  EXPECT_LT((r.heldObjectPose(s, h).value().matrix() - obj.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  RobotState moved = s;
  moved.base = {2, 0, M_PI / 2};
  moved.arm[0] = 0.5;
  const Eigen::Isometry3d expect = r.toolPoseInWorld(moved) * h.link_T_object;
  EXPECT_LT((r.heldObjectPose(moved, h).value().matrix() - expect.matrix()).cwiseAbs().maxCoeff(),
            1e-12);
}

TEST(RobotModelTest, JointValueConversions) {
  const RobotModel& r = robot();
  RobotState s = r.defaultState({1, 2, 0.5});
  s.arm = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
  s.gripper = 0.02;
  const auto v = r.toJointValues(s);
  const auto back = r.fromJointValues(r.fullJointNames(), v, r.defaultState());
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->arm, s.arm);
  EXPECT_EQ(back->base, s.base);
  EXPECT_DOUBLE_EQ(back->gripper, 0.02);
  const auto bad = r.fromJointValues({"elbow"}, std::vector<double>{1.0}, s);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, "joint 'elbow' is not a joint of robot 'mobile_manipulator'");
}

TEST(RobotDescriptionTest, NamedConfigurations) {
  auto loaded = RobotModel::loadDescription(std::filesystem::path(TAMP_SOURCE_DIR) /
                                            "config/robots/mobile_manipulator.yaml");
  ASSERT_TRUE(loaded.ok()) << loaded.error().toString();
  const RobotModel& r = *loaded;
  EXPECT_EQ(r.namedConfigurationNames(), (std::vector<std::string>{"stow", "ready", "carry"}));
  EXPECT_EQ(r.defaultState().arm, *r.namedConfiguration("stow"));
  EXPECT_DOUBLE_EQ(r.options().gripper_open, 0.04);
  collision::Scene scene;
  scene.setRobot(r.collisionGeometry());
  std::vector<Eigen::Isometry3d> P;
  for (const auto& name : r.namedConfigurationNames()) {
    RobotState s = r.defaultState();
    s.arm = *r.namedConfiguration(name);
    for (double g : {r.options().gripper_closed, r.options().gripper_open}) {
      s.gripper = g;
      r.linkPoses(s, P);
      scene.setLinkPoses(P);
      EXPECT_TRUE(scene.selfCollisions().empty()) << name;
    }
  }
  // Stowed, every arm link stays within the base footprint (the base can move without sweeping
  // the arm through the world).
  RobotState s = r.defaultState();
  r.linkPoses(s, P);
  for (size_t k = 0; k < P.size(); ++k) {
    const Eigen::Vector3d t = P[k].translation();
    EXPECT_LT(std::abs(t.x()), 0.3) << r.linkNames()[k];
    EXPECT_LT(std::abs(t.y()), 0.25) << r.linkNames()[k];
  }
  EXPECT_FALSE(r.namedConfiguration("dance").has_value());
}

TEST(RobotDescriptionTest, BrokenDescriptionsNameTheField) {
  const auto dir = std::filesystem::temp_directory_path() / "tamp_robot_desc_test";
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(
      std::filesystem::path(TAMP_SOURCE_DIR) / "config/robots/mobile_manipulator.urdf",
      dir / "mobile_manipulator.urdf", std::filesystem::copy_options::overwrite_existing);
  const auto write = [&](const std::string& text) {
    std::ofstream(dir / "robot.yaml") << text;
    return RobotModel::loadDescription(dir / "robot.yaml");
  };
  const std::string file = (dir / "robot.yaml").string();
  auto r1 = write(
      "urdf: mobile_manipulator.urdf\npayload: 5\nnamed_configurations:\n  stow: [0, 0, 0]\n");
  ASSERT_FALSE(r1.ok());
  EXPECT_EQ(r1.error().toString(),
            file + ":4:9: field 'named_configurations.stow': has 3 values, the arm has 6 joints");
  auto r2 = write(
      "urdf: mobile_manipulator.urdf\npayload: 5\nnamed_configurations:\n  up: [0, 0, 9, 0, 0, "
      "0]\n");
  ASSERT_FALSE(r2.ok());
  EXPECT_EQ(r2.error().toString(),
            file + ":4:7: field 'named_configurations.up': is outside the joint limits");
  auto r3 = write("urdf: mobile_manipulator.urdf\npayload: 5\ntool: gripper_tcp\n");
  ASSERT_FALSE(r3.ok());
  EXPECT_EQ(r3.error().toString(),
            file +
                ":3:1: field 'tool': unknown key 'tool' (expected one of: "
                "base_link, camera_frame, gripper, "
                "gripper_joint, named_configurations, payload, push_limit, tool_link, urdf)");
  auto r4 = write("urdf: missing.urdf\npayload: 5\n");
  ASSERT_FALSE(r4.ok());
  EXPECT_EQ(r4.error().code, ErrorCode::kNotFound);
  // The payload: required, a finite mass >= 0, named by file:line:column and field.
  auto p1 = write("urdf: mobile_manipulator.urdf\n");
  ASSERT_FALSE(p1.ok());
  EXPECT_EQ(p1.error().toString(), file + ":1:1: field 'payload': missing required field");
  auto p2 = write("urdf: mobile_manipulator.urdf\npayload: -2\n");
  ASSERT_FALSE(p2.ok());
  EXPECT_EQ(p2.error().toString(),
            file + ":2:10: field 'payload': must be a finite mass >= 0 (kg), got -2");
  auto p3 = write("urdf: mobile_manipulator.urdf\npayload: .inf\n");
  ASSERT_FALSE(p3.ok());
  EXPECT_EQ(p3.error().toString(),
            file + ":2:10: field 'payload': must be a finite mass >= 0 (kg), got inf");
  auto p4 = write("urdf: mobile_manipulator.urdf\npayload: heavy\n");
  ASSERT_FALSE(p4.ok());
  EXPECT_NE(p4.error().toString().find(file + ":2:10: field 'payload': "), std::string::npos)
      << p4.error().toString();
  auto p5 = write("urdf: mobile_manipulator.urdf\npayload: 0\n");
  ASSERT_TRUE(p5.ok()) << p5.error().toString();
  EXPECT_DOUBLE_EQ(p5->payload(), 0.0);
  EXPECT_DOUBLE_EQ(p5->pushLimit(), 0.0) << "without push_limit the base pushes nothing";
  // The push limit: optional, a finite mass >= 0.
  auto q1 = write("urdf: mobile_manipulator.urdf\npayload: 5\npush_limit: -1\n");
  ASSERT_FALSE(q1.ok());
  EXPECT_EQ(q1.error().toString(), file + ":3:13: field 'push_limit': must be a finite mass >= 0 (kg), got -1");
  auto q2 = write("urdf: mobile_manipulator.urdf\npayload: 5\npush_limit: 40\n");
  ASSERT_TRUE(q2.ok()) << q2.error().toString();
  EXPECT_DOUBLE_EQ(q2->pushLimit(), 40.0);
}

TEST(RobotDescriptionTest, PayloadAndGripperWidth) {
  auto r = RobotModel::loadDefault();
  ASSERT_TRUE(r.ok()) << r.error().toString();
  EXPECT_DOUBLE_EQ(r->payload(), 25.0);
  EXPECT_DOUBLE_EQ(r->options().payload, 25.0);
  EXPECT_DOUBLE_EQ(r->maxGraspWidth(), 0.08);  // 2 x the finger joint's 0.04 m
  EXPECT_DOUBLE_EQ(r->pushLimit(), 60.0);
}

// ---- broken URDFs ------------------------------------------------------------------------------

const char* kTwoLinks = R"(<robot name="r">
  <link name="base_link"><collision><geometry><box size="1 1 1"/></geometry></collision></link>
  <link name="tip"/>
  <joint name="j" type="revolute">
    <parent link="base_link"/><child link="tip"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/>
  </joint>
</robot>)";

RobotModelOptions minimal() {
  RobotModelOptions o;
  o.tool_link = "tip";
  o.gripper_joint = "";
  o.camera_frame = "";
  return o;
}

TEST(RobotModelErrorsTest, MinimalRobotLoads) {
  auto r = RobotModel::fromUrdfString(kTwoLinks, "mini.urdf", minimal());
  ASSERT_TRUE(r.ok()) << r.error().toString();
  EXPECT_EQ(r->armDof(), 1u);
}

TEST(RobotModelErrorsTest, MalformedXmlNamesTheLine) {
  const std::string xml = "<robot name=\"r\">\n  <link name=\"a\">\n</robot>\n";
  auto r = RobotModel::fromUrdfString(xml, "bad.urdf", minimal());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kParseError);
  EXPECT_EQ(r.error().where.file, "bad.urdf");
  EXPECT_EQ(r.error().toString(),
            "bad.urdf:2: invalid XML: mismatched element: XMLElement name=link");
}

TEST(RobotModelErrorsTest, UnknownLinkInJointNamesTheJoint) {
  std::string xml = kTwoLinks;
  xml.replace(xml.find("<child link=\"tip\"/>"), 19, "<child link=\"tipp\"/>");
  auto r = RobotModel::fromUrdfString(xml, "bad.urdf", minimal());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kParseError);
  EXPECT_EQ(r.error().where.line, 4);  // the <joint name="j"> element
  EXPECT_NE(r.error().message.find("invalid URDF: "), std::string::npos) << r.error().message;
}

TEST(RobotModelErrorsTest, CyclesAndSelfLoopsAreRefusedBeforeUrdfdom) {
  std::string self = kTwoLinks;
  self.replace(self.find("<child link=\"tip\"/>"), 19, "<child link=\"base_link\"/>");
  auto r1 = RobotModel::fromUrdfString(self, "bad.urdf", minimal());
  ASSERT_FALSE(r1.ok());
  EXPECT_EQ(
      r1.error().toString(),
      "bad.urdf:4: field 'joint.j': joint 'j': parent and child are the same link 'base_link'");
  const std::string cycle = R"(<robot name="r">
  <link name="a"/><link name="b"/><link name="c"/>
  <joint name="ab" type="fixed"><parent link="a"/><child link="b"/></joint>
  <joint name="bc" type="fixed"><parent link="b"/><child link="c"/></joint>
  <joint name="ca" type="fixed"><parent link="c"/><child link="a"/></joint>
</robot>)";
  auto r2 = RobotModel::fromUrdfString(cycle, "cycle.urdf", minimal());
  ASSERT_FALSE(r2.ok());
  EXPECT_EQ(r2.error().toString(),
            "cycle.urdf:5: field 'joint.ca': the joints form a cycle through link 'a'");
}

TEST(RobotModelErrorsTest, MissingToolLink) {
  RobotModelOptions o = minimal();
  o.tool_link = "hand";
  auto r = RobotModel::fromUrdfString(kTwoLinks, "bad.urdf", o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().toString(),
            "bad.urdf:1: field 'tool_link': tool link 'hand' is not a link of robot 'r'");
}

TEST(RobotModelErrorsTest, InvertedLimits) {
  std::string xml = kTwoLinks;
  xml.replace(xml.find("lower=\"-1\" upper=\"1\""), 20, "lower=\"1\" upper=\"-1\"");
  auto r = RobotModel::fromUrdfString(xml, "bad.urdf", minimal());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().toString(),
            "bad.urdf:4: field 'joint.j.limit': joint 'j': limits must be finite with lower <= "
            "upper, got "
            "[1.000000, -1.000000]");
}

TEST(RobotModelErrorsTest, MeshGeometryIsRefusedByName) {
  std::string xml = kTwoLinks;
  xml.replace(xml.find("<box size=\"1 1 1\"/>"), 19, "<mesh filename=\"base.stl\"/>");
  auto r = RobotModel::fromUrdfString(xml, "bad.urdf", minimal());
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kUnsupported);
  EXPECT_EQ(r.error().toString(),
            "bad.urdf:2: field 'link.base_link.collision': link 'base_link': only box, cylinder "
            "and sphere "
            "collision geometry is supported");
}

TEST(RobotModelErrorsTest, BaseMustBeTheRoot) {
  RobotModelOptions o = minimal();
  o.base_link = "tip";
  auto r = RobotModel::fromUrdfString(kTwoLinks, "bad.urdf", o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().toString(),
            "bad.urdf:2: field 'base_link': the base link 'tip' must be the root of the URDF tree, "
            "but the root "
            "is 'base_link'");
}

TEST(RobotModelErrorsTest, MissingFileAndEmptyInput) {
  auto r = RobotModel::loadFile("/nonexistent/robot.urdf");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kNotFound);
  EXPECT_FALSE(RobotModel::fromUrdfString("", "empty.urdf").ok());
  EXPECT_FALSE(RobotModel::fromUrdfString("<robot name=\"x\"/>", "nolinks.urdf").ok());
}

}  // namespace
}  // namespace tamp::robot
