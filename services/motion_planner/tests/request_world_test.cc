// Requests in hypothetical worlds: object overrides (moved or removed objects, for one request
// only), a held object attached at a given grasp, and object prices from fitted time models.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "tamp/motion_planner/motion_planner.h"
#include "test_worlds.h"

namespace tamp::motion_planner {
namespace {

using testing::baseRequest;
using testing::blockingIds;
using testing::discClearance;
using testing::discTouches;

constexpr double kRadius = testing::kDiscRadius;

Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.translation() = Eigen::Vector3d(x, y, z);
  return p;
}

class RequestWorldTest : public ::testing::Test {
 protected:
  void SetUp() override { seedRandomness(42); }
};

TEST_F(RequestWorldTest, MovedBlockerFreesThePathForThatRequestOnly) {
  const world::World w = testing::corridorWorld(true);  // the crate fills the door
  MotionPlanner mp = testing::discPlanner(w, testing::untimedParams());
  const MotionRequest req = baseRequest({2, 2, 0}, {8, 2, 0});
  const MotionResult before = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(before.status, MotionStatus::kSolved) << before.reason;
  ASSERT_EQ(blockingIds(before.blocking), std::vector<std::string>{"crate"});

  // The crate at a sampled placement in the west room's corner.
  MotionRequest moved = req;
  moved.object_overrides = {{"crate", false, at(1.0, 3.3, 0.4)}};
  const MotionResult r = mp.plan(moved, Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_TRUE(r.blocking.empty()) << r.blocking.front().object_id;
  EXPECT_TRUE(r.stats.roadmap_reused);  // a moved movable keeps the static world's roadmap
  world::World hypothetical = w;
  ASSERT_TRUE(hypothetical.setObjectPose("crate", at(1.0, 3.3, 0.4)).ok());
  EXPECT_TRUE(discTouches(hypothetical, r.path, kRadius, 0.005).empty());  // independent check
  EXPECT_GT(discClearance(hypothetical, r.path, kRadius, 0.005), -1e-3);
  EXPECT_LT(r.cost_s, before.cost_s);  // the crate's effort is no longer paid

  // The planner's world is untouched: the next plain request meets the crate again.
  EXPECT_TRUE(mp.world().object("crate").pose.isApprox(w.object("crate").pose));
  const MotionResult after = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(after.status, MotionStatus::kSolved) << after.reason;
  EXPECT_EQ(blockingIds(after.blocking), std::vector<std::string>{"crate"});
  EXPECT_EQ(discTouches(w, after.path, kRadius, 0.005), std::vector<std::string>{"crate"});
  EXPECT_EQ(mp.roadmapCacheSize(), 1u);
}

TEST_F(RequestWorldTest, RemovedAndMovedIntoThePathAreReported) {
  const world::World w = testing::corridorWorld(true);
  MotionPlanner mp = testing::discPlanner(w, testing::untimedParams());
  MotionRequest req = baseRequest({2, 2, 0}, {8, 2, 0});
  req.object_overrides = {{"crate", true, {}}};
  const MotionResult removed = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(removed.status, MotionStatus::kSolved) << removed.reason;
  EXPECT_TRUE(removed.blocking.empty());

  // far_box moved right behind the door, the crate removed: whatever the path crosses is what an
  // independent check sees in that world.
  req.object_overrides = {{"crate", true, {}}, {"far_box", false, at(6.2, 2.0, 0.25)}};
  const MotionResult r = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  world::World hypothetical = w;
  ASSERT_TRUE(hypothetical.removeObject("crate").ok());
  ASSERT_TRUE(hypothetical.setObjectPose("far_box", at(6.2, 2.0, 0.25)).ok());
  EXPECT_EQ(discTouches(hypothetical, r.path, kRadius, 0.005), blockingIds(r.blocking));
  EXPECT_GT(discClearance(hypothetical, r.path, kRadius, 0.005, {}, /*movables=*/false), -1e-3);
  EXPECT_TRUE(mp.world().findObject("crate"));
}

TEST_F(RequestWorldTest, BadOverridesNameTheField) {
  const world::World w = testing::corridorWorld(true);
  MotionPlanner mp = testing::discPlanner(w);
  MotionRequest req = baseRequest({2, 2, 0}, {8, 2, 0});
  req.object_overrides = {{"crate", true, {}}, {"ghost", false, at(1, 1, 0)}};
  MotionResult r = mp.plan(req, Termination::after(5.0));
  EXPECT_EQ(r.status, MotionStatus::kInvalidRequest);
  EXPECT_NE(r.reason.find("object_overrides[1].object_id"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("ghost"), std::string::npos) << r.reason;

  req.object_overrides = {{"crate", false, at(std::numeric_limits<double>::quiet_NaN(), 1, 0)}};
  r = mp.plan(req, Termination::after(5.0));
  EXPECT_EQ(r.status, MotionStatus::kInvalidRequest);
  EXPECT_NE(r.reason.find("object_overrides[0].pose"), std::string::npos) << r.reason;

  req.object_overrides = {{"crate", true, {}}, {"crate", false, at(1, 1, 0.4)}};
  r = mp.plan(req, Termination::after(5.0));
  EXPECT_EQ(r.status, MotionStatus::kInvalidRequest);
  EXPECT_NE(r.reason.find("object_overrides[1].object_id"), std::string::npos) << r.reason;

  req.object_overrides = {{"far_box", true, {}}};
  req.held_object = "far_box";
  r = mp.plan(req, Termination::after(5.0));
  EXPECT_EQ(r.status, MotionStatus::kInvalidRequest);
  EXPECT_NE(r.reason.find("object_overrides[0].removed"), std::string::npos) << r.reason;
  EXPECT_TRUE(mp.world().findObject("crate"));  // nothing applied
}

TEST_F(RequestWorldTest, AddedObjectsAreInThatRequestsWorldOnly) {
  const world::World w = testing::corridorWorld(false);  // the door is free
  MotionPlanner mp = testing::discPlanner(w, testing::untimedParams());
  MotionRequest req = baseRequest({2, 2, 0}, {8, 2, 0});
  const MotionResult free = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(free.status, MotionStatus::kSolved) << free.reason;
  ASSERT_TRUE(free.blocking.empty());

  // What the caller knows and the planner's world lacks: a crate in the door. A lazy path
  // reports it as it reports the planner's own movables; an independent check agrees.
  const world::World with_crate = testing::corridorWorld(true);
  world::Object crate = with_crate.object("crate");
  crate.id = "told_crate";
  req.added_objects = {crate};
  const MotionResult r = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_EQ(blockingIds(r.blocking), std::vector<std::string>{"told_crate"});
  world::World hypothetical = w;
  ASSERT_TRUE(hypothetical.addObject(crate).ok());
  EXPECT_EQ(discTouches(hypothetical, r.path, kRadius, 0.005), blockingIds(r.blocking));

  // An override applies after the addition: the added crate moved out of the way.
  req.object_overrides = {{"told_crate", false, at(1.0, 3.3, 0.4)}};
  const MotionResult moved = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(moved.status, MotionStatus::kSolved) << moved.reason;
  EXPECT_TRUE(moved.blocking.empty()) << moved.blocking.front().object_id;

  // An id the planner's world has is refused, naming the field; nothing stays behind.
  req.object_overrides.clear();
  req.added_objects = {with_crate.object("crate"), w.object("far_box")};
  req.added_objects[0].id = "another";
  const MotionResult dup = mp.plan(req, Termination::after(5.0));
  EXPECT_EQ(dup.status, MotionStatus::kInvalidRequest);
  EXPECT_NE(dup.reason.find("added_objects[1].id"), std::string::npos) << dup.reason;
  EXPECT_EQ(mp.world().findObject("told_crate"), nullptr);
  EXPECT_EQ(mp.world().findObject("another"), nullptr);
  req.added_objects.clear();
  const MotionResult after = mp.plan(req, Termination::after(5.0));
  ASSERT_EQ(after.status, MotionStatus::kSolved) << after.reason;
  EXPECT_TRUE(after.blocking.empty());
}

/// The held box's centre along a base path, for a box held at `offset` (base frame), densified
/// every 1 cm in (x, y, yaw).
JointPath heldCentres(const JointPath& path, const Eigen::Vector2d& offset) {
  JointPath out;
  out.joint_names = {"base_x", "base_y"};
  const int ix = path.indexOf("base_x"), iy = path.indexOf("base_y"),
            it = path.indexOf("base_theta");
  auto centre = [&](const std::vector<double>& q) {
    const double c = std::cos(q[static_cast<std::size_t>(it)]),
                 s = std::sin(q[static_cast<std::size_t>(it)]);
    return std::vector<double>{q[static_cast<std::size_t>(ix)] + c * offset.x() - s * offset.y(),
                               q[static_cast<std::size_t>(iy)] + s * offset.x() + c * offset.y()};
  };
  for (std::size_t i = 0; i + 1 < path.waypoints.size(); ++i) {
    const auto& a = path.waypoints[i];
    const auto& b = path.waypoints[i + 1];
    double d = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) d = std::max(d, std::abs(b[k] - a[k]));
    const int n = std::max(1, static_cast<int>(std::ceil(d / 0.01)));
    for (int k = 0; k < n; ++k) {
      std::vector<double> q(a.size());
      for (std::size_t j = 0; j < a.size(); ++j) q[j] = a[j] + (b[j] - a[j]) * k / n;
      out.waypoints.push_back(centre(q));
    }
  }
  out.waypoints.push_back(centre(path.waypoints.back()));
  return out;
}

/// The corridor with a 0.3 m parcel far away in a corner: only a grasp decides where it is.
world::World parcelWorld() {
  world::World w = testing::corridorWorld(false);
  if (!w.addObject(testing::box("parcel", 9.5, 0.5, 0.3, 0.3, true, 0.3, 2.0)).ok()) throw std::logic_error("parcel");
  return w;
}

/// A holonomic base (it slides sideways through the door; a stop-and-turn base cannot).
MotionPlannerParams holonomicParams() {
  MotionPlannerParams p = testing::untimedParams();
  p.sampling.base_turn_in_place = false;
  return p;
}

TEST_F(RequestWorldTest, HeldObjectIsAttachedAtTheGivenGrasp) {
  world::World w = parcelWorld();
  MotionPlanner mp = testing::discPlanner(w, holonomicParams());
  MotionRequest req = baseRequest({2, 2, 0}, {8, 2, 0});
  req.held_object = "parcel";
  // Beside the robot: robot and parcel are 1.05 m wide across its heading, wider than the 1 m
  // door, so the robot must turn to pass it.
  const Eigen::Vector2d offset(0.0, 0.6);
  req.held_grasp = HeldGrasp{"", at(offset.x(), offset.y(), 0.0)};
  const MotionResult r = mp.plan(req, Termination::after(10.0));
  ASSERT_EQ(r.status, MotionStatus::kSolved) << r.reason;
  EXPECT_TRUE(blockingIds(r.blocking).empty());  // the held parcel never blocks itself
  // The parcel's inscribed disc stays clear of every wall along the path (independent check).
  EXPECT_GT(discClearance(w, heldCentres(r.path, offset), 0.15, 0.005, {"parcel"}, false), -1e-3);

  // The grasp, not the parcel's world pose, keys the roadmap: the parcel moving (as it does with
  // the robot) keeps the roadmap.
  ASSERT_TRUE(w.setObjectPose("parcel", at(9.5, 3.5, 0.15)).ok());
  mp.setWorld(w);
  const MotionResult again = mp.plan(req, Termination::after(10.0));
  ASSERT_EQ(again.status, MotionStatus::kSolved) << again.reason;
  EXPECT_TRUE(again.stats.roadmap_reused);

  // A grasp that puts the parcel into the south wall at the start.
  MotionRequest wall = baseRequest({2, 0.5, 0}, {8, 2, 0});
  wall.held_object = "parcel";
  wall.held_grasp = HeldGrasp{"", at(0.0, -0.5, 0.0)};
  const MotionResult hit = mp.plan(wall, Termination::after(5.0));
  EXPECT_EQ(hit.status, MotionStatus::kStartInCollision) << hit.reason;
  EXPECT_EQ(hit.colliding_object, "wall_south");

  // Misuse names the field.
  MotionRequest bad = req;
  bad.held_grasp->link = "no_such_link";
  EXPECT_EQ(mp.plan(bad).status, MotionStatus::kInvalidRequest);
  EXPECT_NE(mp.plan(bad).reason.find("held_grasp.link"), std::string::npos);
  bad = req;
  bad.held_object.clear();
  EXPECT_NE(mp.plan(bad).reason.find("held_grasp"), std::string::npos);
}

TEST_F(RequestWorldTest, HeldPaddingGrowsTheHeldObjectForThatRequestOnly) {
  const world::World w = parcelWorld();
  const MotionPlannerParams p = holonomicParams();
  MotionPlanner mp = testing::discPlanner(w, p);
  // The parcel held 0.5 m to the robot's right: at y = 0.7 its south face is 5 cm off the wall.
  const Eigen::Vector2d offset(0.0, -0.5);
  MotionRequest req = baseRequest({2, 0.7, 0}, {8, 2, 0});
  req.held_object = "parcel";
  req.held_grasp = HeldGrasp{"", at(offset.x(), offset.y(), 0.0)};
  req.mode = MotionMode::kFull;
  const MotionResult plain = mp.plan(req, Termination::after(10.0));
  ASSERT_EQ(plain.status, MotionStatus::kSolved) << plain.reason;

  // Grown by 8 cm it touches the wall already at the start: the path leaves the wall first by a
  // short straight motion (checked without the margin), then keeps the margin. Without an escape
  // distance, the start is in collision.
  MotionRequest padded = req;
  padded.held_padding_m = 0.08;
  const MotionResult out = mp.plan(padded, Termination::after(10.0));
  ASSERT_EQ(out.status, MotionStatus::kSolved) << out.reason;
  ASSERT_GE(out.path.waypoints.size(), 3u);
  EXPECT_NEAR(out.path.waypoints[0][1], 0.7, 1e-9);
  EXPECT_GT(out.path.waypoints[1][1], 0.7 + 0.02) << "away from the wall first";
  JointPath after_escape = out.path;
  after_escape.waypoints.erase(after_escape.waypoints.begin());
  EXPECT_GT(discClearance(w, heldCentres(after_escape, offset), 0.15 + 0.08, 0.005, {"parcel"}, false), -1e-3);
  MotionPlannerParams stuck_params = p;
  stuck_params.sampling.start_escape_distance = 0.0;
  MotionPlanner stuck = testing::discPlanner(w, stuck_params);
  const MotionResult hit = stuck.plan(padded, Termination::after(5.0));
  EXPECT_EQ(hit.status, MotionStatus::kStartInCollision) << hit.reason;
  EXPECT_EQ(hit.colliding_object, "wall_south");

  // Grown by 4 cm: solved, and the parcel's inscribed disc keeps the margin off every wall
  // (an independent check on the path), where the plain request need not.
  padded.held_padding_m = 0.04;
  const MotionResult wide = mp.plan(padded, Termination::after(10.0));
  ASSERT_EQ(wide.status, MotionStatus::kSolved) << wide.reason;
  EXPECT_GT(discClearance(w, heldCentres(wide.path, offset), 0.15 + 0.04, 0.005, {"parcel"}, false), -1e-3);

  // The margin was for that request only: the plain request is solved again from the same start.
  EXPECT_EQ(mp.plan(req, Termination::after(10.0)).status, MotionStatus::kSolved);

  // Misuse names the field.
  for (double bad : {-0.01, 0.3, std::numeric_limits<double>::quiet_NaN()}) {
    MotionRequest r = padded;
    r.held_padding_m = bad;
    const MotionResult refused = mp.plan(r);
    EXPECT_EQ(refused.status, MotionStatus::kInvalidRequest) << bad;
    EXPECT_NE(refused.reason.find("held_padding_m"), std::string::npos) << refused.reason;
  }
  MotionRequest none = baseRequest({2, 2, 0}, {8, 2, 0});
  none.held_padding_m = 0.05;
  EXPECT_NE(mp.plan(none).reason.find("held_padding_m: given without a held object"), std::string::npos);
}

TEST(ObjectEffortTest, FittedModelsPriceObjects) {
  const CostParams cost;
  const world::Object crate = testing::box("crate", 0, 0, 0.4, 0.4, true, 0.5, 8.0);
  auto same = fittedObjectEffort(cost, {});
  ASSERT_TRUE(same.ok());
  EXPECT_DOUBLE_EQ((*same)(crate), defaultObjectEffort(crate, cost));

  // Slower gripper actions (pick and place) cost more; the difference is what was added.
  auto slow = fittedObjectEffort(cost, {{ActionKind::kPick, {"gripper_time"}, {9.0}},
                                        {ActionKind::kPlace, {"gripper_time"}, {9.0}}});
  ASSERT_TRUE(slow.ok()) << slow.error().toString();
  const double base = defaultObjectEffort(crate, cost);
  EXPECT_GT((*slow)(crate), base + 1.0);
  auto slow2 = fittedObjectEffort(cost, {{ActionKind::kPick, {"gripper_time"}, {10.0}},
                                         {ActionKind::kPlace, {"gripper_time"}, {10.0}}});
  ASSERT_TRUE(slow2.ok());
  EXPECT_NEAR((*slow2)(crate) - (*slow)(crate), 2.0, 1e-9);  // gripper time adds linearly

  auto bad = fittedObjectEffort(cost, {{ActionKind::kPick, {"warp_speed"}, {1.0}}});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("models[0].names[0]"), std::string::npos)
      << bad.error().message;
  bad = fittedObjectEffort(cost, {{ActionKind::kPlace, {"gripper_time"}, {-1.0}}});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("models[0].values[0]"), std::string::npos)
      << bad.error().message;
}

}  // namespace
}  // namespace tamp::motion_planner
