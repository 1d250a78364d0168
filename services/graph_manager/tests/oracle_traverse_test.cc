// Traverse under policy oracle against scripted services (no DDS, no planner): a constructed
// corridor where the robot either removes the box (a sub-task, then on to the goal) or goes round
// it. The oracle prices both in full (no branch-and-bound cut) and takes the cheaper; a scripted
// failure that will strike the removal branch turns the choice to the detour; two blocking
// objects get a sub-task that removes both together.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "tamp/core/paths.h"
#include "tamp/graph_manager/graph_manager.h"
#include "tamp/world/scenario.h"

namespace tamp::graph_manager {
namespace {

constexpr double kSpeed = 0.5;  // m/s: the scripted efforts

/// The corridor: start (1.5, 1.2), near_box (3.85, 1.2), goal (8.5, 1.2). The straight lazy path
/// start -> goal crosses the movables; every other base path is clear. Lengths of start ->
/// near_box and of the detour start -> goal are set by the test.
class ScriptedServices : public ServiceClients {
 public:
  double removal_len{2.35};  // start -> near_box
  double around_len{8.0};    // start -> goal, full mode
  std::vector<std::string> blocking{"box"};
  std::optional<OracleKnowledge> knowledge;
  std::vector<std::vector<std::string>> removal_goals;  // the "(on o s)" goals asked for
  std::vector<std::string> added;  // per question asked: the ids of its added objects, joined

  static std::string ids(const std::vector<world::Object>& v) {
    std::string s;
    for (const auto& o : v) s += (s.empty() ? "" : " ") + o.id;
    return s;
  }

  TaskPlan plan(const TaskQuery& q) override {
    TaskPlan p;
    std::string at;
    for (const auto& a : q.init)
      if (a.rfind("(robot-at ", 0) == 0) at = a.substr(10, a.size() - 11);
    std::vector<std::string> before{"(robot-at " + at + ")"}, after;
    std::string to;
    for (const auto& g : q.goal) {
      const auto t = atomTokens(g);
      if (t.size() == 2 && t[0] == "robot-at") {
        to = t[1];
      } else if (t.size() == 3 && t[0] == "on") {
        to = "near_box";  // a removal, scripted as one move (its cost is the test's to set)
        for (const auto& a : q.init)
          if (a.rfind("(on " + t[1] + " ", 0) == 0) before.push_back(a);
        after.push_back(g);
      } else {
        p.status = TaskStatus::kUnsolvable;
        return p;
      }
    }
    if (q.goal.size() > 0 && atomTokens(q.goal[0])[0] == "on") removal_goals.push_back(q.goal);
    after.push_back("(robot-at " + to + ")");
    p.status = TaskStatus::kSolved;
    p.actions = {"(move_base " + at + " " + to + ")"};
    p.states = {before, after};
    return p;
  }

  MotionAnswer motion(const MotionQuery& q) override {
    added.push_back(ids(q.added));
    MotionAnswer a;
    a.status = MotionOutcome::kSolved;
    const Pose2D s = q.start.base, g = q.goal_base;
    const bool start_to_goal = std::abs(s.x - 1.5) < 0.01 && std::abs(g.x - 8.5) < 0.01;
    const bool to_near_box = std::abs(s.x - 1.5) < 0.01 && std::abs(g.x - 3.85) < 0.01;
    const double straight = std::hypot(g.x - s.x, g.y - s.y);
    double len = straight;
    if (start_to_goal && q.mode == Mode::kFull) len = around_len;
    if (to_near_box) len = removal_len;
    // A path of that length: up by h, along, down by h.
    const double h = std::max(0.0, (len - straight) / 2.0);
    a.path.joint_names = {"base_x", "base_y", "base_theta"};
    a.path.waypoints = {
        {s.x, s.y, 0.0}, {s.x, s.y + h, 0.0}, {g.x, g.y + h, 0.0}, {g.x, g.y, g.theta}};
    a.path_length = len;
    a.trajectory.joint_names = a.path.joint_names;
    for (std::size_t i = 0; i < a.path.waypoints.size(); ++i)
      a.trajectory.points.push_back(
          TrajectoryPoint{static_cast<double>(i), a.path.waypoints[i], {}});
    if (start_to_goal && q.mode == Mode::kLazy) {
      for (const auto& id : blocking) {
        Crossing c;
        c.object_id = id;
        c.enter_fraction = 0.4;
        c.exit_fraction = 0.45;
        c.swept_base = {Pose2D{4.3, 1.2, 0.0}};
        c.mass = 1.5;
        a.blocking.push_back(c);
      }
    }
    return a;
  }

