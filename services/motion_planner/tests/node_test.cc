// The DDS node in-process on an isolated domain: a client makes motion, placement and grasp
// requests against a world published by a WorldPublisher.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>
#include <thread>

#include "motion_planner_node.h"
#include "tamp/core/paths.h"
#include "test_util.h"
#include "test_worlds.h"

namespace tamp::motion_planner {
namespace {

class NodeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    domain_ = dds::testing::isolatedDomain();
    client_ = dds::testing::makeParticipant(domain_);
    ASSERT_TRUE(client_);
    dds::ServiceArgs args;
    args.name = "motion_planner_test";
    args.domain_id = domain_;
    NodeConfig cfg;
    cfg.robot = "disc";
    cfg.disc_radius = 0.3;
    auto node = MotionPlannerNode::create(args, cfg);
    ASSERT_TRUE(node.ok()) << node.error().toString();
    node_ = std::move(*node);
    publisher_ = std::make_unique<dds::WorldPublisher>(client_);
    world_ = initialWorld();
    ASSERT_TRUE(publisher_->publish(world_).ok());
    motion_ = std::make_unique<dds::RpcClient<msg::MotionRequest, msg::MotionReply>>(client_, dds::services::kMotion);
  }
  virtual world::World initialWorld() const { return testing::corridorWorld(true); }
  void TearDown() override {
    motion_.reset();
    publisher_.reset();
    node_.reset();
  }
  msg::MotionRequest lazyRequest() const {
    msg::MotionRequest r;
    r.group(msg::GROUP_BASE);
    r.mode(msg::MOTION_LAZY);
    r.world_version(publisher_->publishedVersion());
    r.start_base(dds::toMsg(Pose2D{2, 2, 0}));
    r.goal_type(msg::GOAL_BASE_POSE);
    r.goal_base(dds::toMsg(Pose2D{8, 2, 0}));
    r.movable_cost_weight(1.0);  // the effort model as it is (0: movables free)
    return r;
  }

  int domain_{0};
  std::shared_ptr<dds::Participant> client_;
  std::unique_ptr<MotionPlannerNode> node_;
  std::unique_ptr<dds::WorldPublisher> publisher_;
  std::unique_ptr<dds::RpcClient<msg::MotionRequest, msg::MotionReply>> motion_;
  world::World world_;
};

