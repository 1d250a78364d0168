// Perception on frames rendered by the simulator's depth camera: detection and pose accuracy,
// noise on an empty floor, a hidden object coming into view, moved and gone objects, unknown
// obstacles in the occupancy map. Perception only sees the frames and the prior world; the
// ground truth is used for the assertions.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>

#include <gtest/gtest.h>

#include "tamp/collision/scene.h"
#include "tamp/core/paths.h"
#include "tamp/world/scenario.h"
#include "tamp/perception/perception.h"
#include "tamp/perception/self_filter.h"
#include "tamp/sim/params.h"
#include "tamp/sim/setup.h"
#include "tamp/sim/simulator.h"
#include "test_scenes.h"

namespace tamp::perception {
namespace {

using testing::box;
using testing::cylinder;
constexpr double kPi = std::numbers::pi;
constexpr int64_t kSecond = 1'000'000'000;

world::World tableWorld() {
  world::World w("test");
  EXPECT_TRUE(w.addRegion(testing::floorRegion()).ok());
  EXPECT_TRUE(w.addRegion(world::Region{"table_top", "table", world::RegionKind::kTable,
                                        {{1.9, 0.6}, {3.1, 0.6}, {3.1, 1.4}, {1.9, 1.4}}, 0.75})
                  .ok());
  EXPECT_TRUE(w.addObject(box("table", 1.2, 0.8, 0.75, 2.5, 1.0, 0.0, 0.0, world::ObjectKind::kStatic)).ok());
  return w;
}

PerceptionParams paramsWithClasses() {
  PerceptionParams p;
  p.classes.push_back({"crate", world::Shape::box(0.4, 0.4, 0.3), world::ObjectKind::kMovable, 3.0, false});
  p.classes.push_back({"can", world::Shape::cylinder(0.04, 0.12), world::ObjectKind::kMovable, 0.3, true});
  return p;
}

/// Runs frames and collects the events; fails the test on a rejected frame.
struct Runner {
  explicit Runner(Perception& p) : perception(p) {}
  Perception& perception;
  testing::Camera camera;
  int64_t stamp{kSecond};
  std::uint64_t index{0};
  std::vector<WorldEvent> events;

