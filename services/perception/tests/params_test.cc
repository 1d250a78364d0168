#include "tamp/perception/params.h"

#include <gtest/gtest.h>

namespace tamp::perception {
namespace {

TEST(ParamsTest, DefaultsAreValid) { EXPECT_TRUE(PerceptionParams().validate().ok()); }

TEST(ParamsTest, ParsesSectionsAndClasses) {
  auto p = parsePerceptionParams(R"(
sensor: {noise_quadratic: 0.002}
crop: {max_range: 4.5, workspace: [-1, -2, -0.1, 5, 6, 2]}
planes: {voxel_size: 0.03}
clusters: {tolerance: 0.06}
tracking: {confirm_hits: 3, reacquire: false}
occupancy: {enabled: false}
classes:
  - {label: crate, shape: box, size: [0.4, 0.3, 0.3], kind: movable, mass: 3, graspable: false}
  - {label: can, shape: cylinder, radius: 0.04, height: 0.12, mass: 0.3, graspable: true}
node: {world_id: w}
)",
                                 "p.yaml");
  ASSERT_TRUE(p.ok()) << p.error().toString();
  EXPECT_DOUBLE_EQ(p->sensor.noise_quadratic, 0.002);
  EXPECT_DOUBLE_EQ(p->crop.max_range, 4.5);
  ASSERT_TRUE(p->crop.workspace.has_value());
  EXPECT_DOUBLE_EQ(p->crop.workspace->max.y(), 6.0);
  EXPECT_DOUBLE_EQ(p->planes.voxel_size, 0.03);
  EXPECT_EQ(p->tracking.confirm_hits, 3);
  EXPECT_FALSE(p->tracking.reacquire);
  EXPECT_FALSE(p->occupancy.enabled);
  ASSERT_EQ(p->classes.size(), 2u);
  EXPECT_EQ(p->classes[0].shape, world::Shape::box(0.4, 0.3, 0.3));
  EXPECT_EQ(p->classes[1].shape, world::Shape::cylinder(0.04, 0.12));
  EXPECT_TRUE(p->classes[1].graspable);
}

TEST(ParamsTest, ErrorsNameFileLineAndField) {
  auto p = parsePerceptionParams("planes:\n  voxel_size: -1\nclusters:\n  tolerance: 0.05\n  colour: red\n", "bad.yaml");
  ASSERT_FALSE(p.ok());
  const std::string msg = p.error().toString();
  EXPECT_NE(msg.find("bad.yaml:2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("planes.voxel_size"), std::string::npos) << msg;
  EXPECT_NE(msg.find("clusters.colour"), std::string::npos) << msg;  // unknown key refused
}

TEST(ParamsTest, RejectsInconsistentValues) {
  PerceptionParams p;
  p.crop.max_range = 0.1;  // below min_range
  p.clusters.tolerance = 0.01;  // not above the voxel size
  p.classes.push_back({"a", world::Shape::box(0.1, 0.1, 0.1), world::ObjectKind::kMovable, 0.0, false});
  p.classes.push_back({"a", world::Shape::box(0.1, 0.1, 0.1), world::ObjectKind::kMovable, 1.0, false});
  const Status s = p.validate();
  ASSERT_FALSE(s.ok());
  const std::string msg = s.error().toString();
  EXPECT_NE(msg.find("crop.max_range"), std::string::npos) << msg;
  EXPECT_NE(msg.find("clusters.tolerance"), std::string::npos) << msg;
  EXPECT_NE(msg.find("classes[0]"), std::string::npos) << msg;  // movable without mass
  EXPECT_NE(msg.find("duplicate class label 'a'"), std::string::npos) << msg;
}

TEST(ParamsTest, UnknownClassShapeIsAnError) {
  auto p = parsePerceptionParams("classes:\n  - {label: ball, shape: torus}\n", "c.yaml");
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.error().toString().find("unknown class shape 'torus'"), std::string::npos) << p.error().toString();
}

TEST(ParamsTest, ShippedConfigLoads) {
  auto p = loadPerceptionParams(std::string(TAMP_SOURCE_DIR) + "/config/services/perception.yaml");
  ASSERT_TRUE(p.ok()) << p.error().toString();
}

TEST(ParamsTest, ClassesFromThePriorWorld) {
  world::World w;
  world::Object a;
  a.id = "crate_1";
  a.label = "crate";
  a.kind = world::ObjectKind::kMovable;
  a.shape = world::Shape::box(0.4, 0.3, 0.3);
  a.mass = 2;
  world::Object b = a;
  b.id = "crate_2";  // same class
  world::Object c = a;
  c.id = "crate_3";
  c.shape = world::Shape::box(0.5, 0.3, 0.3);  // same label, other size
  world::Object wall = a;
  wall.id = "wall";
  wall.kind = world::ObjectKind::kStatic;
  for (const auto& o : {a, b, c, wall}) ASSERT_TRUE(w.addObject(o).ok());
  const auto classes = classesFromWorld(w);
  ASSERT_EQ(classes.size(), 2u);
  EXPECT_EQ(classes[0].label, "crate");
  EXPECT_EQ(classes[1].label, "crate_2");
  EXPECT_EQ(classes[1].shape, world::Shape::box(0.5, 0.3, 0.3));
}

}  // namespace
}  // namespace tamp::perception
