#include "tamp/sim/depth_sensor.h"

#include <cmath>
#include <cstring>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

namespace tamp::sim {
namespace {

using world::Shape;

const robot::RobotModel& robotModel() {
  static const robot::RobotModel m = [] {
    auto r = robot::RobotModel::loadFile(std::filesystem::path(TAMP_SOURCE_DIR) /
                                         "config/robots/mobile_manipulator.urdf");
    if (!r) throw std::runtime_error(r.error().toString());
    return std::move(r).value();
  }();
  return m;
}

world::Object box(const std::string& id, double sx, double sy, double sz, double x, double y,
                  double z, bool hidden = false) {
  world::Object o;
  o.id = id;
  o.kind = world::ObjectKind::kStatic;
  o.shape = Shape::box(sx, sy, sz);
  o.pose = Eigen::Isometry3d::Identity();
  o.pose.translation() = Eigen::Vector3d(x, y, z);
  o.hidden = hidden;
  return o;
}

/// Optical frame at `position` looking along world +x, horizontal (x_opt = -y, y_opt = -z).
Eigen::Isometry3d lookingAlongX(const Eigen::Vector3d& position) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = -Eigen::Vector3d::UnitY();
  T.linear().col(1) = -Eigen::Vector3d::UnitZ();
  T.linear().col(2) = Eigen::Vector3d::UnitX();
  T.translation() = position;
  return T;
}

DepthSensorParams noiseless(int w = 101, int h = 81) {
  DepthSensorParams p;
  p.width = w;
  p.height = h;
  p.horizontal_fov_rad = M_PI / 2;  // fx = 50.5 / tan(45 deg) = 50.5 px
  p.min_range_m = 0.2;
  p.max_range_m = 8.0;
  p.noise_stddev_m = 0.0;
  p.noise_quadratic = 0.0;
  p.dropout_probability = 0.0;
  return p;
}

std::set<std::string> seenIds(const GroundTruthLabels& l, const PointCloudFrame& f) {
  std::set<std::string> out;
  for (std::size_t i = 0; i < l.pixel.size(); ++i) {
    if (l.pixel[i] >= 0 && f.valid(i)) out.insert(l.ids[l.pixel[i]]);
  }
  return out;
}

TEST(DepthSensorTest, SeesABoxAtTheHandComputedDistance) {
  world::World w;
  // Front face at x = 3.0 - 0.25 = 2.75; the sensor at x = 0.5 -> depth 2.25 on the axis.
  ASSERT_TRUE(w.addObject(box("crate", 0.5, 1.0, 1.0, 3.0, 0.0, 1.0)));
  DepthSensor s(noiseless());
  GroundTruthLabels labels;
  const auto f = s.capture(w, lookingAlongX({0.5, 0.0, 1.0}), 123, &labels);
  ASSERT_EQ(f.width, 101u);
  ASSERT_EQ(f.height, 81u);
  ASSERT_EQ(f.size(), 101u * 81u);
  EXPECT_EQ(f.stamp_ns, 123);
  EXPECT_EQ(f.sensor_id, "camera");
  const std::size_t centre = 40 * 101 + 50;  // (cx, cy) = (50, 40): the optical axis
  ASSERT_TRUE(f.valid(centre));
  EXPECT_NEAR(f.point(centre).z(), 2.25, 1e-5);
  EXPECT_NEAR(f.point(centre).x(), 0.0, 1e-6);
  EXPECT_NEAR(f.point(centre).y(), 0.0, 1e-6);
  EXPECT_EQ(labels.ids[labels.pixel[centre]], "crate");
  // Pixel (60, 40): 10 px right = x_opt = 10 / 50.5 * z -> world y = -0.4455 (inside |y| <= 0.5).
  const std::size_t right = 40 * 101 + 60;
  ASSERT_TRUE(f.valid(right));
  EXPECT_NEAR(f.point(right).z(), 2.25, 1e-5);
  EXPECT_NEAR(f.point(right).x(), 10.0 / 50.5 * 2.25, 1e-5);
  // The box spans y in [-0.5, 0.5]: at depth 2.25 that is |u - 50| <= 0.5 / 2.25 * 50.5 = 11.2.
  EXPECT_EQ(labels.ids[labels.pixel[40 * 101 + 61]], "crate");
  EXPECT_NE(labels.pixel[40 * 101 + 62], labels.pixel[centre]);
  // Bottom rows look at the floor: their world z is 0.
  const std::size_t down = 80 * 101 + 50;
  ASSERT_TRUE(f.valid(down));
  EXPECT_EQ(labels.pixel[down], GroundTruthLabels::kFloor);
  const Eigen::Vector3d pw = f.world_T_sensor * f.point(down).cast<double>();
  EXPECT_NEAR(pw.z(), 0.0, 1e-5);
  // Every valid point transformed to the world lies on the floor or on the crate's surface.
  const Aabb crate = w.object("crate").aabb();
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!f.valid(i)) continue;
    const Eigen::Vector3d p = f.world_T_sensor * f.point(i).cast<double>();
    if (labels.pixel[i] == GroundTruthLabels::kFloor) {
      EXPECT_NEAR(p.z(), 0.0, 1e-4);
    } else {
      EXPECT_NEAR(p.x(), crate.min.x(), 1e-4) << "crate points are on its front face";
      EXPECT_LE(std::abs(p.y()), 0.5 + 1e-4);
    }
  }
}