  FrameResult frame(const world::World& truth, const Eigen::Isometry3d& sensor) {
    const PointCloudFrame f = testing::render(truth, sensor, camera, stamp, index++);
    stamp += kSecond / 5;
    auto r = perception.processFrame(f);
    EXPECT_TRUE(r.ok()) << r.error().toString();
    if (!r.ok()) return {};
    if (std::getenv("TAMP_PERCEPTION_DEBUG") != nullptr) print(*r);
    events.insert(events.end(), r->events.begin(), r->events.end());
    return *r;
  }
  void print(const FrameResult& r) const {
    std::printf("frame %llu: planes %d clusters %d detections %d matched %d tentative %d, %.1f ms\n",
                static_cast<unsigned long long>(index - 1), r.stats.planes, r.stats.clusters, r.stats.detections,
                r.stats.matched, r.stats.tentative, r.times.total);
    for (const auto& pl : r.planes) {
      std::printf("  plane %.3f (measured %.3f) inliers %d area %.2f region '%s' normal %.3f %.3f %.3f\n", pl.height,
                  pl.measured_height, pl.inliers, pl.area, pl.region.c_str(), pl.coefficients.x(), pl.coefficients.y(),
                  pl.coefficients.z());
    }
    for (const auto& d : r.detections) {
      std::printf("  detection %s h %.3f on %.3f rect %.3f x %.3f yaw %.2f at (%.3f, %.3f) circle r %.3f rms %.4f/%.4f n %zu\n",
                  std::string(world::toString(d.kind)).c_str(), d.height, d.support_z, d.rect.extents.x(),
                  d.rect.extents.y(), d.rect.yaw, d.pose.translation().x(), d.pose.translation().y(), d.circle.radius,
                  d.circle.rms, d.rect_rms, d.points.size());
    }
    for (const auto& e : r.events) {
      std::printf("  event %s %s: %s\n", std::string(toString(e.type)).c_str(), e.object_id.c_str(), e.description.c_str());
    }
  }
  std::vector<WorldEvent> eventsOf(EventType type, const std::string& id = "") const {
    std::vector<WorldEvent> out;
    for (const auto& e : events) {
      if (e.type == type && (id.empty() || e.object_id == id)) out.push_back(e);
    }
    return out;
  }
};

/// The perceived (non-prior) object nearest to `truth` in xy, or nullptr.
const world::Object* nearest(const world::World& w, const world::World& prior, const world::Object& truth) {
  const world::Object* best = nullptr;
  double d_best = 1e9;
  for (const auto& o : w.objects()) {
    if (prior.findObject(o.id) != nullptr && o.kind == world::ObjectKind::kStatic) continue;
    const double d = (o.pose.translation().head<2>() - truth.pose.translation().head<2>()).norm();
    if (d < d_best) {
      d_best = d;
      best = &o;
    }
  }
  return best;
}

TEST(SceneTest, FindsEveryObjectAboveTheSizeThresholdWithinRange) {
  world::World truth = tableWorld();
  ASSERT_TRUE(truth.addObject(box("crate", 0.4, 0.4, 0.3, 3.0, -0.3, 0.1)).ok());         // class crate
  ASSERT_TRUE(truth.addObject(cylinder("can", 0.04, 0.12, 2.3, 0.9, 0.75)).ok());          // class can, on the table
  ASSERT_TRUE(truth.addObject(box("parcel", 0.3, 0.2, 0.25, 2.0, -0.6, 0.4)).ok());       // no class
  ASSERT_TRUE(truth.addObject(cylinder("bin", 0.15, 0.5, 1.8, 0.35)).ok());                // no class
  ASSERT_TRUE(truth.addObject(box("pebble", 0.03, 0.03, 0.03, 1.6, -0.2, 0.0)).ok());      // below min_size
  ASSERT_TRUE(truth.addObject(box("far_box", 0.4, 0.4, 0.4, 8.0, 0.5, 0.0)).ok());        // beyond max_range
  const world::World prior = tableWorld();
  Perception perception(prior, paramsWithClasses());
  Runner run(perception);
  FrameResult last;
  for (int k = 0; k < 4; ++k) last = run.frame(truth, testing::mastCamera(0, 0, 0.1 * (k % 2 == 0 ? 1 : -1)));

  // Support planes: the floor and the table top, matched to their regions.
  bool floor = false, table = false;
  for (const auto& pl : last.planes) {
    floor = floor || pl.region == "floor";
    table = table || pl.region == "table_top";
  }
  EXPECT_TRUE(floor);
  EXPECT_TRUE(table);

  const world::World& w = perception.world();
  struct Expect {
    std::string id;
    std::string label;  // class label, or "" for size-classified objects
    double xy_tol, yaw_tol;
  };
  const std::vector<Expect> expected = {
      {"crate", "crate", 0.03, 0.08}, {"can", "can", 0.02, 0.0}, {"parcel", "", 0.06, 0.12}, {"bin", "", 0.04, 0.0}};
  for (const auto& e : expected) {
    const world::Object& t = truth.object(e.id);
    ASSERT_GT(testing::visiblePixels(truth, testing::mastCamera(0, 0, 0.1), run.camera, e.id), 30) << e.id;
    const world::Object* o = nearest(w, prior, t);
    ASSERT_NE(o, nullptr) << e.id;
    const PoseError err = poseError(t.shape, t.pose, o->pose);
    EXPECT_LT(err.xy, e.xy_tol) << e.id << " found as " << o->id;
    EXPECT_LT(err.z, 0.03) << e.id;
    if (e.yaw_tol > 0) {
      EXPECT_LT(yawError(t.shape, yawOf(t.pose), yawOf(o->pose)), e.yaw_tol) << e.id;
    }
    EXPECT_EQ(o->kind, world::ObjectKind::kMovable) << e.id;
    if (!e.label.empty()) {
      EXPECT_EQ(o->label, e.label);
      EXPECT_EQ(o->shape, t.shape) << e.id << ": a class object takes the class's full shape";
    } else {
      EXPECT_NEAR(2 * o->shape.halfHeight(), 2 * t.shape.halfHeight(), 0.03) << e.id;
      EXPECT_EQ(o->shape.kind, t.shape.kind) << e.id;
    }
  }
  EXPECT_EQ(w.findObject("can_1") != nullptr ? w.object("can_1").region : "", "table_top");
  // Nothing else: the pebble is below the size threshold, the far box beyond the range.
  EXPECT_EQ(w.objectCount(), prior.objectCount() + expected.size());
  EXPECT_EQ(run.eventsOf(EventType::kAdded).size(), expected.size());
  EXPECT_TRUE(run.eventsOf(EventType::kGone).empty());
}

TEST(SceneTest, NoFalseObjectFromSensorNoiseOnAnEmptyFloor) {
  for (bool with_floor_region : {true, false}) {
    world::World truth("empty");
    if (with_floor_region) {
      ASSERT_TRUE(truth.addRegion(testing::floorRegion()).ok());
    }
    PerceptionParams params;
    params.sensor.noise_stddev = 0.002;  // a poor sensor (twice the default noise), configured as such
    params.sensor.noise_quadratic = 0.003;
    Perception perception(truth, params);
    Runner run(perception);
    run.camera.noise = 0.002;
    run.camera.noise_quadratic = 0.003;
    for (int k = 0; k < 12; ++k) {
      const double yaw = 0.5 * k, x = 0.3 * (k % 3);
      const FrameResult r = run.frame(truth, testing::mastCamera(x, -x, yaw));
      EXPECT_EQ(r.stats.detections, 0) << "frame " << k;
    }
    EXPECT_EQ(perception.world().objectCount(), 0u);
    EXPECT_TRUE(run.events.empty());
    ASSERT_NE(perception.occupancy(), nullptr);
    EXPECT_EQ(perception.occupancy()->occupiedCount(), 0u) << "floor noise became unknown obstacles";
    for (const auto& t : perception.tracks()) ADD_FAILURE() << "track " << t.id;
  }
}

TEST(SceneTest, WallsOfTheStaticMapMakeNoSupportPlaneAndNoFalseObject) {
  // A room's walls (static, in the prior) seen from its middle: the band of a horizontal plane
  // at any height cuts all of them, and those slices once added up to a "support" that cut every
  // object in two; the far walls' returns (several cm of noise at 4-5 m) once clustered into
  // thin false boxes in front of them. Objects near the walls stay whole.
  world::World truth("room");
  ASSERT_TRUE(truth.addRegion(testing::floorRegion()).ok());
  ASSERT_TRUE(truth.addObject(box("wall_n", 9.0, 0.1, 1.5, 1.5, 3.0, 0.0, 0.0, world::ObjectKind::kStatic)).ok());
  ASSERT_TRUE(truth.addObject(box("wall_s", 9.0, 0.1, 1.5, 1.5, -3.0, 0.0, 0.0, world::ObjectKind::kStatic)).ok());
  ASSERT_TRUE(truth.addObject(box("wall_e", 0.1, 6.0, 1.5, 5.0, 0.0, 0.0, 0.0, world::ObjectKind::kStatic)).ok());
  const world::World prior = truth;
  ASSERT_TRUE(truth.addObject(box("cabinet", 0.6, 0.5, 1.0, 4.2, 1.0, 0.0)).ok());
  ASSERT_TRUE(truth.addObject(cylinder("post", 0.08, 0.9, 3.6, -0.4)).ok());
  ASSERT_TRUE(truth.addObject(box("crate", 0.4, 0.4, 0.3, 2.2, -0.8, 0.3)).ok());
  Perception perception(prior, PerceptionParams{});
  Runner run(perception);
  run.camera.width = 640;
  run.camera.height = 480;
  for (int k = 0; k < 6; ++k) {
    const FrameResult r = run.frame(truth, testing::mastCamera(-0.5, 0.0, 0.4 * ((k % 3) - 1)));
    for (const auto& p : r.planes) EXPECT_EQ(p.region, "floor") << "frame " << k << ": support at " << p.height;
  }
  ASSERT_EQ(perception.world().objectCount(), 6u) << "3 walls + 3 objects";
  for (const char* id : {"cabinet", "post", "crate"}) {
    const world::Object* o = truth.findObject(id);
    int near = 0;
    for (const auto& f : perception.world().objects()) {
      if (prior.findObject(f.id) != nullptr) continue;
      if ((f.pose.translation().head<2>() - o->pose.translation().head<2>()).norm() < 0.1) ++near;
    }
    EXPECT_EQ(near, 1) << id;
  }
}

TEST(SceneTest, FlagsAHiddenObjectOnceItComesIntoView) {
  // A wall (in the static map) hides a box the planner does not know about.
  world::World truth("hidden");
  ASSERT_TRUE(truth.addRegion(testing::floorRegion()).ok());
  ASSERT_TRUE(truth.addObject(box("wall", 0.1, 2.0, 1.4, 2.5, 0.0, 0.0, 0.0, world::ObjectKind::kStatic)).ok());
  world::Object surprise = box("surprise", 0.35, 0.25, 0.3, 3.2, 0.1, 0.5);
  surprise.hidden = true;
  ASSERT_TRUE(truth.addObject(surprise).ok());
  const world::World prior = truth.plannerView();
  ASSERT_EQ(prior.findObject("surprise"), nullptr);
  Perception perception(prior, PerceptionParams());
  Runner run(perception);
  for (int k = 0; k < 3; ++k) run.frame(truth, testing::mastCamera(0, 0, 0));
  EXPECT_TRUE(run.events.empty()) << run.events.front().description;
  EXPECT_EQ(perception.world().objectCount(), 1u);

  // The robot walks around the wall: the box comes into view.
  const Eigen::Isometry3d side = testing::mastCamera(3.2, -1.9, kPi / 2);
  ASSERT_GT(testing::visiblePixels(truth, side, run.camera, "surprise"), 200);
  run.frame(truth, side);
  run.frame(truth, side);
  const auto added = run.eventsOf(EventType::kAdded);
  ASSERT_EQ(added.size(), 1u);
  EXPECT_EQ(added[0].kind, world::ObjectKind::kMovable);
  EXPECT_LT((added[0].pose.translation().head<2>() - surprise.pose.translation().head<2>()).norm(), 0.08);
  const world::Object& o = perception.world().object(added[0].object_id);
  EXPECT_NEAR(2 * o.shape.halfHeight(), 0.3, 0.03);
  EXPECT_GT(o.mass, 0.0);
}

TEST(SceneTest, TracksAMovedObjectAndReacquiresItUnderItsId) {
  world::World truth = tableWorld();
  world::Object crate = box("crate_1", 0.4, 0.4, 0.3, 2.2, -0.4, 0.2);
  crate.label = "crate";
  crate.mass = 3.0;
  ASSERT_TRUE(truth.addObject(crate).ok());
  Perception perception(truth, PerceptionParams());  // the crate is known: prior = truth
  Runner run(perception);
  const auto cam = testing::mastCamera(0, 0, 0);
  for (int k = 0; k < 2; ++k) run.frame(truth, cam);
  EXPECT_TRUE(run.events.empty());
  EXPECT_LT(poseError(crate.shape, crate.pose, perception.world().object("crate_1").pose).xy, 0.02);
  const auto info = perception.track("crate_1");
  ASSERT_TRUE(info.has_value());
  EXPECT_EQ(info->hits, 2);
  EXPECT_GT(info->last_seen_ns, 0);

  // Pushed by 25 cm and turned: tracked (same id), one MOVED event, no new object.
  Eigen::Isometry3d pushed = testing::box("x", 0.4, 0.4, 0.3, 2.4, -0.25, 0.45).pose;
  ASSERT_TRUE(truth.setObjectPose("crate_1", pushed).ok());
  for (int k = 0; k < 3; ++k) run.frame(truth, cam);
  ASSERT_EQ(run.eventsOf(EventType::kMoved, "crate_1").size(), 1u);
  EXPECT_TRUE(run.eventsOf(EventType::kAdded).empty());
  PoseError err = poseError(crate.shape, pushed, perception.world().object("crate_1").pose);
  EXPECT_LT(err.xy, 0.02);
  EXPECT_LT(err.yaw, 0.05);

  // Carried 1.6 m away (beyond the association gate): gone from its place, reacquired there.
  Eigen::Isometry3d carried = testing::box("x", 0.4, 0.4, 0.3, 3.0, -1.5, -0.3).pose;
  ASSERT_TRUE(truth.setObjectPose("crate_1", carried).ok());
  for (int k = 0; k < 3; ++k) run.frame(truth, testing::mastCamera(0, 0, -0.2));
  EXPECT_EQ(run.eventsOf(EventType::kGone, "crate_1").size(), 1u);
  EXPECT_EQ(run.eventsOf(EventType::kMoved, "crate_1").size(), 2u);
  EXPECT_TRUE(run.eventsOf(EventType::kAdded).empty()) << run.eventsOf(EventType::kAdded).front().description;
  ASSERT_NE(perception.world().findObject("crate_1"), nullptr);
  err = poseError(crate.shape, carried, perception.world().object("crate_1").pose);
  EXPECT_LT(err.xy, 0.03);
  EXPECT_EQ(perception.world().objectCount(), truth.objectCount());
}

// Turned in place by 0.45 rad: a 0.6 m crate's corners move 15 cm, a MOVED event; a 16 cm block's
// 4 cm, which is no event (the fitted yaw of a box that small wobbles as much), though its pose
// follows.
TEST(SceneTest, ATurnIsAnEventWhenItMovesTheObjectAsFarAsAMove) {
  world::World truth = tableWorld();
  world::Object crate = box("crate_1", 0.6, 0.3, 0.3, 2.2, -0.6, 0.0);
  crate.mass = 3.0;
  world::Object block = box("block_1", 0.16, 0.12, 0.25, 1.6, 0.5, 0.0);
  block.mass = 0.5;
  ASSERT_TRUE(truth.addObject(crate).ok());
  ASSERT_TRUE(truth.addObject(block).ok());
  Perception perception(truth, PerceptionParams());
  Runner run(perception);
  const auto cam = testing::mastCamera(0, 0, 0);
  for (int k = 0; k < 2; ++k) run.frame(truth, cam);
  ASSERT_TRUE(run.events.empty()) << run.events.front().description;
  const double turn = 0.45;
  const Eigen::Isometry3d crate_turned = box("x", 0.6, 0.3, 0.3, 2.2, -0.6, turn).pose;
  const Eigen::Isometry3d block_turned = box("x", 0.16, 0.12, 0.25, 1.6, 0.5, turn).pose;
  ASSERT_TRUE(truth.setObjectPose("crate_1", crate_turned).ok());
  ASSERT_TRUE(truth.setObjectPose("block_1", block_turned).ok());
  for (int k = 0; k < 4; ++k) run.frame(truth, cam);
  EXPECT_EQ(run.eventsOf(EventType::kMoved, "crate_1").size(), 1u);
  EXPECT_TRUE(run.eventsOf(EventType::kMoved, "block_1").empty()) << run.eventsOf(EventType::kMoved, "block_1").front().description;
  EXPECT_LT(poseError(crate.shape, crate_turned, perception.world().object("crate_1").pose).yaw, 0.08);
  EXPECT_LT(poseError(block.shape, block_turned, perception.world().object("block_1").pose).yaw, 0.15);
  EXPECT_TRUE(run.eventsOf(EventType::kAdded).empty());
}

// A box dropped while the robot drives: the first frame after the drop snaps the estimate to a
// measurement 2.6 cm off (the camera's pose lagging the moving base: transport_drop, where the
// pick then missed the 3 cm grasp tolerance twice). The next frames, taken still, see it where it
// is: a pose set from one frame settles on them before it is held against partial views.
TEST(SceneTest, AnEstimateSnappedFromOneFrameSettlesOnTheNextFrames) {
  world::World truth("hall");
  ASSERT_TRUE(truth.addRegion(testing::floorRegion()).ok());
  world::Object parcel = box("parcel", 0.06, 0.20, 0.25, 3.84, 2.0, 1.58);  // where it was released
  parcel.mass = 1.5;
  parcel.graspable = true;
  ASSERT_TRUE(truth.addObject(parcel).ok());
  Perception perception(truth, PerceptionParams());
  Runner run(perception);
  const auto cam = testing::mastCamera(2.2, 2.0, 0.0);
  const Eigen::Isometry3d fell = box("x", 0.06, 0.20, 0.25, 4.087, 2.0, 1.58).pose;
  const Eigen::Isometry3d seen_moving = box("x", 0.06, 0.20, 0.25, 4.087 - 0.017, 2.0 + 0.02, 1.58).pose;
  ASSERT_TRUE(truth.setObjectPose("parcel", seen_moving).ok());
  run.frame(truth, cam);
  ASSERT_LT(poseError(parcel.shape, seen_moving, perception.world().object("parcel").pose).xy, 0.01);
  ASSERT_TRUE(truth.setObjectPose("parcel", fell).ok());
  for (int k = 0; k < 6; ++k) run.frame(truth, cam);
  EXPECT_LT(poseError(parcel.shape, fell, perception.world().object("parcel").pose).xy, 0.01);
}

// A box of a known class found by a camera that looks at one of its faces: the range noise
// smears that face towards the camera as much as away from it, so its trimmed extent sat 1-2 cm
// towards the camera, and the box with it (transport_drop's re-picks missed by that). The face's
// own points place it now.
TEST(SceneTest, ABoxSeenFaceOnIsPlacedByItsFaceNotPulledTowardsTheCamera) {
  world::World truth("hall");
  ASSERT_TRUE(truth.addRegion(testing::floorRegion()).ok());
  world::World prior = truth;  // the box is not in the prior: found, by its class's size
  world::Object parcel = box("parcel", 0.40, 0.30, 0.35, 3.0, 0.2, 0.0);
  parcel.mass = 2.0;
  ASSERT_TRUE(truth.addObject(parcel).ok());
  PerceptionParams params;
  params.classes = classesFromWorld(truth);
  Perception perception(prior, params);
  Runner run(perception);
  double worst = 0.0, towards = 0.0;
  int frames = 0;
  for (double y : {0.1, 0.2, 0.3}) {
    for (int k = 0; k < 2; ++k) {
      run.frame(truth, testing::mastCamera(0.8, y, 0.0));
      const world::Object* found = nullptr;
      for (const auto& o : perception.world().objects())
        if (o.kind == world::ObjectKind::kMovable) found = &o;
      if (found == nullptr) continue;  // tentative until seen again
      const double dx = found->pose.translation().x() - parcel.pose.translation().x();
      worst = std::max(worst, poseError(parcel.shape, parcel.pose, found->pose).xy);
      towards = std::min(towards, dx);  // negative: towards the camera
      ++frames;
    }
  }
  std::fprintf(stderr, "face-on box: worst xy error %.4f m, most towards the camera %.4f m over %d frames\n", worst,
               towards, frames);
  EXPECT_GE(frames, 4);
  EXPECT_LT(worst, 0.006);
  EXPECT_GT(towards, -0.006);
}

// A thin box standing across a corridor, seen partly: a pillar (known, static) hides one end of it
// from some of the camera poses. A partial view is explained by the box where it stands: its pose
// must not slide towards the visible part (it did, 0.18 m, on namo_corridor), and no MOVED event.
// Then the box really slides 0.15 m along its long side in full view: tracked there.
TEST(SceneTest, APartlyHiddenThinBoxStaysWhereItIsAndIsTrackedWhenItReallyMoves) {
  world::World truth("corridor");
  ASSERT_TRUE(truth.addRegion(testing::floorRegion()).ok());
  world::Object thin = box("box", 0.05, 0.30, 0.30, 4.62, 1.2, 0.0);
  thin.mass = 1.5;
  ASSERT_TRUE(truth.addObject(thin).ok());
  ASSERT_TRUE(truth.addObject(box("pillar", 0.10, 0.12, 1.0, 4.35, 1.30, 0.0, 0.0, world::ObjectKind::kStatic)).ok());
  Perception perception(truth, PerceptionParams());
  Runner run(perception);
  int frames = 0;
  double worst = 0.0;
  for (double x : {3.3, 3.5, 3.7, 3.85}) {
    for (double y : {1.05, 1.2, 1.35}) {
      run.frame(truth, testing::mastCamera(x, y, 0.0));
      ++frames;
      worst = std::max(worst, poseError(thin.shape, thin.pose, perception.world().object("box").pose).xy);
    }
  }
  EXPECT_LT(worst, 0.03) << "over " << frames << " partial views";
  EXPECT_TRUE(run.eventsOf(EventType::kMoved, "box").empty()) << run.eventsOf(EventType::kMoved, "box").front().description;

  ASSERT_TRUE(truth.removeObject("pillar").ok());
  const Eigen::Isometry3d slid = box("x", 0.05, 0.30, 0.30, 4.62, 1.05, 0.0).pose;
  ASSERT_TRUE(truth.setObjectPose("box", slid).ok());
  for (int k = 0; k < 3; ++k) run.frame(truth, testing::mastCamera(3.6, 1.1, 0.0));
  EXPECT_EQ(run.eventsOf(EventType::kMoved, "box").size(), 1u);
  EXPECT_LT(poseError(thin.shape, slid, perception.world().object("box").pose).xy, 0.03);
}

// A crate that no class or prior knows is learned from what is seen: once seen whole, its
// estimate is the crate. Driven past close by, the camera sees only part of it (the rest out of
// the image); that partial view, explained by the estimate where it stands, is no evidence that
// the crate moved. The grown box fitted to the seen end slid 0.2 m a frame along the crate until
// it stood beside it and was declared gone (namo_room_hidden).
TEST(SceneTest, AnUnknownBoxSeenWholeStaysPutWhenDrivenPastClose) {
  world::World prior("room");
  ASSERT_TRUE(prior.addRegion(testing::floorRegion()).ok());
  world::World truth = prior;
  const double yaw = 0.6;
  world::Object crate = box("crate", 0.5, 0.4, 0.45, 2.4, 0.0, 0.0);
  crate.pose = Eigen::Translation3d(2.4, 0.0, 0.225) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
  crate.mass = 4.0;
  ASSERT_TRUE(truth.addObject(crate).ok());
  Perception perception(prior, PerceptionParams());
  Runner run(perception);
  // Seen whole from 1.5-2 m, as the robot approaches.
  for (int k = 0; k < 8; ++k) run.frame(truth, testing::mastCamera(0.4 + 0.05 * k, -0.3, 0.1 * (k % 3)));
  const world::Object* seen = nearest(perception.world(), prior, crate);
  ASSERT_NE(seen, nullptr);
  const std::string id = seen->id;
  ASSERT_LT(poseError(crate.shape, crate.pose, seen->pose).xy, 0.06) << "not learned whole";
  const auto moved_before = run.eventsOf(EventType::kMoved, id).size();
  // Then driven past its side, 0.55 m from its axis, along it, 10 cm a frame.
  const Eigen::Vector2d along(std::cos(yaw), std::sin(yaw)), side(std::sin(yaw), -std::cos(yaw));
  double worst = 0.0;
  for (int k = 0; k <= 14; ++k) {
    const Eigen::Vector2d c = Eigen::Vector2d(2.4, 0.0) + 0.55 * side + (-1.0 + 0.1 * k) * along;
    run.frame(truth, testing::mastCamera(c.x(), c.y(), yaw + 0.3));
    const world::Object* o = perception.world().findObject(id);
    ASSERT_NE(o, nullptr) << "frame " << k << ": the crate was declared gone";
    worst = std::max(worst, poseError(crate.shape, crate.pose, o->pose).xy);
  }
  EXPECT_LT(worst, 0.08) << "the estimate left the crate while driving past";
  EXPECT_EQ(run.eventsOf(EventType::kMoved, id).size(), moved_before);
  EXPECT_TRUE(run.eventsOf(EventType::kGone).empty());
}

// A chair of known size seen from afar, as a robot drives towards it: near the sensor's range the
// image's top edge cuts the chair at a third of its height, and the range noise (5 cm at 5.5 m)
// spreads its face over a band 20 cm deep. That partial view is the chair, not a new object (it
// was a "new static box 0.90 x 0.25 x 0.38 m" against a chair's face in a NAMO mission, which then
// stood where the robot had to stand to push the chair).
TEST(SceneTest, AFarPartialViewOfAKnownObjectIsNoNewObject) {
  // The prior has the chair 6 cm off where it really stands (nearer the robot).
  world::World prior("room");
  ASSERT_TRUE(prior.addRegion(testing::floorRegion()).ok());
  world::Object chair = box("chair", 1.0, 1.1, 0.9, 6.0, 0.0, 0.0);
  chair.mass = 57.7;
  ASSERT_TRUE(prior.addObject(chair).ok());
  world::World truth = prior;
  chair.pose.translation().x() = 5.94;
  ASSERT_TRUE(truth.setObjectPose("chair", chair.pose).ok());
  Perception perception(prior, PerceptionParams());
  Runner run(perception);
  // Head-on and obliquely (the face seen at up to 35 degrees), from 6 m to 2.5 m (where the
  // whole face is in the image, and the chair's estimate comes to where it stands).
  for (double d = 6.0; d >= 2.49; d -= 0.25) {
    for (double bearing : {-0.6, -0.3, 0.0, 0.3, 0.6}) {
      const double x = 5.5 - d * std::cos(bearing), y = -d * std::sin(bearing);
      run.frame(truth, testing::mastCamera(x, y, bearing));
    }
  }
  const auto added = run.eventsOf(EventType::kAdded);
  EXPECT_TRUE(added.empty()) << added.size() << " added, the first: " << added.front().description;
  EXPECT_EQ(perception.world().objects().size(), 1u);
  EXPECT_LT(poseError(chair.shape, chair.pose, perception.world().object("chair").pose).xy, 0.05);
}

// A long box (1.05 x 0.42 x 0.5 m) with one end near a wall, where the truth is the prior, seen
// as a robot drives past it from 6 m to 1.5 m at several bearings: far views spread its faces
// by the range noise (3 sigma is 5 cm at 3.5 m, 11 cm at 5 m), and a known-size fit of such a
// view may turn the box. None of that is a motion: no MOVED event, and the pose stays (in a
// Moghaddam mission the box was "moved 0.32 m, turned 0.51 rad" by such views, which then put
// it on the robot's path).
TEST(SceneTest, FarNoisyViewsOfAKnownBoxWhereItStandsAreNoMotion) {
  world::World truth("room");
  ASSERT_TRUE(truth.addRegion(testing::floorRegion()).ok());
  world::Object crate = box("crate", 1.05, 0.42, 0.5, 6.0, 0.0, 0.0);
  crate.mass = 13.4;
  ASSERT_TRUE(truth.addObject(crate).ok());
  ASSERT_TRUE(truth.addObject(box("wall", 0.1, 3.0, 1.0, 6.8, 0.0, 0.0, 0.0, world::ObjectKind::kStatic)).ok());
  Perception perception(truth, PerceptionParams());
  Runner run(perception);
  double worst = 0.0;
  for (double d = 6.0; d >= 1.49; d -= 0.25) {
    for (double bearing : {-1.2, -0.6, 0.0, 0.6, 1.2}) {
      const double x = 6.0 - d * std::cos(bearing), y = -d * std::sin(bearing);
      run.frame(truth, testing::mastCamera(x, y, bearing));
      worst = std::max(worst, poseError(crate.shape, crate.pose, perception.world().object("crate").pose).xy);
    }
  }
  const auto moved = run.eventsOf(EventType::kMoved, "crate");
  EXPECT_TRUE(moved.empty()) << moved.size() << " moved, the first: " << moved.front().description;
  EXPECT_LT(worst, 0.05);
}

// namo_doorway: a crate of known size (0.9 x 0.9 x 0.6 m) pushed through a doorway, its estimate
// off where the push left it (5-25 cm), then driven round close by: beside it, the part of it the
// camera sees ends at the image's lower edge, not at a face. The known-size fit anchored the box
// on that cut, 0.9 m off the crate: no match for the track, a new crate there, gone two frames
// later (in CI: "moved", "gone", found again 0.6 m away; every change blocked the drive). Now the
// cut is no face (the space beyond it is not seen free) and the track's centre is kept within
// what the view allows: no new or gone object, and the estimate no farther off than it began.
TEST(SceneTest, APushedCrateEstimatedOffStaysOnItWhenDrivenRoundClose) {
  world::World prior("doorway");
  ASSERT_TRUE(prior.addRegion(testing::floorRegion()).ok());
  ASSERT_TRUE(prior.addObject(box("divider_south", 0.2, 3.4, 1.0, 5.1, 1.7, 0.0, 0.0, world::ObjectKind::kStatic)).ok());
  ASSERT_TRUE(prior.addObject(box("divider_north", 0.2, 3.4, 1.0, 5.1, 6.3, 0.0, 0.0, world::ObjectKind::kStatic)).ok());
  world::Object crate = box("crate", 0.9, 0.9, 0.6, 6.56, 4.0, 0.0);
  crate.mass = 40.0;
  ASSERT_TRUE(prior.addObject(crate).ok());
  // The drive round its north side: base x, y, yaw.
  std::vector<Eigen::Vector3d> poses;
  for (int k = 0; k <= 5; ++k) poses.emplace_back(5.5, 4.0, 0.2 * k);
  for (int k = 1; k <= 8; ++k) poses.emplace_back(5.5 + 0.07 * k, 4.0 + 0.12 * k, 1.0);
  for (int k = 0; k <= 5; ++k) poses.emplace_back(6.06, 4.96, 1.0 - 0.2 * k);
  for (int k = 1; k <= 20; ++k) poses.emplace_back(6.06 + 0.1 * k, 4.96, 0.0);  // 0.96 m off its axis
  for (int k = 1; k <= 6; ++k) poses.emplace_back(8.06 + 0.1 * k, 4.96 - 0.08 * k, -0.6);
  for (const Eigen::Vector2d& off : {Eigen::Vector2d(0.05, 0.0), Eigen::Vector2d(0.15, 0.05),
                                     Eigen::Vector2d(-0.15, 0.05), Eigen::Vector2d(0.25, 0.1),
                                     Eigen::Vector2d(0.0, -0.1)}) {
    SCOPED_TRACE("the crate " + std::to_string(off.x()) + ", " + std::to_string(off.y()) + " m off its estimate");
    world::World truth = prior;
    const Eigen::Isometry3d real(Eigen::Translation3d(6.56 + off.x(), 4.0 + off.y(), 0.3));
    ASSERT_TRUE(truth.setObjectPose("crate", real).ok());
    Perception perception(prior, PerceptionParams());
    Runner run(perception);
    double worst = 0.0;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      const Eigen::Vector3d& b = poses[k];
      run.frame(truth, testing::mastCamera(b.x(), b.y(), b.z()));
      const world::Object* o = perception.world().findObject("crate");
      ASSERT_NE(o, nullptr) << "frame " << k << ": the crate was declared gone";
      worst = std::max(worst, poseError(crate.shape, real, o->pose).xy);
    }
    EXPECT_LT(worst, off.norm() + 0.01) << "the estimate left the crate while driving round it";
    EXPECT_TRUE(run.eventsOf(EventType::kAdded).empty()) << run.eventsOf(EventType::kAdded).front().description;
    EXPECT_TRUE(run.eventsOf(EventType::kGone).empty());
  }
}

// A pushed chair (0.6 x 0.6 x 0.9 m, of known size) whose estimate lags 10 cm behind it, seen
// from the robot that backed off 0.6-1 m: its near face stands 10 cm inside the estimate. Points
// inside the estimate counted as explained by it, so the estimate stayed 10 cm short (namo_big_
// crossing: the next drive, planned past the chair's estimate, was refused, and the pushes from
// there rejected, 5 replans). A face is explained by the estimate's surface, not its inside: the
// estimate follows the chair.
TEST(SceneTest, ALaggingEstimateOfAPushedBoxFollowsItsSeenFace) {
  world::World prior("room");
  ASSERT_TRUE(prior.addRegion(testing::floorRegion()).ok());
  world::Object chair = box("chair", 0.6, 0.6, 0.9, 3.0, 0.0, 0.0);
  chair.mass = 50.0;
  ASSERT_TRUE(prior.addObject(chair).ok());
  world::World truth = prior;
  const Eigen::Isometry3d real(Eigen::Translation3d(3.1, 0.0, 0.45));
  ASSERT_TRUE(truth.setObjectPose("chair", real).ok());
  for (double gap : {0.6, 0.8, 1.0}) {
    SCOPED_TRACE("the robot's camera " + std::to_string(gap) + " m before the chair's near face");
    Perception perception(prior, PerceptionParams());
    Runner run(perception);
    for (int k = 0; k < 12; ++k) run.frame(truth, testing::mastCamera(real.translation().x() - 0.3 - gap, 0.0, 0.0));
    EXPECT_LT(poseError(chair.shape, real, perception.world().object("chair").pose).xy, 0.04);
    EXPECT_TRUE(run.eventsOf(EventType::kAdded).empty());
  }
}

TEST(SceneTest, GoneOnlyWhenItsPlaceIsVisibleAndUnoccluded) {
  world::World prior = tableWorld();
  world::Object target = box("target", 0.25, 0.25, 0.25, 3.0, -0.2, 0.0);
  ASSERT_TRUE(prior.addObject(target).ok());
  const auto cam = testing::mastCamera(0, 0, 0);

  {  // Hidden behind a large box: not detected, but not gone either.
    world::World truth = prior;
    ASSERT_TRUE(truth.addObject(box("blocker", 0.6, 0.8, 1.0, 2.2, -0.15, 0.0)).ok());
    ASSERT_EQ(testing::visiblePixels(truth, cam, {}, "target"), 0);
    Perception perception(prior, PerceptionParams());
    Runner run(perception);
    for (int k = 0; k < 4; ++k) run.frame(truth, cam);
    EXPECT_TRUE(run.eventsOf(EventType::kGone).empty());
    EXPECT_NE(perception.world().findObject("target"), nullptr);
    // Even when it really went away behind the blocker: its place is not seen, so not gone.
    ASSERT_TRUE(truth.removeObject("target").ok());
    for (int k = 0; k < 4; ++k) run.frame(truth, cam);
    EXPECT_TRUE(run.eventsOf(EventType::kGone).empty());
    EXPECT_NE(perception.world().findObject("target"), nullptr);
  }
  {  // Taken away while the robot looks elsewhere: not gone (not in view).
    world::World truth = prior;
    ASSERT_TRUE(truth.removeObject("target").ok());
    Perception perception(prior, PerceptionParams());
    Runner run(perception);
    for (int k = 0; k < 4; ++k) run.frame(truth, testing::mastCamera(0, 0, kPi));
    EXPECT_TRUE(run.eventsOf(EventType::kGone).empty());
    // Looking at its place: gone after gone_frames frames, and out of the world model.
    run.frame(truth, cam);
    EXPECT_TRUE(run.eventsOf(EventType::kGone).empty()) << "gone after a single frame";
    run.frame(truth, cam);
    const auto gone = run.eventsOf(EventType::kGone, "target");
    ASSERT_EQ(gone.size(), 1u);
    EXPECT_LT((gone[0].pose.translation() - target.pose.translation()).norm(), 1e-9);
    EXPECT_EQ(perception.world().findObject("target"), nullptr);
    EXPECT_EQ(perception.track("target")->state, TrackInfo::State::kGone);
  }
}

TEST(SceneTest, UnexplainedSpaceGoesToTheOccupancyMapAndIsClearedWhenSeenFree) {
  world::World truth = tableWorld();
  // A thin pole (below the object size threshold) and a long low wall (above the largest
  // object), neither in the prior.
  ASSERT_TRUE(truth.addObject(cylinder("pole", 0.01, 0.8, 1.7, -0.3, 0.0, world::ObjectKind::kStatic)).ok());
  ASSERT_TRUE(truth.addObject(box("long_wall", 2.0, 0.12, 0.5, 3.3, -0.5, 0.0, 0.0, world::ObjectKind::kStatic)).ok());
  const world::World prior = tableWorld();
  PerceptionParams params;
  params.clusters.max_size = 1.5;  // the 2 m wall is larger than any object
  Perception perception(prior, params);
  Runner run(perception);
  const auto cam = testing::mastCamera(0, 0, 0);
  for (int k = 0; k < 3; ++k) run.frame(truth, cam);
  EXPECT_EQ(perception.world().objectCount(), prior.objectCount()) << "neither is an object";
  const OccupancyMap& map = *perception.occupancy();
  auto occupiedNear = [&](const Eigen::Vector3d& p) {
    for (const auto& v : map.occupiedVoxels()) {
      if ((v - p).cwiseAbs().maxCoeff() <= 0.06) return true;
    }
    return false;
  };
  EXPECT_TRUE(occupiedNear({1.7, -0.3, 0.5}));
  EXPECT_TRUE(occupiedNear({1.7, -0.3, 0.2}));
  EXPECT_TRUE(occupiedNear({3.3, -0.44, 0.3}));  // the wall's face towards the sensor
  EXPECT_EQ(map.state({1.2, 0.3, 0.3}), CellState::kFree);  // seen through
  for (const auto& v : map.occupiedVoxels()) {
    const bool pole = (v.head<2>() - Eigen::Vector2d(1.7, -0.3)).norm() < 0.1;
    const bool wall = std::abs(v.y() + 0.5) < 0.12 && std::abs(v.x() - 3.3) < 1.1;
    EXPECT_TRUE(pole || wall) << "stray occupied voxel at " << v.transpose();
  }

  // The planner's collision scene reads the published map.
  collision::Scene scene(perception.world());
  ASSERT_TRUE(scene.setUnknownSpaceFromOctomapBinary(perception.occupancyBinary()).ok());
  const auto probe = world::Shape::box(0.1, 0.1, 0.1);
  const collision::Filter unknown{collision::kUnknownSpace, {}, {}};
  EXPECT_TRUE(scene.shapeInCollision(probe, Eigen::Isometry3d(Eigen::Translation3d(1.7, -0.3, 0.5)),
                                     unknown));
  EXPECT_FALSE(scene.shapeInCollision(probe, Eigen::Isometry3d(Eigen::Translation3d(1.2, 0.5, 0.5)),
                                      unknown));

  // The pole is removed: its voxels are cleared by the rays that now pass through.
  ASSERT_TRUE(truth.removeObject("pole").ok());
  for (int k = 0; k < 4; ++k) run.frame(truth, cam);
  EXPECT_FALSE(occupiedNear({1.7, -0.3, 0.5}));
  EXPECT_FALSE(occupiedNear({1.7, -0.3, 0.2}));
  EXPECT_TRUE(occupiedNear({3.3, -0.44, 0.3}));
}

}  // namespace
}  // namespace tamp::perception

