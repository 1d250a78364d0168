// Robot binding, planning-group state spaces and the collision oracle.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <ompl/base/ProjectionEvaluator.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/base/spaces/SO2StateSpace.h>

#include "internal.h"

namespace tamp::motion_planner::detail {
namespace {

/// Distance from point p to segment a-b (2-D).
double segmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

/// SE(2) as the base really moves: stop and turn. A motion from a to b turns in place at a to the
/// heading of the segment (or its reverse, whichever is nearer), drives straight to b, and turns in place there to b's yaw;
/// a motion without translation is a turn in place. Interpolation follows those three pieces, so
/// every motion check, roadmap edge and path validation checks what the robot will sweep
/// (docs/sim.md, effort_model::baseSteps), not a holonomic slide with the yaw blended in.
class TurnDriveTurnSpace : public ob::SE2StateSpace {
 public:
  /// `turn_radius`: m per rad of turn for segment lengths (the robot's circumradius: the arc its
  /// farthest point sweeps).
  explicit TurnDriveTurnSpace(double turn_radius) : turn_radius_(std::max(turn_radius, 1e-3)) {}

  void interpolate(const ob::State* from, const ob::State* to, double t, ob::State* state) const override {
    const Pieces p = pieces(from, to);
    const auto* a = from->as<StateType>();
    const auto* b = to->as<StateType>();
    auto* o = state->as<StateType>();
    const double l1 = std::abs(p.turn1) * turn_radius_, l3 = std::abs(p.turn2) * turn_radius_;
    const double total = l1 + p.drive + l3;
    if (total <= 0.0) {
      copyState(state, from);
      return;
    }
    const double at = std::clamp(t, 0.0, 1.0) * total;
    if (at <= l1) {
      o->setXY(a->getX(), a->getY());
      o->setYaw(a->getYaw() + (l1 > 0 ? p.turn1 * at / l1 : 0.0));
    } else if (at <= l1 + p.drive) {
      const double f = p.drive > 0 ? (at - l1) / p.drive : 1.0;
      o->setXY(a->getX() + f * (b->getX() - a->getX()), a->getY() + f * (b->getY() - a->getY()));
      o->setYaw(p.heading);
    } else {
      o->setXY(b->getX(), b->getY());
      o->setYaw(p.heading + (l3 > 0 ? p.turn2 * (at - l1 - p.drive) / l3 : 0.0));
    }
    getSubspace(1)->enforceBounds(o->as<ob::SO2StateSpace::StateType>(1));
  }

  /// Fractions of the motion from -> to where the first turn ends and where the drive ends: the
  /// states that stand farthest out along the drive (a location a few cm from a table is touched
  /// there, if anywhere); uniform samples of the motion need not fall on them.
  std::vector<double> cornerFractions(const ob::State* from, const ob::State* to) const {
    const Pieces p = pieces(from, to);
    const double l1 = std::abs(p.turn1) * turn_radius_, l3 = std::abs(p.turn2) * turn_radius_;
    const double total = l1 + p.drive + l3;
    std::vector<double> out;
    if (total <= 0.0) return out;
    if (l1 > 0.0 && l1 < total) out.push_back(l1 / total);
    if (l3 > 0.0 && p.drive > 0.0) out.push_back((l1 + p.drive) / total);
    return out;
  }

  /// The turns at the turn radius plus the drive (what interpolate() parametrises).
  double sweptLength(const ob::State* s1, const ob::State* s2) const {
    const Pieces p = pieces(s1, s2);
    return (std::abs(p.turn1) + std::abs(p.turn2)) * turn_radius_ + p.drive;
  }

  unsigned int validSegmentCount(const ob::State* s1, const ob::State* s2) const override {
    return longestValidSegmentCountFactor_ *
           static_cast<unsigned int>(std::max(1.0, std::ceil(sweptLength(s1, s2) / longestValidSegment_)));
  }