TEST_F(NodeTest, LazyRequestReportsTheBlockingObjectOfThePublishedWorld) {
  auto rep = motion_->call(lazyRequest(), dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  EXPECT_EQ(rep->status(), msg::MOTION_SOLVED) << rep->reason();
  ASSERT_EQ(rep->blocking().size(), 1u);
  EXPECT_EQ(rep->blocking()[0].object_id(), "crate");
  EXPECT_DOUBLE_EQ(rep->blocking()[0].mass(), 8.0);
  EXPECT_LT(rep->blocking()[0].enter_fraction(), rep->blocking()[0].exit_fraction());
  EXPECT_FALSE(rep->blocking()[0].swept_base().empty());
  auto path = dds::fromMsg(rep->path());
  ASSERT_TRUE(path.ok()) << path.error().toString();
  EXPECT_EQ(path->joint_names, (std::vector<std::string>{"base_x", "base_y", "base_theta"}));
  EXPECT_EQ(testing::discTouches(world_, *path, 0.3, 0.005), std::vector<std::string>{"crate"});
  auto traj = dds::fromMsg(rep->trajectory());
  ASSERT_TRUE(traj.ok());
  EXPECT_GT(traj->duration(), 0.0);
  EXPECT_GT(rep->path_length(), 5.9);
}

TEST_F(NodeTest, FullRequestIsAProvenNoPathAndFollowsWorldUpdates) {
  msg::MotionRequest r = lazyRequest();
  r.mode(msg::MOTION_FULL);
  auto rep = motion_->call(r, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  EXPECT_EQ(rep->status(), msg::MOTION_NO_PATH) << rep->reason();
  // The crate leaves the door: the next full request is solved.
  Eigen::Isometry3d p = world_.object("crate").pose;
  p.translation() = Eigen::Vector3d(2.0, 3.4, 0.4);
  ASSERT_TRUE(world_.setObjectPose("crate", p).ok());
  ASSERT_TRUE(publisher_->publish(world_).ok());
  r.world_version(publisher_->publishedVersion());
  r.start_base(dds::toMsg(Pose2D{2, 1, 0}));
  rep = motion_->call(r, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  EXPECT_EQ(rep->status(), msg::MOTION_SOLVED) << rep->reason();
  auto path = dds::fromMsg(rep->path());
  ASSERT_TRUE(path.ok());
  EXPECT_GE(testing::discClearance(world_, *path, 0.3, 0.005), 0.0);
  // straight_only on the wire: the straight line passes the door too low (it touches the wall).
  r.straight_only(true);
  rep = motion_->call(r, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  EXPECT_EQ(rep->status(), msg::MOTION_NO_PATH) << rep->reason();
  EXPECT_NE(rep->reason().find("straight_only"), std::string::npos) << rep->reason();
}

// After a world update the node prepares the base group's roadmap (spinOnce calls
// prepareIfWorldChanged; called directly here): complete afterwards, nothing to do while the world
// stays the same, and a movable's move keeps the roadmap (only a static change rebuilds it).
TEST_F(NodeTest, PreparesTheRoadmapAfterWorldUpdates) {
  auto rep = motion_->call(lazyRequest(), dds::CallOptions{30.0, {}});  // the mirror has the world now
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  ASSERT_EQ(rep->status(), msg::MOTION_SOLVED) << rep->reason();
  auto preps = node_->prepareIfWorldChanged();
  ASSERT_EQ(preps.size(), 2u);  // the default pool
  ASSERT_TRUE(preps[0].has_value());
  const auto& prep = preps[0];
  EXPECT_FALSE(prep->built);  // the request above (served by planner 0) built it
  EXPECT_TRUE(prep->completed);
  EXPECT_GT(prep->edges_evaluated, 0u);
  ASSERT_TRUE(preps[1].has_value());
  EXPECT_TRUE(preps[1]->built);  // planner 1 had none
  EXPECT_TRUE(preps[1]->completed);
  for (const auto& p : node_->prepareIfWorldChanged()) EXPECT_FALSE(p.has_value());  // nothing changed

  Eigen::Isometry3d p = world_.object("crate").pose;
  p.translation() = Eigen::Vector3d(2.0, 3.4, 0.4);
  ASSERT_TRUE(world_.setObjectPose("crate", p).ok());
  ASSERT_TRUE(publisher_->publish(world_).ok());
  std::optional<PrepareStats> moved;
  for (int i = 0; i < 500 && !moved; ++i) {
    moved = node_->prepareIfWorldChanged()[0];
    if (!moved) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(moved.has_value());
  EXPECT_FALSE(moved->built);
  EXPECT_TRUE(moved->completed);
  msg::MotionRequest r = lazyRequest();
  r.start_base(dds::toMsg(Pose2D{2, 1, 0}));
  rep = motion_->call(r, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  EXPECT_EQ(rep->status(), msg::MOTION_SOLVED) << rep->reason();
  EXPECT_TRUE(rep->blocking().empty());
}

TEST_F(NodeTest, MalformedRequestsGetInvalidRequestNamingTheField) {
  msg::MotionRequest r = lazyRequest();
  r.goal_base().x(std::nan(""));
  auto rep = motion_->call(r, dds::CallOptions{10.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  EXPECT_EQ(rep->status(), msg::MOTION_INVALID_REQUEST);
  EXPECT_NE(rep->reason().find("goal_base"), std::string::npos) << rep->reason();

  r = lazyRequest();
  r.ignored_objects().push_back("unknown_thing");
  rep = motion_->call(r, dds::CallOptions{10.0, {}});
  ASSERT_TRUE(rep.ok());
  EXPECT_EQ(rep->status(), msg::MOTION_INVALID_REQUEST);
  EXPECT_NE(rep->reason().find("unknown_thing"), std::string::npos) << rep->reason();

  r = lazyRequest();
  r.start_joint_names().push_back("elbow");
  r.start_joint_positions().push_back(0.3);
  rep = motion_->call(r, dds::CallOptions{10.0, {}});
  ASSERT_TRUE(rep.ok());
  EXPECT_EQ(rep->status(), msg::MOTION_INVALID_REQUEST);
  EXPECT_NE(rep->reason().find("start_joint_names"), std::string::npos) << rep->reason();

  r = lazyRequest();
  r.group(static_cast<msg::PlanningGroup>(17));
  rep = motion_->call(r, dds::CallOptions{10.0, {}});
  ASSERT_TRUE(rep.ok());
  EXPECT_EQ(rep->status(), msg::MOTION_INVALID_REQUEST);
  EXPECT_NE(rep->reason().find("group"), std::string::npos) << rep->reason();

  r = lazyRequest();
  r.start_base(dds::toMsg(Pose2D{5.0, 0.5, 0.0}));  // inside a wall
  rep = motion_->call(r, dds::CallOptions{10.0, {}});
  ASSERT_TRUE(rep.ok());
  EXPECT_EQ(rep->status(), msg::MOTION_START_IN_COLLISION);
  EXPECT_EQ(rep->colliding_object(), "wall_mid_low");
}

TEST_F(NodeTest, PlacementAndGraspRequests) {
  dds::RpcClient<msg::PlacementRequest, msg::PlacementReply> placement(client_, dds::services::kPlacement);
  msg::PlacementRequest pr;
  // Asked in a world version the node has not received: it waits (world_wait_s), then says so.
  pr.world_version(publisher_->publishedVersion() + 1000);
  pr.object_id("crate");
  pr.region_id("floor");
  auto early = placement.call(pr, dds::CallOptions{30.0, {}});
  ASSERT_FALSE(early.ok());
  EXPECT_EQ(early.error().code, ErrorCode::kNotReady) << early.error().toString();
  EXPECT_NE(early.error().message.find("world_version"), std::string::npos) << early.error().toString();
  dds::RpcClient<msg::GraspRequest, msg::GraspReply> grasp_early(client_, dds::services::kGrasp);
  msg::GraspRequest ge;
  ge.object_id("crate");
  ge.world_version(publisher_->publishedVersion() + 1000);
  auto g_early = grasp_early.call(ge, dds::CallOptions{30.0, {}});
  ASSERT_FALSE(g_early.ok());
  EXPECT_EQ(g_early.error().code, ErrorCode::kNotReady) << g_early.error().toString();
  // In the version published (the request waits for the world to be there).
  pr = msg::PlacementRequest();
  pr.world_version(publisher_->publishedVersion());
  pr.object_id("crate");
  pr.region_id("floor");
  for (double x = 2.0; x <= 8.0; x += 0.2) pr.keep_clear_path().push_back(dds::toMsg(Pose2D{x, 2.0, 0.0}));
  pr.keep_clear_radius(0.3);
  pr.max_placements(3);
  auto rep = placement.call(pr, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  ASSERT_FALSE(rep->placements().empty());
  for (const auto& p : rep->placements()) {
    EXPECT_NEAR(p.object_pose().position().z(), 0.4, 1e-9);
    EXPECT_GE(p.clearance(), 0.0);
  }
  pr.region_id("ceiling");
  auto bad = placement.call(pr, dds::CallOptions{10.0, {}});
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kNotFound);
  EXPECT_NE(bad.error().message.find("region_id"), std::string::npos);

  // A planar robot has no gripper: the grasp service says so.
  dds::RpcClient<msg::GraspRequest, msg::GraspReply> grasp(client_, dds::services::kGrasp);
  msg::GraspRequest gr;
  gr.object_id("crate");
  auto g = grasp.call(gr, dds::CallOptions{10.0, {}});
  ASSERT_FALSE(g.ok());
  EXPECT_EQ(g.error().code, ErrorCode::kUnsupported);
}

// movable_cost_weight as it is: 0 is the pure static-only lazy path (movables free), 1 the
// effort model. Two doors: A (short) blocked by two heavy objects, B (a detour) by a light one.
class TwoDoorNodeTest : public NodeTest {
 protected:
  world::World initialWorld() const override { return testing::twoDoorWorld(); }
};

TEST_F(TwoDoorNodeTest, MovableCostWeightZeroIgnoresMovables) {
  msg::MotionRequest r = lazyRequest();
  r.world_version(publisher_->publishedVersion());
  r.start_base(dds::toMsg(Pose2D{2, 0.9, 0}));
  r.goal_base(dds::toMsg(Pose2D{8, 0.9, 0}));
  r.movable_cost_weight(1.0);
  auto priced = motion_->call(r, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(priced.ok()) << priced.error().toString();
  ASSERT_EQ(priced->status(), msg::MOTION_SOLVED) << priced->reason();
  ASSERT_EQ(priced->blocking().size(), 1u);
  EXPECT_EQ(priced->blocking()[0].object_id(), "light");
  EXPECT_GT(priced->cost_s(), priced->blocking()[0].effort_s());

  r.movable_cost_weight(0.0);
  auto free = motion_->call(r, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(free.ok()) << free.error().toString();
  ASSERT_EQ(free->status(), msg::MOTION_SOLVED) << free->reason();
  auto path = dds::fromMsg(free->path());
  ASSERT_TRUE(path.ok());
  EXPECT_EQ(testing::discTouches(world_, *path, 0.3, 0.005), (std::vector<std::string>{"heavy_a", "heavy_b"}));
  EXPECT_LT(free->path_length(), priced->path_length());
  // J is the travel time only: no object is paid for.
  EXPECT_NEAR(free->cost_s(), free->path_length() / MotionPlannerParams{}.cost.base_speed, 1e-6);
  for (const auto& b : free->blocking()) EXPECT_GT(b.effort_s(), 0.0);  // still priced in the report
}

TEST_F(NodeTest, ObjectOverridesPlanInAHypotheticalWorld) {
  msg::MotionRequest r = lazyRequest();
  auto plain = motion_->call(r, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(plain.ok()) << plain.error().toString();
  ASSERT_EQ(plain->status(), msg::MOTION_SOLVED) << plain->reason();
  EXPECT_EQ(plain->world_version(), publisher_->publishedVersion());
  ASSERT_EQ(plain->blocking().size(), 1u);
  EXPECT_GT(plain->blocking()[0].effort_s(), 0.0);

  msg::ObjectOverride o;
  o.object_id("crate");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(1.0, 3.3, 0.4);
  o.pose(dds::toMsg(pose));
  r.object_overrides().push_back(o);
  auto moved = motion_->call(r, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(moved.ok()) << moved.error().toString();
  ASSERT_EQ(moved->status(), msg::MOTION_SOLVED) << moved->reason();
  EXPECT_TRUE(moved->blocking().empty());
  EXPECT_LT(moved->cost_s(), plain->cost_s());
  EXPECT_EQ(moved->world_version(), publisher_->publishedVersion());
  world::World hypothetical = world_;
  ASSERT_TRUE(hypothetical.setObjectPose("crate", pose).ok());
  auto path = dds::fromMsg(moved->path());
  ASSERT_TRUE(path.ok());
  EXPECT_TRUE(testing::discTouches(hypothetical, *path, 0.3, 0.005).empty());

  r.object_overrides()[0].object_id("ghost");
  auto unknown = motion_->call(r, dds::CallOptions{10.0, {}});
  ASSERT_TRUE(unknown.ok());
  EXPECT_EQ(unknown->status(), msg::MOTION_INVALID_REQUEST);
  EXPECT_NE(unknown->reason().find("object_overrides[0].object_id"), std::string::npos) << unknown->reason();
  r.object_overrides()[0].object_id("crate");
  r.object_overrides()[0].pose().position().x(std::nan(""));
  auto nan = motion_->call(r, dds::CallOptions{10.0, {}});
  ASSERT_TRUE(nan.ok());
  EXPECT_EQ(nan->status(), msg::MOTION_INVALID_REQUEST);
  EXPECT_NE(nan->reason().find("object_overrides[0].pose"), std::string::npos) << nan->reason();

  // The mirror's world is unchanged: the crate blocks again.
  auto again = motion_->call(lazyRequest(), dds::CallOptions{30.0, {}});
  ASSERT_TRUE(again.ok());
  ASSERT_EQ(again->blocking().size(), 1u);
  EXPECT_EQ(again->blocking()[0].object_id(), "crate");
}

TEST_F(NodeTest, HeldGraspOnTheWire) {
  msg::MotionRequest r = lazyRequest();
  r.start_base(dds::toMsg(Pose2D{2, 0.5, 0}));
  r.held_object_id("far_box");
  r.held_grasp_given(true);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(0.0, -0.6, 0.0);  // into the south wall at the start
  r.held_link_T_object(dds::toMsg(t));
  auto rep = motion_->call(r, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  EXPECT_EQ(rep->status(), msg::MOTION_START_IN_COLLISION) << rep->reason();
  EXPECT_EQ(rep->colliding_object(), "wall_south");
  t.translation() = Eigen::Vector3d(0.6, 0.0, 0.0);  // ahead of the robot
  r.held_link_T_object(dds::toMsg(t));
  rep = motion_->call(r, dds::CallOptions{30.0, {}});
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  EXPECT_EQ(rep->status(), msg::MOTION_SOLVED) << rep->reason();
  r.held_object_id("");
  rep = motion_->call(r, dds::CallOptions{10.0, {}});
  ASSERT_TRUE(rep.ok());
  EXPECT_EQ(rep->status(), msg::MOTION_INVALID_REQUEST);
  EXPECT_NE(rep->reason().find("held_grasp_given"), std::string::npos) << rep->reason();
}

msg::ActionTimeModel timeModel(ActionKind kind, std::vector<std::string> names, std::vector<double> values) {
  msg::ActionTimeModel m;
  m.kind(dds::toMsg(kind));
  m.parameter_names(std::move(names));
  m.values(std::move(values));
  m.version(1);
  return m;
}

// The fitted models on tamp/effort/model price the objects: slower pick and place raise the
// blocking object's effort of the same request, to what the fitted models say.
TEST_F(NodeTest, FittedEffortModelPricesBlockingObjects) {
  auto before = motion_->call(lazyRequest(), dds::CallOptions{30.0, {}});
  ASSERT_TRUE(before.ok()) << before.error().toString();
  ASSERT_EQ(before->blocking().size(), 1u);
  const world::Object& crate = world_.object("crate");
  EXPECT_NEAR(before->blocking()[0].effort_s(), defaultObjectEffort(crate, CostParams{}), 1e-9);

  dds::Writer<msg::EffortModelSnapshot> writer(client_, dds::topics::kEffortModel);
  msg::EffortModelSnapshot snap;
  snap.model_id("effort_estimator");
  snap.version(7);
  snap.models().push_back(timeModel(ActionKind::kPick, {"gripper_time", "approach_speed"}, {6.0, 0.02}));
  snap.models().push_back(timeModel(ActionKind::kPlace, {"gripper_time"}, {5.0}));
  ASSERT_TRUE(writer.write(snap).ok());
  for (int i = 0; i < 500 && node_->effortModelVersion() != 7; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(node_->effortModelVersion(), 7u);
  auto after = motion_->call(lazyRequest(), dds::CallOptions{30.0, {}});
  ASSERT_TRUE(after.ok()) << after.error().toString();
  ASSERT_EQ(after->blocking().size(), 1u);
  auto fitted = fittedObjectEffort(CostParams{}, {{ActionKind::kPick, {"gripper_time", "approach_speed"}, {6.0, 0.02}},
                                                  {ActionKind::kPlace, {"gripper_time"}, {5.0}}});
  ASSERT_TRUE(fitted.ok());
  EXPECT_GT(after->blocking()[0].effort_s(), before->blocking()[0].effort_s() + 8.0);
  EXPECT_NEAR(after->blocking()[0].effort_s(), (*fitted)(crate), 1e-9);

  // A malformed snapshot is ignored (logged): the fitted prices stay.
  snap.version(8);
  snap.models()[0].values().push_back(1.0);
  ASSERT_TRUE(writer.write(snap).ok());
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(node_->effortModelVersion(), 7u);
}

// Two planners serve two requests at once: a long full-mode request (no proof, so it runs to its
// budget) does not hold up a lazy one; with one planner the lazy one would wait for it.
TEST_F(NodeTest, ConcurrentRequestsRunOnSeparatePlanners) {
  node_.reset();
  dds::ServiceArgs args;
  args.name = "motion_planner_pool_test";
  args.domain_id = domain_;
  NodeConfig cfg;
  cfg.robot = "disc";
  cfg.disc_radius = 0.3;
  cfg.params.proof.enabled = false;
  cfg.planners = 2;
  auto node = MotionPlannerNode::create(args, cfg);
  ASSERT_TRUE(node.ok()) << node.error().toString();
  node_ = std::move(*node);
  ASSERT_EQ(node_->plannerCount(), 2u);
  ASSERT_TRUE(motion_->call(lazyRequest(), dds::CallOptions{30.0, {}}).ok());  // world mirrored
  // Both planners prepared alike: the same request gets the same path from either.
  for (int i = 0; i < 100; ++i) {
    const auto preps = node_->prepareIfWorldChanged();
    if (std::none_of(preps.begin(), preps.end(), [](const auto& p) { return p.has_value(); })) break;
  }

  std::atomic<bool> full_done{false};
  std::atomic<bool> lazy_done_while_full_ran{false};
  std::thread full([&] {
    dds::RpcClient<msg::MotionRequest, msg::MotionReply> client(client_, dds::services::kMotion);
    msg::MotionRequest r = lazyRequest();
    r.mode(msg::MOTION_FULL);  // the crate closes the door: no path, and no proof to say so
    auto rep = client.call(r, dds::CallOptions{3.0, {}});  // the budget the server plans with
    if (!rep.ok() && rep.error().code == ErrorCode::kTimeout) {  // the reply came just after
      full_done = true;
      return;
    }
    full_done = true;
    ASSERT_TRUE(rep.ok()) << rep.error().toString();
    EXPECT_EQ(rep->status(), msg::MOTION_TIMEOUT) << rep->reason();
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the full request is running
  std::vector<std::vector<double>> paths[2];
  for (int k = 0; k < 2; ++k) {
    auto rep = motion_->call(lazyRequest(), dds::CallOptions{30.0, {}});
    ASSERT_TRUE(rep.ok()) << rep.error().toString();
    ASSERT_EQ(rep->status(), msg::MOTION_SOLVED) << rep->reason();
    auto path = dds::fromMsg(rep->path());
    ASSERT_TRUE(path.ok());
    paths[k] = path->waypoints;
  }
  lazy_done_while_full_ran = !full_done.load();
  full.join();
  EXPECT_TRUE(lazy_done_while_full_ran);
  EXPECT_EQ(paths[0], paths[1]);  // the same planner, the same (warm) answer
}

// Before its first request a planner prepares for the robot as it reports itself (arm and
// gripper key the roadmap): a robot standing with its gripper open, not the default state's
// closed gripper, gets a roadmap of its own before any request asks for it.
TEST_F(NodeTest, ThePreparationFollowsTheReportedRobotState) {
  node_.reset();
  dds::ServiceArgs args;
  args.name = "motion_planner_robot_state_test";
  args.domain_id = domain_;
  NodeConfig cfg;  // the mobile manipulator
  cfg.planners = 2;  // planner 0 serves the request below; planner 1 has served none
  auto node = MotionPlannerNode::create(args, cfg);
  ASSERT_TRUE(node.ok()) << node.error().toString();
  node_ = std::move(*node);
  ASSERT_TRUE(motion_->call(lazyRequest(), dds::CallOptions{30.0, {}}).ok());  // world mirrored
  bool idle = false;  // prepared for the default state until there is nothing left to do
  for (int i = 0; i < 100 && !idle; ++i) {
    const auto preps = node_->prepareIfWorldChanged();
    idle = std::none_of(preps.begin(), preps.end(), [](const auto& p) { return p.has_value(); });
  }
  ASSERT_TRUE(idle);

  auto model = robot::RobotModel::loadDefault();
  ASSERT_TRUE(model.ok());
  robot::RobotState st = model->defaultState(Pose2D{2, 2, 0});
  st.gripper = model->options().gripper_open;
  msg::RobotState m;
  m.robot_id(model->name());
  m.base(dds::toMsg(st.base));
  m.joint_names(model->fullJointNames());
  m.joint_positions(model->toJointValues(st));
  dds::Writer<msg::RobotState> states(client_, dds::topics::kRobotState);
  ASSERT_TRUE(states.waitForReaders(Termination::after(10.0)));
  std::optional<PrepareStats> prep;
  for (int i = 0; i < 500 && !prep; ++i) {
    ASSERT_TRUE(states.write(m).ok());  // best effort: written until the node has it
    prep = node_->prepareIfWorldChanged()[1];
    if (!prep) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_TRUE(prep.has_value()) << "no preparation after the robot reported its state";
  EXPECT_TRUE(prep->built) << "the open gripper keys a roadmap the default state did not build";
}

TEST(NodeConfigTest, ShippedConfigLoadsAndBadNodeKeysAreNamed) {
  auto c = loadNodeConfig(configDir() / "services" / "motion_planner.yaml");
  ASSERT_TRUE(c.ok()) << c.error().toString();
  EXPECT_EQ(c->robot, "mobile_manipulator");
  EXPECT_TRUE(c->prepare);
  EXPECT_GT(c->prepare_budget_s, 0.0);
  EXPECT_EQ(c->planners, 2);
  auto bad_pool = parseNodeConfig("node:\n  planners: 0\n", "n.yaml");
  ASSERT_FALSE(bad_pool.ok());
  EXPECT_NE(bad_pool.error().message.find("node.planners"), std::string::npos) << bad_pool.error().message;
  auto bad_budget = parseNodeConfig("node:\n  prepare_budget_s: 0\n", "n.yaml");
  ASSERT_FALSE(bad_budget.ok());
  EXPECT_NE(bad_budget.error().message.find("node.prepare_budget_s"), std::string::npos) << bad_budget.error().message;
  auto bad = parseNodeConfig("node:\n  robot: tank\n  colour: red\n", "n.yaml");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("node.robot"), std::string::npos) << bad.error().message;
  EXPECT_NE(bad.error().message.find("colour"), std::string::npos) << bad.error().message;
}

}  // namespace
}  // namespace tamp::motion_planner
