#include "tamp/world/scenario.h"

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>

#include <gtest/gtest.h>

#include "tamp/collision/scene.h"
#include "tamp/core/paths.h"

namespace tamp::world {
namespace {

namespace fs = std::filesystem;

fs::path scenarioDir() { return fs::path(TAMP_SOURCE_DIR) / "config" / "scenarios"; }

const robot::RobotModel& robotModel() {
  static const robot::RobotModel m = robot::RobotModel::loadDefault().value();
  return m;
}

Scenario load(const std::string& name) {
  auto r = loadScenario(scenarioDir() / (name + ".yaml"));
  if (!r) throw std::runtime_error(r.error().toString());
  return std::move(r).value();
}

std::vector<std::string> shippedScenarios() {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(scenarioDir())) {
    if (e.path().extension() == ".yaml") out.push_back(e.path().stem().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// ---- a minimal PDDL problem reader, independent of the generator -------------------------------

struct ProblemFacts {
  std::set<std::pair<std::string, std::string>> objects;  // (name, type)
  std::set<std::string> init, goal;
};

std::string section(const std::string& text, const std::string& key) {
  const auto start = text.find("(" + key);
  if (start == std::string::npos) return "";
  int depth = 0;
  for (size_t i = start; i < text.size(); ++i) {
    if (text[i] == '(') ++depth;
    if (text[i] == ')' && --depth == 0)
      return text.substr(start + key.size() + 1, i - start - key.size() - 1);
  }
  return "";
}

std::string stripComments(const std::string& text) {
  std::string out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out += line.substr(0, line.find(';')) + "\n";
  return out;
}

std::set<std::string> atoms(const std::string& s) {
  std::set<std::string> out;
  static const std::regex atom(R"(\(([a-z-]+)((?:\s+[a-z_0-9-]+)*)\s*\))");
  for (auto it = std::sregex_iterator(s.begin(), s.end(), atom); it != std::sregex_iterator();
       ++it) {
    std::string args = (*it)[2].str();
    std::istringstream in(args);
    std::string norm = "(" + (*it)[1].str();
    for (std::string a; in >> a;) norm += " " + a;
    norm += ")";
    if ((*it)[1].str() != "and" && (*it)[1].str() != "total-cost") out.insert(norm);
  }
  return out;
}

ProblemFacts readProblem(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = stripComments(ss.str());
  ProblemFacts f;
  std::istringstream objs(section(text, ":objects"));
  std::vector<std::string> pending;
  for (std::string t; objs >> t;) {
    if (t == "-") {
      std::string type;
      objs >> type;
      for (const auto& n : pending) f.objects.insert({n, type});
      pending.clear();
    } else {
      pending.push_back(t);
    }
  }
  f.init = atoms(section(text, ":init"));
  f.goal = atoms(section(text, ":goal"));
  return f;
}

// ---- shipped scenarios
// ---------------------------------------------------------------------------

TEST(ScenarioTest, EveryShippedScenarioLoadsCleanly) {
  const auto names = shippedScenarios();
  EXPECT_GE(names.size(), 6u);
  for (const auto& n : names) {
    auto r = loadScenario(scenarioDir() / (n + ".yaml"));
    ASSERT_TRUE(r.ok()) << n << ": " << r.error().toString();
    EXPECT_EQ(r->name, n) << "scenario name must match its file name";
    EXPECT_TRUE(fs::exists(r->domain)) << n;
    EXPECT_FALSE(r->goal.empty()) << n;
    for (const auto& w : r->warnings) ADD_FAILURE() << n << ": " << w;
    // The PDDL problem derives without error.
    auto p = toPddlProblem(*r, robotModel());
    ASSERT_TRUE(p.ok()) << n << ": " << p.error().toString();
  }
}

TEST(ScenarioTest, RobotIsFreeAtEveryLocation) {
  for (const auto& n : shippedScenarios()) {
    const Scenario sc = load(n);
    collision::Scene scene(sc.world);  // the truth, hidden objects included
    scene.setRobot(robotModel().collisionGeometry());
    ASSERT_TRUE(scene.attachHeld());  // a held object moves with the gripper
    std::vector<Eigen::Isometry3d> poses;
    for (const auto& l : sc.world.locations()) {
      robot::RobotState s = robotModel().defaultState(l.pose);
      robotModel().linkPoses(s, poses);
      scene.setLinkPoses(poses);
      const auto hits = scene.robotCollisions();
      EXPECT_TRUE(hits.empty()) << n << " at " << l.id << " hits "
                                << (hits.empty() ? "" : hits.front());
    }
  }
}

TEST(ScenarioTest, GeneratedProblemsMatchTheHandWrittenOnes) {
  for (const std::string n : {"occluded_can", "holding_start", "namo_corridor"}) {
    const Scenario sc = load(n);
    ASSERT_EQ(sc.problem, fs::path(TAMP_SOURCE_DIR) / "config/pddl/problems" / (n + ".pddl")) << n;
    const ProblemFacts want = readProblem(sc.problem);
    auto got = toPddlProblem(sc, robotModel());
    ASSERT_TRUE(got.ok()) << got.error().toString();
    const std::set<std::pair<std::string, std::string>> objs(got->objects.begin(),
                                                             got->objects.end());
    EXPECT_EQ(objs, want.objects) << n;
    EXPECT_EQ(std::set<std::string>(got->init.begin(), got->init.end()), want.init) << n;
    EXPECT_EQ(std::set<std::string>(got->goal.begin(), got->goal.end()), want.goal) << n;
    // The text form reads back to the same facts.
    const fs::path tmp = fs::temp_directory_path() / ("tamp_scenario_test_" + n + ".pddl");
    std::ofstream(tmp) << got->text();
    const ProblemFacts back = readProblem(tmp);
    EXPECT_EQ(back.init, want.init) << got->text();
    EXPECT_EQ(back.objects, want.objects) << got->text();
  }
}

TEST(ScenarioTest, OccludedCanIsKinematicallyFeasible) {
  const Scenario sc = load("occluded_can");
  const Object& can = sc.world.object("can");
  EXPECT_NEAR(can.pose.translation().z(), 0.75 + 0.06, 1e-12);  // resting on the table top
  // From near_table, a top-down grasp of the can (tool 2 cm below its top).
  const Pose2D base = sc.world.findLocation("near_table")->pose;
  Eigen::Isometry3d target = Eigen::Isometry3d::Identity();
  target.translation() = can.pose.translation() + Eigen::Vector3d(0, 0, 0.04);
  target.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const auto ik = robotModel().inverseKinematics(base.toIsometry().inverse() * target,
                                                 robotModel().defaultState().arm);
  EXPECT_TRUE(ik.ok()) << toString(ik.status);
  // And the counter from near_counter.
  EXPECT_TRUE(reachesRegion(robotModel(), sc.world.findLocation("near_counter")->pose,
                            *sc.world.findRegion("counter")));
  EXPECT_FALSE(reachesRegion(robotModel(), sc.world.findLocation("start")->pose,
                             *sc.world.findRegion("table")));
}

TEST(ScenarioTest, HoldingStartPutsTheCupInTheGripper) {
  const Scenario sc = load("holding_start");
  ASSERT_TRUE(sc.world.held().has_value());
  EXPECT_EQ(sc.world.held()->object_id, "cup");
  EXPECT_EQ(sc.world.held()->link, "gripper_tcp");
  const Eigen::Isometry3d tool = robotModel().toolPoseInWorld(sc.startState());
  const Eigen::Vector3d expect = tool * Eigen::Vector3d(0, 0, 0.03);
  EXPECT_LT((sc.world.object("cup").pose.translation() - expect).norm(), 1e-12);
  EXPECT_TRUE(sc.world.object("cup").region.empty());
  EXPECT_EQ(sc.robot.arm_configuration, "carry");  // stow with a cup in hand is a self-collision
  EXPECT_DOUBLE_EQ(sc.robot.gripper, 0.04);
}

TEST(ScenarioTest, HiddenCrateBlocksTheStraightPath) {
  const Scenario sc = load("namo_room_hidden");
  EXPECT_EQ(sc.world.hiddenCount(), 1u);
  const World planner = sc.plannerWorld();
  EXPECT_EQ(planner.findObject("crate"), nullptr);
  collision::Scene seen(planner), truth(sc.world);
  for (auto* s : {&seen, &truth}) s->setRobot(robotModel().collisionGeometry());
  const Pose2D a = sc.world.findLocation("start")->pose, b = sc.world.findLocation("goal")->pose;
  const double heading = std::atan2(b.y - a.y, b.x - a.x);
  std::set<std::string> hit_seen, hit_truth;
  std::vector<Eigen::Isometry3d> poses;
  for (int i = 0; i <= 200; ++i) {
    const double t = i / 200.0;
    const Pose2D p{a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), heading};
    robotModel().linkPoses(robotModel().defaultState(p), poses);
    for (auto* s : {&seen, &truth}) s->setLinkPoses(poses);
    for (const auto& id : seen.robotCollisions()) hit_seen.insert(id);
    for (const auto& id : truth.robotCollisions()) hit_truth.insert(id);
  }
  EXPECT_TRUE(hit_seen.empty()) << *hit_seen.begin();
  EXPECT_EQ(hit_truth, std::set<std::string>{"crate"});
}

TEST(ScenarioTest, CorridorIsBlockedByTheBox) {
  const Scenario sc = load("namo_corridor");
  collision::Scene scene(sc.world);
  scene.setRobot(robotModel().collisionGeometry());
  std::vector<Eigen::Isometry3d> poses;
  // Driving straight along the corridor axis (y = 1.2) hits the box and nothing else.
  std::set<std::string> hits;
  for (double x = 3.0; x <= 7.0; x += 0.05) {
    robotModel().linkPoses(robotModel().defaultState({x, 1.2, 0.0}), poses);
    scene.setLinkPoses(poses);
    for (const auto& id : scene.robotCollisions()) hits.insert(id);
  }
  EXPECT_EQ(hits, std::set<std::string>{"box"});
  // Without the box the corridor is passable; the detour opening is at y in [18.0, 20.8].
  World w = sc.world;
  ASSERT_TRUE(w.removeObject("box"));
  collision::Scene empty(w);
  empty.setRobot(robotModel().collisionGeometry());
  for (double x = 3.0; x <= 7.0; x += 0.05) {
    robotModel().linkPoses(robotModel().defaultState({x, 1.2, 0.0}), poses);
    empty.setLinkPoses(poses);
    EXPECT_FALSE(empty.robotInCollision()) << "x = " << x;
    robotModel().linkPoses(robotModel().defaultState({x, 18.9, 0.0}), poses);
    empty.setLinkPoses(poses);
    EXPECT_FALSE(empty.robotInCollision()) << "detour x = " << x;
  }
  EXPECT_LT(sc.world.object("box").mass, 2.0);
}

TEST(ScenarioTest, FaultsAreParsed) {
  const Scenario sc = load("holding_start_faults");
  ASSERT_EQ(sc.faults.size(), 3u);
  EXPECT_EQ(sc.faults[0].kind, FaultKind::kDropHeld);
  EXPECT_DOUBLE_EQ(*sc.faults[0].at_time, 2.0);
  EXPECT_EQ(sc.faults[1].kind, FaultKind::kActionFails);
  EXPECT_EQ(*sc.faults[1].at_step, 2);
  EXPECT_EQ(sc.faults[1].action, "pick");
  EXPECT_EQ(sc.faults[2].kind, FaultKind::kObjectAppears);
  ASSERT_TRUE(sc.faults[2].object.has_value());
  EXPECT_EQ(sc.faults[2].object->id, "parcel");
  EXPECT_NEAR(sc.faults[2].object->pose.translation().z(), 0.75 + 0.05, 1e-12);
  EXPECT_EQ(sc.world.findObject("parcel"), nullptr);  // not in the world until it appears
  EXPECT_EQ(sc.sim.seed, 3u);
}

TEST(ScenarioTest, NamoScenarios) {
  const Scenario basic = load("namo_basic");
  ASSERT_TRUE(basic.namo.has_value());
  EXPECT_NEAR(basic.namo->robot_radius, 0.40, 1e-9);
  EXPECT_EQ(basic.goal.base_location, "goal_01");
  EXPECT_NE(basic.world.findObject("movable_box"), nullptr);
  const Scenario m = load("namo_moghaddam_07");
  EXPECT_NEAR(m.namo->robot_radius, 0.5 / std::sqrt(2.0), 1e-9);
  // A NAMO world file works as a scenario on its own.
  auto direct =
      loadScenario(fs::path(TAMP_BENCHMARKS_DIR) /
                   "namo/s-namo_cases/02_basic_with_opening/02_basic_with_opening.json");
  ASSERT_TRUE(direct.ok()) << direct.error().toString();
  EXPECT_EQ(direct->name, "namo_02_basic_with_opening");
  EXPECT_NEAR(direct->namo->robot_radius, robotModel().baseRadius(), 1e-9);
  EXPECT_TRUE(direct->goal.base.has_value());
}

TEST(ScenarioTest, BenchmarkDataIsInTheRepositoryAndNoOtherVariableExpands) {
  // The NAMO worlds ship in tests/data/benchmarks; nothing beside the clone is read.
  EXPECT_EQ(fs::weakly_canonical(benchmarksDir()),
            fs::weakly_canonical(fs::path(TAMP_SOURCE_DIR) / "tests/data/benchmarks"));
  auto text = readTextFile(scenarioDir() / "namo_basic.yaml");
  ASSERT_TRUE(text.ok());
  const std::string yaml = *text;
  const auto at = yaml.find("${TAMP_BENCHMARKS_DIR}");
  ASSERT_NE(at, std::string::npos);
  for (const std::string var : {"${TAMP_SHARED_DIR}/benchmarks", "${HOME}"}) {
    std::string other = yaml;
    other.replace(at, std::string("${TAMP_BENCHMARKS_DIR}").size(), var);
    auto bad = parseScenario(other, (scenarioDir() / "other.yaml").string());
    ASSERT_FALSE(bad.ok()) << var;
    EXPECT_NE(bad.error().toString().find("unknown variable in path '" + var), std::string::npos)
        << bad.error().toString();
  }
}

// ---- broken scenarios: the exact error text
// ------------------------------------------------------

const std::string kFile = (scenarioDir() / "inline.yaml").string();

std::string errorOf(const std::string& yaml) {
  auto r = parseScenario(yaml, kFile);
  if (r.ok()) return "(loaded)";
  return r.error().toString();
}

const char* kMinimal = R"yaml(name: mini
robot: {start: start}
world:
  regions: [{id: table, kind: table, rect: [1, -0.5, 2, 0.5], height: 0.75}]
  locations: [{id: start, pose: [-1, 0, 0]}]
  objects:
    - {id: can, kind: movable, shape: {type: cylinder, radius: 0.03, height: 0.12}, on: table, at: [1.5, 0], mass: 0.3, graspable: true}
goal: {pddl: ["(holding can)"]}
)yaml";

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto pos = s.find(from);
  if (pos == std::string::npos) throw std::logic_error("no '" + from + "' in the template");
  return s.replace(pos, from.size(), to);
}

// ---- graspability: the robot's payload and gripper opening (docs/scenarios.md)

/// kMinimal with the can's entry replaced by `object` (one line of the objects list).
std::string withObject(const std::string& object) {
  return replaced(kMinimal,
                  "{id: can, kind: movable, shape: {type: cylinder, radius: 0.03, height: 0.12}, "
                  "on: table, at: [1.5, 0], mass: 0.3, graspable: true}",
                  object);
}

bool graspableIn(const std::string& yaml, const std::string& id) {
  auto r = parseScenario(yaml, kFile);
  EXPECT_TRUE(r.ok()) << r.error().toString();
  return r.ok() && r->world.object(id).graspable;
}

TEST(ScenarioGraspabilityTest, WithoutTheFlagMovableWithinPayloadAndGripperOpening) {
  ASSERT_DOUBLE_EQ(robotModel().payload(), 25.0);
  ASSERT_DOUBLE_EQ(robotModel().maxGraspWidth(), 0.08);
  const std::string cyl = "{id: can, kind: movable, shape: {type: cylinder, radius: 0.03, height: "
                          "0.12}, on: table, at: [1.5, 0], mass: ";
  EXPECT_TRUE(graspableIn(withObject(cyl + "0.3}"), "can"));
  EXPECT_TRUE(graspableIn(withObject(cyl + "25}"), "can"));    // at the payload
  EXPECT_FALSE(graspableIn(withObject(cyl + "25.5}"), "can"));  // above it
  // Width: the narrowest horizontal extent against the 0.08 m opening.
  const std::string box = "{id: can, kind: movable, on: table, at: [1.5, 0], mass: 1, shape: ";
  EXPECT_TRUE(graspableIn(withObject(box + "{type: box, size: [0.08, 0.5, 0.1]}}"), "can"));
  EXPECT_TRUE(graspableIn(withObject(box + "{type: box, size: [0.5, 0.07, 0.1]}}"), "can"));
  EXPECT_FALSE(graspableIn(withObject(box + "{type: box, size: [0.09, 0.5, 0.1]}}"), "can"));
  EXPECT_FALSE(graspableIn(withObject(box + "{type: cylinder, radius: 0.045, height: 0.1}}"), "can"));
  EXPECT_TRUE(graspableIn(withObject(box + "{type: sphere, radius: 0.035}}"), "can"));
  // A prism's minimum width: a thin diagonal bar (0.05 m wide, 0.4 m long) fits, an L does not.
  EXPECT_TRUE(graspableIn(
      withObject(box + "{type: prism, height: 0.1, polygon: [[0, 0], [0.3, 0.3], [0.265, 0.335], "
                       "[-0.035, 0.035]]}}"),
      "can"));
  EXPECT_FALSE(graspableIn(
      withObject(box + "{type: prism, height: 0.1, polygon: [[0, 0], [0.3, 0], [0.3, 0.05], "
                       "[0.05, 0.05], [0.05, 0.3], [0, 0.3]]}}"),
      "can"));
  // Static objects never are (and the goal must not hold one: use a base goal here).
  const std::string stat = replaced(
      withObject("{id: can, kind: static, shape: {type: box, size: [0.05, 0.05, 0.1]}, on: table, "
                 "at: [1.5, 0]}"),
      "goal: {pddl: [\"(holding can)\"]}", "goal: {base: start}");
  EXPECT_FALSE(graspableIn(stat, "can"));
}

TEST(ScenarioGraspabilityTest, TheFlagMayForbidButNeverAllowAboveThePayload) {
  const std::string wide = "{id: can, kind: movable, shape: {type: box, size: [0.5, 0.5, 0.5]}, "
                           "on: table, at: [1.5, 0], mass: ";
  // false forbids a grasp that the rule would allow.
  EXPECT_FALSE(graspableIn(
      replaced(withObject("{id: can, kind: movable, shape: {type: cylinder, radius: 0.03, height: "
                          "0.12}, on: table, at: [1.5, 0], mass: 0.3, graspable: false}"),
               "goal: {pddl: [\"(holding can)\"]}", "goal: {base: start}"),
      "can"));
  // true asserts one the gripper model cannot judge (furniture moved whole), within the payload.
  EXPECT_TRUE(graspableIn(withObject(wide + "20, graspable: true}"), "can"));
  // true above the payload: an error naming file, line, column and field.
  EXPECT_EQ(errorOf(withObject(wide + "30, graspable: true}")),
            kFile + ":7:121: field 'world.objects[0].graspable': 'can' weighs 30 kg, more than the "
                    "robot's payload of 25 kg (" +
                (fs::path(TAMP_SOURCE_DIR) / "config/robots/mobile_manipulator.yaml").string() +
                "); a scenario may forbid a grasp, never allow one above the payload");
  // ... also for hidden objects and objects that appear in a fault.
  const std::string hidden = replaced(
      kMinimal, "goal:",
      "  hidden_objects:\n    - {id: crate, kind: movable, shape: {type: box, size: [0.5, 0.5, "
      "0.5]}, on: table, at: [1.2, 0], mass: 40, graspable: true}\ngoal:");
  EXPECT_NE(errorOf(hidden).find(
                "field 'world.hidden_objects[0].graspable': 'crate' weighs 40 kg, more than"),
            std::string::npos)
      << errorOf(hidden);
  const std::string fault =
      std::string(kMinimal) +
      "faults:\n  - type: object_appears\n    at_time: 1\n    object: {id: crate, kind: "
      "movable, shape: {type: box, size: [0.5, 0.5, 0.5]}, on: table, at: [1.2, 0], mass: 40, "
      "graspable: true}\n";
  EXPECT_NE(errorOf(fault).find(
                "field 'faults[0].object.graspable': 'crate' weighs 40 kg, more than"),
            std::string::npos)
      << errorOf(fault);
}

TEST(ScenarioGraspabilityTest, NamoMassRuleFollowsThePayload) {
  // namo_basic's box (23.3 kg at density 45) is within the 25 kg payload.
  const Scenario basic = load("namo_basic");
  EXPECT_NEAR(basic.world.object("movable_box").mass, 23.26, 0.01);
  EXPECT_TRUE(basic.world.object("movable_box").graspable);
  // At the loader's default density (31 kg) it is above the payload, so not graspable.
  auto text = readTextFile(scenarioDir() / "namo_basic.yaml");
  ASSERT_TRUE(text.ok());
  const std::string dense = replaced(*text, "density: 45.0", "density: 60.0");
  auto heavy = parseScenario(dense, (scenarioDir() / "dense.yaml").string());
  ASSERT_TRUE(heavy.ok()) << heavy.error().toString();
  EXPECT_NEAR(heavy->world.object("movable_box").mass, 31.02, 0.01);
  EXPECT_FALSE(heavy->world.object("movable_box").graspable);
  // max_graspable_mass may lower the limit ...
  auto lower = parseScenario(replaced(*text, "density: 45.0", "max_graspable_mass: 20"),
                             (scenarioDir() / "lower.yaml").string());
  ASSERT_TRUE(lower.ok()) << lower.error().toString();
  EXPECT_FALSE(lower->world.object("movable_box").graspable);
  // ... never raise it above the payload.
  const std::string above = replaced(*text, "density: 45.0", "max_graspable_mass: 50");
  auto bad = parseScenario(above, (scenarioDir() / "above.yaml").string());
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().toString().find(
                "field 'world.namo_options.max_graspable_mass': must not exceed the robot's "
                "payload of 25 kg"),
            std::string::npos)
      << bad.error().toString();
  // Moghaddam 07 at the default density: the same 22 of 27 movables as the former fixed 25 kg.
  const Scenario m = load("namo_moghaddam_07");
  int movable = 0, graspable = 0;
  for (const auto& o : m.world.objects()) {
    if (o.kind != ObjectKind::kMovable) continue;
    ++movable;
    graspable += o.graspable ? 1 : 0;
    EXPECT_EQ(o.graspable, o.mass <= 25.0) << o.id;
  }
  EXPECT_EQ(movable, 27);
  EXPECT_EQ(graspable, 22);
  // A NAMO file loaded on its own follows the default robot's payload as well.
  auto direct = loadScenario(fs::path(TAMP_BENCHMARKS_DIR) /
                             "namo/moghaddam_planning_2016_benchmark/01/01.json");
  ASSERT_TRUE(direct.ok()) << direct.error().toString();
  int direct_movable = 0;
  for (const auto& o : direct->world.objects()) {
    if (o.kind != ObjectKind::kMovable) continue;
    ++direct_movable;
    EXPECT_EQ(o.graspable, o.mass <= robotModel().payload()) << o.id << " " << o.mass;
  }
  EXPECT_GT(direct_movable, 0);
}