TEST(DepthSensorTest, RespectsFieldOfView) {
  // 90 deg horizontal FOV: at 4 m ahead the view spans |y| <= 4 (to the pixel centres: 50/50.5*4).
  world::World w;
  ASSERT_TRUE(w.addObject(box("inside", 0.2, 0.2, 0.2, 4.0, 3.5, 1.0)));   // 41 deg off axis
  ASSERT_TRUE(w.addObject(box("outside", 0.2, 0.2, 0.2, 4.0, -4.6, 1.0)));  // 49 deg off axis
  ASSERT_TRUE(w.addObject(box("behind", 0.5, 0.5, 0.5, -2.0, 0.0, 1.0)));
  DepthSensor s(noiseless());
  GroundTruthLabels labels;
  const auto f = s.capture(w, lookingAlongX({0.0, 0.0, 1.0}), 0, &labels);
  const auto seen = seenIds(labels, f);
  EXPECT_TRUE(seen.count("inside"));
  EXPECT_FALSE(seen.count("outside"));
  EXPECT_FALSE(seen.count("behind"));
  // A narrower FOV (40 deg) loses "inside".
  auto p = noiseless();
  p.horizontal_fov_rad = 40 * M_PI / 180;
  DepthSensor narrow(p);
  const auto f2 = narrow.capture(w, lookingAlongX({0.0, 0.0, 1.0}), 0, &labels);
  EXPECT_FALSE(seenIds(labels, f2).count("inside"));
  EXPECT_NEAR(narrow.params().verticalFovRad(), 2 * std::atan(40.5 / (50.5 / std::tan(20 * M_PI / 180))),
              1e-12);
}

TEST(DepthSensorTest, RespectsRangeLimitsAndOcclusion) {
  world::World w;
  ASSERT_TRUE(w.addObject(box("near", 0.05, 0.1, 0.1, 0.15, 0.0, 1.0)));  // face at 0.125 < 0.2
  ASSERT_TRUE(w.addObject(box("wall", 0.1, 20, 3, 5.0, 0.0, 1.5)));      // face at 4.95
  auto p = noiseless();
  p.max_range_m = 4.0;
  DepthSensor s(p);
  GroundTruthLabels labels;
  auto f = s.capture(w, lookingAlongX({0.0, 0.0, 1.0}), 0, &labels);
  const std::size_t centre = 40 * 101 + 50;
  EXPECT_FALSE(f.valid(centre)) << "the near box is below min range and hides the wall";
  EXPECT_EQ(labels.ids[labels.pixel[centre]], "near");
  // A pixel beside the near box looks at the wall at 4.95 > 4.0 m: no return either.
  const std::size_t side = 40 * 101 + 10;  // 40 px off axis: beside the near box
  EXPECT_FALSE(f.valid(side));
  // Every valid return is within [min, max] depth.
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!f.valid(i)) continue;
    EXPECT_GE(f.point(i).z(), 0.2f);
    EXPECT_LE(f.point(i).z(), 4.0f);
  }
  p.max_range_m = 6.0;
  DepthSensor far(p);
  f = far.capture(w, lookingAlongX({0.0, 0.0, 1.0}), 0, &labels);
  ASSERT_TRUE(f.valid(side));
  EXPECT_NEAR(f.point(side).z(), 4.95, 1e-5);
}