 private:
  struct Pieces {
    double turn1{0.0};  // rad, signed
    double drive{0.0};  // m
    double turn2{0.0};  // rad, signed
    double heading{0.0};
  };
  static double wrap(double a) { return std::remainder(a, 2.0 * M_PI); }
  static Pieces pieces(const ob::State* from, const ob::State* to) {
    const auto* a = from->as<StateType>();
    const auto* b = to->as<StateType>();
    Pieces p;
    const double dx = b->getX() - a->getX(), dy = b->getY() - a->getY();
    p.drive = std::hypot(dx, dy);
    if (p.drive < 1e-6) {
      p.drive = 0.0;
      p.heading = a->getYaw();
      p.turn1 = wrap(b->getYaw() - a->getYaw());
      return p;
    }
    // Forwards or backwards, whichever turns less at the start (as effort_model::baseSteps).
    p.heading = std::atan2(dy, dx);
    if (std::abs(wrap(p.heading + M_PI - a->getYaw())) < std::abs(wrap(p.heading - a->getYaw())))
      p.heading = wrap(p.heading + M_PI);
    p.turn1 = wrap(p.heading - a->getYaw());
    p.turn2 = wrap(b->getYaw() - p.heading);
    return p;
  }
  double turn_radius_;
};

/// KPIECE projection of the base: (x, y) of the SE(2) state (itself or the first component).
class BaseXYProjection : public ob::ProjectionEvaluator {
 public:
  BaseXYProjection(const ob::StateSpacePtr& space, double cell, bool compound)
      : ob::ProjectionEvaluator(space), cell_(cell), compound_(compound) {}
  unsigned int getDimension() const override { return 2; }
  void defaultCellSizes() override { cellSizes_ = {cell_, cell_}; }
  void project(const ob::State* s, Eigen::Ref<Eigen::VectorXd> out) const override {
    const auto* b = compound_ ? s->as<ob::CompoundState>()->as<ob::SE2StateSpace::StateType>(0)
                              : s->as<ob::SE2StateSpace::StateType>();
    out(0) = b->getX();
    out(1) = b->getY();
  }

 private:
  double cell_;
  bool compound_;
};

/// KPIECE projection of the arm: its first (up to) three joints.
class ArmProjection : public ob::ProjectionEvaluator {
 public:
  ArmProjection(const ob::StateSpacePtr& space, double cell, unsigned dims)
      : ob::ProjectionEvaluator(space), cell_(cell), dims_(dims) {}
  unsigned int getDimension() const override { return dims_; }
  void defaultCellSizes() override { cellSizes_.assign(dims_, cell_); }
  void project(const ob::State* s, Eigen::Ref<Eigen::VectorXd> out) const override {
    const auto* v = s->as<ob::RealVectorStateSpace::StateType>();
    for (unsigned i = 0; i < dims_; ++i) out(i) = v->values[i];
  }