// A NAMO world's movables are movable by the benchmark's own rule; the masses are the loader's
// assumption, so a scenario caps them at the most its robot can move (the larger of payload and
// push limit). A scenario may set the cap higher, and heavier movables are then ones this robot
// cannot move; a cap below 1 kg is an error naming the field.
TEST(ScenarioGraspabilityTest, NamoMassesAreCappedAtWhatTheRobotCanMove) {
  const double can_move = std::max(robotModel().payload(), robotModel().pushLimit());
  ASSERT_GT(can_move, 25.0);
  // Moghaddam world 04 at our robot's scale: its largest box is above the push limit at 60 kg/m^3.
  auto text = readTextFile(scenarioDir() / "namo_moghaddam_07.yaml");
  ASSERT_TRUE(text.ok());
  const std::string w04 = replaced(replaced(*text, "benchmark_07.svg", "benchmark_04.svg"), "  namo: ",
                                   "  namo_options: {robot_radius: 0.39}\n  namo: ");
  auto heaviestOf = [](const Scenario& sc, int* at_cap, double cap) {
    double heaviest = 0;
    for (const auto& o : sc.world.objects()) {
      if (o.kind != ObjectKind::kMovable) continue;
      heaviest = std::max(heaviest, o.mass);
      if (at_cap != nullptr && o.mass == cap) ++*at_cap;
    }
    return heaviest;
  };
  auto capped = parseScenario(w04, (scenarioDir() / "w04.yaml").string());
  ASSERT_TRUE(capped.ok()) << capped.error().toString();
  int at_cap = 0;
  EXPECT_DOUBLE_EQ(heaviestOf(*capped, &at_cap, can_move), can_move);
  EXPECT_GT(at_cap, 0);
  const std::string with_cap = replaced(w04, "robot_radius: 0.39}", "robot_radius: 0.39, max_mass: 150}");
  auto raised = parseScenario(with_cap, (scenarioDir() / "raised.yaml").string());
  ASSERT_TRUE(raised.ok()) << raised.error().toString();
  EXPECT_GT(heaviestOf(*raised, nullptr, 0.0), can_move);
  auto bad = parseScenario(replaced(with_cap, "max_mass: 150", "max_mass: 0"),
                           (scenarioDir() / "bad_cap.yaml").string());
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().toString().find("world.namo_options"), std::string::npos) << bad.error().toString();
  EXPECT_NE(bad.error().toString().find("max_mass must be >= 1 kg, got 0"), std::string::npos)
      << bad.error().toString();
  // A NAMO file loaded on its own is capped the same way.
  auto direct = loadScenario(fs::path(TAMP_BENCHMARKS_DIR) /
                             "namo/moghaddam_planning_2016_benchmark/moghaddam_planning_2016_benchmark_04.svg");
  ASSERT_TRUE(direct.ok()) << direct.error().toString();
  for (const auto& o : direct->world.objects()) {
    if (o.kind == ObjectKind::kMovable) {
      EXPECT_LE(o.mass, can_move) << o.id;
    }
  }
}

