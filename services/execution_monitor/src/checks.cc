#include "tamp/execution_monitor/checks.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "tamp/core/format.h"
#include "tamp/core/geometry.h"
#include "tamp/effort_model/features.h"

namespace tamp::execution_monitor {
namespace {

constexpr double kAngleWeight = 0.5;  // m per rad in the path metric
constexpr double kMaxSamplesPerSegment = 1e5;

Error bad(const std::string& field, const std::string& message) {
  return Error(ErrorCode::kInvalidArgument, field + ": " + message,
               SourceLocation{"", 0, 0, field});
}

/// Where a trajectory joint lives in a RobotState.
struct Slot {
  enum class Kind { kBaseX, kBaseY, kBaseTheta, kArm, kGripper } kind;
  int arm_index{-1};
  bool angular{false};
};

std::optional<Slot> slotOf(const std::string& name, const robot::RobotModel& robot) {
  if (name == kBaseJointNames[0]) return Slot{Slot::Kind::kBaseX, -1, false};
  if (name == kBaseJointNames[1]) return Slot{Slot::Kind::kBaseY, -1, false};
  if (name == kBaseJointNames[2]) return Slot{Slot::Kind::kBaseTheta, -1, true};
  const auto& arm = robot.armJointNames();
  const auto it = std::find(arm.begin(), arm.end(), name);
  if (it != arm.end()) {
    const robot::Joint* j = robot.findJoint(name);
    const bool angular = j && j->type != robot::JointType::kPrismatic;
    return Slot{Slot::Kind::kArm, static_cast<int>(it - arm.begin()), angular};
  }
  if (!robot.gripperJointName().empty() && name == robot.gripperJointName()) {
    return Slot{Slot::Kind::kGripper, -1, false};
  }
  return std::nullopt;
}

double& valueOf(robot::RobotState& s, const Slot& slot) {
  switch (slot.kind) {
    case Slot::Kind::kBaseX:
      return s.base.x;
    case Slot::Kind::kBaseY:
      return s.base.y;
    case Slot::Kind::kBaseTheta:
      return s.base.theta;
    case Slot::Kind::kArm:
      return s.arm[static_cast<std::size_t>(slot.arm_index)];
    case Slot::Kind::kGripper:
      return s.gripper;
  }
  throw std::logic_error("slot");
}

std::vector<Slot> slotsOf(const ExecutionCommand& c, const robot::RobotModel& robot) {
  std::vector<Slot> slots;
  for (const auto& name : c.trajectory.joint_names) {
    auto s = slotOf(name, robot);
    if (!s)
      throw std::invalid_argument("execution_monitor: unknown joint '" + name +
                                  "' (validateCommand first)");
    slots.push_back(*s);
  }
  return slots;
}

/// Weighted joint-space distance between two states (the path metric).
double distance(const robot::RobotState& a, const robot::RobotState& b) {
  double d2 =
      (a.base.x - b.base.x) * (a.base.x - b.base.x) + (a.base.y - b.base.y) * (a.base.y - b.base.y);
  const double dt = kAngleWeight * (a.base.theta - b.base.theta);
  d2 += dt * dt;
  for (std::size_t j = 0; j < a.arm.size() && j < b.arm.size(); ++j) {
    const double dj = kAngleWeight * (a.arm[j] - b.arm[j]);
    d2 += dj * dj;
  }
  const double dg = a.gripper - b.gripper;
  return std::sqrt(d2 + dg * dg);
}

robot::RobotState lerp(const robot::RobotState& a, const robot::RobotState& b, double w) {
  robot::RobotState s = a;
  s.base.x += w * (b.base.x - a.base.x);
  s.base.y += w * (b.base.y - a.base.y);
  s.base.theta += w * (b.base.theta - a.base.theta);
  for (std::size_t j = 0; j < s.arm.size() && j < b.arm.size(); ++j)
    s.arm[j] += w * (b.arm[j] - a.arm[j]);
  s.gripper += w * (b.gripper - a.gripper);
  return s;
}

std::string describe(const robot::RobotState& s) {
  return "(" + formatNumber(s.base.x, 3) + ", " + formatNumber(s.base.y, 3) + ", " +
         formatNumber(s.base.theta, 3) + ")";
}

}  // namespace

Status validateCommand(const ExecutionCommand& c, const robot::RobotModel& robot) {
  if (c.command_id.empty()) return bad("command_id", "must not be empty");
  if (std::find(kAllActionKinds.begin(), kAllActionKinds.end(), c.kind) == kAllActionKinds.end()) {
    return bad("kind", "unknown action kind " + std::to_string(static_cast<int>(c.kind)));
  }
  const Trajectory& t = c.trajectory;
  if (t.joint_names.empty()) return bad("trajectory.joint_names", "empty");
  if (t.points.empty()) return bad("trajectory.points", "empty trajectory");
  std::set<std::string> seen;
  bool base = false, arm = false;
  std::size_t base_count = 0;
  for (std::size_t j = 0; j < t.joint_names.size(); ++j) {
    const std::string field = "trajectory.joint_names[" + std::to_string(j) + "]";
    const std::string& name = t.joint_names[j];
    const auto slot = slotOf(name, robot);
    if (!slot) return bad(field, "unknown joint '" + name + "'");
    if (!seen.insert(name).second) return bad(field, "duplicate joint '" + name + "'");
    const bool is_base = slot->kind == Slot::Kind::kBaseX || slot->kind == Slot::Kind::kBaseY ||
                         slot->kind == Slot::Kind::kBaseTheta;
    base |= is_base;
    arm |= !is_base;
    base_count += is_base ? 1 : 0;
    if (c.kind == ActionKind::kMoveBase && !is_base) {
      return bad(field, "move_base moves the base joints only, got '" + name + "'");
    }
    if (c.kind != ActionKind::kMoveBase && is_base) {
      return bad(field, std::string(toString(c.kind)) + " moves the arm only, got base joint '" +
                            name + "'");
    }
  }
  if (c.kind == ActionKind::kMoveBase && base_count != 3) {
    return bad("trajectory.joint_names", "move_base needs base_x, base_y and base_theta");
  }
  (void)arm;
  (void)base;
  double last_t = -1.0;
  for (std::size_t i = 0; i < t.points.size(); ++i) {
    const auto& p = t.points[i];
    const std::string field = "trajectory.points[" + std::to_string(i) + "]";
    if (p.positions.size() != t.joint_names.size()) {
      return bad(field + ".positions", std::to_string(p.positions.size()) + " values for " +
                                           std::to_string(t.joint_names.size()) + " joints");
    }
    if (!p.velocities.empty() && p.velocities.size() != t.joint_names.size()) {
      return bad(field + ".velocities", std::to_string(p.velocities.size()) + " values for " +
                                            std::to_string(t.joint_names.size()) + " joints");
    }
    for (std::size_t j = 0; j < p.positions.size(); ++j) {
      if (!std::isfinite(p.positions[j])) {
        return bad(field + ".positions[" + std::to_string(j) + "]",
                   "not finite (" + t.joint_names[j] + ")");
      }
    }
    for (std::size_t j = 0; j < p.velocities.size(); ++j) {
      if (!std::isfinite(p.velocities[j])) {
        return bad(field + ".velocities[" + std::to_string(j) + "]",
                   "not finite (" + t.joint_names[j] + ")");
      }
    }
    if (!std::isfinite(p.time_from_start) || p.time_from_start < 0.0) {
      return bad(field + ".time_from_start",
                 "must be finite and >= 0, got " + formatNumber(p.time_from_start));
    }
    if (i > 0 && !(p.time_from_start > last_t)) {
      return bad(field + ".time_from_start", "times must increase strictly, got " +
                                                 formatNumber(p.time_from_start) + " after " +
                                                 formatNumber(last_t));
    }
    last_t = p.time_from_start;
  }
  // Arm joints within their limits (the base joints are unbounded).
  for (std::size_t j = 0; j < t.joint_names.size(); ++j) {
    const auto slot = slotOf(t.joint_names[j], robot);
    if (slot->kind != Slot::Kind::kArm) continue;
    const robot::JointLimits& lim = robot.armLimits()[static_cast<std::size_t>(slot->arm_index)];
    for (std::size_t i = 0; i < t.points.size(); ++i) {
      const double v = t.points[i].positions[j];
      if (v < lim.lower - 1e-9 || v > lim.upper + 1e-9) {
        return bad(
            "trajectory.points[" + std::to_string(i) + "].positions[" + std::to_string(j) + "]",
            t.joint_names[j] + " = " + formatNumber(v, 4) + " outside its limits [" +
                formatNumber(lim.lower, 4) + ", " + formatNumber(lim.upper, 4) + "]");
      }
    }
  }
  if ((c.kind == ActionKind::kPick || c.kind == ActionKind::kPlace) && c.object_id.empty()) {
    return bad("object_id", std::string(toString(c.kind)) + " needs the object");
  }
  if (c.kind == ActionKind::kPlace && !c.object_target) {
    return bad("object_target", "place needs the object's target pose (object_target_given)");
  }
  if (c.object_target && !c.object_target->matrix().allFinite())
    return bad("object_target", "not finite");
  if (!std::isfinite(c.expected_duration_s) || c.expected_duration_s < 0.0) {
    return bad("expected_duration_s",
               "must be finite and >= 0, got " + formatNumber(c.expected_duration_s));
  }
  if (!std::isfinite(c.expected_stddev_s) || c.expected_stddev_s < 0.0) {
    return bad("expected_stddev_s",
               "must be finite and >= 0, got " + formatNumber(c.expected_stddev_s));
  }
  return Status::Ok();
}

robot::RobotState stateAt(const ExecutionCommand& c, std::size_t point,
                          const robot::RobotState& current, const robot::RobotModel& robot) {
  if (point >= c.trajectory.points.size()) {
    throw std::invalid_argument("stateAt: point " + std::to_string(point) + " of " +
                                std::to_string(c.trajectory.points.size()));
  }
  robot::RobotState s = current;
  if (s.arm.size() != robot.armDof()) s.arm.resize(robot.armDof(), 0.0);
  const auto slots = slotsOf(c, robot);
  for (std::size_t j = 0; j < slots.size(); ++j)
    valueOf(s, slots[j]) = c.trajectory.points[point].positions[j];
  return s;
}

std::optional<CheckFailure> checkStart(const ExecutionCommand& c, const robot::RobotState& current,
                                       const robot::RobotModel& robot, const StartTolerance& tol) {
  robot::RobotState cur = current;
  if (cur.arm.size() != robot.armDof()) {
    return CheckFailure{"start: the robot state has " + std::to_string(cur.arm.size()) +
                            " arm values, the robot " + std::to_string(robot.armDof()) +
                            " arm joints",
                        ""};
  }
  const auto slots = slotsOf(c, robot);
  const auto& first = c.trajectory.points.front().positions;
  for (std::size_t j = 0; j < slots.size(); ++j) {
    const double actual = valueOf(cur, slots[j]);
    const double diff =
        slots[j].angular ? std::abs(angleDiff(first[j], actual)) : std::abs(first[j] - actual);
    const double limit = slots[j].angular ? tol.angle_rad : tol.position_m;
    if (!(diff <= limit)) {
      return CheckFailure{"start: trajectory.points[0] " + c.trajectory.joint_names[j] + " = " +
                              formatNumber(first[j], 4) + " differs from the robot's " +
                              formatNumber(actual, 4) + " by " + formatNumber(diff, 3) +
                              (slots[j].angular ? " rad" : " m") + " (tolerance " +
                              formatNumber(limit) + "); robot base at " + describe(cur),
                          ""};
    }
  }
  return std::nullopt;
}

std::optional<CheckFailure> checkHeld(const ExecutionCommand& c, const std::string& held) {
  if (c.kind == ActionKind::kPlace && held != c.object_id) {
    return CheckFailure{"held object: place needs the gripper to hold '" + c.object_id + "', " +
                            (held.empty() ? std::string("it is empty") : "it holds '" + held + "'"),
                        held.empty() ? c.object_id : held};
  }
  if (c.kind == ActionKind::kPick && !held.empty()) {
    return CheckFailure{"held object: pick needs an empty hand, the gripper holds '" + held + "'",
                        held};
  }
  return std::nullopt;
}

std::optional<CheckFailure> checkPickTarget(const ExecutionCommand& c, const world::World& world,
                                            double tolerance_m) {
  if (c.kind != ActionKind::kPick) return std::nullopt;
  const world::Object* o = world.findObject(c.object_id);
  if (!o)
    return CheckFailure{"object_id: no object '" + c.object_id + "' in the world model",
                        c.object_id};
  if (o->kind != world::ObjectKind::kMovable) {
    return CheckFailure{"object_id: '" + c.object_id + "' is static in the world model",
                        c.object_id};
  }
  if (c.object_target) {
    const double d = (o->pose.translation() - c.object_target->translation()).norm();
    if (!(d <= tolerance_m)) {
      return CheckFailure{"object_target: '" + c.object_id + "' is " + formatNumber(d, 3) +
                              " m from the commanded pose in the world model (tolerance " +
                              formatNumber(tolerance_m) + " m)",
                          c.object_id};
    }
  }
  return std::nullopt;
}

robot::RobotState SweptPath::at(double f) const {
  if (states.empty()) throw std::invalid_argument("SweptPath::at: empty path");
  f = std::clamp(f, 0.0, 1.0);
  if (states.size() == 1) return states.front();
  const auto it = std::upper_bound(s.begin(), s.end(), f);
  if (it == s.end()) return states.back();
  const std::size_t j = static_cast<std::size_t>(it - s.begin());
  if (j == 0) return states.front();
  const double span = s[j] - s[j - 1];
  return lerp(states[j - 1], states[j], span > 0.0 ? (f - s[j - 1]) / span : 1.0);
}

double SweptPath::project(const robot::RobotState& state, double from) const {
  if (states.size() < 2 || length <= 0.0) return from;
  double best_f = from, best_d = std::numeric_limits<double>::infinity();
  for (std::size_t j = 1; j < states.size(); ++j) {
    if (s[j] < from) continue;
    // Nearest point on the segment, by bisection-free sampling of the straight segment: the
    // metric is Euclidean (weighted), so the projection has a closed form.
    const robot::RobotState& a = states[j - 1];
    const robot::RobotState& b = states[j];
    const double seg = distance(a, b);
    double w = 0.0;
    if (seg > 0.0) {
      // <state - a, b - a> / |b - a|^2 in the weighted metric.
      double dot = (state.base.x - a.base.x) * (b.base.x - a.base.x) +
                   (state.base.y - a.base.y) * (b.base.y - a.base.y) +
                   kAngleWeight * kAngleWeight * (state.base.theta - a.base.theta) *
                       (b.base.theta - a.base.theta) +
                   (state.gripper - a.gripper) * (b.gripper - a.gripper);
      for (std::size_t k = 0; k < a.arm.size() && k < state.arm.size(); ++k) {
        dot += kAngleWeight * kAngleWeight * (state.arm[k] - a.arm[k]) * (b.arm[k] - a.arm[k]);
      }
      w = std::clamp(dot / (seg * seg), 0.0, 1.0);
    }
    double f = s[j - 1] + w * (s[j] - s[j - 1]);
    if (f < from) {
      f = from;
    }
    const double d = distance(at(f), state);
    if (d < best_d - 1e-9) {
      best_d = d;
      best_f = f;
    }
  }
  return std::max(best_f, from);
}

namespace {

/// The states a stop-and-turn base passes through (effort_model::baseSteps: turn in place to each
/// straight run's heading, drive it, turn to the last heading), so that straight interpolation
/// between them sweeps what the robot sweeps; a holonomic blend of position and yaw does not.
std::vector<robot::RobotState> stopAndTurn(const std::vector<robot::RobotState>& states) {
  if (states.size() < 2) return states;
  std::vector<Pose2D> poses;
  for (const auto& s : states) poses.push_back(s.base);
  std::vector<robot::RobotState> out{states.front()};
  for (const auto& step : effort_model::baseSteps(poses)) {
    if (step.kind == effort_model::BaseStep::Kind::kTurn) {
      robot::RobotState n = out.back();
      n.base.theta += angleDiff(step.target_heading, n.base.theta);
      out.push_back(n);
      continue;
    }
    for (std::size_t i : step.points) {
      robot::RobotState n = out.back();
      n.base.x = states[i].base.x;
      n.base.y = states[i].base.y;
      out.push_back(n);
    }
  }
  return out;
}

/// The robot's shapes `by` smaller on each side (see `world::shrunk`).
collision::RobotGeometry shrunk(collision::RobotGeometry g, double by) {
  for (auto& part : g.parts) part.shape = world::shrunk(part.shape, by);
  return g;
}

}  // namespace

SweptPath makePath(const ExecutionCommand& c, const robot::RobotState& current,
                   const robot::RobotModel& robot) {
  SweptPath p;
  for (std::size_t i = 0; i < c.trajectory.points.size(); ++i)
    p.states.push_back(stateAt(c, i, current, robot));
  if (c.kind == ActionKind::kMoveBase) p.states = stopAndTurn(p.states);
  std::vector<double> cum{0.0};
  for (std::size_t i = 1; i < p.states.size(); ++i)
    cum.push_back(cum.back() + distance(p.states[i - 1], p.states[i]));
  p.length = cum.back();
  for (double v : cum) p.s.push_back(p.length > 0.0 ? v / p.length : 0.0);
  if (p.length <= 0.0 && !p.s.empty()) p.s.back() = 1.0;
  return p;
}

PathChecker::PathChecker(const robot::RobotModel& robot, PathCheckParams params)
    : robot_(&robot), params_(params) {
  if (!(params_.step_m > 0.0) || !(params_.step_rad > 0.0) || !std::isfinite(params_.step_m) ||
      !std::isfinite(params_.step_rad)) {
    throw std::invalid_argument("PathChecker: path_check steps must be positive, got step_m " +
                                formatNumber(params_.step_m) + ", step_rad " +
                                formatNumber(params_.step_rad));
  }
  scene_.setRobot(shrunk(robot.collisionGeometry(), params_.tolerance_m));
}

void PathChecker::setWorld(const world::World& world) {
  if (has_world_) {
    scene_.syncWorld(world);
  } else {
    scene_.setWorld(world);
    has_world_ = true;
  }
}

std::vector<std::string> PathChecker::contactsAt(const robot::RobotState& state) {
  robot_->linkPoses(state, poses_);
  scene_.setLinkPoses(poses_);
  return scene_.robotCollisions();
}

std::vector<std::string> PathChecker::startContactsAt(const robot::RobotState& state) {
  std::vector<std::string> out = contactsAt(state);
  if (!(params_.start_contact_m > 0.0)) return out;
  // Nearest first, one distance query per object found (few objects are ever this near).
  for (;;) {
    const collision::DistanceResult d = scene_.robotDistance(collision::Filter::allBut(out));
    if (!d.found() || d.distance > params_.start_contact_m ||
        std::find(out.begin(), out.end(), d.object) != out.end())
      break;
    out.push_back(d.object);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::optional<PathChecker::Hit> PathChecker::firstContact(const SweptPath& path, double from,
                                                          const std::vector<std::string>& ignore) {
  if (path.states.empty()) return std::nullopt;
  const collision::Filter filter = collision::Filter::allBut(ignore);
  auto check = [&](const robot::RobotState& s) -> std::optional<std::string> {
    robot_->linkPoses(s, poses_);
    scene_.setLinkPoses(poses_);
    const auto hits = scene_.robotCollisions(filter);
    if (hits.empty()) return std::nullopt;
    return hits.front();
  };
  from = std::clamp(from, 0.0, 1.0);
  if (auto hit = check(path.at(from))) return Hit{*hit, from};
  for (std::size_t j = 1; j < path.states.size(); ++j) {
    if (path.s[j] < from) continue;
    const robot::RobotState& a = path.states[j - 1];
    const robot::RobotState& b = path.states[j];
    double steps = std::hypot(b.base.x - a.base.x, b.base.y - a.base.y) / params_.step_m;
    steps = std::max(steps, std::abs(b.base.theta - a.base.theta) / params_.step_rad);
    for (std::size_t k = 0; k < a.arm.size() && k < b.arm.size(); ++k) {
      steps = std::max(steps, std::abs(b.arm[k] - a.arm[k]) / params_.step_rad);
    }
    steps = std::max(steps, std::abs(b.gripper - a.gripper) / params_.step_m);
    // Bounded: a segment of kilometres is checked more coarsely rather than for ever.
    const int n = static_cast<int>(std::clamp(std::ceil(steps), 1.0, kMaxSamplesPerSegment));
    for (int i = 1; i <= n; ++i) {
      const double w = static_cast<double>(i) / n;
      const double f = path.s[j - 1] + w * (path.s[j] - path.s[j - 1]);
      if (f <= from) continue;
      if (auto hit = check(lerp(a, b, w))) return Hit{*hit, f};
    }
  }
  return std::nullopt;
}

std::vector<std::string> PathChecker::supportsOf(const world::Object& o,
                                                 const Eigen::Isometry3d& pose) const {
  constexpr double kProbe = 0.005;  // m
  std::vector<std::string> out;
  if (!has_world_) return out;
  const double bottom = o.shape.aabb(pose).min.z();
  Eigen::Isometry3d probe = pose;
  probe.translation().z() -= kProbe;
  for (const auto& id : scene_.shapeCollisions(o.shape, probe, collision::Filter::allBut({o.id}))) {
    const world::Object* other = scene_.world().findObject(id);
    if (other && other->aabb().max.z() <= bottom + kProbe) out.push_back(id);
  }
  return out;
}

std::vector<std::string> allowedContacts(const ExecutionCommand& c, const std::string& held) {
  std::vector<std::string> out;
  if (!c.object_id.empty()) out.push_back(c.object_id);
  if (!held.empty() && held != c.object_id) out.push_back(held);
  return out;
}

}  // namespace tamp::execution_monitor