 private:
  double cell_;
  unsigned dims_;
};

}  // namespace

std::vector<double> turnCorners(const ob::StateSpace& space, const ob::State* a, const ob::State* b) {
  if (const auto* tdt = dynamic_cast<const TurnDriveTurnSpace*>(&space)) return tdt->cornerFractions(a, b);
  return {};
}

double sweptLength(const ob::StateSpace& space, const ob::State* a, const ob::State* b) {
  if (const auto* tdt = dynamic_cast<const TurnDriveTurnSpace*>(&space)) return tdt->sweptLength(a, b);
  return space.distance(a, b);
}

bool isStopAndTurn(const ob::StateSpace& space) { return dynamic_cast<const TurnDriveTurnSpace*>(&space) != nullptr; }

namespace {
/// Checks the states of the motion s1 -> s2 at the sorted fractions `at` (the last one 1: s2
/// itself), in order; on the first invalid one, `last_valid` gets the fraction before it.
bool checkAt(const ob::SpaceInformation& si, const ob::State* s1, const ob::State* s2, const std::vector<double>& at,
             std::pair<ob::State*, double>& last_valid) {
  const auto& space = si.getStateSpace();
  ob::State* tmp = space->allocState();
  double previous = 0.0;
  bool ok = true;
  for (double f : at) {
    const ob::State* s = s2;
    if (f < 1.0) {
      space->interpolate(s1, s2, f, tmp);
      s = tmp;
    }
    if (!si.isValid(s)) {
      ok = false;
      break;
    }
    previous = f;
  }
  if (!ok) {
    if (last_valid.first != nullptr) space->interpolate(s1, s2, previous, last_valid.first);
    last_valid.second = previous;
  }
  space->freeState(tmp);
  return ok;
}

/// j / n for j = 1 .. n - 1, then 1.
std::vector<double> uniformFractions(unsigned n) {
  std::vector<double> at;
  for (unsigned j = 1; j < n; ++j) at.push_back(static_cast<double>(j) / n);
  at.push_back(1.0);
  return at;
}
}  // namespace

bool CornerMotionValidator::checkMotion(const ob::State* s1, const ob::State* s2) const {
  std::pair<ob::State*, double> unused{nullptr, 0.0};
  return checkMotion(s1, s2, unused);
}

bool CornerMotionValidator::checkMotion(const ob::State* s1, const ob::State* s2,
                                        std::pair<ob::State*, double>& last_valid) const {
  const auto& space = si_->getStateSpace();
  std::vector<double> at = uniformFractions(space->validSegmentCount(s1, s2));
  at.pop_back();
  const std::vector<double> corners = turnCorners(*space, s1, s2);
  at.insert(at.end(), corners.begin(), corners.end());
  std::sort(at.begin(), at.end());
  at.push_back(1.0);
  const bool ok = checkAt(*si_, s1, s2, at, last_valid);
  ++(ok ? valid_ : invalid_);
  return ok;
}

unsigned SweptArmMotionValidator::segments(const ob::State* s1, const ob::State* s2) const {
  const std::vector<double> a = gs_.values(s1), b = gs_.values(s2);
  double bound = 0.0;
  for (std::size_t i = 0; i < a.size() && i < b.size() && i < radii_.size(); ++i) bound += std::abs(b[i] - a[i]) * radii_[i];
  const double swept = std::ceil(bound / step_);
  const unsigned n = si_->getStateSpace()->validSegmentCount(s1, s2);
  return std::max(n, swept >= 1e7 ? 10000000u : static_cast<unsigned>(swept));
}

bool SweptArmMotionValidator::checkMotion(const ob::State* s1, const ob::State* s2) const {
  std::pair<ob::State*, double> unused{nullptr, 0.0};
  return checkMotion(s1, s2, unused);
}

bool SweptArmMotionValidator::checkMotion(const ob::State* s1, const ob::State* s2,
                                          std::pair<ob::State*, double>& last_valid) const {
  const bool ok = checkAt(*si_, s1, s2, uniformFractions(segments(s1, s2)), last_valid);
  ++(ok ? valid_ : invalid_);
  return ok;
}

bool ClearanceValidityChecker::nearEnd(const Eigen::Vector2d& at, std::size_t from) const {
  for (std::size_t i = from; i < ends_.size(); ++i)
    if ((at - ends_[i]).norm() <= near_) return true;
  return false;
}

bool ClearanceValidityChecker::isValid(const ob::State* s) const {
  if (!si_->satisfiesBounds(s)) return false;
  const Pose2D p = gs_.basePose(s);
  const Eigen::Vector2d at(p.x, p.y);
  const bool near_start = !ends_.empty() && (at - ends_.front()).norm() <= near_;
  if (near_start && floor_ > 0.0) return oracle_.allFree(s) && oracle_.movableDistance(s) >= floor_;
  if (relaxed_ || near_start || nearEnd(at, 1)) return oracle_.allFree(s);
  if (!padded_->allFree(s)) return false;
  return implied_ || oracle_.allFree(s);
}

// ---- RobotBinding -----------------------------------------------------------------------------

RobotBinding::RobotBinding(robot::RobotModel model)
    : model_(std::move(model)), geometry_(model_->collisionGeometry()), hold_link_(model_->options().tool_link) {
  computeFootprint();
  computeArmSweep();
}

namespace {
/// The links below `root` (itself included) with the chain length of joint offsets from `root`'s
/// origin to each, along the kinematic tree.
std::vector<std::pair<std::string, double>> chainsBelow(const robot::RobotModel& model, const std::string& root) {
  std::vector<std::pair<std::string, double>> out{{root, 0.0}};
  for (std::size_t i = 0; i < out.size(); ++i) {
    for (const auto& j : model.joints()) {
      if (j.parent_link != out[i].first) continue;
      if (std::any_of(out.begin(), out.end(), [&](const auto& e) { return e.first == j.child_link; })) continue;
      out.emplace_back(j.child_link, out[i].second + j.parent_T_joint.translation().norm());
    }
  }
  return out;
}
}  // namespace

void RobotBinding::computeArmSweep() {
  if (!model_ || model_->armJointNames().empty()) return;
  const robot::Joint* first = model_->findJoint(model_->armJointNames().front());
  if (!first) return;
  arm_reach_ = chainsBelow(*model_, first->child_link);
  // Per joint: the chain from that joint's child link out to the farthest part it moves.
  for (const auto& name : model_->armJointNames()) {
    const robot::Joint* joint = model_->findJoint(name);
    double r = 0.0;
    for (const auto& [link, chain] : chainsBelow(*model_, joint ? joint->child_link : first->child_link)) {
      for (const auto& part : geometry_.parts) {
        if (geometry_.links[static_cast<std::size_t>(part.link)] != link) continue;
        const Aabb box = part.shape.aabb(Eigen::Isometry3d::Identity());
        r = std::max(r, chain + part.link_T_shape.translation().norm() + 0.5 * (box.max - box.min).norm());
      }
    }
    arm_joint_radii_.push_back(r);
  }
}

double RobotBinding::armReachTo(const std::string& link) const {
  for (const auto& [name, d] : arm_reach_)
    if (name == link) return d;
  return -1.0;
}

RobotBinding::RobotBinding(collision::RobotGeometry planar) : geometry_(std::move(planar)) {
  if (geometry_.links.empty()) throw std::invalid_argument("planar robot geometry has no links");
  for (const auto& p : geometry_.parts) {
    if (p.link < 0 || static_cast<std::size_t>(p.link) >= geometry_.links.size()) {
      throw std::invalid_argument("planar robot geometry: part on link index " + std::to_string(p.link) +
                                  " out of range");
    }
    if (auto why = p.shape.invalidReason()) throw std::invalid_argument("planar robot geometry: " + *why);
  }
  if (geometry_.parts.empty()) throw std::invalid_argument("planar robot geometry has no parts");
  hold_link_ = geometry_.links.front();
  computeFootprint();
}

void RobotBinding::computeFootprint() {
  // Parts rigidly on the base: link 0 (planar robots: every link sits at the base pose).
  for (std::size_t pi = 0; pi < geometry_.parts.size(); ++pi) {
    const collision::RobotPart& p = geometry_.parts[pi];
    if (model_ && p.link != 0) continue;
    const world::Polygon2 local = p.shape.footprint(32);
    world::Polygon2 poly;
    for (const auto& v : local) {
      const Eigen::Vector3d w = p.link_T_shape * Eigen::Vector3d(v.x(), v.y(), 0.0);
      poly.emplace_back(w.x(), w.y());
      footprint_radius_ = std::max(footprint_radius_, w.head<2>().norm());
    }
    if (poly.size() < 3 || !world::containsPoint(poly, Eigen::Vector2d::Zero())) continue;
    double r = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < poly.size(); ++i) {
      r = std::min(r, segmentDistance(Eigen::Vector2d::Zero(), poly[i], poly[(i + 1) % poly.size()]));
    }
    // A shape's footprint polygon is inscribed in curved shapes: exact enough (32 sides).
    if (r > inscribed_radius_) {
      inscribed_radius_ = r;
      inscribed_part_ = pi;
      const Aabb box = p.shape.aabb(p.link_T_shape);
      inscribed_zmin_ = box.min.z();
      inscribed_zmax_ = box.max.z();
    }
  }
  if (model_) footprint_radius_ = std::max(footprint_radius_, model_->baseRadius());
}