TEST(ScenarioErrorsTest, MinimalLoads) {
  auto r = parseScenario(kMinimal, kFile);
  ASSERT_TRUE(r.ok()) << r.error().toString();
  EXPECT_EQ(r->robot.arm_configuration, "stow");
  EXPECT_EQ(r->domain, fs::path(TAMP_SOURCE_DIR) / "config/pddl/mobile_manipulation.pddl");
}

TEST(ScenarioErrorsTest, ExactMessages) {
  EXPECT_EQ(errorOf(replaced(kMinimal, "mass: 0.3", "mass: 0.3, colour: red")),
            kFile +
                ":7:121: field 'world.objects[0].colour': unknown key 'colour' (expected one of: "
                "at, graspable, id, "
                "kind, label, mass, on, pose, shape)");
  EXPECT_EQ(errorOf(replaced(kMinimal, "on: table", "on: tabel")),
            kFile + ":7:89: field 'world.objects[0].on': unknown region 'tabel'");
  EXPECT_EQ(errorOf(replaced(kMinimal, "at: [1.5, 0]", "at: [3.5, 0]")),
            kFile + ":7:100: field 'world.objects[0].at': [3.5, 0] is outside region 'table'");
  EXPECT_EQ(errorOf(replaced(kMinimal, "type: cylinder", "type: cone")),
            kFile +
                ":7:46: field 'world.objects[0].shape.type': unknown shape type 'cone' (expected "
                "box, cylinder, "
                "sphere or prism)");
  EXPECT_EQ(
      errorOf(replaced(kMinimal, "radius: 0.03", "radius: -0.03")),
      kFile + ":7:39: field 'world.objects[0].shape': cylinder radius must be positive, got -0.03");
  EXPECT_EQ(errorOf(replaced(kMinimal, "mass: 0.3", "mass: 0")),
            kFile +
                ":7:116: field 'world.objects[0].mass': a movable object needs a positive mass "
                "(kg), got 0");
  EXPECT_EQ(errorOf(replaced(kMinimal, "robot: {start: start}", "robot: {start: home}")),
            kFile + ":2:16: field 'robot.start': unknown location 'home'");
  EXPECT_EQ(errorOf(replaced(kMinimal, "robot: {start: start}",
                             "robot: {start: start, arm: [0, 0, 0, 0, 0, 3.5]}")),
            kFile + ":2:28: field 'robot.arm': arm_joint_6 = 3.5 is outside its limits [-3, 3]");
  EXPECT_EQ(
      errorOf(replaced(kMinimal, "robot: {start: start}", "robot: {start: start, arm: dance}")),
      kFile +
          ":2:28: field 'robot.arm': unknown arm configuration 'dance' (robot has: stow, ready, carry)");
  EXPECT_EQ(errorOf(replaced(kMinimal, "(holding can)", "(holding table)")),
            kFile +
                ":8:15: field 'goal.pddl[0]': 'table' in '(holding table)' is not a movable object "
                "(hidden objects are "
                "unknown to the planner)");
  EXPECT_EQ(errorOf(replaced(kMinimal, "(holding can)", "(on can)")),
            kFile + ":8:15: field 'goal.pddl[0]': 'on' takes 2 arguments, got 1");
  EXPECT_EQ(errorOf(replaced(kMinimal, "(holding can)", "(grasped can)")),
            kFile + ":8:15: field 'goal.pddl[0]': unknown predicate 'grasped' in '(grasped can)'");
  EXPECT_EQ(errorOf(replaced(kMinimal, "name: mini", "name: Mini")),
            kFile + ":1:7: field 'name': 'Mini' is not a valid id");
  EXPECT_EQ(
      errorOf(std::string(kMinimal) + "faults: [{type: drop_held, at_time: 1, at_step: 2}]\n"),
      kFile + ":9:10: field 'faults[0]': give exactly one of 'at_time' (s) or 'at_step'");
  EXPECT_EQ(errorOf(std::string(kMinimal) +
                    "faults: [{type: drop_held, at_time: 1, action: move_base}]\n"),
            kFile + ":9:48: field 'faults[0].action': a drop waits for an action of a kind only with at_step");
  EXPECT_EQ(errorOf(std::string(kMinimal) +
                    "faults: [{type: drop_held, at_step: 1, action: fly}]\n"),
            kFile + ":9:48: field 'faults[0].action': unknown action 'fly' (expected move_base, move_arm, pick or place)");
  EXPECT_EQ(errorOf(std::string(kMinimal) + "sim: {grasp_duration: -1}\n"),
            kFile + ":9:23: field 'sim.grasp_duration': must be >= 0, got -1");
  EXPECT_EQ(errorOf(replaced(kMinimal, "world:\n", "world:\n  namo: ${NOPE}/x.json\n")),
            kFile +
                ":4:9: field 'world.namo': unknown variable in path '${NOPE}/x.json' (known: "
                "${TAMP_BENCHMARKS_DIR}, "
                "${TAMP_CONFIG_DIR})");
  EXPECT_EQ(errorOf(""),
            kFile + ":1:1: a scenario is a mapping (name:, robot:, world:, goal:, ...)");
  EXPECT_EQ(errorOf("- 1\n"), kFile + ":1:1: expected a mapping (key: value pairs)");
  EXPECT_EQ(errorOf(replaced(kMinimal, "goal: {pddl: [\"(holding can)\"]}", "goal: base")),
            kFile + ":8:7: field 'goal': expected a mapping (key: value pairs)");
  EXPECT_EQ(errorOf("name: x\nrobot: [1\n"),
            kFile + ":3:1: invalid YAML: end of sequence flow not found");
}

