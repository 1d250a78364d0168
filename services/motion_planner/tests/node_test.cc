// The DDS node in-process on an isolated domain: a client makes motion, placement and grasp
// requests against a world published by a WorldPublisher.
#include <gtest/gtest.h>

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
    world_ = testing::corridorWorld(true);
    ASSERT_TRUE(publisher_->publish(world_).ok());
    motion_ = std::make_unique<dds::RpcClient<msg::MotionRequest, msg::MotionReply>>(client_, dds::services::kMotion);
  }
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
}

// After a world update the node prepares the base group's roadmap (spinOnce calls
// prepareIfWorldChanged; called directly here): complete afterwards, nothing to do while the world
// stays the same, and a movable's move keeps the roadmap (only a static change rebuilds it).
TEST_F(NodeTest, PreparesTheRoadmapAfterWorldUpdates) {
  auto rep = motion_->call(lazyRequest(), dds::CallOptions{30.0, {}});  // the mirror has the world now
  ASSERT_TRUE(rep.ok()) << rep.error().toString();
  ASSERT_EQ(rep->status(), msg::MOTION_SOLVED) << rep->reason();
  auto prep = node_->prepareIfWorldChanged();
  ASSERT_TRUE(prep.has_value());
  EXPECT_FALSE(prep->built);  // the request above built it
  EXPECT_TRUE(prep->completed);
  EXPECT_GT(prep->edges_evaluated, 0u);
  EXPECT_FALSE(node_->prepareIfWorldChanged().has_value());  // nothing changed

  Eigen::Isometry3d p = world_.object("crate").pose;
  p.translation() = Eigen::Vector3d(2.0, 3.4, 0.4);
  ASSERT_TRUE(world_.setObjectPose("crate", p).ok());
  ASSERT_TRUE(publisher_->publish(world_).ok());
  std::optional<PrepareStats> moved;
  for (int i = 0; i < 500 && !moved; ++i) {
    moved = node_->prepareIfWorldChanged();
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
  // Make sure the world is there (a motion call waits for its version).
  ASSERT_TRUE(motion_->call(lazyRequest(), dds::CallOptions{30.0, {}}).ok());
  dds::RpcClient<msg::PlacementRequest, msg::PlacementReply> placement(client_, dds::services::kPlacement);
  msg::PlacementRequest pr;
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

TEST(NodeConfigTest, ShippedConfigLoadsAndBadNodeKeysAreNamed) {
  auto c = loadNodeConfig(configDir() / "services" / "motion_planner.yaml");
  ASSERT_TRUE(c.ok()) << c.error().toString();
  EXPECT_EQ(c->robot, "mobile_manipulator");
  EXPECT_TRUE(c->prepare);
  EXPECT_GT(c->prepare_budget_s, 0.0);
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