void RobotBinding::linkPoses(const robot::RobotState& s, std::vector<Eigen::Isometry3d>& out) const {
  if (model_) {
    model_->linkPoses(s, out);
    return;
  }
  out.assign(geometry_.links.size(), s.base.toIsometry());
}

// ---- GroupSpace -------------------------------------------------------------------------------

GroupSpace::GroupSpace(const RobotBinding& robot, PlanningGroup group, const robot::RobotState& start,
                       const Aabb& base_bounds, const SamplingParams& params)
    : robot_(robot), group_(group), start_(start), base_bounds_(base_bounds) {
  if (group != PlanningGroup::kBase && !robot.hasArm()) {
    throw std::invalid_argument("group '" + std::string(toString(group)) + "' needs a robot with an arm");
  }
  std::shared_ptr<ob::SE2StateSpace> se2;
  if (group != PlanningGroup::kArm) {
    se2 = params.base_turn_in_place ? std::make_shared<TurnDriveTurnSpace>(robot.footprintRadius())
                                    : std::make_shared<ob::SE2StateSpace>();
    ob::RealVectorBounds b(2);
    b.setLow(0, base_bounds.min.x());
    b.setLow(1, base_bounds.min.y());
    b.setHigh(0, base_bounds.max.x());
    b.setHigh(1, base_bounds.max.y());
    se2->setBounds(b);
    for (auto n : kBaseJointNames) names_.emplace_back(n);
  }
  std::shared_ptr<ob::RealVectorStateSpace> arm;
  if (group != PlanningGroup::kBase) {
    const auto& model = *robot.model();
    arm = std::make_shared<ob::RealVectorStateSpace>(static_cast<unsigned>(model.armDof()));
    ob::RealVectorBounds b(static_cast<unsigned>(model.armDof()));
    for (std::size_t i = 0; i < model.armDof(); ++i) {
      const auto& l = model.armLimits()[i];
      b.setLow(static_cast<unsigned>(i), std::isfinite(l.lower) ? l.lower : -M_PI);
      b.setHigh(static_cast<unsigned>(i), std::isfinite(l.upper) ? l.upper : M_PI);
    }
    arm->setBounds(b);
    for (const auto& n : model.armJointNames()) names_.push_back(n);
  }
  switch (group) {
    case PlanningGroup::kBase:
      space_ = se2;
      space_->registerDefaultProjection(std::make_shared<BaseXYProjection>(space_, params.kpiece_cell_size, false));
      break;
    case PlanningGroup::kArm:
      space_ = arm;
      space_->registerDefaultProjection(std::make_shared<ArmProjection>(
          space_, params.arm_cell_size, std::min<unsigned>(3, static_cast<unsigned>(robot.armDof()))));
      break;
    case PlanningGroup::kWholeBody: {
      auto c = std::make_shared<ob::CompoundStateSpace>();
      c->addSubspace(se2, 1.0);
      c->addSubspace(arm, 0.5);
      c->lock();
      space_ = c;
      space_->registerDefaultProjection(std::make_shared<BaseXYProjection>(space_, params.kpiece_cell_size, true));
      break;
    }
  }
  space_->setup();
  scratch_ = start_;
  if (group == PlanningGroup::kBase) {
    // The robot moves rigidly with its base: link poses relative to the base, once.
    robot::RobotState at_origin = start_;
    at_origin.base = Pose2D{};
    robot_.linkPoses(at_origin, base_T_link_);
  } else {
    const auto& geo = robot.geometry();
    for (std::size_t i = 0; i < geo.parts.size(); ++i)
      if (robot.armReachTo(geo.links[static_cast<std::size_t>(geo.parts[i].link)]) >= 0.0) arm_parts_.push_back(i);
  }
}