// ---- issue 13: inputs that loaded silently before

TEST(ScenarioInputRulesTest, AnIdSharedByALocationAndARegionIsRefused) {
  EXPECT_EQ(errorOf(replaced(kMinimal, "{id: start, pose: [-1, 0, 0]}",
                             "{id: start, pose: [-1, 0, 0]}, {id: table, pose: [0, 0, 0]}")),
            kFile + ":5:51: field 'world.locations[1].id': id 'table' is already a region (regions, "
                    "locations and objects are PDDL objects: one id each)");
  // An object named like a region is the same mistake.
  EXPECT_EQ(errorOf(replaced(kMinimal, "{id: can, kind: movable", "{id: table, kind: movable")),
            kFile + ":7:12: field 'world.objects[0].id': id 'table' is already a region (regions, "
                    "locations and objects are PDDL objects: one id each)");
}

TEST(ScenarioInputRulesTest, AWrongTypeInAGoalOrInitAtomNamesTheElement) {
  // 'start' is a location where (on ?item ?region) wants a region.
  EXPECT_EQ(errorOf(replaced(kMinimal, "goal: {pddl: [\"(holding can)\"]}",
                             "goal: {pddl: [\"(hand-empty)\", \"(on can start)\"]}")),
            kFile + ":8:31: field 'goal.pddl[1]': 'start' in '(on can start)' is not a region");
  EXPECT_EQ(errorOf(replaced(kMinimal, "goal:",
                             "pddl:\n  domain: ${TAMP_CONFIG_DIR}/pddl/mobile_manipulation.pddl\n"
                             "  init: [\"(robot-at table)\"]\ngoal:")),
            kFile + ":10:10: field 'pddl.init[0]': 'table' in '(robot-at table)' is not a location");
}

