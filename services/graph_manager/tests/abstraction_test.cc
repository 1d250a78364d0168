#include "tamp/graph_manager/abstraction.h"
#include "tamp/graph_manager/graph.h"

#include <algorithm>

#include <gtest/gtest.h>

#include "tamp/core/paths.h"
#include "tamp/world/scenario.h"

namespace tamp::graph_manager {
namespace {

bool has(const std::vector<std::string>& v, const std::string& a) { return std::find(v.begin(), v.end(), a) != v.end(); }

struct Fixture {
  world::Scenario sc;
  robot::RobotModel robot;
};

Fixture load(const std::string& name) {
  auto sc = world::loadScenario(configDir() / "scenarios" / (name + ".yaml"));
  EXPECT_TRUE(sc.ok()) << (sc ? "" : sc.error().toString());
  auto robot = robot::RobotModel::loadDescription(sc->robot.description);
  EXPECT_TRUE(robot.ok());
  return {*sc, *robot};
}

TEST(AbstractionTest, MatchesTheScenarioDerivedProblemAtTheStart) {
  auto f = load("occluded_can");
  Abstraction a(f.sc.plannerWorld(), f.robot);
  const auto atoms = a.dynamicAtoms(f.sc.plannerWorld(), f.sc.robot.start, "stow", "");
  auto expected = world::toPddlProblem(f.sc, f.robot);
  ASSERT_TRUE(expected.ok());
  std::vector<std::string> mine = a.staticAtoms();
  mine.insert(mine.end(), atoms.begin(), atoms.end());
  std::sort(mine.begin(), mine.end());
  // Same facts as the scenario's problem, which the tests already check against the hand-written one.
  for (const auto& x : expected->init) EXPECT_TRUE(has(mine, x)) << x;
  for (const auto& x : mine) EXPECT_TRUE(has(expected->init, x)) << x;
}

TEST(AbstractionTest, ACurrentBasePoseAwayFromEveryLocationBecomesALocation) {
  auto f = load("namo_corridor");
  Abstraction a(f.sc.plannerWorld(), f.robot);
  const Pose2D somewhere{2.5, 1.2, 0.3};
  const auto atoms = a.dynamicAtoms(f.sc.plannerWorld(), somewhere, "stow", "");
  EXPECT_TRUE(has(atoms, "(robot-at here)"));
  EXPECT_TRUE(has(a.objects(), "here - location"));
  EXPECT_TRUE(has(a.staticAtoms(), "(reaches here stow)"));
  // Within tolerance of a named location: that location.
  const auto at_start = a.dynamicAtoms(f.sc.plannerWorld(), Pose2D{1.51, 1.2, 0.0}, "stow", "");
  EXPECT_TRUE(has(at_start, "(robot-at start)"));
}

// A large floor region is "reached" from every base pose, the parcel on it only from near_box: a
// slot at the parcel's pose carries the object-level reach facts (the lazy refinement).
TEST(AbstractionTest, AnObjectOnALargeRegionRefinedToASlotIsReachedOnlyWhereTheArmReachesIt) {
  auto f = load("hall_transport");
  Abstraction a(f.sc.plannerWorld(), f.robot);
  const auto statics = a.staticAtoms();
  EXPECT_TRUE(has(statics, "(reaches near_box over_hall)"));
  EXPECT_TRUE(has(statics, "(reaches near_dock over_hall)")) << "the region-level fact the refinement corrects";
  const auto atoms = a.dynamicAtoms(f.sc.plannerWorld(), f.sc.robot.start, "stow", "");
  ASSERT_TRUE(has(atoms, "(on box hall)"));
  EXPECT_EQ(a.refinedSupports(atoms), atoms) << "no slot yet: nothing to refine";
  const std::string s = a.addSlot("box", "hall", f.sc.world.object("box").pose);
  EXPECT_FALSE(has(a.staticAtoms(), "(reaches near_dock " + Abstraction::armconfOver(s) + ")"));
  EXPECT_FALSE(has(a.staticAtoms(), "(reaches start " + Abstraction::armconfOver(s) + ")"));
  // The graph manager adds the stand a grasp proves (GraphManager::standBeside).
  if (!a.isReached(Abstraction::armconfOver(s))) a.addReach("near_box", Abstraction::armconfOver(s));
  EXPECT_TRUE(a.isReached(Abstraction::armconfOver(s)));
  EXPECT_TRUE(has(a.staticAtoms(), "(reaches near_box " + Abstraction::armconfOver(s) + ")"));
  const auto refined = a.refinedSupports(atoms);
  EXPECT_TRUE(has(refined, "(on box " + s + ")"));
  EXPECT_FALSE(has(refined, "(on box hall)"));
  EXPECT_EQ(refined.size(), atoms.size());
  // The parcel moved away from the slot: its region again.
  world::World moved = f.sc.plannerWorld();
  Eigen::Isometry3d pose = moved.object("box").pose;
  pose.translation().x() += 1.0;
  ASSERT_TRUE(moved.setObjectPose("box", pose).ok());
  a.setWorld(moved);
  EXPECT_EQ(a.refinedSupports(atoms), atoms);
  EXPECT_FALSE(a.isReached("over_nowhere"));
}

// The reach facts of new locations and slots are computed on two threads (abstraction.cc,
// reachAll): the same facts as world::reachesRegion asked pair by pair, reached and not, for a
// grid of stands round the box and slots beside it.
TEST(AbstractionTest, ReachFactsOfNewLocationsAndSlotsAreThoseOfTheSerialCheck) {
  auto f = load("namo_corridor");
  Abstraction a(f.sc.plannerWorld(), f.robot);
  const Eigen::Isometry3d box = f.sc.world.object("box").pose;
  std::vector<std::pair<std::string, Pose2D>> stands;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 4; ++j) {
      const Pose2D p{box.translation().x() - 1.0 + 0.25 * i, box.translation().y() - 0.6 + 0.3 * j, 0.2 * (i - j)};
      stands.emplace_back(a.locationFor(p, "stand", 0.0), p);
    }
  }
  std::vector<std::pair<std::string, world::Region>> slots;
  for (int k = 0; k < 4; ++k) {
    Eigen::Isometry3d pose = box;
    pose.translation() += Eigen::Vector3d(-0.3 + 0.2 * k, 0.15 * (k % 2), 0.0);
    const std::string s = a.addSlot("box", "box_floor", pose);
    const world::Region* r = a.region(s);
    ASSERT_NE(r, nullptr);
    slots.emplace_back(s, *r);
  }
  const std::vector<std::string> statics = a.staticAtoms();
  int reached = 0, not_reached = 0;
  for (const auto& [l, pose] : stands) {
    for (const auto& [s, region] : slots) {
      const bool expected = world::reachesRegion(f.robot, pose, region);
      EXPECT_EQ(has(statics, "(reaches " + l + " " + Abstraction::armconfOver(s) + ")"), expected) << l << " " << s;
      ++(expected ? reached : not_reached);
    }
    const world::Region& floor = *a.region("box_floor");
    EXPECT_EQ(has(statics, "(reaches " + l + " over_box_floor)"), world::reachesRegion(f.robot, pose, floor)) << l;
  }
  EXPECT_GT(reached, 0);
  EXPECT_GT(not_reached, 0);
}