std::vector<double> GroupSpace::values(const ob::State* s) const {
  std::vector<double> v;
  v.reserve(names_.size());
  const ob::SE2StateSpace::StateType* b = nullptr;
  const ob::RealVectorStateSpace::StateType* a = nullptr;
  switch (group_) {
    case PlanningGroup::kBase: b = s->as<ob::SE2StateSpace::StateType>(); break;
    case PlanningGroup::kArm: a = s->as<ob::RealVectorStateSpace::StateType>(); break;
    case PlanningGroup::kWholeBody:
      b = s->as<ob::CompoundState>()->as<ob::SE2StateSpace::StateType>(0);
      a = s->as<ob::CompoundState>()->as<ob::RealVectorStateSpace::StateType>(1);
      break;
  }
  if (b) {
    v.push_back(b->getX());
    v.push_back(b->getY());
    v.push_back(b->getYaw());
  }
  if (a) {
    for (std::size_t i = 0; i < robot_.armDof(); ++i) v.push_back(a->values[i]);
  }
  return v;
}

void GroupSpace::setValues(const std::vector<double>& v, ob::State* s) const {
  if (v.size() != names_.size()) {
    throw std::invalid_argument("GroupSpace::setValues: " + std::to_string(v.size()) + " values for " +
                                std::to_string(names_.size()) + " joints");
  }
  ob::SE2StateSpace::StateType* b = nullptr;
  ob::RealVectorStateSpace::StateType* a = nullptr;
  switch (group_) {
    case PlanningGroup::kBase: b = s->as<ob::SE2StateSpace::StateType>(); break;
    case PlanningGroup::kArm: a = s->as<ob::RealVectorStateSpace::StateType>(); break;
    case PlanningGroup::kWholeBody:
      b = s->as<ob::CompoundState>()->as<ob::SE2StateSpace::StateType>(0);
      a = s->as<ob::CompoundState>()->as<ob::RealVectorStateSpace::StateType>(1);
      break;
  }
  std::size_t k = 0;
  if (b) {
    b->setXY(v[0], v[1]);
    b->setYaw(wrapAngle(v[2]));
    k = 3;
  }
  if (a) {
    for (std::size_t i = 0; i < robot_.armDof(); ++i) a->values[i] = v[k + i];
  }
}

