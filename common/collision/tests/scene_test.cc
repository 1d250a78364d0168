#include "tamp/collision/scene.h"

#include <filesystem>
#include <random>
#include <sstream>

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include "tamp/world/namo.h"

namespace tamp::collision {
namespace {

using world::Object;
using world::ObjectKind;
using world::Shape;

Eigen::Isometry3d at(double x, double y, double z, double yaw = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

Object make(const std::string& id, Shape shape, const Eigen::Isometry3d& pose, ObjectKind kind) {
  Object o;
  o.id = id;
  o.kind = kind;
  o.shape = std::move(shape);
  o.pose = pose;
  o.mass = kind == ObjectKind::kMovable ? 1.0 : 0.0;
  return o;
}

// Unit cube robot (one link "base", centred at z = 0.5 when the base is at the origin).
RobotGeometry cubeRobot() { return RobotGeometry::box(1.0, 1.0, 1.0); }

class SceneTest : public ::testing::TestWithParam<Scene::PrismMode> {
 protected:
  Scene::Options opts() const { return Scene::Options{GetParam()}; }
};

TEST_P(SceneTest, BoxContactByHand) {
  world::World w;
  // A 1 m cube whose near face is at x = 0.5 + gap from a robot cube centred at the origin.
  ASSERT_TRUE(w.addObject(make("wall", Shape::box(1, 1, 1), at(1.4, 0, 0.5), ObjectKind::kStatic)));
  Scene s(w, opts());
  s.setRobot(cubeRobot());
  s.setBasePose({0, 0, 0});  // robot face at x = 0.5, wall face at 0.9
  EXPECT_FALSE(s.robotInCollision());
  s.setBasePose({0.5, 0, 0});  // robot face at 1.0: overlaps the wall by 0.1
  EXPECT_TRUE(s.robotInCollision());
  EXPECT_EQ(s.robotCollisions(), std::vector<std::string>{"wall"});
  s.setBasePose({-0.2, 0, 0});  // robot face at x = 0.3, wall face at 0.9: gap 0.6
  EXPECT_FALSE(s.robotInCollision());
  const DistanceResult d = s.robotDistance();
  ASSERT_TRUE(d.found());
  EXPECT_EQ(d.object, "wall");
  EXPECT_EQ(d.robot, "base");
  EXPECT_NEAR(d.distance, 0.6, 1e-4);
  EXPECT_NEAR(d.point_on_robot.x(), 0.3, 1e-4);
  EXPECT_NEAR(d.point_on_object.x(), 0.9, 1e-4);
  // Rotated by 45 degrees the robot's corner reaches x = -0.2 + sqrt(0.5) = 0.507: still clear.
  s.setBasePose({-0.2, 0, M_PI / 4});
  EXPECT_FALSE(s.robotInCollision());
  EXPECT_NEAR(s.robotDistance().distance, 0.9 - (-0.2 + std::sqrt(0.5)), 1e-4);
  s.setBasePose({0.2, 0, M_PI / 4});  // corner at 0.907 > 0.9
  EXPECT_TRUE(s.robotInCollision());
}

TEST_P(SceneTest, WhichObjectsAndFilters) {
  world::World w;
  ASSERT_TRUE(
      w.addObject(make("wall", Shape::box(0.2, 4, 1), at(0.55, 0, 0.5), ObjectKind::kStatic)));
  ASSERT_TRUE(w.addObject(
      make("crate", Shape::box(0.4, 0.4, 0.4), at(-0.6, 0, 0.2), ObjectKind::kMovable)));
  ASSERT_TRUE(
      w.addObject(make("ball", Shape::sphere(0.2), at(0, 0.65, 0.2), ObjectKind::kMovable)));
  ASSERT_TRUE(w.addObject(make("far", Shape::sphere(0.2), at(5, 5, 0.2), ObjectKind::kMovable)));
  Scene s(w, opts());
  EXPECT_EQ(s.staticCount(), 1u);
  EXPECT_EQ(s.movableCount(), 3u);
  s.setRobot(cubeRobot());
  s.setBasePose({0, 0, 0});
  EXPECT_EQ(s.robotCollisions(), (std::vector<std::string>{"ball", "crate", "wall"}));
  EXPECT_EQ(s.robotCollisions(Filter::staticOnly()), std::vector<std::string>{"wall"});
  EXPECT_EQ(s.robotCollisions(Filter::movableOnly()), (std::vector<std::string>{"ball", "crate"}));
  EXPECT_EQ(s.robotCollisions(Filter::objects({"crate", "far"})),
            std::vector<std::string>{"crate"});
  EXPECT_EQ(s.robotCollisions(Filter::allBut({"wall", "ball"})), std::vector<std::string>{"crate"});
  EXPECT_FALSE(s.robotInCollision(Filter::objects({"far"})));
  EXPECT_FALSE(s.robotInCollision(Filter::objects({"no_such_id"})));
  const auto contacts = s.robotContacts(Filter::movableOnly());
  ASSERT_EQ(contacts.size(), 2u);
  EXPECT_EQ(contacts[0], (Contact{"base", "ball"}));
  // A free shape.
  EXPECT_EQ(s.shapeCollisions(Shape::sphere(0.3), at(-0.6, 0.4, 0.2)),
            std::vector<std::string>{"crate"});
  EXPECT_FALSE(s.shapeInCollision(Shape::sphere(0.1), at(3, 3, 0.2)));
  const DistanceResult sd = s.shapeDistance(Shape::sphere(0.1), at(5, 5.5, 0.2));
  EXPECT_EQ(sd.object, "far");
  EXPECT_NEAR(sd.distance, 0.5 - 0.2 - 0.1, 1e-4);
  EXPECT_THROW((void)s.shapeInCollision(Shape::sphere(-1), at(0, 0, 0)), std::invalid_argument);
}

TEST_P(SceneTest, NonConvexPrismRespectsTheNotch) {
  // L-shaped wall: [0,2]x[0,1] plus [0,1]x[1,2]; the notch [1,2]x[1,2] is free.
  world::World w;
  const world::Polygon2 l{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  ASSERT_TRUE(w.addObject(make("ell", Shape::prism(l, 1.0), at(0, 0, 0.5), ObjectKind::kStatic)));
  Scene s(w, opts());
  const Shape probe = Shape::cylinder(0.2, 0.5);
  EXPECT_FALSE(s.shapeInCollision(probe, at(1.5, 1.5, 0.5)));  // in the notch, 0.3 from both arms
  // Entirely inside an arm: a solid for convex pieces; the mesh is a surface (documented).
  const bool solid = GetParam() == PrismMode::kConvexPieces;
  EXPECT_EQ(s.shapeInCollision(probe, at(1.5, 0.5, 0.5)), solid);
  EXPECT_EQ(s.shapeInCollision(probe, at(0.5, 1.5, 0.5)), solid);
  EXPECT_TRUE(s.shapeInCollision(probe, at(1.1, 1.5, 0.5)));   // crosses the left arm's right face
  EXPECT_TRUE(s.shapeInCollision(probe, at(1.5, 1.15, 0.5)));  // 0.15 above the arm's top edge
  EXPECT_FALSE(s.shapeInCollision(probe, at(1.5, 1.5, 1.3)));  // above the prism (top at z = 1)
  EXPECT_TRUE(s.shapeInCollision(probe, at(1.5, 0.5, 1.2)));   // overlaps the top slab by 0.05
  EXPECT_FALSE(s.shapeInCollision(probe, at(2.5, 2.5, 0.5)));
  const DistanceResult d = s.shapeDistance(Shape::sphere(0.1), at(1.6, 1.5, 0.5));
  EXPECT_EQ(d.object, "ell");
  EXPECT_NEAR(d.distance, 0.5 - 0.1, 1e-4);  // nearest: the bottom arm's top face at y = 1
}

TEST_P(SceneTest, AttachedObjectMovesWithItsLink) {
  world::World w;
  ASSERT_TRUE(w.addObject(make("shelf", Shape::box(0.2, 2, 2), at(2, 0, 1), ObjectKind::kStatic)));
  ASSERT_TRUE(
      w.addObject(make("cup", Shape::cylinder(0.05, 0.1), at(0.58, 0, 0.5), ObjectKind::kMovable)));
  Scene s(w, opts());
  RobotGeometry g;
  g.links = {"base", "gripper"};
  g.parts.push_back({0, Shape::box(0.4, 0.4, 0.4), at(0, 0, 0.2)});
  g.parts.push_back({1, Shape::box(0.1, 0.1, 0.1), Eigen::Isometry3d::Identity()});
  g.allowed_self_collisions = {{0, 1}};
  s.setRobot(g);
  std::vector<Eigen::Isometry3d> poses{at(0, 0, 0), at(0.5, 0, 0.5)};
  s.setLinkPoses(poses);
  EXPECT_EQ(s.robotCollisions(), std::vector<std::string>{"cup"});  // gripper touches the cup
  ASSERT_TRUE(s.attach("cup", "gripper", at(0.1, 0, 0)));
  EXPECT_EQ(s.attachedObjects(), std::vector<std::string>{"cup"});
  EXPECT_EQ(s.movableCount(), 0u);
  EXPECT_FALSE(s.robotInCollision());       // held objects do not collide with themselves
  EXPECT_TRUE(s.selfCollisions().empty());  // cup touches its own link only
  // Reach towards the shelf: the gripper stays clear (x = 1.8 - 0.05 = 1.75 < 1.9) but the cup,
  // 0.1 ahead with radius 0.05, reaches x = 1.95 > 1.9.
  poses[1] = at(1.8, 0, 0.5);
  s.setLinkPoses(poses);
  EXPECT_EQ(s.robotCollisions(), std::vector<std::string>{"shelf"});
  const auto contacts = s.robotContacts();
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_EQ(contacts[0], (Contact{"cup", "shelf"}));
  EXPECT_FALSE(s.attach("cup", "gripper", at(0, 0, 0)));  // already attached
  EXPECT_EQ(s.attach("shelf", "gripper", at(0, 0, 0)).error().message,
            "attach: object 'shelf' is static");
  EXPECT_EQ(s.attach("cup2", "gripper", at(0, 0, 0)).error().code, ErrorCode::kNotFound);
  ASSERT_TRUE(s.detach("cup"));
  EXPECT_EQ(s.movableCount(), 1u);
  EXPECT_FALSE(s.robotInCollision());  // the cup is back at (0.6, 0, 0.5), far from the gripper
  EXPECT_FALSE(s.detach("cup"));
}

TEST_P(SceneTest, AttachHeldFromWorld) {
  world::World w;
  ASSERT_TRUE(w.addObject(make("cup", Shape::sphere(0.05), at(0.6, 0, 0.5), ObjectKind::kMovable)));
  // A wall 0.03 m into the cup's path once the base turns left: y in [1.63, 1.73].
  ASSERT_TRUE(
      w.addObject(make("wall", Shape::box(1, 0.1, 1), at(1, 1.68, 0.5), ObjectKind::kStatic)));
  ASSERT_TRUE(w.setHeld(world::HeldObject{"cup", "base", at(0.6, 0, 0.5)}));
  Scene s(w, opts());
  s.setRobot(RobotGeometry::disc(0.1, 0.2));
  ASSERT_TRUE(s.attachHeld());
  s.setBasePose({1, 1, 0});  // cup at (1.6, 1, 0.5): clear
  EXPECT_FALSE(s.robotInCollision());
  s.setBasePose({1, 1, M_PI / 2});  // cup at (1, 1.6, 0.5): reaches y = 1.65
  EXPECT_EQ(s.robotContacts(), (std::vector<Contact>{{"cup", "wall"}}));
  const DistanceResult d = s.robotDistance(Filter::staticOnly());
  EXPECT_LE(d.distance, 0.0);
  s.setBasePose({1, 0.9, M_PI / 2});  // cup top at y = 1.55: 0.08 from the wall
  const DistanceResult d2 = s.robotDistance();
  EXPECT_EQ(d2.robot, "cup");
  EXPECT_NEAR(d2.distance, 0.08, 1e-4);  // GJK tolerance
}

TEST_P(SceneTest, SyncWorldIsIncremental) {
  world::World w;
  ASSERT_TRUE(
      w.addObject(make("a", Shape::box(0.2, 0.2, 0.2), at(3, 0, 0.1), ObjectKind::kMovable)));
  ASSERT_TRUE(
      w.addObject(make("b", Shape::box(0.2, 0.2, 0.2), at(0, 3, 0.1), ObjectKind::kMovable)));
  Scene s(w, opts());
  s.setRobot(RobotGeometry::disc(0.3, 1.0));
  s.setBasePose({0, 0, 0});
  EXPECT_FALSE(s.robotInCollision());
  world::World w2 = w;
  ASSERT_TRUE(w2.setObjectPose("a", at(0.35, 0, 0.1)));  // 0.05 from the disc's edge: overlaps
  ASSERT_TRUE(w2.removeObject("b"));
  ASSERT_TRUE(w2.addObject(make("c", Shape::sphere(0.1), at(0, -0.35, 0.5), ObjectKind::kStatic)));
  s.syncWorld(w2);
  EXPECT_EQ(s.robotCollisions(), (std::vector<std::string>{"a", "c"}));
  EXPECT_EQ(s.staticCount(), 1u);
  EXPECT_EQ(s.movableCount(), 1u);
  world::World w3 = w2;
  Object a = w3.object("a");
  a.shape = Shape::box(0.05, 0.05, 0.05);  // shrinks away from the disc
  ASSERT_TRUE(w3.updateObject(a));
  s.syncWorld(w3);
  EXPECT_EQ(s.robotCollisions(), std::vector<std::string>{"c"});
  // The result equals a scene built from scratch on the same world.
  Scene fresh(w3, opts());
  fresh.setRobot(RobotGeometry::disc(0.3, 1.0));
  fresh.setBasePose({0, 0, 0});
  EXPECT_EQ(fresh.robotCollisions(), s.robotCollisions());
}

TEST_P(SceneTest, CopyIsIndependent) {
  world::World w;
  ASSERT_TRUE(w.addObject(make("a", Shape::sphere(0.2), at(1, 0, 0.5), ObjectKind::kMovable)));
  Scene s(w, opts());
  s.setRobot(RobotGeometry::disc(0.3, 1.0));
  s.setBasePose({0.6, 0, 0});
  Scene c = s;
  EXPECT_TRUE(c.robotInCollision());
  c.setBasePose({-2, 0, 0});
  EXPECT_FALSE(c.robotInCollision());
  EXPECT_TRUE(s.robotInCollision());
}

INSTANTIATE_TEST_SUITE_P(PrismModes, SceneTest,
                         ::testing::Values(Scene::PrismMode::kConvexPieces,
                                           Scene::PrismMode::kMesh));

TEST(SceneUnknownSpaceTest, OctreeVoxelsCollide) {
  Scene s;
  s.setRobot(RobotGeometry::disc(0.25, 1.0));
  s.setBasePose({0, 0, 0});
  // A column of 10 cm voxels centred at x = 0.5: its near face is at x = 0.45 > 0.25.
  std::vector<Eigen::Vector3d> vox;
  for (int k = 0; k < 10; ++k) vox.emplace_back(0.55, 0.05, 0.05 + 0.1 * k);
  s.setUnknownSpace(vox, 0.1);
  EXPECT_TRUE(s.hasUnknownSpace());
  EXPECT_FALSE(s.robotInCollision());
  const DistanceResult d = s.robotDistance();
  EXPECT_EQ(d.object, kUnknownSpaceId);
  EXPECT_NEAR(d.distance, 0.5 - 0.25, 0.02);
  s.setBasePose({0.3, 0, 0});
  EXPECT_EQ(s.robotCollisions(), std::vector<std::string>{kUnknownSpaceId});
  EXPECT_FALSE(s.robotInCollision(Filter::staticOnly()));
  // Binary round trip through OctoMap.
  octomap::OcTree t(0.1);
  t.updateNode(octomap::point3d(0.35f, 0.05f, 0.45f), true);
  std::ostringstream os;
  ASSERT_TRUE(t.writeBinary(os));
  ASSERT_TRUE(s.setUnknownSpaceFromOctomapBinary(os.str()));
  EXPECT_TRUE(s.robotInCollision());
  s.setBasePose({-1, 0, 0});
  EXPECT_FALSE(s.robotInCollision());
  const Status bad = s.setUnknownSpaceFromOctomapBinary("not an octree");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, ErrorCode::kParseError);
  s.clearUnknownSpace();
  EXPECT_FALSE(s.hasUnknownSpace());
  EXPECT_THROW(s.setUnknownSpace(vox, 0.0), std::invalid_argument);
}

TEST(SceneRobotTest, SelfCollisionSkipsAllowedPairs) {
  Scene s;
  RobotGeometry g;
  g.links = {"base", "upper", "fore"};
  g.parts.push_back({0, Shape::box(1, 1, 0.2), Eigen::Isometry3d::Identity()});
  g.parts.push_back({1, Shape::cylinder(0.05, 0.6), at(0, 0, 0.3)});
  g.parts.push_back({2, Shape::cylinder(0.05, 0.6), at(0, 0, 0.3)});
  g.allowed_self_collisions = {{0, 1}, {1, 2}};
  s.setRobot(g);
  std::vector<Eigen::Isometry3d> poses{at(0, 0, 0), at(0, 0, 0.05), at(0, 0, 0.6)};
  s.setLinkPoses(poses);
  EXPECT_TRUE(s.selfCollisions().empty());
  // Fold the forearm down into the base.
  Eigen::Isometry3d fold = at(0.3, 0, 0.6);
  fold.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  poses[2] = fold;
  s.setLinkPoses(poses);
  const auto self = s.selfCollisions();
  ASSERT_EQ(self.size(), 1u);
  EXPECT_EQ(self[0], (std::pair<std::string, std::string>{"base", "fore"}));
  EXPECT_THROW(s.setLinkPoses(std::vector<Eigen::Isometry3d>(2)), std::invalid_argument);
  RobotGeometry bad = g;
  bad.parts[0].link = 7;
  EXPECT_THROW(s.setRobot(bad), std::invalid_argument);
}

// Random disc placements in a walled room with a non-convex obstacle: the broad phase + convex
// pieces agree with the mesh representation and with an independent 2-D test.
TEST(SceneConsistencyTest, ConvexPiecesAgreeWithMeshAndWithPlanarGeometry) {
  world::World w;
  const world::Polygon2 u{{0, 0}, {3, 0}, {3, 3}, {2, 3}, {2, 1}, {1, 1}, {1, 3}, {0, 3}};  // a U
  ASSERT_TRUE(w.addObject(make("u", Shape::prism(u, 1.0), at(2, 2, 0.5), ObjectKind::kStatic)));
  Scene a(w, Scene::Options{Scene::PrismMode::kConvexPieces});
  Scene b(w, Scene::Options{Scene::PrismMode::kMesh});
  a.setRobot(RobotGeometry::disc(0.2, 1.0));
  b.setRobot(RobotGeometry::disc(0.2, 1.0));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> xy(1.0, 6.0);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Pose2D p{xy(rng), xy(rng), 0};
    a.setBasePose(p);
    b.setBasePose(p);
    const bool ca = a.robotInCollision();
    // Planar ground truth: disc centre within 0.2 of the U polygon (placed at (2, 2)).
    world::Polygon2 placed;
    for (const auto& v : u) placed.emplace_back(v.x() + 2, v.y() + 2);
    double dmin = 1e9;
    for (size_t k = 0; k < placed.size(); ++k) {
      const Eigen::Vector2d s0 = placed[k], s1 = placed[(k + 1) % placed.size()], c(p.x, p.y);
      const double t = std::clamp((c - s0).dot(s1 - s0) / (s1 - s0).squaredNorm(), 0.0, 1.0);
      dmin = std::min(dmin, (s0 + t * (s1 - s0) - c).norm());
    }
    const bool inside = world::containsPoint(placed, {p.x, p.y});
    const bool truth = inside || dmin < 0.2;
    if (std::abs(dmin - 0.2) < 1e-3) continue;  // too close to call (cylinder facets)
    EXPECT_EQ(ca, truth) << "pose " << p;
    EXPECT_EQ(b.robotInCollision(), truth) << "pose " << p;
    hits += ca;
  }
  EXPECT_GT(hits, 100);
}

// REFERENCE.md: in every bare Moghaddam world the robot start and goal squares overlap no static
// polygon and no convex movable polygon (they may touch). A 1 % smaller square must be free.
TEST(SceneNamoTest, MoghaddamStartAndGoalSquaresAreFree) {
  const std::filesystem::path dir =
      std::filesystem::path(TAMP_BENCHMARKS_DIR) / "namo/moghaddam_planning_2016_benchmark";
  int worlds = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".svg") continue;
    auto loaded = world::loadNamo(entry.path());
    ASSERT_TRUE(loaded.ok()) << loaded.error().toString();
    const world::NamoWorld& nw = *loaded;
    Scene scene(nw.world);
    world::Polygon2 shrunk;
    for (const auto& p : nw.robot_footprint) shrunk.push_back(0.99 * p);
    const Shape square = Shape::prism(shrunk, 0.5);
    std::vector<std::string> allowed;  // non-convex movables may overlap (README)
    for (const auto& o : nw.world.objects()) {
      if (o.kind == ObjectKind::kMovable && !world::isConvex(o.shape.polygon))
        allowed.push_back(o.id);
    }
    for (const Pose2D& p : {nw.start, nw.goals.at(0).pose}) {
      const auto hits = scene.shapeCollisions(square, at(p.x, p.y, 0.3), Filter::allBut(allowed));
      EXPECT_TRUE(hits.empty()) << entry.path().filename() << " at " << p << " hits "
                                << hits.front();
    }
    // A disc of the reference radius at the start is free of static obstacles too.
    scene.setRobot(RobotGeometry::disc(nw.robot_radius * 0.99, 1.0));
    scene.setBasePose(nw.start);
    EXPECT_FALSE(scene.robotInCollision(Filter::staticOnly())) << entry.path().filename();
    ++worlds;
  }
  EXPECT_EQ(worlds, 19);
}