TEST(DepthSensorTest, MountedOnTheRobotSeesAheadNotBehindHiddenIncluded) {
  const auto& robot = robotModel();
  world::World w;
  // Both hidden: the simulator's ground truth sees what the planner does not know.
  ASSERT_TRUE(w.addObject(box("ahead", 0.4, 0.4, 0.4, 2.0, 0.0, 0.2, /*hidden=*/true)));
  ASSERT_TRUE(w.addObject(box("behind", 0.4, 0.4, 0.4, -2.0, 0.0, 0.2, /*hidden=*/true)));
  const robot::RobotState state = robot.defaultState(Pose2D{0, 0, 0});
  auto params = noiseless(160, 120);
  params.horizontal_fov_rad = 1.2;
  DepthSensor s(params);
  GroundTruthLabels labels;
  const auto f = s.capture(w, robot, state, 0, &labels);
  const auto cam = robot.linkPoseInWorld("camera_optical_frame", state);
  ASSERT_TRUE(cam);
  EXPECT_TRUE(f.world_T_sensor.isApprox(*cam, 1e-12));
  const auto seen = seenIds(labels, f);
  EXPECT_TRUE(seen.count("ahead"));
  EXPECT_FALSE(seen.count("behind"));
  // The points labelled "ahead" lie on its surface in the world frame.
  const Aabb b = w.object("ahead").aabb();
  int n = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!f.valid(i) || labels.pixel[i] < 0 || labels.ids[labels.pixel[i]] != "ahead") continue;
    const Eigen::Vector3d p = f.world_T_sensor * f.point(i).cast<double>();
    EXPECT_TRUE(p.x() >= b.min.x() - 1e-4 && p.x() <= b.max.x() + 1e-4 &&
                std::abs(p.y()) <= 0.2 + 1e-4 && p.z() <= 0.4 + 1e-4);
    ++n;
  }
  EXPECT_GT(n, 20);
  // Turned around, the robot sees "behind" and not "ahead".
  const auto f2 = s.capture(w, robot, robot.defaultState(Pose2D{0, 0, M_PI}), 0, &labels);
  const auto seen2 = seenIds(labels, f2);
  EXPECT_TRUE(seen2.count("behind"));
  EXPECT_FALSE(seen2.count("ahead"));
}

TEST(DepthSensorTest, RobotSelfViewIsOptional) {
  const auto& robot = robotModel();
  world::World w;
  robot::RobotState state = robot.defaultState(Pose2D{1, 2, 0.3});
  auto params = noiseless(160, 120);
  params.horizontal_fov_rad = 1.5;
  GroundTruthLabels labels;
  DepthSensor blind(params);
  auto f = blind.capture(w, robot, state, 0, &labels);
  for (auto l : labels.pixel) EXPECT_TRUE(l == GroundTruthLabels::kFloor || l == GroundTruthLabels::kNone);
  params.see_robot = true;
  DepthSensor self(params);
  f = self.capture(w, robot, state, 0, &labels);
  std::set<std::string> links;
  for (std::size_t i = 0; i < labels.pixel.size(); ++i) {
    if (labels.pixel[i] >= 0) links.insert(labels.ids[labels.pixel[i]]);
  }
  // The camera looks down over the base and the arm standing on its pedestal in front of it; it
  // does not see its own housing (the rays start inside it).
  EXPECT_FALSE(links.empty());
  EXPECT_FALSE(links.count("camera_link"));
  for (const auto& l : links) EXPECT_NE(robot.linkIndex(l), -1) << l;
}

