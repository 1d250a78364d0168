// Planning (planning.h): set-up of the spaces and checkers, leaving the start, the goal.
#include <algorithm>
#include <cmath>
#include <iterator>

#include <ompl/base/goals/GoalSampleableRegion.h>
#include <ompl/base/goals/GoalState.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/util/RandomNumbers.h>

#include "planning.h"
#include "tamp/core/format.h"
#include "tamp/core/log.h"

namespace tamp::motion_planner {
namespace {

/// Base goal with a position tolerance and a free yaw (rotation-symmetric robots).
class AnyYawGoal : public ob::GoalSampleableRegion {
 public:
  AnyYawGoal(const ob::SpaceInformationPtr& si, const detail::GroupSpace& gs, const ob::State* templ,
             double x, double y, double tol)
      : ob::GoalSampleableRegion(si), gs_(gs), templ_(si->cloneState(templ)), x_(x), y_(y) {
    setThreshold(tol);
  }
  ~AnyYawGoal() override { si_->freeState(templ_); }
  double distanceGoal(const ob::State* s) const override {
    const Pose2D p = gs_.basePose(s);
    double d = std::hypot(p.x - x_, p.y - y_);
    if (gs_.movesArm()) {  // whole body: the arm must match too
      const auto v = gs_.values(s), t = gs_.values(templ_);
      for (std::size_t i = 3; i < v.size(); ++i) d += std::abs(v[i] - t[i]);
    }
    return d;
  }
  void sampleGoal(ob::State* s) const override {
    si_->copyState(s, templ_);
    auto v = gs_.values(s);
    v[2] = rng_.uniformReal(-M_PI, M_PI);
    gs_.setValues(v, s);
  }
  unsigned int maxSampleCount() const override { return 1000000u; }