Pose2D GroupSpace::basePose(const ob::State* s) const {
  const ob::SE2StateSpace::StateType* b = nullptr;
  if (group_ == PlanningGroup::kBase) b = s->as<ob::SE2StateSpace::StateType>();
  if (group_ == PlanningGroup::kWholeBody) b = s->as<ob::CompoundState>()->as<ob::SE2StateSpace::StateType>(0);
  if (!b) return start_.base;
  return Pose2D{b->getX(), b->getY(), b->getYaw()};
}

robot::RobotState GroupSpace::robotState(const ob::State* s) const {
  robot::RobotState r = start_;
  r.base = basePose(s);
  if (movesArm()) {
    const auto* a = group_ == PlanningGroup::kArm
                        ? s->as<ob::RealVectorStateSpace::StateType>()
                        : s->as<ob::CompoundState>()->as<ob::RealVectorStateSpace::StateType>(1);
    for (std::size_t i = 0; i < robot_.armDof(); ++i) r.arm[i] = a->values[i];
  }
  return r;
}

bool GroupSpace::armAboveFloor() const {
  const auto& geo = robot_.geometry();
  for (std::size_t i : arm_parts_) {
    const auto& part = geo.parts[i];
    if (part.shape.aabb(poses_[static_cast<std::size_t>(part.link)] * part.link_T_shape).min.z() < 0.0) return false;
  }
  return true;
}