TEST(ScenarioInputRulesTest, PosesOutsideTheWorkspaceAreRefused) {
  const std::string ws = replaced(kMinimal, "world:\n", "world:\n  workspace: [-2, -1, 3, 1]\n");
  ASSERT_EQ(errorOf(ws), "(loaded)");
  EXPECT_EQ(errorOf(replaced(ws, "pose: [-1, 0, 0]", "pose: [-5, 0, 0]")),
            kFile + ":6:33: field 'world.locations[0].pose': [-5, 0] is outside the workspace "
                    "[-2, -1, 3, 1]");
  EXPECT_EQ(errorOf(replaced(ws, "rect: [1, -0.5, 2, 0.5]", "rect: [1, -0.5, 4, 0.5]")),
            kFile + ":5:44: field 'world.regions[0].rect': corner [4, -0.5] is outside the "
                    "workspace [-2, -1, 3, 1]");
  // An object outside the workspace (and so outside its region too).
  const std::string obj = replaced(replaced(ws, "on: table, at: [1.5, 0]", "pose: {xyz: [2.5, 3, 0.8]}"),
                                   "goal: {pddl: [\"(holding can)\"]}", "goal: {base: start}");
  EXPECT_NE(errorOf(obj).find("field 'world.objects[0].pose': [2.5, 3] is outside the workspace"),
            std::string::npos)
      << errorOf(obj);
  EXPECT_EQ(errorOf(replaced(ws, "goal: {pddl: [\"(holding can)\"]}", "goal: {base: [0, 7, 0]}")),
            kFile + ":9:14: field 'goal.base': [0, 7] is outside the workspace [-2, -1, 3, 1]");
  // A static wall may straddle the edge (the room's walls do), not stand beyond it.
  const std::string wall =
      "    - {id: wall, kind: static, shape: {type: box, size: [0.1, 2.0, 1.0]}, pose: {xyz: [3.05, 0, 0.5]}}\n";
  EXPECT_EQ(errorOf(replaced(ws, "goal:", wall + "goal:")), "(loaded)");
  EXPECT_NE(errorOf(replaced(ws, "goal:", replaced(wall, "3.05", "4.5") + "goal:"))
                .find("field 'world.objects[1].pose': [4.5, 0] is outside the workspace [-2, -1, 3, 1] "
                      "by more than the object's size"),
            std::string::npos)
      << errorOf(replaced(ws, "goal:", replaced(wall, "3.05", "4.5") + "goal:"));
  // Without a workspace nothing bounds the poses.
  EXPECT_EQ(errorOf(replaced(kMinimal, "pose: [-1, 0, 0]", "pose: [-50, 0, 0]")), "(loaded)");
}