// The 1691-vertex costmap outline of 05_citi_second_floor decomposes into convex pieces whose
// union has the outline's area; the robot's start is free and a point inside the wall is not.
TEST(SceneNamoTest, LargeNonConvexOutline) {
  auto loaded = world::loadNamo(
      std::filesystem::path(TAMP_BENCHMARKS_DIR) /
      "namo/s-namo_cases/05_citi_second_floor/05_citi_second_floor_omniscient.json");
  ASSERT_TRUE(loaded.ok()) << loaded.error().toString();
  const world::Object& wall = loaded->world.object("ext_obstacle");
  ASSERT_GT(wall.shape.polygon.size(), 1000u);
  const auto pieces = world::convexDecomposition(wall.shape.polygon);
  double area = 0;
  for (const auto& p : pieces) area += world::signedArea(p);
  EXPECT_NEAR(area, world::signedArea(wall.shape.polygon),
              1e-6 * std::abs(world::signedArea(wall.shape.polygon)));
  Scene scene(loaded->world);
  scene.setRobot(RobotGeometry::disc(loaded->robot_radius, 1.0));
  scene.setBasePose(loaded->start);
  EXPECT_FALSE(scene.robotInCollision());
  const Eigen::Vector2d v = wall.shape.polygon[0];  // a vertex of the outline: on the wall
  const Eigen::Vector3d w = wall.pose * Eigen::Vector3d(v.x(), v.y(), 0.0);
  EXPECT_EQ(scene.shapeCollisions(Shape::sphere(0.05), at(w.x(), w.y(), 0.3)),
            std::vector<std::string>{"ext_obstacle"});
}

}  // namespace
}  // namespace tamp::collision