 private:
  const detail::GroupSpace& gs_;
  ob::State* templ_;
  double x_, y_;
  mutable ompl::RNG rng_;
};

}  // namespace

// ---- set-up: state space, validity and clearance checkers, start state ----

Planning::Planning(MotionPlanner::Impl& planner_impl, const MotionRequest& request, const Termination& term,
                   const RequestWorld& rw, PlanOutput& output)
    : impl(planner_impl),
      P(planner_impl.params),
      req(request),
      termination(term),
      out(output),
      res(output.res),
      held_shape(rw.held_shape),
      bounds(rw.bounds),
      held(rw.held),
      held_link(rw.held_link),
      link_T_held(rw.link_T_held),
      lazy(request.mode == MotionMode::kLazy),
      gs(impl.robot, req.group, req.start, bounds, P.sampling),
      space(gs.space()),
      ignored(req.ignored_objects),
      oracle(requestOracle()),
      sweep_radii(sweepRadii()),
      si(makeSi(oracle, !lazy)),
      start(nullptr, StateFree{space.get()}),
      escaped(nullptr, StateFree{space.get()}),
      spu(gs.secondsPerUnit(P.cost)),
      res_check(P.sampling.validity_resolution) {
  const bool pushes = !held.empty() && held_link == impl.robot.geometry().links.front();
  const bool keeps_room = P.sampling.base_clearance > 0.0 || P.sampling.base_start_margin > 0.0;
  if (!lazy && req.group == PlanningGroup::kBase && keeps_room && !pushes) setUpClearance();
  start.reset(space->allocState());
  {
    std::vector<double> v;
    if (gs.hasBase()) v = {req.start.base.x, req.start.base.y, wrapAngle(req.start.base.theta)};
    if (gs.movesArm()) v.insert(v.end(), req.start.arm.begin(), req.start.arm.end());
    gs.setValues(v, start.get());
  }
  if (clearance) setUpStartFloor();
  if (held_shape) oracle.setSelfScene(&plainScene());
}

/// The request's checker: the movables but the held and the ignored ones, with their effort.
detail::Oracle Planning::requestOracle() {
  std::vector<detail::MovableInfo> movables;
  for (const auto& o : impl.world.objects()) {
    if (o.kind != world::ObjectKind::kMovable || o.id == held) continue;
    if (std::find(ignored.begin(), ignored.end(), o.id) != ignored.end()) continue;
    detail::MovableInfo mi;
    mi.id = o.id;
    mi.mass = o.mass;
    mi.effort_s = impl.effort(o);
    mi.cost_s = mi.effort_s * req.object_cost_scale;
    mi.aabb = o.aabb();
    mi.object = impl.world.objectPtr(o.id);
    movables.push_back(std::move(mi));
  }
  const double reach =
      req.group == PlanningGroup::kBase ? impl.reachRadius(req.start, held, held_link, link_T_held) : 0.0;
  detail::Oracle o(impl.scene, gs, ignored, std::move(movables), reach);
  if (req.group == PlanningGroup::kBase)
    o.setClearance(impl.clearanceGrid(), impl.reachCover(req.start, held, held_link, link_T_held));
  return o;
}

std::vector<double> Planning::sweepRadii() const {
  std::vector<double> sweep = impl.robot.armJointRadii();
  if (!held.empty() && impl.robot.armReachTo(held_link) >= 0.0) {
    // The held object rides on `held_link`, below every arm joint: its reach from each joint is
    // at most that joint's radius plus the object's extent beyond the link.
    const Aabb box = impl.world.object(held).shape.aabb(Eigen::Isometry3d::Identity());
    const double extent = link_T_held.translation().norm() + 0.5 * (box.max - box.min).norm() + req.held_padding_m;
    for (double& r : sweep) r += extent;
  }
  return sweep;
}

ob::SpaceInformationPtr Planning::makeSi(detail::Oracle& checker, bool full, bool swept) const {
  auto info = std::make_shared<ob::SpaceInformation>(space);
  info->setStateValidityChecker(std::make_shared<detail::OracleValidityChecker>(info, checker, full));
  info->setStateValidityCheckingResolution(
      std::min(1.0, P.sampling.validity_resolution / std::max(1e-9, space->getMaximumExtent())));
  if (swept) {
    info->setMotionValidator(
        std::make_shared<detail::SweptArmMotionValidator>(info, gs, sweep_radii, P.sampling.arm_swept_step));
  } else if (detail::isStopAndTurn(*space)) {
    info->setMotionValidator(std::make_shared<detail::CornerMotionValidator>(info));
  }
  info->setup();
  return info;
}

/// Full checks, and an arm's motions checked as the robot sweeps them (`arm_swept_step`), as the
/// rest of its path is: a straight way out checked at `validity_resolution` moves a fingertip
/// centimetres between two checks, across an object a few cm wide.
ob::SpaceInformationPtr Planning::sweptSi(detail::Oracle& checker) const {
  const bool swept = req.group == PlanningGroup::kArm && P.sampling.arm_swept_step > 0.0 && !sweep_radii.empty();
  return makeSi(checker, true, swept);
}

void Planning::setUpClearance() {
  // Grown boxes, cylinders and spheres contain the originals (a grown prism need not); the
  // grown scene has no unknown space.
  const auto& parts = impl.robot.geometry().parts;
  const bool contains = !impl.scene.hasUnknownSpace() && std::all_of(parts.begin(), parts.end(), [](const auto& part) {
    return part.shape.kind != world::ShapeKind::kPrism;
  });
  if (P.sampling.base_clearance > 0.0) {
    padded_scene = std::make_unique<collision::Scene>(impl.world);
    padded_scene->setRobot(grownGeometry(impl.robot.geometry(), P.sampling.base_clearance));
    if (!held.empty()) (void)padded_scene->attach(held, held_link, link_T_held);
    // Those shapes grown by d reach at most d*sqrt(2) farther in xy (a box's corner).
    const double reach = oracle.reachRadius() + (contains ? std::sqrt(2.0) * P.sampling.base_clearance : 0.0);
    padded_oracle = std::make_unique<detail::Oracle>(*padded_scene, gs, ignored, oracle.movables(), reach);
    if (contains && oracle.reachRadius() > 0.0) {
      std::vector<Eigen::Vector3d> cover = impl.reachCover(req.start, held, held_link, link_T_held);
      for (auto& c : cover) c.z() += std::sqrt(2.0) * P.sampling.base_clearance;
      padded_oracle->setClearance(impl.clearanceGrid(), std::move(cover));
    }
  }
  std::vector<Eigen::Vector2d> ends{{req.start.base.x, req.start.base.y}};
  if (req.goal.kind == MotionGoal::Kind::kBasePose) ends.emplace_back(req.goal.base.x, req.goal.base.y);
  if (req.goal.kind == MotionGoal::Kind::kConfiguration && req.goal.configuration.size() >= 2)
    ends.emplace_back(req.goal.configuration[0], req.goal.configuration[1]);
  clearance = std::make_shared<detail::ClearanceValidityChecker>(si, oracle, padded_oracle.get(), gs, std::move(ends),
                                                                 P.sampling.base_clearance_near_ends, contains);
  si->setStateValidityChecker(clearance);
}

/// A start nearer than `base_start_margin` to a movable (and not touching it: that start is left
/// by `leaveStart`) keeps its distance near the start: no nearer than the start, nor than a goal
/// state that stands nearer still, less 1 mm for the distance query's own error.
void Planning::setUpStartFloor() {
  if (!(P.sampling.base_start_margin > 0.0)) return;
  double floor = oracle.movableDistance(start.get());
  if (!(floor > 0.0) || floor >= P.sampling.base_start_margin) return;
  std::vector<double> goal;
  if (req.goal.kind == MotionGoal::Kind::kBasePose)
    goal = {req.goal.base.x, req.goal.base.y, wrapAngle(req.goal.base.theta)};
  if (req.goal.kind == MotionGoal::Kind::kConfiguration) goal = req.goal.configuration;
  if (goal.size() == space->getDimension()) {
    StatePtr g(space->allocState(), StateFree{space.get()});
    gs.setValues(goal, g.get());
    floor = std::min(floor, oracle.movableDistance(g.get()));
  }
  constexpr double kDistanceError = 0.001;
  if (floor - kDistanceError > 0.0) {
    clearance->setStartFloor(floor - kDistanceError);
    log::get("motion_planner")->debug("the start stands {:.4f} m from a movable: no nearer within {} m of it", floor,
                                      P.sampling.base_clearance_near_ends);
  }
  gs.placeRobot(start.get(), impl.scene);
}

bool Planning::collides(const ob::State* s) { return lazy ? !oracle.staticFree(s) : !oracle.allFree(s); }

collision::Scene& Planning::plainScene() {
  if (!plain) {
    world::World w = impl.world;
    world::Object o = w.object(held);
    o.shape = *held_shape;
    (void)w.updateObject(o);
    plain = std::make_unique<collision::Scene>(w);
    plain->setRobot(impl.robot.geometry());
    (void)plain->attach(held, held_link, link_T_held);
  }
  return *plain;
}

// Contacts of the robot with itself at `s` (placed in the scene by the caller).
std::string Planning::selfHit(const ob::State* s) {
  if (impl.scene.attachedObjects().empty() && !gs.movesArm()) return {};
  collision::Scene* sc = &impl.scene;
  if (held_shape) {
    sc = &plainScene();
    gs.placeRobot(s, *sc);
  }
  const auto self = sc->selfCollisions();
  return self.empty() ? std::string() : "self:" + self.front().first + "/" + self.front().second;
}

// ---- the start ----

Outcome Planning::leaveStart() {
  if (collides(start.get())) {
    const std::string who = oracle.collidingObject(start.get(), !lazy);
    std::vector<int> touching;
    if (!lazy && oracle.staticFree(start.get())) oracle.touched(start.get(), touching);
    if (!touching.empty() && P.sampling.start_escape_distance > 0.0) escapeTouchedMovables(touching);
    // Touching only with the held object's margin: leave by a short straight motion checked
    // without it (the robot was stopped before the contact it is now given room for).
    if (!escaped && held_shape && P.sampling.start_escape_distance > 0.0) escapeHeldMargin();
    if (!escaped && lazy && P.sampling.start_escape_distance > 0.0) {
      const std::vector<std::string> fixed = touchedFixedOnly();
      if (!fixed.empty()) escapeFixed(fixed);
    }
    if (!escaped && P.sampling.start_escape_distance > 0.0 && P.sampling.start_escape_depth > 0.0) {
      escapeStaticsShallowly();
    }
    if (!escaped) {
      return finish(MotionStatus::kStartInCollision, "the start state touches '" + who + "'" +
                                                         (touching.empty() ? "" : " (no way out of the contact found)"),
                    who);
    }
  }
  gs.placeRobot(start.get(), impl.scene);
  if (std::string s = selfHit(start.get()); !s.empty()) {
    return finish(MotionStatus::kStartInCollision, "the start state is in self-collision (" + s + ")", s);
  }
  return std::nullopt;
}

/// Out of the contact with the `touching` movables (indices into the oracle's), checked against
/// everything else; `escaped` stays empty when there is no way out. A way out that goes no deeper
/// into what it touches is taken first: a straight motion that slides a finger across an object
/// just put down pushes it, and the robot is stopped before it. A start deeper in an object than
/// `start_escape_depth` has no such way; it leaves through the objects it touches.
void Planning::escapeTouchedMovables(const std::vector<int>& touching) {
  const bool no_deeper = P.sampling.start_escape_depth > 0.0 && escapeNoDeeper(touching);
  if (!no_deeper)
    log::get("motion_planner")->debug("no way out of the start's contact going no deeper than {} m: through it",
                                      P.sampling.start_escape_depth);
  const bool left = no_deeper || escapeThrough(touching);
  if (left)
    for (int i : touching) res.start_contacts.push_back(oracle.movables()[static_cast<std::size_t>(i)].id);
}

/// Lazy mode: the objects this request fixes (movables the caller cannot move, static for this
/// request) that the start touches, when it touches nothing else static; empty otherwise.
std::vector<std::string> Planning::touchedFixedOnly() {
  std::vector<std::string> touched;
  gs.placeRobot(start.get(), impl.scene);
  for (const auto& id : req.fixed_objects)
    if (impl.scene.robotInCollision(collision::Filter::objects({id}))) touched.push_back(id);
  if (!touched.empty()) {
    std::vector<std::string> ignore = ignored;
    ignore.insert(ignore.end(), touched.begin(), touched.end());
    if (impl.scene.robotInCollision(collision::Filter{collision::kStaticObjects | collision::kUnknownSpace, {}, ignore}))
      touched.clear();
  }
  return touched;
}

/// Lazy mode: out of the contact with objects this request fixes (a perceived object that the
/// caller can neither carry nor push, estimated reaching where the robot stands), as a full-mode
/// start leaves movables: going no deeper into them first, else through them, to a state that
/// touches nothing static (they included).
void Planning::escapeFixed(const std::vector<std::string>& touched) {
  bool found = false;
  if (P.sampling.start_escape_depth > 0.0) {
    collision::Scene smaller = shrunkScene(touched);
    detail::Oracle escape_oracle(smaller, gs, ignored, oracle.movables(), oracle.reachRadius());
    if (held_shape) escape_oracle.setSelfScene(&plainScene());
    found = escapeBy(makeSi(escape_oracle, false));
  }
  if (!found) {
    std::vector<std::string> ignore = ignored;
    ignore.insert(ignore.end(), touched.begin(), touched.end());
    detail::Oracle escape_oracle(impl.scene, gs, ignore, oracle.movables(), oracle.reachRadius());
    if (held_shape) escape_oracle.setSelfScene(&plainScene());
    found = escapeBy(makeSi(escape_oracle, false));
  }
  if (found) res.start_contacts.insert(res.start_contacts.end(), touched.begin(), touched.end());
}

/// Out of a shallow contact with static objects (and, lazy, the ones the request fixes): when the
/// start touches them, and is free of them `start_escape_depth` smaller and of everything else, a
/// short straight motion going no deeper into them (checked against them that much smaller) to a
/// free state; never through them, as a movable may be left. A robot stopped at a wall by its own
/// safety (or localised a few millimetres off) stands there: the planner's model of the robot and
/// the world is not the world. `escaped` stays empty otherwise.
void Planning::escapeStaticsShallowly() {
  std::vector<std::string> touched;
  gs.placeRobot(start.get(), impl.scene);
  for (const auto& o : impl.world.objects()) {  // (lazy: the fixed objects are static for the request)
    if (o.kind != world::ObjectKind::kStatic) continue;
    if (std::find(ignored.begin(), ignored.end(), o.id) != ignored.end()) continue;
    if (impl.scene.robotInCollision(collision::Filter::objects({o.id}))) touched.push_back(o.id);
  }
  if (touched.empty()) return;
  collision::Scene smaller = shrunkScene(touched);
  detail::Oracle shallow(smaller, gs, ignored, oracle.movables(), oracle.reachRadius());
  const bool free = lazy ? shallow.staticFree(start.get()) : shallow.allFree(start.get());
  gs.placeRobot(start.get(), impl.scene);
  if (!free) return;
  if (held_shape) shallow.setSelfScene(&plainScene());
  if (escapeBy(makeSi(shallow, !lazy))) res.start_contacts.insert(res.start_contacts.end(), touched.begin(), touched.end());
}

/// A copy of the request's scene with the objects `ids` `start_escape_depth` smaller.
collision::Scene Planning::shrunkScene(const std::vector<std::string>& ids) {
  world::World w = impl.scene.world();
  for (const auto& id : ids) {
    world::Object o = w.object(id);
    o.shape = world::shrunk(o.shape, P.sampling.start_escape_depth);
    (void)w.updateObject(std::move(o));
  }
  collision::Scene smaller(impl.scene);
  smaller.syncWorld(w);
  return smaller;
}

/// A short way out of the start, each state checked by `checker` (whose oracle sees the held
/// object's self-collisions without its margin); sets `escaped`, or clears it when there is none.
/// The robot is placed back at the start in the request's scene.
bool Planning::escapeBy(const ob::SpaceInformationPtr& checker) {
  escaped.reset(space->allocState());
  const bool found = detail::escapeStart(si, checker, start.get(), P.sampling.start_escape_distance,
                                         P.sampling.start_escape_attempts, escaped.get());
  if (!found) escaped.reset();
  gs.placeRobot(start.get(), impl.scene);
  return found;
}

/// The way out checked against everything, the touched objects `start_escape_depth` smaller.
bool Planning::escapeNoDeeper(const std::vector<int>& touching) {
  std::vector<std::string> ids;
  for (int i : touching) ids.push_back(oracle.movables()[static_cast<std::size_t>(i)].id);
  collision::Scene smaller = shrunkScene(ids);
  detail::Oracle escape_oracle(smaller, gs, ignored, oracle.movables(), oracle.reachRadius());
  if (held_shape) escape_oracle.setSelfScene(&plainScene());
  return escapeBy(sweptSi(escape_oracle));
}

/// The way out checked against everything but the touched objects.
bool Planning::escapeThrough(const std::vector<int>& touching) {
  std::vector<std::string> ignore = ignored;
  std::vector<detail::MovableInfo> others;
  for (std::size_t i = 0; i < oracle.movables().size(); ++i) {
    const auto& m = oracle.movables()[i];
    if (std::binary_search(touching.begin(), touching.end(), static_cast<int>(i))) {
      ignore.push_back(m.id);
    } else {
      others.push_back(m);
    }
  }
  detail::Oracle escape_oracle(impl.scene, gs, ignore, std::move(others), oracle.reachRadius());
  if (held_shape) escape_oracle.setSelfScene(&plainScene());
  return escapeBy(makeSi(escape_oracle, true));
}

/// Out of a contact that only the held object's margin makes; `escaped` stays empty when the
/// start touches something without the margin too, or there is no way out.
void Planning::escapeHeldMargin() {
  detail::Oracle plain_oracle(plainScene(), gs, ignored, oracle.movables(), oracle.reachRadius());
  if (lazy ? plain_oracle.staticFree(start.get()) : plain_oracle.allFree(start.get())) (void)escapeBy(makeSi(plain_oracle, !lazy));
  gs.placeRobot(start.get(), impl.scene);
}

// ---- goal ----

Outcome Planning::setGoal() {
  Stopwatch goal_clock;
  pdef = std::make_shared<ob::ProblemDefinition>(si);
  pdef->addStartState(escaped ? escaped.get() : start.get());
  const auto& G = req.goal;
  if (auto done = G.kind == MotionGoal::Kind::kConfiguration || G.kind == MotionGoal::Kind::kBasePose
                      ? setStateGoal()
                      : setEndEffectorGoal()) {
    return done;
  }
  res.stats.goal_ms = goal_clock.millis();
  return std::nullopt;
}

/// Whether `s` is free (as the mode checks it) and not in self-collision; else who it touches.
bool Planning::checkGoal(ob::State* s, std::string& who) {
  if (collides(s)) {
    who = oracle.collidingObject(s, !lazy);
    return false;
  }
  gs.placeRobot(s, impl.scene);
  who = gs.movesArm() ? selfHit(s) : std::string();
  return who.empty();
}

/// A configuration or base pose goal (with any yaw: the first of 16 that is free).
Outcome Planning::setStateGoal() {
  const auto& G = req.goal;
  std::vector<double> v;
  if (G.kind == MotionGoal::Kind::kConfiguration) {
    v = G.configuration;
  } else {
    v = {G.base.x, G.base.y, wrapAngle(G.base.theta)};
    if (gs.movesArm()) v.insert(v.end(), req.start.arm.begin(), req.start.arm.end());
  }
  ob::State* gsState = space->allocState();
  goal_states.push_back(gsState);
  gs.setValues(v, gsState);
  if (gs.hasBase()) base_goal = Eigen::Vector2d(v[0], v[1]);
  std::string who;
  const bool any_yaw = G.kind == MotionGoal::Kind::kBasePose && G.any_base_yaw;
  bool free = checkGoal(gsState, who);
  if (!free && any_yaw) {  // another yaw may fit
    auto vv = v;
    for (int k = 1; k < 16 && !free; ++k) {
      vv[2] = wrapAngle(v[2] + k * M_PI / 8);
      gs.setValues(vv, gsState);
      std::string w2;
      free = checkGoal(gsState, w2);
    }
  }
  if (!free) return finish(MotionStatus::kGoalInCollision, "the goal state touches '" + who + "'", who);
  if (any_yaw) {
    pdef->setGoal(std::make_shared<AnyYawGoal>(si, gs, gsState, v[0], v[1], P.sampling.goal_position_tolerance));
  } else {
    pdef->setGoalState(gsState, gs.hasBase() ? P.sampling.goal_position_tolerance
                                             : P.sampling.goal_orientation_tolerance);
  }
  return std::nullopt;
}

/// An end-effector pose goal through IK: up to three free solutions from the goalBases().
Outcome Planning::setEndEffectorGoal() {
  const auto& G = req.goal;
  const auto* m = impl.robot.model();
  collision::Filter filter = requestFilter();
  const std::vector<Pose2D> bases = goalBases();
  std::string reject;
  int found = 0;
  for (std::size_t bi = 0; bi < bases.size() && found < 3; ++bi) {
    if (termination()) return finish(MotionStatus::kTimeout, "the deadline passed while solving IK for the goal");
    auto q = solveIk(impl, bases[bi], G.end_effector, req.start.arm, filter, req.start.gripper,
                     P.seed + static_cast<std::uint32_t>(bi), 16, termination);
    if (!q) continue;
    std::vector<double> v;
    if (gs.hasBase()) v = {bases[bi].x, bases[bi].y, bases[bi].theta};
    // (Not insert(): GCC 12 at -O3 reports a false -Warray-bounds for it here.)
    std::copy(q->begin(), q->end(), std::back_inserter(v));
    ob::State* s = space->allocState();
    goal_states.push_back(s);
    gs.setValues(v, s);
    if (!checkGoal(s, reject)) {
      space->freeState(s);
      goal_states.pop_back();
      continue;
    }
    ++found;
  }
  if (found == 0) {
    // Distinguish "unreachable" from "reachable only in collision".
    auto q = m->inverseKinematics(req.start.base.toIsometry().inverse() * G.end_effector, req.start.arm);
    if (req.group == PlanningGroup::kArm && q.ok()) {
      ob::State* s = space->allocState();
      goal_states.push_back(s);
      gs.setValues(q.q, s);
      std::string who = oracle.collidingObject(s, !lazy);
      if (!who.empty()) {
        return finish(MotionStatus::kGoalInCollision, "every IK solution of the goal touches an object, e.g. '" + who + "'",
                      who);
      }
    }
    return finish(MotionStatus::kNoPath, "goal.end_effector: no collision-free IK solution (" +
                                             std::to_string(bases.size()) + " base pose(s) tried)");
  }
  auto goals = std::make_shared<ob::GoalStates>(si);
  for (auto* s : goal_states) goals->addState(s);
  goals->setThreshold(P.sampling.goal_orientation_tolerance);
  pdef->setGoal(goals);
  return std::nullopt;
}

/// Where the base may stand for an end-effector goal: the start's (arm group), else rings round
/// the goal within the bounds.
std::vector<Pose2D> Planning::goalBases() const {
  std::vector<Pose2D> bases;
  if (req.group == PlanningGroup::kArm) {
    bases.push_back(req.start.base);
  } else {
    const Eigen::Vector3d t = req.goal.end_effector.translation();
    const auto& gp = P.grasp;
    for (int ring = 0; ring < 3; ++ring) {
      const double d = gp.base_distance_min + (gp.base_distance_max - gp.base_distance_min) * ring / 2.0;
      for (int k = 0; k < gp.base_poses; ++k) {
        // Start from the direction of the robot, alternate around it.
        const double a0 = std::atan2(req.start.base.y - t.y(), req.start.base.x - t.x());
        const double a = a0 + ((k % 2) ? 1 : -1) * ((k + 1) / 2) * (2 * M_PI / gp.base_poses);
        Pose2D b{t.x() + d * std::cos(a), t.y() + d * std::sin(a), wrapAngle(a + M_PI)};
        if (b.x < bounds.min.x() || b.x > bounds.max.x() || b.y < bounds.min.y() || b.y > bounds.max.y()) continue;
        bases.push_back(b);
      }
    }
  }
  return bases;
}

/// What the mode checks: static objects and unknown space (lazy) or everything (full), but the
/// ignored objects.
collision::Filter Planning::requestFilter() const {
  return lazy ? collision::Filter{collision::kStaticObjects | collision::kUnknownSpace, {}, ignored}
              : collision::Filter{collision::kAllGroups, {}, ignored};
}

}  // namespace tamp::motion_planner