TEST(AbstractionTest, ASlotIsARegionWithItsOwnConfigurationAndBindsTheObjectPose) {
  auto f = load("namo_corridor");
  Abstraction a(f.sc.plannerWorld(), f.robot);
  Eigen::Isometry3d pose = f.sc.world.object("box").pose;
  pose.translation() += Eigen::Vector3d(-0.4, 0.6, 0.0);
  const std::string s = a.addSlot("box", "free_patch", pose);
  EXPECT_EQ(a.addSlot("box", "free_patch", pose), s) << "the same pose is the same slot";
  EXPECT_TRUE(has(a.objects(), s + " - region"));
  EXPECT_TRUE(has(a.staticAtoms(), "(conf-over over_" + s + " " + s + ")"));
  const Binding b = a.bind({"(on box " + s + ")", "(robot-at start)", "(hand-empty)", "(arm-at stow)"});
  ASSERT_TRUE(b.object_poses.count("box"));
  EXPECT_NEAR((b.object_poses.at("box").translation() - pose.translation()).norm(), 0.0, 1e-12);
  EXPECT_EQ(b.location, "start");
  // An object standing on the slot's pose is on the slot.
  world::World w = f.sc.plannerWorld();
  ASSERT_TRUE(w.setObjectPose("box", pose).ok());
  EXPECT_TRUE(has(a.dynamicAtoms(w, f.sc.robot.start, "stow", ""), "(on box " + s + ")"));
}