TEST(ScenarioInputRulesTest, ANameThatDiffersFromTheFileNameIsRefusedWhenLoadingAFile) {
  const fs::path dir = fs::temp_directory_path() / "tamp_scenario_name_test";
  fs::create_directories(dir);
  std::ofstream(dir / "mini.yaml") << kMinimal;
  std::ofstream(dir / "other.yaml") << kMinimal;
  auto same = loadScenario(dir / "mini.yaml");
  EXPECT_TRUE(same.ok()) << same.error().toString();
  auto other = loadScenario(dir / "other.yaml");
  ASSERT_FALSE(other.ok());
  EXPECT_EQ(other.error().toString(),
            (dir / "other.yaml").string() +
                ":1:7: field 'name': 'mini' differs from the file name 'other' (a scenario file is "
                "named <name>.yaml)");
  fs::remove_all(dir);
}

TEST(ScenarioInputRulesTest, ADuplicateKeyIsRefused) {
  EXPECT_EQ(errorOf(replaced(kMinimal, "robot: {start: start}", "robot: {start: start, start: start}")),
            kFile + ":2:23: field 'robot.start': duplicate key 'start' (first given at line 2)");
}

TEST(ScenarioInputRulesTest, EveryShippedScenarioFollowsTheRules) {
  int n = 0;
  for (const auto& entry : fs::directory_iterator(scenarioDir())) {
    if (entry.path().extension() != ".yaml") continue;
    auto sc = loadScenario(entry.path());
    EXPECT_TRUE(sc.ok()) << sc.error().toString();
    ++n;
  }
  EXPECT_GE(n, 9);
}

TEST(ScenarioErrorsTest, AllErrorsOfAFileAreReported) {
  const std::string bad = replaced(replaced(kMinimal, "on: table", "on: tabel"),
                                   "robot: {start: start}", "robot: {start: home}");
  auto r = parseScenario(bad, kFile);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("unknown region 'tabel'"), std::string::npos)
      << r.error().message;
  EXPECT_NE(r.error().message.find("unknown location 'home'"), std::string::npos)
      << r.error().message;
}

TEST(ScenarioErrorsTest, HeldObjectMustBeGraspable) {
  const std::string y = replaced(
      replaced(kMinimal, "robot: {start: start}", "robot: {start: start, holding: {object: can}}"),
      "graspable: true", "graspable: false");
  EXPECT_EQ(
      errorOf(y),
      kFile + ":2:41: field 'robot.holding.object': object 'can' must be movable and graspable");
}

}  // namespace
}  // namespace tamp::world
