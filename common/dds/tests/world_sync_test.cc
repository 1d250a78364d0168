#include "tamp/dds/world_sync.h"

#include <thread>

#include <gtest/gtest.h>

#include "test_util.h"

namespace tamp::dds {
namespace {

world::World sampleWorld() {
  world::World w("kitchen");
  world::Object table;
  table.id = "table";
  table.label = "table";
  table.kind = world::ObjectKind::kStatic;
  table.shape = world::Shape::box(1.2, 0.8, 0.75);
  table.pose.translation() = Eigen::Vector3d(2, 0, 0.375);
  EXPECT_TRUE(w.addObject(table).ok());
  world::Object can;
  can.id = "can";
  can.label = "can";
  can.kind = world::ObjectKind::kMovable;
  can.shape = world::Shape::cylinder(0.033, 0.12);
  can.pose.translation() = Eigen::Vector3d(2, 0.1, 0.81);
  can.mass = 0.35;
  can.graspable = true;
  can.region = "table_top";
  EXPECT_TRUE(w.addObject(can).ok());
  world::Object wall;
  wall.id = "wall";
  wall.label = "L wall";
  wall.shape = world::Shape::prism({{0, 0}, {2, 0}, {2, 0.2}, {0.2, 0.2}, {0.2, 2}, {0, 2}}, 1.0);
  wall.pose.translation() = Eigen::Vector3d(-3, -3, 0.5);
  EXPECT_TRUE(w.addObject(wall).ok());
  EXPECT_TRUE(w.addRegion(world::Region{"table_top", "table top", world::RegionKind::kTable,
                                        {{1.4, -0.4}, {2.6, -0.4}, {2.6, 0.4}, {1.4, 0.4}}, 0.75})
                  .ok());
  EXPECT_TRUE(w.addLocation(world::Location{"near_table", "near table", Pose2D{1.0, 0.0, 0.0}}).ok());
  return w;
}

bool waitFor(const std::function<bool()>& pred) {
  const Deadline d = Deadline::in(10.0);
  while (!d.expired()) {
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

TEST(WorldSyncTest, MirrorAssemblesThePublishedWorldAndFollowsChanges) {
  auto p = testing::makeParticipant();
  ASSERT_TRUE(p);
  WorldPublisher pub(p);
  world::World w = sampleWorld();
  ASSERT_TRUE(pub.publish(w).ok());

  WorldMirror mirror(p);  // late joiner: transient-local state
  ASSERT_TRUE(mirror.waitForPublishedVersion(w.version(), Termination::after(10.0)));
  ASSERT_TRUE(waitFor([&] { return mirror.snapshot().objectCount() == 3; }));
  world::World got = mirror.snapshot();
  EXPECT_EQ(got.object("can"), w.object("can"));
  EXPECT_EQ(got.object("wall"), w.object("wall"));
  ASSERT_NE(got.findRegion("table_top"), nullptr);
  EXPECT_EQ(*got.findRegion("table_top"), *w.findRegion("table_top"));
  ASSERT_NE(got.findLocation("near_table"), nullptr);
  EXPECT_EQ(got.findLocation("near_table")->pose, (Pose2D{1.0, 0.0, 0.0}));

  Eigen::Isometry3d moved = w.object("can").pose;
  moved.translation().x() = 2.3;
  ASSERT_TRUE(w.setObjectPose("can", moved).ok());
  ASSERT_TRUE(w.removeObject("wall").ok());
  ASSERT_TRUE(pub.publish(w).ok());
  ASSERT_TRUE(waitFor([&] {
    auto s = mirror.snapshot();
    return s.findObject("wall") == nullptr && s.findObject("can") != nullptr &&
           std::abs(s.object("can").pose.translation().x() - 2.3) < 1e-12;
  }));
}

// A restarted publisher (perception after kill -9) rebuilds its world from the scenario, whose
// version counter starts low again. Continuing above the versions published before it, its
// worlds reach a mirror that held the old ones: the mirror's version follows it, and moved
// objects arrive. Without the floor the mirror would keep the old version and never complete one.
TEST(WorldSyncTest, ARestartedPublisherContinuesAboveTheVersionsBeforeIt) {
  auto p = testing::makeParticipant();
  ASSERT_TRUE(p);
  world::World w = sampleWorld();
  Eigen::Isometry3d moved = w.object("can").pose;
  for (int i = 0; i < 5; ++i) {
    moved.translation().y() += 0.01;
    ASSERT_TRUE(w.setObjectPose("can", moved).ok());
  }
  auto first = std::make_unique<WorldPublisher>(p);
  ASSERT_TRUE(first->publish(w).ok());
  const std::uint64_t before = first->publishedVersion();
  WorldMirror mirror(p);
  ASSERT_TRUE(mirror.waitForPublishedVersion(before, Termination::after(10.0)));
  first.reset();

  world::World again = sampleWorld();  // the restarted publisher's world: a low version
  ASSERT_LT(again.version(), before);
  WorldPublisher second(p);
  second.continueAbove(before);
  EXPECT_EQ(second.versionOf(again), before + again.version());
  ASSERT_TRUE(second.publish(again).ok());
  EXPECT_GT(second.publishedVersion(), before);
  ASSERT_TRUE(mirror.waitForPublishedVersion(second.publishedVersion(), Termination::after(10.0)));
  ASSERT_TRUE(waitFor([&] {
    auto s = mirror.snapshot();
    return s.findObject("can") != nullptr &&
           std::abs(s.object("can").pose.translation().y() - sampleWorld().object("can").pose.translation().y()) < 1e-12;
  }));
}

TEST(WorldSyncTest, PublisherRefusesHiddenObjects) {
  auto p = testing::makeParticipant();
  ASSERT_TRUE(p);
  WorldPublisher pub(p);
  world::World w = sampleWorld();
  world::Object ghost = w.object("can");
  ghost.id = "ghost";
  ghost.hidden = true;
  ASSERT_TRUE(w.addObject(ghost).ok());
  Status s = pub.publish(w);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("hidden"), std::string::npos);
  EXPECT_TRUE(pub.publish(w.plannerView()).ok());
}

TEST(WorldSyncTest, MalformedObjectMessageIsIgnored) {
  auto p = testing::makeParticipant();
  ASSERT_TRUE(p);
  WorldMirror mirror(p);
  Writer<msg::WorldObject> raw(p, topics::kWorldObjects);
  msg::WorldObject bad = toMsg(sampleWorld().object("can"), 1);
  bad.id("broken");
  bad.shape().dimensions({-1.0, 0.1});  // negative radius
  ASSERT_TRUE(raw.write(bad).ok());
  msg::WorldObject good = toMsg(sampleWorld().object("can"), 1);
  ASSERT_TRUE(raw.write(good).ok());
  ASSERT_TRUE(waitFor([&] { return mirror.snapshot().findObject("can") != nullptr; }));
  EXPECT_EQ(mirror.snapshot().findObject("broken"), nullptr);
  auto r = fromMsg(bad);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().where.field, "objects[broken].shape");
}

// Objects and meta travel on separate topics: a meta that overtakes its objects must not make
// the mirror claim the version (a planner would plan in the old world).
TEST(WorldSyncTest, VersionIsHeldOnlyWhenEveryObjectOfTheManifestHasArrived) {
  auto p = testing::makeParticipant();
  ASSERT_TRUE(p);
  WorldMirror mirror(p);
  Writer<msg::WorldObject> objects(p, topics::kWorldObjects);
  Writer<msg::WorldMeta> metas(p, topics::kWorldMeta);
  const world::World w = sampleWorld();
  msg::WorldMeta meta = metaToMsg(w, "world");
  meta.version(2);
  meta.object_ids({"can", "table"});
  meta.object_versions({2, 1});
  ASSERT_TRUE(metas.write(meta).ok());
  ASSERT_TRUE(objects.write(toMsg(w.object("table"), 1)).ok());
  ASSERT_TRUE(waitFor([&] { return mirror.snapshot().findObject("table") != nullptr; }));
  ASSERT_TRUE(waitFor([&] { return mirror.snapshot().findLocation("near_table") != nullptr; }));
  EXPECT_EQ(mirror.publishedVersion(), 0u) << "the can of version 2 has not arrived";
  ASSERT_TRUE(objects.write(toMsg(w.object("can"), 1)).ok());  // an older sample of it
  ASSERT_TRUE(waitFor([&] { return mirror.snapshot().findObject("can") != nullptr; }));
  EXPECT_EQ(mirror.publishedVersion(), 0u) << "the can is older than the manifest says";
  ASSERT_TRUE(objects.write(toMsg(w.object("can"), 2)).ok());
  EXPECT_TRUE(mirror.waitForPublishedVersion(2, Termination::after(10.0)));
  // Version 3 removes the can: held only once the removal has arrived.
  meta.version(3);
  meta.object_ids({"table"});
  meta.object_versions({1});
  ASSERT_TRUE(metas.write(meta).ok());
  ASSERT_TRUE(waitFor([&] { return mirror.changes() >= 5; }));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(mirror.publishedVersion(), 2u) << "the can is still here";
  ASSERT_TRUE(objects.dispose(toMsg(w.object("can"), 3)).ok());
  EXPECT_TRUE(mirror.waitForPublishedVersion(3, Termination::after(10.0)));
  EXPECT_EQ(mirror.snapshot().findObject("can"), nullptr);
}

// A service that joins late (a restarted graph manager) must assemble the world even when objects
// were removed before it joined, from another participant, many times over.
TEST(WorldSyncTest, ALateJoinerAssemblesAWorldFromWhichObjectsWereRemoved) {
  auto pp = testing::makeParticipant();
  ASSERT_TRUE(pp);
  WorldPublisher pub(pp);
  world::World w = sampleWorld();
  ASSERT_TRUE(pub.publish(w).ok());
  for (int i = 0; i < 20; ++i) {
    world::Object o = w.object("can");
    o.id = "track_" + std::to_string(i);
    o.pose.translation().y() += 0.1 * i;
    ASSERT_TRUE(w.addObject(o).ok());
    ASSERT_TRUE(pub.publish(w).ok());
    if (i % 2 == 0) {
      ASSERT_TRUE(w.removeObject(o.id).ok());
      ASSERT_TRUE(pub.publish(w).ok());
    }
  }
  for (int round = 0; round < 5; ++round) {
    auto pm = testing::makeParticipant();
    ASSERT_TRUE(pm);
    WorldMirror mirror(pm);
    ASSERT_TRUE(mirror.waitForPublishedVersion(w.version(), Termination::after(10.0))) << "round " << round;
    EXPECT_EQ(mirror.snapshot().objectCount(), w.objectCount()) << "round " << round;
  }
}

}  // namespace
}  // namespace tamp::dds