// Two placements sampled for one object may lie closer than twice the slot tolerance: an object
// standing between them is on the nearer one, whichever was made last (namo_corridor_appearing:
// the box placed on the first slot was seen on the second, and the re-join moved it again).
TEST(AbstractionTest, AnObjectBetweenTwoOfItsSlotsIsOnTheNearerOne) {
  auto f = load("namo_corridor");
  Abstraction a(f.sc.plannerWorld(), f.robot);
  Eigen::Isometry3d first = f.sc.world.object("box").pose;
  first.translation() += Eigen::Vector3d(-0.4, 0.6, 0.0);
  Eigen::Isometry3d second = first;
  second.translation().x() += 0.08;
  const std::string s1 = a.addSlot("box", "free_patch", first);
  const std::string s2 = a.addSlot("box", "free_patch", second);
  ASSERT_NE(s1, s2);
  world::World w = f.sc.plannerWorld();
  for (double dx : {0.02, 0.06}) {
    Eigen::Isometry3d seen = first;
    seen.translation().x() += dx;
    ASSERT_TRUE(w.setObjectPose("box", seen).ok());
    const std::string expected = dx < 0.04 ? s1 : s2;
    const auto atoms = a.dynamicAtoms(w, f.sc.robot.start, "stow", "");
    EXPECT_TRUE(has(atoms, "(on box " + expected + ")")) << dx;
    EXPECT_EQ(a.slotAt("box", seen.translation().head<2>()), expected) << dx;
    EXPECT_EQ(a.slotAt("box", seen.translation().head<2>(), "box_floor"), "") << "not a slot of that region";
  }
}

// An object perceived where the scenario names no region (a box put down in the corridor) stands
// on a slot of its own: it can be picked, from where the arm reaches that slot.
TEST(AbstractionTest, AnObjectOnNoKnownRegionGetsASlotWhereItStands) {
  auto f = load("namo_corridor");
  Abstraction a(f.sc.plannerWorld(), f.robot);
  world::World w = f.sc.plannerWorld();
  world::Object box2 = w.object("box");
  box2.id = "box_2";
  box2.region.clear();
  box2.pose.translation().head<2>() = Eigen::Vector2d(6.1, 1.2);
  ASSERT_EQ(w.regionBelow(box2.pose.translation() - Eigen::Vector3d(0, 0, box2.shape.halfHeight())), nullptr);
  ASSERT_TRUE(w.addObject(box2).ok());
  const auto atoms = a.dynamicAtoms(w, f.sc.robot.start, "stow", "");
  const std::string s = a.slotAt("box_2", Eigen::Vector2d(6.1, 1.2));
  ASSERT_FALSE(s.empty());
  EXPECT_TRUE(has(atoms, "(on box_2 " + s + ")"));
  // Seen again a few millimetres off: the same slot, not a new one.
  const std::size_t slots = a.slotCount();
  ASSERT_TRUE(w.setObjectPose("box_2", Eigen::Isometry3d(Eigen::Translation3d(6.104, 1.198, box2.pose.translation().z()))).ok());
  EXPECT_TRUE(has(a.dynamicAtoms(w, f.sc.robot.start, "stow", ""), "(on box_2 " + s + ")"));
  EXPECT_EQ(a.slotCount(), slots);
  // A base pose beside it reaches the slot; the start, 4.6 m away, does not.
  const std::string near = a.locationFor(Pose2D{5.6, 1.2, 0.0}, "near_box_2");
  EXPECT_TRUE(has(a.staticAtoms(), "(reaches " + near + " over_" + s + ")"));
  EXPECT_FALSE(has(a.staticAtoms(), "(reaches start over_" + s + ")"));
  // Off the floor (in a hand the planner believes empty): no support, no slot.
  world::Object cup = box2;
  cup.id = "cup";
  cup.pose.translation() = Eigen::Vector3d(7.0, 1.2, 0.9);
  ASSERT_TRUE(w.addObject(cup).ok());
  const std::size_t before = a.slotCount();
  for (const auto& atom : a.dynamicAtoms(w, f.sc.robot.start, "stow", "")) EXPECT_EQ(atom.find("cup"), std::string::npos) << atom;
  EXPECT_EQ(a.slotCount(), before);
}

TEST(AbstractionTest, HeavyObjectsAreNotGraspable) {
  auto f = load("namo_corridor");
  AbstractionParams p;
  p.payload_cap_kg = 1.0;  // the box weighs 1.5 kg
  Abstraction a(f.sc.plannerWorld(), f.robot, p);
  EXPECT_FALSE(has(a.staticAtoms(), "(graspable box)"));
  Abstraction b(f.sc.plannerWorld(), f.robot);
  EXPECT_TRUE(has(b.staticAtoms(), "(graspable box)"));
}

