// Perception's checkpoint (node/checkpoint.h): what a restarted perception starts from. Written
// and read back exactly; a broken file is refused naming the line and field; applied to the
// prior, moved objects are where the checkpoint has them, gone ones are gone, found ones added.
#include <gtest/gtest.h>

#include "checkpoint.h"
#include "test_scenes.h"

namespace tamp::perception {
namespace {

world::World priorWithTwoBoxes() {
  world::World prior("checkpoint_test");
  EXPECT_TRUE(prior.addRegion(testing::floorRegion()).ok());
  for (const auto* id : {"box", "crate"}) {
    world::Object o = testing::box(id, 0.3, 0.3, 0.3, id[0] == 'b' ? 1.0 : 2.0, 0.5, 0.0);
    o.mass = 2.0;
    o.graspable = true;
    EXPECT_TRUE(prior.addObject(o).ok());
  }
  EXPECT_TRUE(prior.addObject(testing::box("wall", 0.1, 3.0, 1.0, 3.0, 0.0, 0.0, 0.0, world::ObjectKind::kStatic)).ok());
  return prior;
}

TEST(CheckpointTest, TheWorldAndTheGraspAreReadBackAsWritten) {
  world::World w = priorWithTwoBoxes();
  world::Object box = w.object("box");
  box.pose.translation() = Eigen::Vector3d(0.45, 0.01, 0.9);
  ASSERT_TRUE(w.updateObject(box).ok());
  Perception::HeldGrasp g{"box", Eigen::Isometry3d::Identity()};
  g.tool_T_object.translation() = Eigen::Vector3d(0.0, 0.0, 0.03);
  g.tool_T_object.rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  auto c = parseCheckpoint(formatCheckpoint(w, g), "perception.checkpoint");
  ASSERT_TRUE(c) << c.error().toString();
  ASSERT_TRUE(c->held.has_value());
  EXPECT_EQ(c->held->object_id, "box");
  EXPECT_TRUE(c->held->tool_T_object.isApprox(g.tool_T_object, 1e-12));
  ASSERT_EQ(c->movables.size(), 2u) << "the movables only, not the wall";
  EXPECT_EQ(c->movables[0].id, "box");
  EXPECT_TRUE(c->movables[0].pose.isApprox(box.pose, 1e-12));
  EXPECT_EQ(c->movables[0].shape.size, box.shape.size);
  EXPECT_DOUBLE_EQ(c->movables[0].mass, 2.0);
  EXPECT_TRUE(c->movables[0].graspable);
  EXPECT_EQ(c->world_version, 0u) << "none recorded";
  auto empty_hand = parseCheckpoint(formatCheckpoint(w, std::nullopt, 41), "perception.checkpoint");
  ASSERT_TRUE(empty_hand) << empty_hand.error().toString();
  EXPECT_FALSE(empty_hand->held.has_value());
  EXPECT_EQ(empty_hand->world_version, 41u);
}

TEST(CheckpointTest, ABrokenCheckpointIsRefusedNamingTheLineAndField) {
  const std::string good = formatCheckpoint(priorWithTwoBoxes(), std::nullopt);
  const auto why = [](const std::string& text) {
    auto c = parseCheckpoint(text, "perception.checkpoint");
    return c ? std::string("accepted") : c.error().toString();
  };
  EXPECT_NE(why("something else\n").find("perception.checkpoint:1"), std::string::npos) << why("something else\n");
  EXPECT_NE(why(good + "held box 1 0 0\n").find(":4"), std::string::npos) << why(good + "held box 1 0 0\n");
  EXPECT_NE(why(good + "held box 1 0 0\n").find("held"), std::string::npos);
  EXPECT_NE(why(good + "object 00ff\n").find("object"), std::string::npos) << why(good + "object 00ff\n");
  EXPECT_NE(why(good + "object zz\n").find(":4"), std::string::npos);
  EXPECT_NE(why(good + "pose box 1 2 3\n").find("unknown record 'pose'"), std::string::npos);
  for (const char* bad : {"world_version x\n", "world_version 0\n", "world_version -3\n", "world_version 4 5\n",
                          "world_version\n", "world_version 99999999999999999999999\n"}) {
    EXPECT_NE(why(good + bad).find("world_version"), std::string::npos) << bad << ": " << why(good + bad);
    EXPECT_NE(why(good + bad).find(":4"), std::string::npos) << bad << ": " << why(good + bad);
  }
  EXPECT_NE(why(good + "world_version 3\nworld_version 4\n").find("a second world version"), std::string::npos);
  // A torn last line (a crash while writing is excluded by the atomic write, a hand edit is not).
  EXPECT_NE(why(good.substr(0, good.size() - 10)).find("object"), std::string::npos);
}

TEST(CheckpointTest, AppliedToThePriorMovedObjectsMoveGoneOnesGoAndFoundOnesAreAdded) {
  const world::World prior = priorWithTwoBoxes();
  PerceptionCheckpoint c;
  world::Object box = prior.object("box");
  box.pose.translation().x() = 1.7;
  c.movables.push_back(box);  // moved; crate gone
  world::Object found = testing::box("box_1", 0.2, 0.2, 0.2, 0.5, -1.0, 0.0);
  c.movables.push_back(found);
  auto w = restoredPrior(prior, c);
  ASSERT_TRUE(w) << w.error().toString();
  EXPECT_NEAR(w->object("box").pose.translation().x(), 1.7, 1e-12);
  EXPECT_EQ(w->findObject("crate"), nullptr);
  ASSERT_NE(w->findObject("box_1"), nullptr);
  ASSERT_NE(w->findObject("wall"), nullptr) << "static objects stay the prior's";
  // A checkpoint that names a static object of the prior as movable is not applied.
  PerceptionCheckpoint wrong;
  world::Object wall = prior.object("wall");
  wall.kind = world::ObjectKind::kMovable;
  wrong.movables.push_back(wall);
  auto refused = restoredPrior(prior, wrong);
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().toString().find("'wall'"), std::string::npos) << refused.error().toString();
}

}  // namespace
}  // namespace tamp::perception
