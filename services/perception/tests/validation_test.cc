// Malformed frames are rejected naming the field; nothing crashes and the world is unchanged.
#include "tamp/perception/validation.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "tamp/perception/perception.h"

namespace tamp::perception {
namespace {

PointCloudFrame goodFrame() {
  PointCloudFrame f;
  f.sensor_id = "cam";
  f.stamp_ns = 10;
  f.width = 2;
  f.height = 2;
  f.xyz = {0.1f, 0.2f, 1.0f, 0.0f, 0.0f, 2.0f, NAN, NAN, NAN, 0.3f, -0.1f, 1.5f};
  return f;
}

std::string fieldOf(const Status& s) { return s.ok() ? "" : s.error().where.field; }

TEST(ValidationTest, AcceptsAGoodFrame) { EXPECT_TRUE(validateFrame(goodFrame(), 100).ok()); }

TEST(ValidationTest, RejectsSizeNotMultipleOfThree) {
  auto f = goodFrame();
  f.xyz.push_back(1.0f);
  const Status s = validateFrame(f, 100);
  EXPECT_EQ(fieldOf(s), "xyz");
  EXPECT_NE(s.error().message.find("not a multiple of 3"), std::string::npos);
}

TEST(ValidationTest, RejectsEmptyCloud) {
  auto f = goodFrame();
  f.xyz.clear();
  f.width = 0;
  const Status s = validateFrame(f, 100);
  EXPECT_EQ(fieldOf(s), "xyz");
  EXPECT_NE(s.error().message.find("empty"), std::string::npos);
}

TEST(ValidationTest, RejectsNanSensorPose) {
  auto f = goodFrame();
  f.world_T_sensor.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(fieldOf(validateFrame(f, 100)), "world_T_sensor");
  auto g = goodFrame();
  g.world_T_sensor.linear() *= 2.0;  // not a rotation
  EXPECT_EQ(fieldOf(validateFrame(g, 100)), "world_T_sensor");
}

TEST(ValidationTest, RejectsLayoutMismatchAndMixedPointsAndTooMany) {
  auto f = goodFrame();
  f.width = 3;
  EXPECT_EQ(fieldOf(validateFrame(f, 100)), "width");
  auto g = goodFrame();
  g.xyz[4] = NAN;  // point 1 half NaN
  EXPECT_EQ(fieldOf(validateFrame(g, 100)), "xyz[1]");
  auto h = goodFrame();
  h.xyz[0] = h.xyz[1] = h.xyz[2] = std::numeric_limits<float>::infinity();  // an all-infinite no-return is fine
  EXPECT_TRUE(validateFrame(h, 100).ok());
  EXPECT_EQ(fieldOf(validateFrame(goodFrame(), 3)), "xyz");  // 4 points > 3
}

TEST(ValidationTest, PerceptionRejectsMalformedFramesAndKeepsItsWorld) {
  Perception p(world::World("w"), PerceptionParams());
  const world::World before = p.world();
  auto f = goodFrame();
  f.xyz.resize(7);
  auto r = p.processFrame(f);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
  EXPECT_EQ(r.error().where.field, "xyz");
  auto g = goodFrame();
  g.world_T_sensor.linear()(0, 0) = std::numeric_limits<double>::quiet_NaN();
  r = p.processFrame(g);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().where.field, "world_T_sensor");
  EXPECT_EQ(p.frames(), 0u);
  EXPECT_EQ(p.world().version(), before.version());

  // An older frame after a newer one is refused by stamp.
  auto newer = goodFrame();
  newer.stamp_ns = 100;
  ASSERT_TRUE(p.processFrame(newer).ok());
  auto older = goodFrame();
  older.stamp_ns = 50;
  r = p.processFrame(older);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().where.field, "stamp_ns");
}

TEST(ValidationTest, ExpiredDeadlineLeavesTheWorldUnchanged) {
  Perception p(world::World("w"), PerceptionParams());
  auto r = p.processFrame(goodFrame(), Termination(Deadline::in(-1.0)));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kTimeout);
  EXPECT_EQ(p.frames(), 0u);
}

}  // namespace
}  // namespace tamp::perception
