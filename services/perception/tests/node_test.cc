// The perception node in-process on an isolated DDS domain: a cloud in, world objects, events
// and the occupancy map out; a malformed cloud is rejected without harm.
#include <atomic>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

#include "../../../common/dds/tests/test_util.h"
#include "cloud_convert.h"
#include "tamp/dds/convert.h"
#include "perception_node.h"
#include "tamp/dds/world_sync.h"
#include "tamp/robot/robot_model.h"
#include "tamp/sim/depth_sensor.h"
#include "test_scenes.h"

namespace tamp::perception {
namespace {

bool waitFor(const std::function<bool()>& pred, double seconds = 20.0) {
  const Deadline d = Deadline::in(seconds);
  while (!d.expired()) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return pred();
}

TEST(PerceptionNodeTest, CloudInWorldObjectsEventsAndOccupancyOut) {
  const int domain = dds::testing::isolatedDomain();
  world::World prior("node_test");
  ASSERT_TRUE(prior.addRegion(testing::floorRegion()).ok());
  world::World truth = prior;
  ASSERT_TRUE(truth.addObject(testing::box("parcel", 0.3, 0.3, 0.3, 2.2, 0.1, 0.3)).ok());

  dds::ServiceArgs args;
  args.name = "perception_test";
  args.domain_id = domain;
  args.heartbeat_period_s = 0.2;
  PerceptionNodeOptions options;
  options.prior = prior;
  options.occupancy_period_s = 0.0;
  PerceptionNode node(args, options);
  std::thread runner([&] { node.run(); });

  auto p = dds::testing::makeParticipant(domain);
  ASSERT_TRUE(p);
  dds::WorldMirror mirror(p);
  std::mutex mutex;
  std::vector<msg::WorldEvent> events;
  dds::Reader<msg::WorldEvent> event_reader(p, dds::topics::kWorldEvents,
                                             [&](const msg::WorldEvent& e, const dds::SampleMeta&) {
                                               std::lock_guard lock(mutex);
                                               events.push_back(e);
                                             });
  std::atomic<int> maps{0};
  std::atomic<bool> map_ok{false};
  dds::Reader<msg::OccupancyMap> map_reader(p, dds::topics::kOccupancy,
                                            [&](const msg::OccupancyMap& m, const dds::SampleMeta&) {
                                              const std::string head(m.octree().begin(), m.octree().begin() + std::min<std::size_t>(28, m.octree().size()));
                                              map_ok = head == "# Octomap OcTree binary file" && m.resolution() > 0;
                                              ++maps;
                                            });
  dds::Writer<msg::PointCloudFrame> clouds(p, dds::topics::kPointCloud);
  ASSERT_TRUE(clouds.waitForReaders(Termination::after(10.0)));
  // The prior world is published at start (transient-local): the mirror has the floor region.
  ASSERT_TRUE(waitFor([&] { return mirror.publishedVersion() > 0; }));

  // A malformed cloud (7 floats) is rejected and counted; the node carries on.
  msg::PointCloudFrame bad = dds::toMsg(testing::render(truth, testing::mastCamera(0, 0, 0), {}, 1));
  bad.points(std::vector<float>(7, 1.0f));
  ASSERT_TRUE(clouds.write(bad).ok());
  ASSERT_TRUE(waitFor([&] { return node.framesRejected() == 1; }));

  const auto cam = testing::mastCamera(0, 0, 0);
  for (int k = 0; k < 2; ++k) {
    const auto frame = testing::render(truth, cam, {}, 1'000'000'000LL * (k + 1), static_cast<std::uint64_t>(k));
    ASSERT_TRUE(clouds.write(dds::toMsg(frame, static_cast<std::uint64_t>(k))).ok());
    ASSERT_TRUE(waitFor([&] { return node.framesProcessed() == static_cast<std::uint64_t>(k + 1); }))
        << "processed " << node.framesProcessed() << ", rejected " << node.framesRejected();
  }

  // The new object arrives as a keyed WorldObject, with an ADDED event and an occupancy map.
  std::string id;
  ASSERT_TRUE(waitFor([&] {
    const world::World w = mirror.snapshot();
    for (const auto& o : w.objects()) {
      if ((o.pose.translation().head<2>() - Eigen::Vector2d(2.2, 0.1)).norm() < 0.08) id = o.id;
    }
    return !id.empty();
  }));
  const world::Object seen = mirror.snapshot().object(id);
  EXPECT_EQ(seen.kind, world::ObjectKind::kMovable);
  EXPECT_NEAR(2 * seen.shape.halfHeight(), 0.3, 0.03);
  ASSERT_TRUE(waitFor([&] {
    std::lock_guard lock(mutex);
    return std::any_of(events.begin(), events.end(), [&](const msg::WorldEvent& e) {
      return e.type() == msg::WORLD_OBJECT_ADDED && e.object_id() == id;
    });
  }));
  ASSERT_TRUE(waitFor([&] { return maps.load() >= 2; }));
  EXPECT_TRUE(map_ok.load());
  EXPECT_EQ(node.framesRejected(), 1u);
  EXPECT_EQ(node.worldSnapshot().findObject(id) != nullptr, true);

  node.stop();
  runner.join();
}

TEST(PerceptionNodeTest, RobotStateFiltersTheRobotsOwnArm) {
  // The simulator's camera sees the robot's arm (see_robot); the node gets the robot state on
  // its topic and reports no object. Without a state close to a frame the frame is unfiltered.
  const int domain = dds::testing::isolatedDomain();
  world::World prior("node_robot_test");
  ASSERT_TRUE(prior.addRegion(testing::floorRegion()).ok());
  auto model = robot::RobotModel::loadDefault();
  ASSERT_TRUE(model.ok()) << model.error().toString();
  robot::RobotState s = model->defaultState(Pose2D{0.0, 0.0, 0.0});
  s.arm = *model->namedConfiguration("ready");

  dds::ServiceArgs args;
  args.name = "perception_robot_test";
  args.domain_id = domain;
  args.heartbeat_period_s = 0.2;
  PerceptionNodeOptions options;
  options.prior = prior;
  options.robot = std::make_shared<const robot::RobotModel>(*model);
  options.robot_state_max_age_s = 0.1;
  PerceptionNode node(args, options);
  std::thread runner([&] { node.run(); });

  auto p = dds::testing::makeParticipant(domain);
  ASSERT_TRUE(p);
  dds::Writer<msg::RobotState> states(p, dds::topics::kRobotState);
  dds::Writer<msg::PointCloudFrame> clouds(p, dds::topics::kPointCloud);
  ASSERT_TRUE(states.waitForReaders(Termination::after(10.0)));
  ASSERT_TRUE(clouds.waitForReaders(Termination::after(10.0)));
  sim::DepthSensorParams cam;
  cam.see_robot = true;
  sim::DepthSensor sensor(cam);
  msg::RobotState m;
  m.robot_id(model->name());
  m.base(dds::toMsg(s.base));
  m.joint_names(model->fullJointNames());
  m.joint_positions(model->toJointValues(s));
  // A malformed state (one value short) is refused; the node carries on.
  msg::RobotState bad = m;
  bad.joint_positions().pop_back();
  ASSERT_TRUE(states.write(bad).ok());
  for (int k = 0; k < 4; ++k) {
    const int64_t stamp = 1'000'000'000LL * (k + 1);
    m.header().stamp_ns(stamp);
    // The state stream is best effort (a sample written before the reader has matched the
    // writer is lost): write it until the node has it.
    const std::uint64_t before = node.robotStates();
    ASSERT_TRUE(waitFor([&] {
      if (node.robotStates() > before) return true;
      EXPECT_TRUE(states.write(m).ok());
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      return node.robotStates() > before;
    }));
    ASSERT_TRUE(clouds.write(dds::toMsg(sensor.capture(prior, *model, s, stamp), k)).ok());
    ASSERT_TRUE(waitFor([&] { return node.framesProcessed() == static_cast<std::uint64_t>(k + 1); }));
  }
  EXPECT_EQ(node.framesWithoutState(), 0u);
  EXPECT_EQ(node.worldSnapshot().objects().size(), 0u) << "the arm was reported as an object";
  // A frame 1 s after the last state is processed unfiltered (and counted).
  ASSERT_TRUE(clouds.write(dds::toMsg(sensor.capture(prior, *model, s, 6'000'000'000LL), 9)).ok());
  ASSERT_TRUE(waitFor([&] { return node.framesProcessed() == 5u; }));
  EXPECT_EQ(node.framesWithoutState(), 1u);
  node.stop();
  runner.join();
}

TEST(PerceptionNodeTest, ConvertsCloudsBothWaysAndNamesBadFields) {
  const auto frame = testing::render(world::World(), testing::mastCamera(0, 0, 0), {}, 42);
  auto back = fromMsg(dds::toMsg(frame, 3), 1'000'000);
  ASSERT_TRUE(back.ok()) << back.error().toString();
  EXPECT_EQ(back->stamp_ns, 42);
  EXPECT_EQ(back->width, frame.width);
  EXPECT_EQ(back->xyz.size(), frame.xyz.size());
  EXPECT_TRUE(back->world_T_sensor.isApprox(frame.world_T_sensor, 1e-9));

  msg::PointCloudFrame m = dds::toMsg(frame);
  m.sensor_pose().orientation().w(std::numeric_limits<double>::quiet_NaN());
  auto r = fromMsg(m, 1'000'000);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().toString().find("sensor_pose"), std::string::npos) << r.error().toString();
  m = dds::toMsg(frame);
  m.points().pop_back();
  r = fromMsg(m, 1'000'000);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().where.field, "points");
  m = dds::toMsg(frame);
  m.width(m.width() + 1);
  r = fromMsg(m, 1'000'000);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().where.field, "width");
  r = fromMsg(dds::toMsg(frame), 10);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().where.field, "points");
}

TEST(PerceptionNodeTest, NodeOptionsFromYaml) {
  auto o = parseNodeOptions("node: {world_id: lab, occupancy_period_s: 2}\nplanes: {voxel_size: 0.03}\n", "n.yaml");
  ASSERT_TRUE(o.ok()) << o.error().toString();
  EXPECT_EQ(o->world_id, "lab");
  EXPECT_DOUBLE_EQ(o->occupancy_period_s, 2.0);
  EXPECT_DOUBLE_EQ(o->params.planes.voxel_size, 0.03);
  auto bad = parseNodeOptions("node: {occupancy_period_s: -1, colour: 3}\n", "n.yaml");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().toString().find("node.occupancy_period_s"), std::string::npos) << bad.error().toString();
  EXPECT_NE(bad.error().toString().find("node.colour"), std::string::npos) << bad.error().toString();
  auto age = parseNodeOptions("node: {robot_state_max_age_s: -1}\nself_filter: {padding: 0.05}\n", "n.yaml");
  ASSERT_FALSE(age.ok());
  EXPECT_NE(age.error().toString().find("node.robot_state_max_age_s"), std::string::npos) << age.error().toString();
  auto wait = parseNodeOptions("node: {robot_state_wait_s: 9}\n", "n.yaml");
  ASSERT_FALSE(wait.ok());
  EXPECT_NE(wait.error().toString().find("node.robot_state_wait_s"), std::string::npos) << wait.error().toString();
  auto pad = parseNodeOptions("self_filter: {padding: 0.05, enabled: false}\n", "n.yaml");
  ASSERT_TRUE(pad.ok()) << pad.error().toString();
  EXPECT_DOUBLE_EQ(pad->params.self_filter.padding, 0.05);
  EXPECT_FALSE(pad->params.self_filter.enabled);
  auto neg = parseNodeOptions("self_filter: {padding: -0.01}\n", "n.yaml");
  ASSERT_FALSE(neg.ok());
  EXPECT_NE(neg.error().toString().find("self_filter.padding"), std::string::npos) << neg.error().toString();
}

}  // namespace
}  // namespace tamp::perception