TEST(DepthSensorTest, NoiseGrowsWithDepthAndIsDeterministic) {
  world::World w;
  ASSERT_TRUE(w.addObject(box("wall_near", 0.1, 40, 40, 1.05, 0.0, 1.0)));
  auto p = noiseless(200, 150);
  p.noise_stddev_m = 0.002;
  p.noise_quadratic = 0.004;
  p.dropout_probability = 0.05;
  p.seed = 7;
  // stddev of the depth, dropout fraction for a wall facing the sensor at depth d.
  auto measure = [&](double d, std::uint64_t seed, PointCloudFrame* out) {
    world::World ww;
    EXPECT_TRUE(ww.addObject(box("wall", 0.1, 400, 400, d + 0.05, 0.0, 1.0)));
    auto q = p;
    q.seed = seed;
    q.max_range_m = 20;
    DepthSensor s(q);
    GroundTruthLabels labels;
    const auto f = s.capture(ww, lookingAlongX({0.0, 0.0, 1.0}), 0, &labels);
    if (out) *out = f;
    double sum = 0, sum2 = 0;
    int n = 0, on_wall = 0;
    for (std::size_t i = 0; i < f.size(); ++i) {
      if (labels.pixel[i] != 0) continue;  // the floor is nearer than the wall in the lower rows
      ++on_wall;
      if (!f.valid(i)) continue;
      const double e = f.point(i).z() - d;  // the wall's face is at depth d for every pixel
      sum += e;
      sum2 += e * e;
      ++n;
    }
    const double mean = sum / n;
    EXPECT_GT(on_wall, 10000);
    return std::tuple{mean, std::sqrt(sum2 / n - mean * mean), 1.0 - double(n) / on_wall};
  };
  const auto [m1, s1, drop1] = measure(1.0, 7, nullptr);
  const auto [m4, s4, drop4] = measure(4.0, 7, nullptr);
  EXPECT_NEAR(s1, 0.002 + 0.004 * 1.0, 0.1 * 0.006);
  EXPECT_NEAR(s4, 0.002 + 0.004 * 16.0, 0.1 * 0.066);
  EXPECT_NEAR(m1, 0.0, 4 * 0.006 / std::sqrt(28000.0));
  EXPECT_NEAR(drop1, 0.05, 0.005);
  EXPECT_NEAR(drop4, 0.05, 0.005);
  // Same seed and frame number: identical; another seed: different.
  PointCloudFrame a, b, c;
  measure(2.0, 7, &a);
  measure(2.0, 7, &b);
  measure(2.0, 8, &c);
  ASSERT_EQ(a.xyz.size(), b.xyz.size());
  EXPECT_EQ(0, std::memcmp(a.xyz.data(), b.xyz.data(), a.xyz.size() * sizeof(float)));
  EXPECT_NE(0, std::memcmp(a.xyz.data(), c.xyz.data(), a.xyz.size() * sizeof(float)));
}

TEST(DepthSensorTest, RejectsBadParametersNamingTheField) {
  DepthSensorParams p;
  p.width = 0;
  p.max_range_m = 0.1;
  const Status s = p.validate();
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("sensor.width"), std::string::npos) << s.error().message;
  EXPECT_NE(s.error().message.find("sensor.max_range_m"), std::string::npos);
  EXPECT_EQ(s.error().where.field, "sensor.width");
  EXPECT_THROW(DepthSensor{p}, std::invalid_argument);
  DepthSensorParams q;
  q.frame = "no_such_link";
  DepthSensor s2(q);
  world::World w;
  EXPECT_THROW((void)s2.capture(w, robotModel(), robotModel().defaultState(), 0),
               std::invalid_argument);
}

}  // namespace
}  // namespace tamp::sim