  Result<std::vector<PlacementOption>> placements(const PlacementQuery& q) override {
    added.push_back(ids(q.added));
    PlacementOption p;
    p.object_pose = Eigen::Isometry3d::Identity();
    p.object_pose.translation() = Eigen::Vector3d(4.2, q.object_id == "box" ? 1.85 : 2.0, 0.15);
    p.base_pose = Pose2D{3.6, 1.85, 0.0};
    return std::vector<PlacementOption>{p};
  }

  Result<std::vector<GraspOption>> grasps(const GraspQuery& q) override {
    added.push_back(ids(q.added));
    GraspOption g;
    g.base_pose = q.base.value_or(Pose2D{3.85, 1.2, 0.0});
    return std::vector<GraspOption>{g};
  }

  std::vector<EffortAnswer> effort(const std::vector<EffortQuery>& qs) override {
    std::vector<EffortAnswer> out;
    for (const auto& q : qs) {
      double len = 0.0;
      for (std::size_t i = 1; i < q.path.waypoints.size(); ++i)
        len += std::hypot(q.path.waypoints[i][0] - q.path.waypoints[i - 1][0],
                          q.path.waypoints[i][1] - q.path.waypoints[i - 1][1]);
      out.push_back(EffortAnswer{true, len / kSpeed, 0.1, ""});
    }
    return out;
  }