namespace tamp::perception {
namespace {

// occluded_can's table as the robot sees it from its start (3 m away, facing along x), turning
// to near_table and driving there. The can stands behind a 5 x 7 cm box and a cup, all three
// within the size tolerance of each other. At the first view that split the box from the cup,
// the box's own points (noisy, 9.9 x 7.7 cm) exceeded its size by the sum over both axes, 5.6
// cm, and fitted the occluded can (3.3 cm): the can's track took the box's place, the cup's the
// can's, the box's the cup's, and the mission picked at the wrong place (thirteenth session's
// sweep; seed 1 here). Now every object stays where it stands, and no MOVED event moves one.
TEST(SceneTest, FarViewsOfThreeSmallObjectsSideBySideKeepEachOnItsOwnTrack) {
  auto sc = world::loadScenario(configDir() / "scenarios" / "occluded_can.yaml");
  ASSERT_TRUE(sc.ok()) << sc.error().toString();
  auto params = loadPerceptionParams(configDir() / "services" / "perception.yaml");
  ASSERT_TRUE(params.ok()) << params.error().toString();
  const world::World truth = sc->world;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    Perception perception(sc->plannerWorld(), *params);
    Runner run(perception);
    run.camera.seed = seed;
    const double x0 = -1.5, y0 = -1.0, x1 = 0.88, y1 = 0.0;
    const double yaw = std::atan2(y1 - y0, x1 - x0);
    for (int k = 0; k < 15; ++k) run.frame(truth, testing::mastCamera(x0, y0, 0.0));
    for (double a = 0.0; a <= yaw; a += 0.03) run.frame(truth, testing::mastCamera(x0, y0, a));
    for (double s = 0.0; s <= 1.0001; s += 0.05)
      run.frame(truth, testing::mastCamera(x0 + s * (x1 - x0), y0 + s * (y1 - y0), yaw));
    for (double a = yaw; a >= 0.0; a -= 0.1) run.frame(truth, testing::mastCamera(x1, y1, a));
    for (const char* id : {"can", "box", "cup"}) {
      const world::Object* o = perception.world().findObject(id);
      ASSERT_NE(o, nullptr) << id << ", seed " << seed;
      EXPECT_LT((o->pose.translation() - truth.object(id).pose.translation()).head<2>().norm(), 0.03)
          << id << ", seed " << seed;
    }
    for (const WorldEvent& e : run.eventsOf(EventType::kMoved))
      EXPECT_LT((e.pose.translation() - truth.object(e.object_id).pose.translation()).head<2>().norm(), 0.03)
          << "seed " << seed << ": " << e.description;
  }
}

// namo_moghaddam_07's start: walls fill most of the image, the floor is a fifth of the points,
// and three boxes stand 0.3 m apart on it before the robot. In one frame of 50, RANSAC missed the
// floor and took a plane tilted 4 degrees through a strip of it and the boxes; rejected, that
// strip left the plane search, and the rest of the floor joined the boxes into one detection of
// 1.7 x 1.9 m that no track explained: a mission got a "new static box" there that closed its way.
// Frames of the simulator's own camera, where the robot stands; no detection may be larger than
// the boxes, nor any object added.
TEST(SceneTest, TheFloorIsFoundInEveryFrameWhereWallsFillTheImage) {
  const std::filesystem::path scenario = configDir() / "scenarios" / "namo_moghaddam_07.yaml";
  auto sc = world::loadScenario(scenario);
  ASSERT_TRUE(sc.ok()) << sc.error().toString();
  auto params = loadPerceptionParams(configDir() / "services" / "perception.yaml");
  ASSERT_TRUE(params.ok()) << params.error().toString();
  auto sim_params = sim::loadSimParams(configDir() / "services" / "sim.yaml");
  ASSERT_TRUE(sim_params.ok()) << sim_params.error().toString();
  sim_params->scenario = scenario.string();
  auto setup = sim::loadSetup(*sim_params);
  ASSERT_TRUE(setup.ok()) << setup.error().toString();
  sim::Simulator simulator(setup->world, setup->robot, setup->initial, *sim_params);
  double largest = 0.0;  // the largest footprint diagonal of a movable object
  for (const auto& o : sc->world.objects()) {
    if (o.kind != world::ObjectKind::kMovable) continue;
    const Aabb b = o.shape.localAabb();
    largest = std::max(largest, (b.max - b.min).head<2>().norm());
  }
  Perception perception(sc->plannerWorld(), *params);
  int oversized = 0;
  std::vector<std::string> added;
  for (int k = 0; k < 150; ++k) {
    const PointCloudFrame f = simulator.captureCloud(kSecond * (k + 1));
    const RobotBody body = robotBodyAt(simulator.robot(), simulator.robotState().state, {}, f.stamp_ns);
    auto r = perception.processFrame(f, Termination(), &body);
    ASSERT_TRUE(r.ok()) << r.error().toString();
    for (const auto& d : r->detections) oversized += d.majorExtent() > largest ? 1 : 0;
    for (const auto& e : r->events)
      if (e.type == EventType::kAdded) added.push_back("frame " + std::to_string(k) + ": " + e.description);
  }
  EXPECT_EQ(oversized, 0) << "detections larger than any box (" << largest << " m)";
  EXPECT_TRUE(added.empty()) << added.size() << " added, the first: " << added.front();
}

// An object the planner does not know, standing 3 mm from a known one (closer than the 5 cm
// clustering tolerance): it is found as a new object, not taken for a fragment of the known one,
// and the known one stays where it is. (Adjacency alone never joined them; what joined the boxes
// of TheFloorIsFoundInEveryFrameWhereWallsFillTheImage was floor left between them.)
TEST(SceneTest, AnUnknownObjectAgainstAKnownOneIsFound) {
  for (const double size : {0.25, 0.4}) {
    world::World truth("touching");
    ASSERT_TRUE(truth.addRegion(testing::floorRegion()).ok());
    ASSERT_TRUE(truth.addObject(box("known", 0.6, 0.6, 0.5, 3.0, 0.0, 0.0)).ok());
    world::Object surprise = box("surprise", size, size, 0.3, 3.0, 0.3 + 0.003 + size / 2, 0.0);
    surprise.hidden = true;
    ASSERT_TRUE(truth.addObject(surprise).ok());
    Perception perception(truth.plannerView(), PerceptionParams());
    Runner run(perception);
    for (int k = 0; k < 4; ++k) run.frame(truth, testing::mastCamera(0.5, 0.0, 0.1));
    const auto added = run.eventsOf(EventType::kAdded);
    ASSERT_EQ(added.size(), 1u) << "size " << size;
    EXPECT_LT((added[0].pose.translation().head<2>() - surprise.pose.translation().head<2>()).norm(), 0.1)
        << "size " << size << ": " << added[0].description;
    EXPECT_LT((perception.world().object("known").pose.translation() - truth.object("known").pose.translation()).norm(), 0.03)
        << "size " << size;
  }
}

}  // namespace
}  // namespace tamp::perception