TEST(AbstractionTest, ALocationIsReusedWithinItsToleranceOrWithinWhatTheCallerAsks) {
  auto f = load("namo_corridor");
  Abstraction a(f.sc.plannerWorld(), f.robot);
  const std::string stand = a.locationFor(Pose2D{4.62, 0.50, M_PI / 2}, "push_box");
  // 4 cm off: the same place for the robot (5 cm tolerance), another one to the centimetre.
  EXPECT_EQ(a.locationFor(Pose2D{4.62, 0.54, M_PI / 2}, "push_box"), stand);
  const std::string exact = a.locationFor(Pose2D{4.62, 0.54, M_PI / 2}, "push_box", 0.01);
  EXPECT_NE(exact, stand);
  ASSERT_TRUE(a.locationPose(exact).has_value());
  EXPECT_NEAR(a.locationPose(exact)->y, 0.54, 1e-12);
  // Asked again to the centimetre: the one just made (the nearest within 1 cm).
  EXPECT_EQ(a.locationFor(Pose2D{4.62, 0.545, M_PI / 2}, "push_box", 0.01), exact);
  EXPECT_EQ(a.findLocation(Pose2D{4.62, 0.515, M_PI / 2}, 0.01), "");
}

TEST(AbstractionTest, APushIsAStaticFactBetweenKnownSymbolsOnly) {
  auto f = load("namo_corridor");
  Abstraction a(f.sc.plannerWorld(), f.robot);
  Eigen::Isometry3d pose = f.sc.world.object("box").pose;
  pose.translation() += Eigen::Vector3d(0.0, 0.5, 0.0);
  const std::string s = a.addSlot("box", "box_floor", pose);
  const std::string from = a.locationFor(Pose2D{4.62, 0.5, M_PI / 2}, "push_box");
  const std::string to = a.locationFor(Pose2D{4.62, 1.0, M_PI / 2}, "pushed_box");
  a.addPush("box", "box_floor", from, to, s);
  EXPECT_TRUE(has(a.staticAtoms(), "(push-to box box_floor " + from + " " + to + " " + s + ")"));
  // A symbol that does not exist makes no fact.
  a.addPush("box", "box_floor", from, "nowhere", s);
  a.addPush("box", "no_region", from, to, s);
  a.addPush("box", "box_floor", from, to, "no_slot");
  int pushes = 0;
  for (const auto& x : a.staticAtoms()) pushes += x.rfind("(push-to ", 0) == 0;
  EXPECT_EQ(pushes, 1);
  // An object the world lost (perception no longer sees it) takes its pushes with it: a fact
  // about an undeclared object would make the whole problem invalid.
  world::World without = f.sc.plannerWorld();
  ASSERT_TRUE(without.removeObject("box").ok());
  a.setWorld(without);
  for (const auto& x : a.staticAtoms()) EXPECT_NE(x.rfind("(push-to ", 0), 0u) << x;
}

TEST(AbstractionTest, ADomainPushesOnlyWithThePushActionAndItsFact) {
  auto text = readTextFile(configDir() / "pddl" / "mobile_manipulation.pddl");
  ASSERT_TRUE(text.ok());
  EXPECT_TRUE(pushesIn(*text));
  EXPECT_TRUE(pushesIn("(:ACTION  Push\n :parameters ()) (PUSH-TO\t?o)"));
  EXPECT_FALSE(pushesIn("(:action pushy) (push-to ?o)"));
  EXPECT_FALSE(pushesIn("(:action push :parameters ())"));
}

TEST(AbstractionTest, AtomTokensNormalise) {
  EXPECT_EQ(atomTokens("( On  Box\tfree_patch )"), (std::vector<std::string>{"on", "box", "free_patch"}));
}

TEST(AbstractionTest, AnObservedArmConfigurationIsASymbolOfItsOwnThatNoFactReaches) {
  auto f = load("occluded_can");
  Abstraction a(f.sc.plannerWorld(), f.robot);
  const std::string c = a.addObservedArmconf("arm_observed");
  EXPECT_EQ(c, "arm_observed");
  EXPECT_EQ(a.addObservedArmconf("arm_observed"), "arm_observed_2");
  EXPECT_NE(a.addObservedArmconf("stow"), "stow");
  EXPECT_TRUE(has(a.objects(), "arm_observed - armconf"));
  const auto atoms = a.dynamicAtoms(f.sc.plannerWorld(), f.sc.robot.start, c, "");
  EXPECT_TRUE(has(atoms, "(arm-at arm_observed)"));
  for (const auto& s : a.staticAtoms()) EXPECT_EQ(s.find("arm_observed"), std::string::npos) << s;
  EXPECT_TRUE(a.regionOfArmconf(c).empty());
}

}  // namespace
}  // namespace tamp::graph_manager