  Result<OracleKnowledge> oracle() override {
    if (!knowledge) return Error(ErrorCode::kUnavailable, "no oracle in this test");
    return *knowledge;
  }
};

struct Corridor {
  world::Scenario sc;
  robot::RobotModel robot;
};

Corridor corridor(bool with_crate) {
  auto sc = world::loadScenario(configDir() / "scenarios" / "namo_corridor.yaml");
  if (!sc) throw std::runtime_error(sc.error().toString());
  auto robot = robot::RobotModel::loadDescription(sc->robot.description);
  if (!robot) throw std::runtime_error(robot.error().toString());
  if (with_crate) {
    world::Object crate = sc->world.object("box");
    crate.id = "crate";
    crate.pose.translation().x() += 0.3;
    if (Status s = sc->world.addObject(crate); !s) throw std::runtime_error(s.error().toString());
  }
  return {*sc, *robot};
}

struct Outcome {
  TraverseResult result;
  std::string first_action;
  bool around{false};
  bool around_cut{false};
  double around_effort{kInfinity};
};

/// `extra`: objects in the graph's world beside the scenario's (e.g. the oracle's hidden ones, as
/// the node's OracleWorldSource adds them).
Outcome traverseWith(Policy policy, ScriptedServices& services, bool with_crate = false,
                     const std::vector<world::Object>& extra = {}) {
  const Corridor c = corridor(with_crate);
  GraphManagerParams p;
  p.policy = policy;
  p.max_contingencies = 0;
  p.placements_per_object = 1;
  world::World told = c.sc.plannerWorld();
  for (const auto& o : extra)
    if (Status s = told.addObject(o); !s) throw std::runtime_error(s.error().toString());
  GraphManager gm(Abstraction(told, c.robot), "(define (domain scripted))",
                  MissionGoal{{"(robot-at goal)"}}, services, p);
  Observation obs;
  obs.robot = c.sc.startState();
  obs.valid = true;
  if (Status s = gm.start(told, obs); !s) throw std::runtime_error(s.error().toString());
  Outcome o;
  o.result = gm.traverse(gm.root(), gm.contextOf(obs));
  if (!o.result.found) return o;
  const Edge& first = gm.graph().edge(o.result.branch.front());
  o.first_action = first.action;
  o.around = first.variant == Variant::kAround;
  for (const Decision& d : gm.decisions())
    for (const Alternative& a : d.alternatives)
      if (a.description.find("[around]") != std::string::npos) {
        o.around_cut = o.around_cut || a.cut;
        o.around_effort = a.effort_s;
      }
  return o;
}

TEST(OracleTraverseTest, TheCheaperRemovalIsChosenWithTheDetourPricedInFull) {
  ScriptedServices s;
  s.knowledge = OracleKnowledge{};
  const Outcome o = traverseWith(Policy::kOracle, s);
  ASSERT_TRUE(o.result.found) << o.result.reason;
  EXPECT_EQ(o.first_action, "(move_base start near_box)");
  EXPECT_NEAR(o.result.cost_s, (2.35 + 4.65) / kSpeed, 1e-6);
  // Exhaustive: the detour was not cut, its full price is known.
  EXPECT_FALSE(o.around_cut);
  EXPECT_NEAR(o.around_effort, 8.0 / kSpeed, 1e-6);
  // Branch-and-bound (policy effort) makes the same choice but cuts the detour on its bound.
  ScriptedServices e;
  const Outcome b = traverseWith(Policy::kEffort, e);
  ASSERT_TRUE(b.result.found) << b.result.reason;
  EXPECT_EQ(b.first_action, "(move_base start near_box)");
  EXPECT_TRUE(b.around_cut);
}

TEST(OracleTraverseTest, TheCheaperDetourIsChosenWhenTheRemovalCostsMore) {
  ScriptedServices s;
  s.knowledge = OracleKnowledge{};
  s.removal_len = 6.0;  // 12 s + 9.3 s > 16 s round
  const Outcome o = traverseWith(Policy::kOracle, s);
  ASSERT_TRUE(o.result.found) << o.result.reason;
  EXPECT_TRUE(o.around) << o.first_action;
  EXPECT_NEAR(o.result.cost_s, 8.0 / kSpeed, 1e-6);
}

TEST(OracleTraverseTest, AScriptedFailureOnTheRemovalBranchTurnsTheChoiceToTheDetour) {
  // The robot's second command will fail once (any move_base at step 1): the removal branch's
  // second drive (9.3 s) is paid twice, 23.3 s > 16 s round (one command: step 0, untouched).
  OracleFault f;
  f.type = OracleFault::Type::kFailAction;
  f.step = 1;
  f.action = ActionKind::kMoveBase;
  ScriptedServices s;
  s.knowledge = OracleKnowledge{{}, {f}, 0, 0.0};
  const Outcome o = traverseWith(Policy::kOracle, s);
  ASSERT_TRUE(o.result.found) << o.result.reason;
  EXPECT_TRUE(o.around) << o.first_action;
  // Once the simulator has accepted two commands the fault is behind: the removal wins again.
  ScriptedServices later;
  later.knowledge = OracleKnowledge{{}, {f}, 2, 0.0};
  const Outcome l = traverseWith(Policy::kOracle, later);
  ASSERT_TRUE(l.result.found) << l.result.reason;
  EXPECT_EQ(l.first_action, "(move_base start near_box)");
}

TEST(OracleTraverseTest, TwoBlockingObjectsAreAlsoRemovedTogether) {
  ScriptedServices s;
  s.knowledge = OracleKnowledge{};
  s.blocking = {"box", "crate"};
  ASSERT_TRUE(traverseWith(Policy::kOracle, s, true).result.found);
  const auto both = std::count_if(s.removal_goals.begin(), s.removal_goals.end(),
                                  [](const auto& g) { return g.size() == 2; });
  EXPECT_EQ(both, 1) << "one sub-task removes box and crate together";
  ScriptedServices e;
  e.blocking = {"box", "crate"};
  ASSERT_TRUE(traverseWith(Policy::kEffort, e, true).result.found);
  EXPECT_EQ(e.removal_goals.size(), 2u) << "one sub-task per object";
  for (const auto& g : e.removal_goals)
    EXPECT_EQ(g.size(), 1u) << "policy effort removes one object per sub-task";
}

world::Object chairAt(double x, double y) {
  world::Object o;
  o.id = "chair";
  o.kind = world::ObjectKind::kMovable;
  o.shape = world::Shape::box(0.4, 0.4, 0.8);
  o.pose = Eigen::Isometry3d::Identity();
  o.pose.translation() = Eigen::Vector3d(x, y, 0.4);
  o.mass = 5.0;
  return o;
}

TEST(OracleTraverseTest, EveryQuestionCarriesTheHiddenObjectsTheServicesLack) {
  // The oracle told of a hidden chair; perception has not found it, so the graph's world has it
  // (withHidden) and the motion planner's does not: every question carries it.
  const world::Object chair = chairAt(2.5, 3.0);
  ScriptedServices s;
  s.knowledge = OracleKnowledge{{chair}, {}, 0, 0.0};
  ASSERT_TRUE(traverseWith(Policy::kOracle, s, false, {chair}).result.found);
  ASSERT_GE(s.added.size(), 3u);
  for (const auto& a : s.added) EXPECT_EQ(a, "chair");

  // Another policy adds nothing, whatever the world holds.
  ScriptedServices e;
  e.knowledge = s.knowledge;
  ASSERT_TRUE(traverseWith(Policy::kEffort, e, false, {chair}).result.found);
  ASSERT_FALSE(e.added.empty());
  for (const auto& a : e.added) EXPECT_EQ(a, "");

  // An object of the world under the hidden one's id but elsewhere is perception's: not added.
  ScriptedServices n;
  n.knowledge = s.knowledge;
  ASSERT_TRUE(traverseWith(Policy::kOracle, n, false, {chairAt(7.0, 5.0)}).result.found);
  for (const auto& a : n.added) EXPECT_EQ(a, "");
}

}  // namespace
}  // namespace tamp::graph_manager