void GroupSpace::placeRobot(const ob::State* s, collision::Scene& scene) const {
  if (group_ == PlanningGroup::kBase) {
    const Eigen::Isometry3d world_T_base = basePose(s).toIsometry();
    poses_.resize(base_T_link_.size());
    for (std::size_t i = 0; i < base_T_link_.size(); ++i) poses_[i] = world_T_base * base_T_link_[i];
    scene.setLinkPoses(poses_);
    return;
  }
  scratch_.base = basePose(s);
  const auto* a = group_ == PlanningGroup::kArm
                      ? s->as<ob::RealVectorStateSpace::StateType>()
                      : s->as<ob::CompoundState>()->as<ob::RealVectorStateSpace::StateType>(1);
  for (std::size_t i = 0; i < robot_.armDof(); ++i) scratch_.arm[i] = a->values[i];
  robot_.linkPoses(scratch_, poses_);
  scene.setLinkPoses(poses_);
}

// ---- Oracle -----------------------------------------------------------------------------------

Oracle::Oracle(collision::Scene& scene, const GroupSpace& gs, std::vector<std::string> ignored,
               std::vector<MovableInfo> movables, double reach_radius)
    : scene_(scene), gs_(gs), movables_(std::move(movables)) {
  static_filter_ = collision::Filter{collision::kStaticObjects | collision::kUnknownSpace, {}, ignored};
  all_filter_ = collision::Filter{collision::kAllGroups, {}, ignored};
  movable_filter_ = collision::Filter{collision::kMovableObjects, {}, std::move(ignored)};
  for (std::size_t i = 0; i < movables_.size(); ++i) index_[movables_[i].id] = static_cast<int>(i);
  self_check_ = gs.movesArm();
  rigid_ = gs.group() == PlanningGroup::kBase && reach_radius > 0;
  reach_radius_ = reach_radius;
}

std::vector<std::pair<std::string, std::string>> Oracle::selfContacts(const ob::State* s) {
  if (!self_scene_) return scene_.selfCollisions();
  gs_.placeRobot(s, *self_scene_);
  return self_scene_->selfCollisions();
}

bool Oracle::selfFree(const ob::State* s) { return selfContacts(s).empty(); }

void Oracle::setClearance(std::shared_ptr<const collision::ClearanceGrid> grid, std::vector<Eigen::Vector3d> cover) {
  const bool usable = rigid_ && !self_check_ && !scene_.hasUnknownSpace() && !cover.empty();
  clearance_ = usable ? std::move(grid) : nullptr;
  cover_ = usable ? std::move(cover) : std::vector<Eigen::Vector3d>{};
  // A round robot: the reach circle about the base origin is the tighter cover.
  double widest = 0.0;
  for (const auto& k : cover_) widest = std::max(widest, k.z());
  if (usable && reach_radius_ <= widest) cover_ = {Eigen::Vector3d(0.0, 0.0, reach_radius_)};
}

bool Oracle::clearOfStatics(const ob::State* s) {
  if (!clearance_) return false;
  const Pose2D p = gs_.basePose(s);
  const double c = std::cos(p.theta), sn = std::sin(p.theta);
  for (const Eigen::Vector3d& k : cover_) {
    if (clearance_->clearance(p.x + c * k.x() - sn * k.y(), p.y + sn * k.x() + c * k.y()) <= k.z()) return false;
  }
  ++grid_answers_;
  return true;
}

bool Oracle::staticFree(const ob::State* s) {
  ++checks_;
  if (clearOfStatics(s)) return true;
  gs_.placeRobot(s, scene_);
  if (self_check_ && !gs_.armAboveFloor()) return false;
  if (scene_.robotInCollision(static_filter_)) return false;
  return !self_check_ || selfFree(s);
}

