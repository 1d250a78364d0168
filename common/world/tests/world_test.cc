#include "tamp/world/world.h"

#include <gtest/gtest.h>

namespace tamp::world {
namespace {

Object box(const std::string& id, double x, double y, ObjectKind kind = ObjectKind::kMovable) {
  Object o;
  o.id = id;
  o.label = "box";
  o.kind = kind;
  o.shape = Shape::box(0.2, 0.2, 0.2);
  o.pose.translation() = Eigen::Vector3d(x, y, 0.1);
  o.mass = kind == ObjectKind::kMovable ? 1.0 : 0.0;
  o.graspable = kind == ObjectKind::kMovable;
  return o;
}

Region table(const std::string& id, double x0, double y0, double x1, double y1, double h) {
  Region r;
  r.id = id;
  r.kind = RegionKind::kTable;
  r.polygon = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  r.height = h;
  return r;
}

TEST(WorldIdTest, ValidIds) {
  EXPECT_TRUE(isValidId("can"));
  EXPECT_TRUE(isValidId("wall_01"));
  EXPECT_TRUE(isValidId("a-b"));
  EXPECT_FALSE(isValidId(""));
  EXPECT_FALSE(isValidId("Can"));
  EXPECT_FALSE(isValidId("1box"));
  EXPECT_FALSE(isValidId("_x"));
  EXPECT_FALSE(isValidId("a b"));
  EXPECT_FALSE(isValidId(std::string(65, 'a')));
}

TEST(ShapeTest, ValidationMessages) {
  EXPECT_EQ(*Shape::box(1, 0, 1).invalidReason(),
            "box size must be positive and finite, got [1, 0, 1]");
  EXPECT_EQ(*Shape::cylinder(-1, 1).invalidReason(), "cylinder radius must be positive, got -1");
  EXPECT_EQ(*Shape::prism({{0, 0}, {1, 0}, {2, 0}}, 1).invalidReason(),
            "prism polygon needs at least 3 distinct, non-collinear vertices, got 2");
  EXPECT_TRUE(Shape::sphere(0.1).valid());
}

TEST(ShapeTest, AabbOfRotatedBox) {
  const Shape b = Shape::box(2, 1, 1);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(1, 2, 3);
  const Aabb a = b.aabb(T);
  EXPECT_NEAR(a.min.x(), 0.5, 1e-12);
  EXPECT_NEAR(a.max.x(), 1.5, 1e-12);
  EXPECT_NEAR(a.min.y(), 1.0, 1e-12);
  EXPECT_NEAR(a.max.y(), 3.0, 1e-12);
  EXPECT_NEAR(a.min.z(), 2.5, 1e-12);
}

TEST(ShapeTest, ShrunkIsSmallerOnEachSideAndNeverEmpty) {
  const Shape box = shrunk(Shape::box(0.4, 0.2, 0.1), 0.01);
  EXPECT_TRUE(box.size.isApprox(Eigen::Vector3d(0.38, 0.18, 0.08)));
  const Shape cyl = shrunk(Shape::cylinder(0.035, 0.10), 0.005);
  EXPECT_DOUBLE_EQ(cyl.radius, 0.03);
  EXPECT_DOUBLE_EQ(cyl.height, 0.09);
  EXPECT_DOUBLE_EQ(shrunk(Shape::sphere(0.002), 0.01).radius, 1e-3);
  EXPECT_TRUE(shrunk(Shape::box(0.4, 0.2, 0.1), 0.0) == Shape::box(0.4, 0.2, 0.1));
  const Shape prism = Shape::prism({{0, 0}, {1, 0}, {0, 1}}, 0.5);
  EXPECT_TRUE(shrunk(prism, 0.01) == prism);
}

TEST(ShapeTest, VolumeAndPrismFootprint) {
  EXPECT_NEAR(Shape::cylinder(1, 2).volume(), 2 * M_PI, 1e-12);
  const Shape p = Shape::prism({{0, 0}, {0, 2}, {2, 2}, {2, 0}}, 0.5);  // clockwise in
  EXPECT_GT(signedArea(p.polygon), 0);                                  // stored ccw
  EXPECT_NEAR(p.volume(), 2.0, 1e-12);
  EXPECT_NEAR(p.halfHeight(), 0.25, 1e-12);
}

TEST(WorldTest, AddFindRemoveAndVersion) {
  World w("test");
  EXPECT_EQ(w.version(), 0u);
  ASSERT_TRUE(w.addObject(box("b", 0, 0)));
  ASSERT_TRUE(w.addObject(box("a", 1, 0)));
  EXPECT_EQ(w.version(), 2u);
  ASSERT_EQ(w.objectCount(), 2u);
  EXPECT_EQ(w.objects()[0].id, "a");  // sorted by id
  EXPECT_NE(w.findObject("b"), nullptr);
  EXPECT_EQ(w.findObject("c"), nullptr);
  EXPECT_THROW(w.object("c"), std::invalid_argument);

  const Status dup = w.addObject(box("a", 5, 5));
  ASSERT_FALSE(dup);
  EXPECT_EQ(dup.error().message, "object id 'a' is already taken");
  EXPECT_EQ(w.version(), 2u);  // failed mutations do not count

  Object bad = box("Bad", 0, 0);
  EXPECT_EQ(
      w.addObject(bad).error().message,
      "object 'Bad': object id 'Bad' is invalid (expected a lower-case letter, then lower-case "
      "letters, digits, '_' or '-', at most 64 characters)");
  Object massless = box("m", 0, 0);
  massless.mass = 0;
  EXPECT_EQ(w.addObject(massless).error().message,
            "object 'm': a movable object needs a positive mass, got 0");

  ASSERT_TRUE(w.removeObject("a"));
  EXPECT_EQ(w.removeObject("a").error().code, ErrorCode::kNotFound);
  EXPECT_EQ(w.objectCount(), 1u);
}

TEST(WorldTest, CopiesShareObjectsUntilModified) {
  World w;
  for (int i = 0; i < 50; ++i)
    ASSERT_TRUE(w.addObject(box(std::string("o").append(std::to_string(i)), i, 0)));
  World c = w;
  EXPECT_EQ(w.objectPtr("o7").get(), c.objectPtr("o7").get());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(9, 9, 0.1);
  ASSERT_TRUE(c.setObjectPose("o7", T));
  EXPECT_NE(w.objectPtr("o7").get(), c.objectPtr("o7").get());
  EXPECT_EQ(w.objectPtr("o8").get(), c.objectPtr("o8").get());
  EXPECT_DOUBLE_EQ(w.object("o7").pose.translation().x(), 7.0);  // original untouched
  EXPECT_EQ(c.version(), w.version() + 1);
}

TEST(WorldTest, DiffReportsAddedRemovedMovedChanged) {
  World a;
  ASSERT_TRUE(a.addObject(box("keep", 0, 0)));
  ASSERT_TRUE(a.addObject(box("gone", 1, 0)));
  ASSERT_TRUE(a.addObject(box("mover", 2, 0)));
  ASSERT_TRUE(a.addObject(box("heavy", 3, 0)));
  ASSERT_TRUE(a.addRegion(table("table", 0, 0, 1, 1, 0.75)));
  World b = a;
  ASSERT_TRUE(b.removeObject("gone"));
  ASSERT_TRUE(b.addObject(box("fresh", 4, 0)));
  Eigen::Isometry3d T = b.object("mover").pose;
  T.translation().y() += 0.5;
  ASSERT_TRUE(b.setObjectPose("mover", T));
  Object h = b.object("heavy");
  h.mass = 12;
  ASSERT_TRUE(b.updateObject(h));
  ASSERT_TRUE(b.addLocation(Location{"near_table", "", Pose2D{1, 1, 0}}));
  ASSERT_TRUE(b.setHeld(HeldObject{"keep", "gripper", Eigen::Isometry3d::Identity()}));

  const WorldDiff d = diff(a, b);
  ASSERT_EQ(d.added.size(), 1u);
  EXPECT_EQ(d.added[0].id, "fresh");
  EXPECT_EQ(d.removed, std::vector<std::string>{"gone"});
  ASSERT_EQ(d.moved.size(), 1u);
  EXPECT_EQ(d.moved[0].id, "mover");
  EXPECT_DOUBLE_EQ(d.moved[0].pose.translation().y(), 0.5);
  ASSERT_EQ(d.changed.size(), 1u);
  EXPECT_EQ(d.changed[0].id, "heavy");
  EXPECT_EQ(d.locations_added_or_changed.size(), 1u);
  EXPECT_TRUE(d.regions_added_or_changed.empty());
  EXPECT_TRUE(d.held_changed);
  EXPECT_EQ(d.touchedObjects(), (std::vector<std::string>{"fresh", "gone", "heavy", "mover"}));

  // Replaying the diff on `a` gives `b`.
  World c = a;
  ASSERT_TRUE(applyDiff(c, d));
  EXPECT_TRUE(diff(c, b).empty());
  EXPECT_TRUE(diff(b, c).empty());
  // A small move below the tolerance is not reported.
  World e = b;
  T.translation().y() += 1e-6;
  ASSERT_TRUE(e.setObjectPose("mover", T));
  EXPECT_FALSE(diff(b, e).empty());
  EXPECT_TRUE(diff(b, e, 1e-3).empty());
}

TEST(WorldTest, ApplyDiffFailsAtomically) {
  World a;
  ASSERT_TRUE(a.addObject(box("x", 0, 0)));
  WorldDiff d;
  d.added.push_back(box("y", 1, 1));
  d.removed.push_back("missing");
  const auto v = a.version();
  const Status s = applyDiff(a, d);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code, ErrorCode::kNotFound);
  EXPECT_EQ(a.version(), v);
  EXPECT_EQ(a.findObject("y"), nullptr);
}

TEST(WorldTest, PlannerViewHidesHiddenObjects) {
  World w;
  ASSERT_TRUE(w.addObject(box("seen", 0, 0)));
  Object h = box("ghost", 1, 0);
  h.hidden = true;
  ASSERT_TRUE(w.addObject(h));
  ASSERT_TRUE(w.setHeld(HeldObject{"ghost", "gripper", Eigen::Isometry3d::Identity()}));
  EXPECT_EQ(w.hiddenCount(), 1u);
  const World v = w.plannerView();
  EXPECT_EQ(v.objectCount(), 1u);
  EXPECT_EQ(v.findObject("ghost"), nullptr);
  EXPECT_FALSE(v.held().has_value());
  EXPECT_EQ(v.objectPtr("seen").get(), w.objectPtr("seen").get());
}

TEST(WorldTest, HeldObjectMustExistAndBeMovable) {
  World w;
  ASSERT_TRUE(w.addObject(box("wall", 0, 0, ObjectKind::kStatic)));
  EXPECT_EQ(w.setHeld(HeldObject{"nope", "g", Eigen::Isometry3d::Identity()}).error().code,
            ErrorCode::kNotFound);
  EXPECT_EQ(w.setHeld(HeldObject{"wall", "g", Eigen::Isometry3d::Identity()}).error().message,
            "held object 'wall' is not movable");
  ASSERT_TRUE(w.addObject(box("cup", 1, 0)));
  ASSERT_TRUE(w.setHeld(HeldObject{"cup", "g", Eigen::Isometry3d::Identity()}));
  ASSERT_TRUE(w.removeObject("cup"));
  EXPECT_FALSE(w.held().has_value());
}

TEST(WorldTest, RegionBelowPrefersTheTableUnderThePoint) {
  World w;
  Region floor;
  floor.id = "floor";
  floor.polygon = {{-5, -5}, {5, -5}, {5, 5}, {-5, 5}};
  ASSERT_TRUE(w.addRegion(floor));
  ASSERT_TRUE(w.addRegion(table("table", 0, 0, 1, 1, 0.75)));
  EXPECT_EQ(w.regionBelow({0.5, 0.5, 0.80})->id, "table");
  EXPECT_EQ(w.regionBelow({0.5, 0.5, 0.05})->id, "floor");  // under the table top
  EXPECT_EQ(w.regionBelow({2, 2, 0.05})->id, "floor");
  EXPECT_EQ(w.regionBelow({9, 9, 0.05}), nullptr);
  Region bad = table("bad", 0, 0, 0, 1, 0.75);
  EXPECT_EQ(w.addRegion(bad).error().message, "region 'bad': region polygon has zero area");
}

TEST(WorldTest, BoundsCoverObjectsOrWorkspace) {
  World w;
  ASSERT_TRUE(w.addObject(box("a", 0, 0)));
  ASSERT_TRUE(w.addObject(box("b", 4, 2)));
  Aabb b = w.bounds();
  EXPECT_NEAR(b.min.x(), -0.1, 1e-12);
  EXPECT_NEAR(b.max.y(), 2.1, 1e-12);
  Aabb ws;
  ws.extend(Eigen::Vector3d(-1, -1, 0));
  ws.extend(Eigen::Vector3d(10, 10, 2));
  w.setWorkspace(ws);
  EXPECT_DOUBLE_EQ(w.bounds().max.x(), 10.0);
}

}  // namespace
}  // namespace tamp::world
