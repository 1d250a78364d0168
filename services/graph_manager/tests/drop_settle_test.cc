// DropSettleWatch: after a drop, a re-pick is planned only from an object that rests, steadily,
// in the world model (transport_drop, session 25: the first fall estimate vanished 10 ms after it
// was seen resting, and the re-pick was planned without the box).
#include "tamp/graph_manager/drop_settle.h"

#include <stdexcept>

#include <gtest/gtest.h>

namespace tamp::graph_manager {
namespace {

world::World floorWith(std::optional<Eigen::Vector3d> box_at) {
  world::World w("hall");
  EXPECT_TRUE(w.addRegion(world::Region{"floor", "floor", world::RegionKind::kFloor,
                                        {{-10, -10}, {10, -10}, {10, 10}, {-10, 10}}, 0.0})
                  .ok());
  if (box_at) {
    world::Object box;
    box.id = "box";
    box.kind = world::ObjectKind::kMovable;
    box.shape = world::Shape::box(0.06, 0.20, 0.25);
    box.mass = 1.5;
    box.pose.translation() = *box_at;
    EXPECT_TRUE(w.addObject(box).ok());
  }
  return w;
}

TEST(DropSettleWatchTest, AnEstimateThatVanishesRightAfterItRestedIsWaitedOutUntilTheObjectRestsAgain) {
  DropSettleWatch watch("box", 0.3);
  const Eigen::Vector3d fell(4.73, 2.0, 0.125), really(4.92, 2.0, 0.125);
  EXPECT_FALSE(watch.settled(floorWith(Eigen::Vector3d(4.70, 2.0, 0.8)), 0.00));  // still in the air
  EXPECT_FALSE(watch.settled(floorWith(fell), 0.02));                             // the fall estimate
  EXPECT_FALSE(watch.settled(floorWith(std::nullopt), 0.03));                     // seen through: gone
  EXPECT_FALSE(watch.settled(floorWith(std::nullopt), 0.50));
  EXPECT_FALSE(watch.settled(floorWith(really), 0.90));  // found where it fell
  EXPECT_FALSE(watch.settled(floorWith(really + Eigen::Vector3d(0.01, 0, 0)), 1.10));  // noise: still
  EXPECT_TRUE(watch.settled(floorWith(really), 1.21));
  ASSERT_TRUE(watch.restingAt().has_value());
  EXPECT_NEAR(watch.restingAt()->x(), 4.92, 1e-9);
  EXPECT_EQ(watch.restarts(), 1);
}

TEST(DropSettleWatchTest, AnEstimateThatMovesStartsTheWaitOver) {
  DropSettleWatch watch("box", 0.3);
  EXPECT_FALSE(watch.settled(floorWith(Eigen::Vector3d(4.73, 2.0, 0.125)), 0.0));
  EXPECT_FALSE(watch.settled(floorWith(Eigen::Vector3d(4.92, 2.0, 0.125)), 0.31));  // moved 19 cm
  EXPECT_FALSE(watch.settled(floorWith(Eigen::Vector3d(4.92, 2.0, 0.125)), 0.5));
  EXPECT_TRUE(watch.settled(floorWith(Eigen::Vector3d(4.92, 2.0, 0.125)), 0.62));
  EXPECT_EQ(watch.restarts(), 1);
}

TEST(DropSettleWatchTest, WithoutAConfirmationTheFirstRestingLookIsEnough) {
  DropSettleWatch watch("box", 0.0);
  EXPECT_TRUE(watch.settled(floorWith(Eigen::Vector3d(4.73, 2.0, 0.125)), 0.0));
  EXPECT_EQ(watch.restarts(), 0);
}

TEST(DropSettleWatchTest, BadParametersAreMisuse) {
  EXPECT_THROW(DropSettleWatch("box", -1.0), std::invalid_argument);
  EXPECT_THROW(DropSettleWatch("box", 0.3, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace tamp::graph_manager