bool Oracle::allFree(const ob::State* s) {
  ++checks_;
  if (clearOfStatics(s)) {
    // Only the movables within reach remain (rigid: the reach square prefilter holds).
    bool near = false;
    for (std::size_t i = 0; i < movables_.size() && !near; ++i) near = mayTouch(s, static_cast<int>(i));
    if (!near) return true;
    gs_.placeRobot(s, scene_);
    return !scene_.robotInCollision(movable_filter_);
  }
  gs_.placeRobot(s, scene_);
  if (self_check_ && !gs_.armAboveFloor()) return false;
  if (scene_.robotInCollision(all_filter_)) return false;
  return !self_check_ || selfFree(s);
}

double Oracle::movableDistance(const ob::State* s) {
  ++checks_;
  gs_.placeRobot(s, scene_);
  return scene_.robotDistance(movable_filter_).distance;
}

bool Oracle::mayTouch(const ob::State* s, int index) const {
  if (!rigid_) return true;
  const Pose2D p = gs_.basePose(s);
  const Aabb& box = movables_[static_cast<std::size_t>(index)].aabb;
  const double r = reach_radius_;
  return !(box.max.x() < p.x - r || box.min.x() > p.x + r || box.max.y() < p.y - r || box.min.y() > p.y + r);
}

void Oracle::touched(const ob::State* s, std::vector<int>& out) {
  out.clear();
  if (movables_.empty()) return;
  ++checks_;
  if (rigid_) {
    // The robot's reach square at `s` against the movables' boxes: most states on a roadmap or a
    // shortcut are far from every movable, and then the scene query is skipped.
    bool any = false;
    for (std::size_t i = 0; i < movables_.size() && !any; ++i) any = mayTouch(s, static_cast<int>(i));
    if (!any) return;
  }
  gs_.placeRobot(s, scene_);
  for (const auto& id : scene_.robotCollisions(movable_filter_)) {
    auto it = index_.find(id);
    if (it != index_.end()) out.push_back(it->second);
  }
  std::sort(out.begin(), out.end());
}

bool Oracle::touches(const ob::State* s, int index) {
  ++checks_;
  if (!mayTouch(s, index)) return false;
  gs_.placeRobot(s, scene_);
  collision::Filter f{collision::kMovableObjects, {movables_[static_cast<std::size_t>(index)].id}, {}};
  return scene_.robotInCollision(f);
}

std::string Oracle::collidingObject(const ob::State* s, bool include_movables) {
  gs_.placeRobot(s, scene_);
  const auto ids = scene_.robotCollisions(include_movables ? all_filter_ : static_filter_);
  if (!ids.empty()) return ids.front();
  if (self_check_ && !gs_.armAboveFloor()) return RobotBinding::kFloor;
  if (self_check_ || !scene_.attachedObjects().empty()) {
    const auto self = selfContacts(s);
    if (!self.empty()) return "self:" + self.front().first + "/" + self.front().second;
  }
  return {};
}

void Oracle::candidates(const ob::State* a, const ob::State* b, std::vector<int>& out) const {
  out.clear();
  if (!rigid_) {
    for (std::size_t i = 0; i < movables_.size(); ++i) out.push_back(static_cast<int>(i));
    return;
  }
  const Pose2D pa = gs_.basePose(a), pb = gs_.basePose(b);
  const double r = reach_radius_;
  const double x0 = std::min(pa.x, pb.x) - r, x1 = std::max(pa.x, pb.x) + r;
  const double y0 = std::min(pa.y, pb.y) - r, y1 = std::max(pa.y, pb.y) + r;
  for (std::size_t i = 0; i < movables_.size(); ++i) {
    const Aabb& box = movables_[i].aabb;
    if (box.max.x() < x0 || box.min.x() > x1 || box.max.y() < y0 || box.min.y() > y1) continue;
    out.push_back(static_cast<int>(i));
  }
}

}  // namespace tamp::motion_planner::detail
