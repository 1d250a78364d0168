#include "tamp/core/format.h"
#include "tamp/sim/simulator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <unordered_map>
#include <stdexcept>

#include "tamp/collision/scene.h"
#include "tamp/core/geometry.h"
#include "tamp/core/log.h"
#include "tamp/effort_model/features.h"
#include "tamp/sim/dynamics.h"
#include "tamp/sim/depth_sensor.h"
#include "tamp/sim/ray_scene.h"

namespace tamp::sim {
namespace {

/// Angle (rad) of the object's z axis from vertical, up to the shape's symmetry: a box, a
/// cylinder or a sphere upside down stands as well as upright.
double tiltFromUpright(const world::Shape& shape, const Eigen::Isometry3d& pose) {
  const double c = pose.linear()(2, 2);
  const bool flips = shape.kind == world::ShapeKind::kBox || shape.kind == world::ShapeKind::kCylinder ||
                     shape.kind == world::ShapeKind::kSphere;
  return std::acos(std::clamp(flips ? std::abs(c) : c, -1.0, 1.0));
}

/// The rotation (rad) from `a` to `b` up to the shape's symmetries: a cylinder looks the same
/// turned by any angle about its axis, a box turned by pi (pi/2 with a square footprint), and
/// both upside down. A box placed "rotated by pi" is placed where it was commanded.
double symmetricTurn(const world::Shape& shape, const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Matrix3d rel = a.linear().transpose() * b.linear();
  if (shape.kind == world::ShapeKind::kCylinder) {
    // Only the tilt of the z axis counts; upside down is the same cylinder.
    return std::acos(std::clamp(std::abs(rel(2, 2)), 0.0, 1.0));
  }
  double best = Eigen::AngleAxisd(rel).angle();
  if (shape.kind == world::ShapeKind::kBox) {
    const bool square = std::abs(shape.size.x() - shape.size.y()) < 1e-9;
    // Turns about z, and the same upside down (a flip about x).
    for (const Eigen::Matrix3d& flip : {Eigen::Matrix3d(Eigen::Matrix3d::Identity()),
                                        Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix()}) {
      for (int k = 0; k < 4; ++k) {
        if (!square && k % 2 == 1) continue;
        const Eigen::Matrix3d z = Eigen::AngleAxisd(k * M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
        best = std::min(best, Eigen::AngleAxisd(Eigen::Matrix3d(rel * flip * z)).angle());
      }
    }
  }
  return best;
}

using Vec = Eigen::VectorXd;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kFloorTolerance = 1e-4;
constexpr double kSupportProbe = 0.005;  // m: how far below an object its supports are looked for
/// A pushed object slides on this far after the base stops (m): the base is not left touching it.
constexpr double kPushSlide = 0.01;
/// m: how far a place may press the held object into its support (the arm's compliance): a
/// place's contact with the support is no stop up to this depth, and settle() accepts a release
/// this far into it (its ray starts as high above the object's bottom).
constexpr double kPlacePress = 0.02;

const std::shared_ptr<spdlog::logger>& logger() {
  static const auto l = tamp::log::get("sim");
  return l;
}

Error invalid(const std::string& field, const std::string& message) {
  return Error(ErrorCode::kInvalidArgument, field + ": " + message, SourceLocation{"", 0, 0, field});
}

double boundingRadius(const world::Shape& s) {
  switch (s.kind) {
    case world::ShapeKind::kBox:
      return 0.5 * s.size.norm();
    case world::ShapeKind::kSphere:
      return s.radius;
    case world::ShapeKind::kCylinder:
      return std::hypot(s.radius, 0.5 * s.height);
    case world::ShapeKind::kPrism: {
      double r = 0.0;
      for (const auto& v : s.polygon) r = std::max(r, v.norm());
      return std::hypot(r, 0.5 * s.height);
    }
  }
  return 0.0;
}

/// Width of `s` along the unit direction `d` (shape frame).
double widthAlong(const world::Shape& s, const Eigen::Vector3d& d) {
  switch (s.kind) {
    case world::ShapeKind::kBox:
      return s.size.cwiseProduct(d.cwiseAbs()).sum();
    case world::ShapeKind::kSphere:
      return 2.0 * s.radius;
    case world::ShapeKind::kCylinder:
      return 2.0 * s.radius * std::hypot(d.x(), d.y()) + s.height * std::abs(d.z());
    case world::ShapeKind::kPrism: {
      double lo = kInf, hi = -kInf;
      for (const auto& v : s.polygon) {
        const double p = v.x() * d.x() + v.y() * d.y();
        lo = std::min(lo, p);
        hi = std::max(hi, p);
      }
      return (hi - lo) + s.height * std::abs(d.z());
    }
  }
  return 0.0;
}

/// A piecewise-linear path in the full joint space with a cumulative parameter u (metres of
/// drive, radians of turn, scaled joint displacement, or metres of tool path).
struct GeoPath {
  std::vector<Vec> q;
  std::vector<double> u;

  Vec at(double fraction) const {
    if (q.size() == 1 || u.back() <= 0.0) return fraction >= 1.0 ? q.back() : q.front();
    const double target = std::clamp(fraction, 0.0, 1.0) * u.back();
    const auto it = std::upper_bound(u.begin(), u.end(), target);
    if (it == u.end()) return q.back();
    const std::size_t j = static_cast<std::size_t>(it - u.begin());  // u[j-1] <= target < u[j]
    const double span = u[j] - u[j - 1];
    const double w = span > 0.0 ? (target - u[j - 1]) / span : 1.0;
    return q[j - 1] + w * (q[j] - q[j - 1]);
  }
};

struct Phase {
  enum class Kind { kPause, kMotion, kGripper } kind{Kind::kPause};
  double nominal{0.0};  // model duration, s (before the noise factor)
  double t0{0.0}, t1{0.0};  // actual times relative to the action start
  GeoPath path;             // kMotion
  double length{0.0};
  MotionProfile profile;    // kMotion: the true timing along path.u
  Vec start, end;
};

/// A scripted fault scheduled within the action in progress.
struct ScheduledFault {
  std::size_t index;  // into Impl::scripted
  double rel_time;
};

struct Active {
  ActionCommand cmd;
  int step{0};
  double start{0.0};  // sim time
  double k{1.0};      // noise factor
  std::vector<Phase> phases;
  double total{0.0};
  double end{0.0};  // relative time the action ends (total or an early stop)
  Outcome outcome{Outcome::kSucceeded};
  std::string blocking;
  std::string blocking_part;  // the robot's link (or held object) that would touch it
  std::string reason;
  std::string failure;  // a manipulation failure found at the grasp (reported at the end)
  int gripper_phase{-1};
  bool gripper_done{false};
  double approach_m{0.0}, retreat_m{0.0}, mass{0.0};
  std::vector<std::string> ignore_objects;
  std::vector<std::pair<std::string, std::string>> ignore_pairs;  // (robot part / attached, object)
  std::vector<ScheduledFault> faults;
  std::optional<Fault> fail_fault;  // injected "fail next action"
  double fail_at{kInf};
  // A push: the object riding ahead of the base, how far the base drove before touching it, the
  // direction and the base's start.
  // It moves only forward, as far as the base came past contact (a base backing off after the
  // push leaves it): the base's furthest progress so far, and at the trajectory's end.
  std::string pushed;
  double push_gap{0.0};
  Eigen::Vector2d push_dir{1.0, 0.0};
  Eigen::Vector2d push_from{0.0, 0.0};
  Eigen::Isometry3d push_start{Eigen::Isometry3d::Identity()};
  double push_max{0.0};
  double push_apex{0.0};
};

}  // namespace

std::string_view toString(Outcome outcome) {
  switch (outcome) {
    case Outcome::kSucceeded: return "succeeded";
    case Outcome::kBlocked: return "blocked";
    case Outcome::kFailed: return "failed";
    case Outcome::kCancelled: return "cancelled";
  }
  return "unknown";
}

struct Simulator::Impl {
  world::World world;
  robot::RobotModel robot;
  SimParams params;
  collision::Scene scene;
  DepthSensor sensor;
  std::unordered_map<std::string, double> joint_speed;  // URDF velocity limit per arm joint
  std::vector<std::string> full_names;
  int dof{0};
  bool has_gripper{false};
  int tool_link{-1};
  double r_arm{0.0};   // bound: displacement of any arm point per radian of any arm joint
  double r_base{0.0};  // bound: displacement of any robot point per radian of base turn
  std::vector<bool> hand_link;  // per link: part of the hand (gripper)
  Vec idle;            // the robot's state when no action runs
  double now{0.0};
  double epoch_s{0.0};
  int actions{0};
  std::mt19937_64 rng;
  std::vector<Fault> scripted;
  std::vector<bool> fired;
  std::vector<Fault> injected;        // fire at the next step()
  std::vector<Fault> pending_fails;   // kFailAction waiting for the next (matching) action
  std::optional<Active> active;
  std::vector<Eigen::Isometry3d> link_poses;  // scratch
  std::string last_contact_part;  // scratch: the robot part of the last contact found
  struct Riding {
    std::string id;
    int link;
    Eigen::Isometry3d link_T_object;
  };
  std::vector<Riding> riding;  // objects resting on the robot (dropped onto it), carried along
  std::vector<ActionLogEntry> log;            // every accepted action, in order (the truth)
  std::map<std::string, std::size_t> logged;  // command id -> index in `log`
  std::vector<ActionResult> replayed;         // results of repeated ids, out at the next step()
  // The commanding side's own names of objects it perceived (perception's ids), bound to objects
  // of the truth when a command first names one: the physical world has no ids. Commanded id ->
  // truth id.
  std::map<std::string, std::string> names;

  std::string truthId(const std::string& id) const {
    const auto it = names.find(id);
    return it == names.end() ? id : it->second;
  }
  /// The name the commanding side uses for the truth's object `id`.
  std::string commandedId(const std::string& id) const {
    for (const auto& [commanded, truth] : names)
      if (truth == id) return commanded;
    return id;
  }
  /// `c` with its object named as the truth names it. An id the truth does not know, in a command
  /// with the object's pose (pick, place), is bound to the movable object that pose lies in (the
  /// nearest centre within the object's bounding radius), once; otherwise the id stays, and the
  /// command fails as naming no object.
  ActionCommand inTruthNames(ActionCommand c) {
    if (c.object_id.empty() || world.findObject(c.object_id) != nullptr) return c;
    if (names.count(c.object_id)) {
      c.object_id = names.at(c.object_id);
      return c;
    }
    if (!c.object_pose || !c.object_pose->matrix().allFinite()) return c;
    const world::Object* best = nullptr;
    double best_d = 0.0;
    for (const auto& o : world.objects()) {
      if (o.kind != world::ObjectKind::kMovable || commandedId(o.id) != o.id) continue;
      const double d = (o.pose.translation() - c.object_pose->translation()).norm();
      if (d <= boundingRadius(o.shape) && (best == nullptr || d < best_d)) best = &o, best_d = d;
    }
    if (best == nullptr) return c;
    logger()->info("'{}' of the commands is '{}' ({:.3f} m from the commanded pose)", c.object_id, best->id, best_d);
    names[c.object_id] = best->id;
    c.object_id = best->id;
    return c;
  }

  Impl(world::World w, robot::RobotModel r, SimParams p)
      : world(std::move(w)), robot(std::move(r)), params(std::move(p)), sensor(params.sensor) {}

  // ---- state conversions ------------------------------------------------------------------------
  robot::RobotState toState(const Vec& q) const {
    robot::RobotState s;
    s.base = Pose2D{q[0], q[1], q[2]};
    s.arm.assign(q.data() + 3, q.data() + 3 + dof);
    if (has_gripper) s.gripper = q[3 + dof];
    return s;
  }
  Vec toVec(const robot::RobotState& s) const {
    Vec q(static_cast<Eigen::Index>(full_names.size()));
    q[0] = s.base.x;
    q[1] = s.base.y;
    q[2] = s.base.theta;
    for (int j = 0; j < dof; ++j) q[3 + j] = s.arm[j];
    if (has_gripper) q[3 + dof] = s.gripper;
    return q;
  }

  double heldMass() const {
    if (!world.held()) return 0.0;
    const auto* o = world.findObject(world.held()->object_id);
    return o ? o->mass : 0.0;
  }
  /// How far the held object and objects riding on the robot reach beyond its links (m).
  double heldExtent() const {
    double r = 0.0;
    if (world.held()) {
      if (const auto* o = world.findObject(world.held()->object_id)) {
        r = world.held()->link_T_object.translation().norm() + boundingRadius(o->shape);
      }
    }
    for (const auto& ride : riding) {
      if (const auto* o = world.findObject(ride.id)) {
        r = std::max(r, ride.link_T_object.translation().norm() + boundingRadius(o->shape));
      }
    }
    return r;
  }

  void computeBounds() {
    // Distal links of the first arm joint (the arm, the gripper and its fingers).
    const auto& joints = robot.joints();
    const auto* first = robot.findJoint(robot.armJointNames().front());
    std::set<std::string> distal{first->child_link};
    double chain = 0.0;
    for (bool grew = true; grew;) {
      grew = false;
      for (const auto& j : joints) {
        if (distal.count(j.parent_link) && !distal.count(j.child_link)) {
          distal.insert(j.child_link);
          chain += j.parent_T_joint.translation().norm();
          grew = true;
        }
      }
    }
    const auto& geo = robot.collisionGeometry();
    double arm_part = 0.0;
    robot.linkPoses(robot.defaultState(Pose2D{}), link_poses);
    double base_fixed = 0.0;
    for (const auto& part : geo.parts) {
      const double r = boundingRadius(part.shape);
      if (distal.count(geo.links[part.link])) {
        arm_part = std::max(arm_part, part.link_T_shape.translation().norm() + r);
      } else {
        base_fixed = std::max(base_fixed, (link_poses[part.link] * part.link_T_shape).translation().norm() + r);
      }
    }
    r_arm = chain + arm_part;
    // The hand: links from the last arm joint on (a dropped object does not land on it).
    const auto* last = robot.findJoint(robot.armJointNames().back());
    std::set<std::string> hand{last->child_link};
    for (bool grew = true; grew;) {
      grew = false;
      for (const auto& j : joints) {
        if (hand.count(j.parent_link) && !hand.count(j.child_link)) {
          hand.insert(j.child_link);
          grew = true;
        }
      }
    }
    hand_link.assign(geo.links.size(), false);
    for (std::size_t i = 0; i < geo.links.size(); ++i) hand_link[i] = hand.count(geo.links[i]) > 0;
    const int li = robot.linkIndex(first->parent_link);
    const double shoulder = (link_poses[li] * first->parent_T_joint).translation().norm();
    r_base = std::max(base_fixed, shoulder + r_arm);
  }

  /// Upper bound of the displacement of any robot point between q0 and q1.
  double displacementBound(const Vec& q0, const Vec& q1) const {
    const double extra = heldExtent();
    double arm = 0.0;
    for (int j = 0; j < dof; ++j) arm += std::abs(q1[3 + j] - q0[3 + j]);
    double b = std::hypot(q1[0] - q0[0], q1[1] - q0[1]) + std::abs(q1[2] - q0[2]) * (r_base + extra) +
               arm * (r_arm + extra);
    if (has_gripper) b += std::abs(q1[3 + dof] - q0[3 + dof]);
    return b;
  }

  // ---- collision --------------------------------------------------------------------------------
  /// The first object the robot at q touches, or "" (objects and pairs of `a` ignored).
  std::string contactAt(const Vec& q, const Active* a) {
    robot.linkPoses(toState(q), link_poses);
    scene.setLinkPoses(link_poses);
    collision::Filter filter;
    if (a) filter.ignore = a->ignore_objects;
    for (const auto& c : scene.robotContacts(filter)) {
      bool ignored = false;
      if (a) {
        for (const auto& [r, o] : a->ignore_pairs) ignored |= (c.robot == r && c.object == o);
      }
      if (!ignored) {
        last_contact_part = c.robot;
        return c.object;
      }
    }
    // The floor plane: no part of the robot may go below it.
    const auto& geo = robot.collisionGeometry();
    for (const auto& part : geo.parts) {
      if (part.shape.aabb(link_poses[part.link] * part.link_T_shape).min.z() < -kFloorTolerance) {
        last_contact_part = geo.links[part.link];
        return std::string(kFloorId);
      }
    }
    return "";
  }

  std::vector<std::string> objectsTouching(const Vec& q) {
    robot.linkPoses(toState(q), link_poses);
    scene.setLinkPoses(link_poses);
    return scene.robotCollisions();
  }

  /// Objects an object at `pose` rests on: those it touches (or nearly: probed 5 mm lower) whose
  /// top is not above its bottom.
  /// `press`: a support may also reach this far above the object's bottom (a place pressing
  /// the object into it).
  std::vector<std::string> supportsOf(const world::Object& o, const Eigen::Isometry3d& pose,
                                      double press = kSupportProbe) {
    std::vector<std::string> out;
    const double bottom = o.shape.aabb(pose).min.z();
    Eigen::Isometry3d probe = pose;
    probe.translation().z() -= kSupportProbe;
    for (const auto& id : scene.shapeCollisions(o.shape, probe, collision::Filter::allBut({o.id}))) {
      const auto* other = world.findObject(id);
      if (other && other->aabb().max.z() <= bottom + press) out.push_back(id);
    }
    return out;
  }

  double fractionAt(const Phase& p, double rel, double k) const {
    if (p.length <= 0.0) return rel >= p.t1 ? 1.0 : 0.0;
    const double s = p.profile.positionAt((rel - p.t0) / k);
    return s / p.length;
  }

  Vec stateAt(const Active& a, double rel) const {
    rel = std::clamp(rel, 0.0, a.end);
    for (const Phase& p : a.phases) {
      if (rel > p.t1) continue;
      if (p.kind != Phase::Kind::kMotion) return p.start;
      return p.path.at(fractionAt(p, rel, a.k));
    }
    return a.phases.empty() ? idle : a.phases.back().end;
  }

  /// Sweeps the rest of the action from relative time `from`: the relative time at which the
  /// robot must stop before a contact (and the object), or nothing when the way is clear.
  std::optional<std::pair<double, std::string>> sweep(Active& a, double from) {
    for (const Phase& p : a.phases) {
      if (p.kind != Phase::Kind::kMotion || p.t1 <= from) continue;
      const double f_from = p.t0 >= from ? 0.0 : fractionAt(p, from, a.k);
      const double U = p.path.u.back();
      double f_prev = f_from;
      const double t_prev0 = std::max(from, p.t0);
      // The starting sample itself (a new object may have appeared on the robot).
      if (from > 0.0 || p.t0 > 0.0) {
        const std::string hit = contactAt(p.path.at(f_from), &a);
        if (!hit.empty()) {
          a.blocking_part = last_contact_part;
          return std::pair{t_prev0, hit};
        }
      }
      for (std::size_t j = 1; j < p.path.q.size(); ++j) {
        const double u0 = p.path.u[j - 1], u1 = p.path.u[j];
        if (U > 0.0 && u1 / U <= f_from) continue;
        const int n = std::max(
            1, static_cast<int>(std::ceil(displacementBound(p.path.q[j - 1], p.path.q[j]) / params.max_step_m)));
        for (int i = 1; i <= n; ++i) {
          const double w = static_cast<double>(i) / n;
          const double f = U > 0.0 ? (u0 + w * (u1 - u0)) / U : 1.0;
          if (f <= f_from) continue;
          const Vec q = p.path.q[j - 1] + w * (p.path.q[j] - p.path.q[j - 1]);
          const std::string hit = contactAt(q, &a);
          if (!hit.empty()) {
            a.blocking_part = last_contact_part;
            const double t = f_prev <= f_from ? t_prev0
                                               : p.t0 + a.k * p.profile.timeAt(f_prev * p.length);
            return std::pair{t, hit};
          }
          f_prev = f;
        }
      }
    }
    return std::nullopt;
  }

  /// Re-checks the action in progress after the world changed at relative time `rel`.
  void resweep(double rel) {
    if (!active) return;
    Active& a = *active;
    // A failed or cancelled action has stopped already; a blocked one is re-planned: the world
    // change may block it earlier, or remove what blocked it.
    if (a.outcome != Outcome::kSucceeded && a.outcome != Outcome::kBlocked) return;
    a.outcome = Outcome::kSucceeded;
    a.end = a.total;
    a.blocking.clear();
    if (auto stop = sweep(a, rel)) {
      a.end = std::max(rel, stop->first);
      a.outcome = Outcome::kBlocked;
      a.blocking = stop->second;
    }
  }

  void syncScene() {
    scene.syncWorld(world);
  }

  /// The collision scene built anew over `world` (the held object attached, posed at `idle`).
  Status rebuildScene() {
    scene = collision::Scene(world);
    scene.setRobot(robot.collisionGeometry());
    if (Status s = scene.attachHeld(); !s) return s;
    syncHeldPose(idle);
    syncScene();
    return Status::Ok();
  }

  /// Keeps the world poses of the held object and of objects resting on the robot where the
  /// robot's links are.
  void syncHeldPose(const Vec& q) {
    if (!world.held() && riding.empty()) return;
    const robot::RobotState st = toState(q);
    if (world.held()) {
      auto pose = robot.heldObjectPose(st, *world.held());
      if (pose) (void)world.setObjectPose(world.held()->object_id, *pose);
    }
    if (!riding.empty()) {
      robot.linkPoses(st, link_poses);
      for (const auto& r : riding) (void)world.setObjectPose(r.id, link_poses[r.link] * r.link_T_object);
    }
    if (active && !active->pushed.empty()) {
      Active& a = *active;
      a.push_max = std::max(a.push_max, (Eigen::Vector2d(q[0], q[1]) - a.push_from).dot(a.push_dir));
      (void)world.setObjectPose(a.pushed, pushedPose(a, a.push_max));
    }
  }

  /// Where the pushed object is once the base came `progress` m along the push.
  static Eigen::Isometry3d pushedPose(const Active& a, double progress) {
    Eigen::Isometry3d pose = a.push_start;
    pose.translation().head<2>() += std::max(0.0, progress - a.push_gap) * a.push_dir;
    return pose;
  }

  Vec current() const { return active ? stateAt(*active, now - active->start) : idle; }

  // ---- physics of objects -----------------------------------------------------------------------
  /// Where an object released at `pose` comes to rest.
  struct Settled {
    Eigen::Isometry3d pose;
    std::string region;     ///< support region (its surface height matches), else empty
    std::string support;    ///< object id or robot link it rests on; empty: the floor
    int robot_link{-1};     ///< >= 0: it rests on this robot link
    double drop{0.0};       ///< release height above the support (m; < 0: released into it)
    double tilt{0.0};       ///< angle of its z axis from vertical at release (rad)
  };
  /// The object falls straight down from `pose` (a vertical ray from its centre, started 2 cm
  /// above its bottom) onto the first surface: another object, a robot link, or the floor; it
  /// comes to rest upright with its yaw kept. Physics beyond that (toppling, sliding off an edge
  /// its centre is over) is not simulated.
  Settled settle(const world::Object& o, const Eigen::Isometry3d& pose, const Vec& q) {
    Settled s;
    const double bottom = o.shape.aabb(pose).min.z();
    const Eigen::Vector3d c = pose.translation();
    RayScene rays;
    rays.setFloor(0.0);
    std::vector<std::string> ids;
    for (const world::Object& other : world.objects()) {
      if (other.id == o.id) continue;
      rays.add(other.shape, other.pose, static_cast<int>(ids.size()));
      ids.push_back(other.id);
    }
    robot.linkPoses(toState(q), link_poses);
    const auto& geo = robot.collisionGeometry();
    const int first_link = static_cast<int>(ids.size());
    for (const auto& part : geo.parts) {
      if (hand_link[part.link]) continue;
      rays.add(part.shape, link_poses[part.link] * part.link_T_shape, first_link + part.link);
    }
    rays.build();
    const double start = std::min(c.z(), bottom + 0.02);
    const RayHit hit = rays.cast(Eigen::Vector3d(c.x(), c.y(), start), -Eigen::Vector3d::UnitZ(), 0.0, kInf);
    const double surface = hit.hit() ? start - hit.t : 0.0;
    if (hit.tag >= first_link) {
      s.robot_link = hit.tag - first_link;
      s.support = geo.links[s.robot_link];
    } else if (hit.tag >= 0) {
      s.support = ids[hit.tag];
    }
    if (s.robot_link < 0) {
      const world::Region* region = world.regionBelow(Eigen::Vector3d(c.x(), c.y(), surface), 0.02);
      if (region && std::abs(region->height - surface) <= 0.02) s.region = region->id;
    }
    s.drop = bottom - surface;
    s.tilt = tiltFromUpright(o.shape, pose);
    const double yaw = std::atan2(pose.linear()(1, 0), pose.linear()(0, 0));
    s.pose = Eigen::Isometry3d::Identity();
    s.pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    s.pose.translation() = Eigen::Vector3d(c.x(), c.y(), surface + o.shape.halfHeight());
    return s;
  }

  /// Puts object `o` (detached, not held) at its settled place; one resting on the robot rides
  /// along with that link (attached to it in the collision scene).
  void rest(world::Object o, const Settled& s) {
    o.pose = s.pose;
    o.region = s.region;
    (void)world.updateObject(o);
    syncScene();
    if (s.robot_link >= 0) {
      const std::string& link = robot.collisionGeometry().links[s.robot_link];
      const Eigen::Isometry3d link_T_object = link_poses[s.robot_link].inverse() * s.pose;
      if (scene.attach(o.id, link, link_T_object)) riding.push_back({o.id, s.robot_link, link_T_object});
    }
  }

  /// Stops tracking `id` as riding on the robot (it is being picked or removed).
  void stopRiding(const std::string& id) {
    for (auto it = riding.begin(); it != riding.end(); ++it) {
      if (it->id == id) {
        (void)scene.detach(id);
        riding.erase(it);
        return;
      }
    }
  }

  /// A push starts: the base must touch `a.cmd.object_id` first, within the contact gap,
  /// driving straight towards the trajectory's end; the object then rides ahead of the base.
  Status startPush(Active& a) {
    const auto& pts = a.cmd.trajectory.points;
    const Eigen::Vector2d p0(pts.front().positions[0], pts.front().positions[1]);
    Eigen::Vector2d d = Eigen::Vector2d::Zero();  // towards the point farthest from the start
    for (const auto& p : pts) {
      const Eigen::Vector2d v = Eigen::Vector2d(p.positions[0], p.positions[1]) - p0;
      if (v.norm() > d.norm()) d = v;
    }
    if (d.norm() < 1e-6) {
      return Error(ErrorCode::kInvalidArgument, "a push must drive the base", SourceLocation{"", 0, 0, "trajectory"});
    }
    d.normalize();
    double gap = -1.0;
    for (double s = 0.0; s <= params.push.max_contact_gap_m + 1e-9; s += 0.005) {
      Vec q = idle;
      q[0] += s * d.x();
      q[1] += s * d.y();
      const std::string hit = contactAt(q, nullptr);
      if (hit.empty()) continue;
      if (hit != a.cmd.object_id) {
        return Error(ErrorCode::kInvalidArgument, "push of '" + a.cmd.object_id + "': the base touches '" + hit + "' first",
                     SourceLocation{"", 0, 0, "object_id"});
      }
      gap = s;
      break;
    }
    if (gap < 0.0) {
      return Error(ErrorCode::kInvalidArgument,
                   "push of '" + a.cmd.object_id + "': it is not within " + formatNumber(params.push.max_contact_gap_m) +
                       " m ahead of the base",
                   SourceLocation{"", 0, 0, "object_id"});
    }
    const auto& geo = robot.collisionGeometry();
    const auto it = std::find(geo.links.begin(), geo.links.end(), robot.options().base_link);
    if (it == geo.links.end()) return Error(ErrorCode::kInternal, "the robot's base link has no collision geometry");
    const int link = static_cast<int>(it - geo.links.begin());
    robot.linkPoses(toState(idle), link_poses);
    stopRiding(a.cmd.object_id);
    const Eigen::Isometry3d link_T_object = link_poses[link].inverse() * world.object(a.cmd.object_id).pose;
    if (!scene.attach(a.cmd.object_id, geo.links[link], link_T_object)) {
      return Error(ErrorCode::kInternal, "push of '" + a.cmd.object_id + "': cannot attach it to the base");
    }
    riding.push_back({a.cmd.object_id, link, link_T_object});
    a.pushed = a.cmd.object_id;
    a.push_gap = gap;
    a.push_dir = d;
    a.push_from = Eigen::Vector2d(idle[0], idle[1]);
    a.push_start = world.object(a.cmd.object_id).pose;
    a.push_max = 0.0;
    a.push_apex = 0.0;
    for (const auto& p : pts)
      a.push_apex = std::max(a.push_apex, (Eigen::Vector2d(p.positions[0], p.positions[1]) - a.push_from).dot(d));
    return Status::Ok();
  }

  /// A push ends (however it ended): the object stays where the base left it, less the gap the
  /// base drove before touching it, slipped sideways and turned by the push's own error.
  void releasePushed(Active& a, const Vec& q) {
    stopRiding(a.pushed);
    world::Object o = world.object(a.pushed);
    const double driven = (Eigen::Vector2d(q[0], q[1]) - a.push_from).dot(a.push_dir);
    const double furthest = std::max(driven, a.outcome == Outcome::kSucceeded ? a.push_apex : a.push_max);
    const double moved = std::max(0.0, furthest - a.push_gap);
    // It slides on by kPushSlide after the base stops: the base is not left touching it.
    const Eigen::Isometry3d pose = pushedPose(a, moved > 0.0 ? furthest + kPushSlide : furthest);
    Eigen::Isometry3d slipped = pose;
    if (moved > 0.0) {
      std::normal_distribution<double> unit(0.0, 1.0);
      const Eigen::Vector2d side(-a.push_dir.y(), a.push_dir.x());
      slipped.translation().head<2>() += params.push.lateral_slip * moved * unit(rng) * side;
      slipped.linear() = Eigen::AngleAxisd(params.push.yaw_slip_rad_per_m * moved * unit(rng), Eigen::Vector3d::UnitZ())
                             .toRotationMatrix() *
                         slipped.linear();
    }
    // The slip never pushes the object into something, the robot included: it stays unslipped then.
    syncScene();
    o.pose = slipped;
    (void)world.updateObject(o);
    syncScene();
    if (!scene.shapeCollisions(o.shape, slipped, collision::Filter::allBut({o.id})).empty() ||
        contactAt(q, nullptr) == o.id) {
      o.pose = pose;
      (void)world.updateObject(o);
      syncScene();
    }
    a.pushed.clear();
  }

  /// Drops the held object where it is (a fault). Returns its id ("" when the gripper is empty).
  std::string dropHeld(const Vec& q) {
    if (!world.held()) return "";
    syncHeldPose(q);
    const std::string id = world.held()->object_id;
    world::Object o = world.object(id);
    const Settled s = settle(o, o.pose, q);
    (void)scene.detach(id);
    (void)world.setHeld(std::nullopt);
    rest(std::move(o), s);
    return id;
  }

  // ---- faults -----------------------------------------------------------------------------------
  FaultEvent fire(const Fault& f, StepEvents& ev) {
    FaultEvent e;
    e.fault_id = f.id;
    e.type = f.type;
    e.time_s = now;
    const double rel = active ? now - active->start : 0.0;
    switch (f.type) {
      case FaultType::kDropHeldObject: {
        e.object_id = dropHeld(current());
        e.description = e.object_id.empty() ? "drop: the gripper was empty"
                                            : "dropped '" + e.object_id + "'";
        if (!e.object_id.empty()) {
          ev.world_changed = true;
          resweep(rel);
        }
        break;
      }
      case FaultType::kSpawnObject: {
        e.object_id = f.object.id;
        if (Status s = world.addObject(f.object); !s) {
          e.description = "spawn failed: " + s.error().message;
        } else {
          e.description = "object '" + f.object.id + "' appeared";
          syncScene();
          ev.world_changed = true;
          resweep(rel);
        }
        break;
      }
      case FaultType::kRemoveObject: {
        e.object_id = f.object_id;
        stopRiding(f.object_id);
        if (Status s = world.removeObject(f.object_id); !s) {
          e.description = "remove failed: " + s.error().message;
        } else {
          e.description = "object '" + f.object_id + "' disappeared";
          syncScene();
          ev.world_changed = true;
          resweep(rel);
        }
        break;
      }
      case FaultType::kFailAction: {
        const bool running = active && rel < active->end;
        if (running && (!f.action || *f.action == active->cmd.kind)) {
          active->outcome = Outcome::kFailed;
          active->reason = "action failed (fault '" + f.id + "')" + (f.reason.empty() ? "" : ": " + f.reason);
          active->end = std::max(0.0, rel);
          active->blocking.clear();
          e.description = "action '" + active->cmd.command_id + "' failed";
          // A pick that fails after its gripper closed: the object slips out of the fingers and
          // falls onto what is below it (it is not carried away on the retreat).
          if (active->cmd.kind == ActionKind::kPick && world.held() &&
              world.held()->object_id == active->cmd.object_id) {
            e.object_id = dropHeld(current());
            e.description += "; '" + e.object_id + "' slipped out of the gripper";
            ev.world_changed = true;
          }
        } else {
          pending_fails.push_back(f);
          e.description = "the next " + (f.action ? std::string(toString(*f.action)) + " " : std::string()) +
                          "action will fail";
        }
        break;
      }
    }
    if (!f.reason.empty()) e.description += " (" + f.reason + ")";
    logger()->info("fault '{}' at t={:.3f}s: {}", f.id, now, e.description);
    return e;
  }

  // ---- manipulation events ----------------------------------------------------------------------
  /// Why a pick with the robot at q would fail, or "".
  std::string pickFailure(const ActionCommand& c, const Vec& q) const {
    if (world.held()) return "the gripper already holds '" + world.held()->object_id + "'";
    const world::Object* o = world.findObject(c.object_id);
    if (!o) return "there is no object '" + c.object_id + "' to grasp";
    if (o->kind != world::ObjectKind::kMovable || !o->graspable) return "'" + o->id + "' is not graspable";
    if (c.object_pose) {
      const double off = (o->pose.translation() - c.object_pose->translation()).norm();
      if (off > params.grasp.position_tolerance_m) {
        return "'" + o->id + "' is not where the command says: " + formatNumber(off, 4) + " m away (tolerance " +
               formatNumber(params.grasp.position_tolerance_m, 4) + " m)";
      }
    }
    const robot::RobotState s = toState(q);
    const Eigen::Isometry3d tool = robot.toolPoseInWorld(s);
    const Eigen::Vector3d local = o->pose.inverse() * tool.translation();
    const Aabb box = o->shape.localAabb();
    const Eigen::Vector3d outside =
        (box.min - local).cwiseMax(local - box.max).cwiseMax(Eigen::Vector3d::Zero());
    if (outside.norm() > params.grasp.tcp_tolerance_m) {
      return "the gripper closes " + formatNumber(outside.norm(), 4) + " m away from '" + o->id + "'";
    }
    if (has_gripper) {
      const Eigen::Vector3d across = o->pose.linear().transpose() * tool.linear().col(1);
      const double width = widthAlong(o->shape, across);
      const double opening = 2.0 * robot.gripperLimits().upper;
      if (width > opening) {
        return "'" + o->id + "' is " + formatNumber(width, 4) + " m wide across the fingers; the gripper opens " +
               formatNumber(opening, 4) + " m";
      }
    }
    if (o->mass > params.grasp.max_payload_kg) {
      return "'" + o->id + "' (" + formatNumber(o->mass, 4) + " kg) exceeds the payload limit of " +
             formatNumber(params.grasp.max_payload_kg, 4) + " kg";
    }
    return "";
  }

  /// Where a parallel-jaw gripper closing at `world_T_tool` leaves `o`: the fingers close along
  /// the tool's y axis until both touch, so the object ends centred between them along that axis
  /// (it slides), and a box whose faces are within kMaxSquareRad of the finger pads is turned
  /// flat against them (about its centre). Along the other axes the object stays where it was.
  Eigen::Isometry3d squeezed(const world::Object& o, const Eigen::Isometry3d& world_T_tool) const {
    constexpr double kMaxSquareRad = 0.35;
    Eigen::Isometry3d tool_T_obj = world_T_tool.inverse() * o.pose;
    if (o.shape.kind == world::ShapeKind::kBox) {
      int best = 0;  // the box axis closest to the closing direction
      for (int k = 1; k < 3; ++k) {
        if (std::abs(tool_T_obj.linear()(1, k)) > std::abs(tool_T_obj.linear()(1, best))) best = k;
      }
      Eigen::Vector3d normal = tool_T_obj.linear().col(best);
      if (normal.y() < 0.0) normal = -normal;
      if (std::acos(std::clamp(normal.y(), -1.0, 1.0)) <= kMaxSquareRad) {
        const Eigen::Quaterniond turn = Eigen::Quaterniond::FromTwoVectors(normal, Eigen::Vector3d::UnitY());
        tool_T_obj.linear() = turn.toRotationMatrix() * tool_T_obj.linear();
      }
    }
    const Aabb extent = o.shape.aabb(tool_T_obj);  // in the tool frame
    tool_T_obj.translation().y() -= 0.5 * (extent.min.y() + extent.max.y());
    return world_T_tool * tool_T_obj;
  }

  void gripperEvent(Active& a, StepEvents& ev) {
    a.gripper_done = true;
    const Vec q = stateAt(a, now - a.start);
    const ActionCommand& c = a.cmd;
    if (c.kind == ActionKind::kPick) {
      a.failure = pickFailure(c, q);
      if (!a.failure.empty()) {
        logger()->info("pick '{}' fails: {}", c.command_id, a.failure);
        return;
      }
      stopRiding(c.object_id);
      world::Object o = world.object(c.object_id);
      if (c.object_pose) {
        const Eigen::Vector3d off = o.pose.translation() - c.object_pose->translation();
        logger()->info("pick '{}': '{}' {:.4f} m from where the command says ({:+.4f}, {:+.4f}, {:+.4f})", c.command_id,
                       o.id, off.norm(), off.x(), off.y(), off.z());
      }
      o.region.clear();
      o.pose = squeezed(o, robot.toolPoseInWorld(toState(q)));
      (void)world.updateObject(o);
      (void)world.setHeld(robot.hold(o.id, toState(q), o.pose));
      syncScene();
      (void)scene.attachHeld();
      ev.world_changed = true;
      return;
    }
    // Place: release the held object where the gripper is; it settles onto the support below.
    if (!world.held() || world.held()->object_id != c.object_id) {
      a.failure = "the gripper does not hold '" + c.object_id + "'";
      return;
    }
    syncHeldPose(q);
    world::Object o = world.object(c.object_id);
    const Eigen::Isometry3d released = o.pose;
    (void)scene.detach(o.id);
    (void)world.setHeld(std::nullopt);
    const Settled s = settle(o, released, q);
    rest(o, s);
    o = world.object(c.object_id);
    ev.world_changed = true;
    const Eigen::Isometry3d& target = *c.object_pose;
    const double off = (released.translation() - target.translation()).norm();
    const double turn = symmetricTurn(o.shape, released, target);
    if (s.tilt > params.place.max_tilt_rad) {
      a.failure = "'" + o.id + "' released tilted by " + formatNumber(s.tilt, 4) + " rad and toppled";
    } else if (s.drop > params.place.max_drop_m) {
      a.failure = "'" + o.id + "' released " + formatNumber(s.drop, 4) + " m above its support and dropped";
    } else if (s.drop < -kPlacePress) {
      a.failure = "'" + o.id + "' released " + formatNumber(-s.drop, 4) + " m below the support surface";
    } else if (s.robot_link >= 0) {
      a.failure = "'" + o.id + "' came to rest on the robot ('" + s.support + "')";
    } else if (s.region.empty()) {
      a.failure = "'" + o.id + "' is not on a support region" +
                  (s.support.empty() ? std::string() : " (it rests on '" + s.support + "')");
    } else if (off > params.place.position_tolerance_m) {
      a.failure = "'" + o.id + "' released " + formatNumber(off, 4) + " m from the commanded pose (tolerance " +
                  formatNumber(params.place.position_tolerance_m, 4) + " m)";
    } else if (turn > params.place.angle_tolerance_rad) {
      a.failure = "'" + o.id + "' released rotated by " + formatNumber(turn, 4) + " rad from the commanded pose";
    } else {
      for (const auto& other : scene.shapeCollisions(o.shape, o.pose, collision::Filter::allBut({o.id}))) {
        const auto* x = world.findObject(other);
        if (x && x->aabb().max.z() <= o.aabb().min.z() + kSupportProbe) continue;  // its support
        a.failure = "'" + o.id + "' lands in collision with '" + other + "'";
        break;
      }
    }
    if (!a.failure.empty()) logger()->info("place '{}' fails: {}", c.command_id, a.failure);
  }

  void finish(StepEvents& ev) {
    Active& a = *active;
    if (a.outcome == Outcome::kSucceeded && !a.failure.empty()) {
      a.outcome = Outcome::kFailed;
      a.reason = a.failure;
    }
    ActionResult r;
    r.command_id = a.cmd.command_id;
    r.outcome = a.outcome;
    r.duration_s = a.end;
    r.progress = a.total > 0.0 ? std::clamp(a.end / a.total, 0.0, 1.0) : 1.0;
    r.blocking_object_id = commandedId(a.blocking);
    r.reason = a.outcome == Outcome::kBlocked && a.reason.empty()
                   ? "stopped before contact with '" + r.blocking_object_id + "'" +
                         (a.blocking_part.empty() ? std::string() : " (of " + a.blocking_part + ")")
                   : a.reason;
    idle = stateAt(a, a.end);
    if (!a.pushed.empty()) {
      releasePushed(a, idle);
      ev.world_changed = true;
    }
    // Velocities are zero at rest: the state is exactly the stop state.
    effort_model::ExecutionRecord rec;
    rec.action.kind = a.cmd.kind;
    if (a.cmd.kind == ActionKind::kMoveBase || a.cmd.kind == ActionKind::kMoveArm) {
      rec.action.path = a.cmd.trajectory.path();
    } else {
      rec.action.approach_m = a.approach_m;
      rec.action.retreat_m = a.retreat_m;
    }
    rec.action.object_mass_kg = a.mass;
    rec.duration_s = a.end;
    rec.timestamp_s = epoch_s + now;
    rec.source = "sim";
    rec.success = a.outcome == Outcome::kSucceeded;
    rec.record_id = a.cmd.command_id;
    logger()->info("'{}' ({}) {} after {:.3f}s{}", r.command_id, toString(a.cmd.kind),
                  toString(r.outcome), r.duration_s, r.reason.empty() ? "" : ": " + r.reason);
    log[logged.at(r.command_id)].result = r;
    ev.results.push_back(std::move(r));
    ev.records.push_back(std::move(rec));
    active.reset();
    syncHeldPose(idle);
  }

  // ---- command validation and planning ----------------------------------------------------------
  Result<std::vector<int>> validate(const ActionCommand& c) const;
  /// The action's timeline; `nominal`: no noise and no stall, the random stream untouched.
  Result<Active> plan(const ActionCommand& c, const std::vector<int>& columns, bool nominal = false);
  /// An action being planned: its phases so far, where the robot is after them, the commanded
  /// waypoints as full joint vectors.
  struct Draft {
    Active a;
    Vec cur;
    std::vector<Vec> wp;
    bool nominal{false};
  };
  void addPause(Draft& d, double seconds);
  /// A jerk-limited move along `path` (parameter length `length`), then now and then a stall.
  void addMotion(Draft& d, GeoPath path, double length, const Limits& lim);
  void planBase(Draft& d);
  void planArm(Draft& d, const std::vector<int>& cols);
  void planHand(Draft& d);
  /// The dense tool path of waypoints [from, to] (`tool`: each waypoint's tool position).
  GeoPath toolPath(const std::vector<Vec>& wp, const std::vector<Eigen::Vector3d>& tool, std::size_t from,
                   std::size_t to);
  Eigen::Vector3d toolAt(const Vec& q);
  /// Contacts that belong to a pick or place: the picked object and its supports, the placed
  /// object and the supports where it really ends (`at_grasp`: the grasp waypoint).
  void ignoreTaskContacts(Active& a, const world::Object* obj, const Vec& at_grasp);
  /// Phase times: the true timing stretched by the execution noise (none when nominal).
  void stampTimeline(Draft& d);
};

Result<std::vector<int>> Simulator::Impl::validate(const ActionCommand& c) const {
  if (c.command_id.empty()) return invalid("command_id", "must not be empty");
  const Trajectory& t = c.trajectory;
  const std::string kind(toString(c.kind));
  if (std::find(kAllActionKinds.begin(), kAllActionKinds.end(), c.kind) == kAllActionKinds.end()) {
    return invalid("kind", "unknown action kind " + std::to_string(static_cast<int>(c.kind)));
  }
  if (t.joint_names.empty()) return invalid("trajectory.joint_names", "no joints");
  if (t.points.empty()) return invalid("trajectory.points", "no points");
  std::vector<int> cols;
  for (std::size_t j = 0; j < t.joint_names.size(); ++j) {
    const std::string field = "trajectory.joint_names[" + std::to_string(j) + "]";
    const std::string& name = t.joint_names[j];
    const auto it = std::find(full_names.begin(), full_names.end(), name);
    if (it == full_names.end()) {
      return invalid(field, "unknown joint '" + name + "' (robot joints: base_x, base_y, base_theta, the arm joints" +
                                (has_gripper ? ", " + full_names.back() : std::string()) + ")");
    }
    for (std::size_t i = 0; i < j; ++i) {
      if (t.joint_names[i] == name) return invalid(field, "duplicate joint '" + name + "'");
    }
    const int col = static_cast<int>(it - full_names.begin());
    if (c.kind == ActionKind::kMoveBase && col >= 3) {
      return invalid(field, "move_base moves base_x, base_y and base_theta only, got '" + name + "'");
    }
    if (c.kind != ActionKind::kMoveBase && col < 3) {
      return invalid(field, kind + " cannot move the base joint '" + name + "' (use move_base)");
    }
    cols.push_back(col);
  }
  if (c.kind == ActionKind::kMoveBase && cols.size() != 3) {
    return invalid("trajectory.joint_names", "move_base needs base_x, base_y and base_theta");
  }
  const Vec q = current();
  double last_time = -kInf;
  for (std::size_t i = 0; i < t.points.size(); ++i) {
    const TrajectoryPoint& p = t.points[i];
    const std::string field = "trajectory.points[" + std::to_string(i) + "]";
    if (!std::isfinite(p.time_from_start) || p.time_from_start < 0.0) {
      return invalid(field + ".time_from_start", "must be finite and >= 0, got " + formatNumber(p.time_from_start, 4));
    }
    if (p.time_from_start <= last_time) {
      return invalid(field + ".time_from_start", "times must increase strictly: " + formatNumber(p.time_from_start, 4) +
                                                   " s after " + formatNumber(last_time, 4) + " s");
    }
    last_time = p.time_from_start;
    if (p.positions.size() != cols.size()) {
      return invalid(field + ".positions", "has " + std::to_string(p.positions.size()) + " values for " +
                                               std::to_string(cols.size()) + " joints");
    }
    if (!p.velocities.empty() && p.velocities.size() != cols.size()) {
      return invalid(field + ".velocities", "has " + std::to_string(p.velocities.size()) + " values for " +
                                                std::to_string(cols.size()) + " joints (or give none)");
    }
    for (std::size_t j = 0; j < cols.size(); ++j) {
      const std::string pf = field + ".positions[" + std::to_string(j) + "]";
      const double v = p.positions[j];
      const std::string& name = t.joint_names[j];
      if (!std::isfinite(v)) return invalid(pf, name + " is not finite");
      if (std::abs(v) > effort_model::InputLimits::kMaxAbsPathValue) {
        return invalid(pf, name + " = " + formatNumber(v, 4) + " is implausibly large");
      }
      if (!p.velocities.empty() && !std::isfinite(p.velocities[j])) {
        return invalid(field + ".velocities[" + std::to_string(j) + "]", name + " is not finite");
      }
      const int col = cols[j];
      if (col >= 3) {
        const robot::JointLimits lim = col < 3 + dof ? robot.armLimits()[col - 3] : robot.gripperLimits();
        if (v < lim.lower - 1e-6 || v > lim.upper + 1e-6) {
          return invalid(pf, name + " = " + formatNumber(v, 4) + " is outside its limits [" + formatNumber(lim.lower, 4) + ", " +
                                 formatNumber(lim.upper, 4) + "]");
        }
      }
      if (i == 0) {
        const bool angular = col == 2 || (col >= 3 && col < 3 + dof);
        const double diff = col == 2 ? std::abs(angleDiff(v, q[col])) : std::abs(v - q[col]);
        const double tol = angular ? params.start_tolerance.angle_rad : params.start_tolerance.position_m;
        if (diff > tol) {
          return invalid(pf, "the trajectory starts with " + name + " = " + formatNumber(v, 4) + " but the robot is at " +
                                 formatNumber(q[col], 4) + " (tolerance " + formatNumber(tol, 4) + ")");
        }
      }
    }
  }
  const bool manipulation = c.kind == ActionKind::kPick || c.kind == ActionKind::kPlace;
  if (manipulation) {
    if (!world::isValidId(c.object_id)) {
      return invalid("object_id", kind + " needs a valid object id, got '" + c.object_id + "'");
    }
    if (c.kind == ActionKind::kPlace && !c.object_pose) {
      return invalid("object_pose", "place needs the pose where the object goes");
    }
    if (c.object_pose && !c.object_pose->matrix().allFinite()) {
      return invalid("object_pose", "is not finite");
    }
  } else if (c.kind == ActionKind::kMoveBase && !c.object_id.empty()) {
    // A push.
    const world::Object* o = world.findObject(c.object_id);
    if (o == nullptr || o->kind != world::ObjectKind::kMovable) {
      return invalid("object_id", "move_base pushes a movable object, got '" + c.object_id + "'");
    }
    if (world.held() && world.held()->object_id == c.object_id) {
      return invalid("object_id", "move_base cannot push the held object '" + c.object_id + "'");
    }
  } else if (!c.object_id.empty()) {
    return invalid("object_id", kind + " takes no object (got '" + c.object_id + "')");
  }
  return cols;
}

Result<Active> Simulator::Impl::plan(const ActionCommand& c, const std::vector<int>& cols, bool nominal) {
  Draft d;
  d.a.cmd = c;
  d.nominal = nominal;
  d.cur = current();
  // Waypoints as full joint vectors (joints not commanded keep their current value).
  for (const auto& p : c.trajectory.points) {
    Vec q = d.cur;
    for (std::size_t j = 0; j < cols.size(); ++j) q[cols[j]] = p.positions[j];
    d.wp.push_back(q);
  }
  if (c.kind == ActionKind::kMoveBase) {
    planBase(d);
  } else if (c.kind == ActionKind::kMoveArm) {
    planArm(d, cols);
  } else {
    planHand(d);
  }
  stampTimeline(d);
  // Objects touching the robot at the start do not block it (it may back away from them).
  for (const auto& id : objectsTouching(d.a.phases.front().start)) {
    if (std::find(d.a.ignore_objects.begin(), d.a.ignore_objects.end(), id) == d.a.ignore_objects.end()) {
      d.a.ignore_objects.push_back(id);
    }
  }
  return std::move(d.a);
}

void Simulator::Impl::addPause(Draft& d, double seconds) {
  if (seconds <= 0.0) return;
  Phase ph;
  ph.kind = Phase::Kind::kPause;
  ph.nominal = seconds;
  ph.start = ph.end = d.cur;
  d.a.phases.push_back(std::move(ph));
}

void Simulator::Impl::addMotion(Draft& d, GeoPath path, double length, const Limits& lim) {
  const DynamicsParams& dyn = params.dynamics;
  Phase ph;
  ph.kind = Phase::Kind::kMotion;
  ph.length = length;
  ph.profile = MotionProfile::restToRest(length, lim.speed, lim.accel, lim.jerk);
  ph.nominal = ph.profile.duration();
  ph.start = path.q.front();
  ph.end = path.q.back();
  ph.path = std::move(path);
  d.cur = ph.end;
  d.a.phases.push_back(std::move(ph));
  if (!d.nominal && dyn.stall.probability > 0.0 &&
      std::uniform_real_distribution<double>(0.0, 1.0)(rng) < dyn.stall.probability) {
    addPause(d, std::uniform_real_distribution<double>(dyn.stall.min_s, dyn.stall.max_s)(rng));
  }
}

void Simulator::Impl::planBase(Draft& d) {
  // Stop-and-turn along the steps the motion planner and the execution monitor check
  // (effort_model::baseSteps: the geometry); each turn and drive timed by the robot's own
  // S-curve. A push is slowed by the pushed object's mass as a load is.
  const DynamicsParams& dyn = params.dynamics;
  const ActionCommand& c = d.a.cmd;
  const world::Object* pushed = c.object_id.empty() ? nullptr : world.findObject(c.object_id);
  d.a.mass = pushed ? pushed->mass : heldMass();
  const double f = loadFactor(dyn, d.a.mass);
  addPause(d, dyn.base.latency_s);
  std::vector<Pose2D> poses;
  for (const Vec& q : d.wp) poses.push_back(Pose2D{q[0], q[1], q[2]});
  for (const auto& step : effort_model::baseSteps(poses)) {
    GeoPath g;
    if (step.kind == effort_model::BaseStep::Kind::kTurn) {
      Vec end = d.cur;
      end[2] = d.cur[2] + angleDiff(step.target_heading, d.cur[2]);
      g.q = {d.cur, end};
      g.u = {0.0, std::abs(end[2] - d.cur[2])};
      const double turn = g.u.back();
      addMotion(d, std::move(g), turn, scaled(dyn.base.angular(), f));
    } else {
      g.q = {d.cur};
      g.u = {0.0};
      for (std::size_t i : step.points) {
        Vec n = g.q.back();
        n[0] = d.wp[i][0];
        n[1] = d.wp[i][1];
        g.u.push_back(g.u.back() + std::hypot(n[0] - g.q.back()[0], n[1] - g.q.back()[1]));
        g.q.push_back(n);
      }
      const double length = g.u.back();
      addMotion(d, std::move(g), length, scaled(dyn.base.linear(), f));
    }
    addPause(d, dyn.base.settle_s);
  }
}

void Simulator::Impl::planArm(Draft& d, const std::vector<int>& cols) {
  const DynamicsParams& dyn = params.dynamics;
  d.a.mass = heldMass();
  addPause(d, dyn.arm.latency_s);
  const std::size_t n = cols.size();
  std::vector<std::vector<double>> arm(d.wp.size(), std::vector<double>(n));
  for (std::size_t i = 0; i < d.wp.size(); ++i) {
    for (std::size_t j = 0; j < n; ++j) arm[i][j] = d.wp[i][cols[j]];
  }
  // Each run one jerk-limited S-curve along the commanded polyline (through every waypoint, as
  // the planner checked it), then a settle pause.
  for (const auto& run : armRuns(arm, d.a.cmd.trajectory.joint_names, joint_speed, dyn.arm, loadFactor(dyn, d.a.mass))) {
    GeoPath g;
    g.q = {d.cur};
    g.u = {0.0};
    for (std::size_t k = 1; k < run.points.size(); ++k) {
      g.q.push_back(d.wp[run.points[k]]);
      g.u.push_back(run.u[k]);
    }
    const double length = g.u.back();
    addMotion(d, std::move(g), length, run.limits);
    addPause(d, dyn.arm.settle_s);
  }
}

GeoPath Simulator::Impl::toolPath(const std::vector<Vec>& wp, const std::vector<Eigen::Vector3d>& tool,
                                  std::size_t from, std::size_t to) {
  GeoPath p;
  p.q = {wp[from]};
  p.u = {0.0};
  Eigen::Vector3d last = tool[from];
  for (std::size_t i = from + 1; i <= to; ++i) {
    const int n = std::max(1, static_cast<int>(std::ceil(displacementBound(wp[i - 1], wp[i]) / params.max_step_m)));
    for (int k = 1; k <= n; ++k) {
      const Vec q = wp[i - 1] + (static_cast<double>(k) / n) * (wp[i] - wp[i - 1]);
      const Eigen::Vector3d x = toolAt(q);
      p.u.push_back(p.u.back() + (x - last).norm());
      p.q.push_back(q);
      last = x;
    }
  }
  return p;
}

Eigen::Vector3d Simulator::Impl::toolAt(const Vec& q) {
  robot.linkPoses(toState(q), link_poses);
  return link_poses[tool_link].translation();
}

void Simulator::Impl::planHand(Draft& d) {
  // Pick / place: approach to the grasp waypoint along the tool path, gripper, retreat.
  const DynamicsParams& dyn = params.dynamics;
  const ActionCommand& c = d.a.cmd;
  Active& a = d.a;
  const world::Object* obj = world.findObject(c.object_id);
  d.wp.front() = d.cur;
  std::vector<Eigen::Vector3d> tool;
  for (const Vec& q : d.wp) tool.push_back(toolAt(q));
  // The grasp waypoint: the one whose tool is farthest from the start's.
  std::size_t g = 0;
  double far = -1.0;
  for (std::size_t i = 0; i < d.wp.size(); ++i) {
    const double dist = (tool[i] - tool[0]).norm();
    if (dist > far + 1e-12) {
      far = dist;
      g = i;
    }
  }
  // The mass carried: a pick that will fail at the grasp waypoint (as the world is now) carries
  // nothing on its retreat; a place carries the held object on its approach.
  const bool pick = c.kind == ActionKind::kPick;
  if (pick) {
    a.mass = obj && pickFailure(c, d.wp[g]).empty() ? obj->mass : 0.0;
  } else {
    a.mass = world.held() && world.held()->object_id == c.object_id ? heldMass() : 0.0;
  }
  const double f = loadFactor(dyn, a.mass);
  GeoPath approach = toolPath(d.wp, tool, 0, g);
  GeoPath retreat = toolPath(d.wp, tool, g, d.wp.size() - 1);
  a.approach_m = approach.u.back();
  a.retreat_m = retreat.u.back();
  const double fa = pick ? 1.0 : f, fr = pick ? f : 1.0;
  if (approach.q.size() > 1) addMotion(d, std::move(approach), a.approach_m, scaled(dyn.hand.approach(), fa));
  Phase grip;
  grip.kind = Phase::Kind::kGripper;
  grip.nominal = pick ? dyn.hand.close_s : dyn.hand.open_s;
  grip.start = grip.end = d.cur;
  a.gripper_phase = static_cast<int>(a.phases.size());
  a.phases.push_back(std::move(grip));
  if (retreat.q.size() > 1) addMotion(d, std::move(retreat), a.retreat_m, scaled(dyn.hand.approach(), fr));
  ignoreTaskContacts(a, obj, d.wp[g]);
}

void Simulator::Impl::ignoreTaskContacts(Active& a, const world::Object* obj, const Vec& at_grasp) {
  const ActionCommand& c = a.cmd;
  if (c.kind == ActionKind::kPick) {
    a.ignore_objects.push_back(c.object_id);
    if (obj) {
      for (const auto& s : supportsOf(*obj, obj->pose)) a.ignore_pairs.emplace_back(obj->id, s);
    }
  } else if (obj && c.object_pose) {
    // Where the object really ends at the end of the place motion (its grasp as held, not the
    // commanded pose the robot computed from what it believed of the object).
    const Eigen::Isometry3d at_end = world.held() && world.held()->object_id == obj->id
                                         ? robot.toolPoseInWorld(toState(at_grasp)) * world.held()->link_T_object
                                         : *c.object_pose;
    for (const auto& s : supportsOf(*obj, at_end, kPlacePress)) a.ignore_pairs.emplace_back(obj->id, s);
  }
}

void Simulator::Impl::stampTimeline(Draft& d) {
  Active& a = d.a;
  // The timeline: the true timing stretched by the execution noise (none for the nominal one).
  a.k = !d.nominal && params.duration_noise > 0.0
            ? std::exp(params.duration_noise * std::normal_distribution<double>(0.0, 1.0)(rng))
            : 1.0;
  double t = 0.0;
  for (Phase& p : a.phases) {
    p.t0 = t;
    t += a.k * p.nominal;
    p.t1 = t;
  }
  a.total = t;
  a.end = t;
  if (a.phases.empty()) {  // nothing to do (a single-point motion)
    Phase ph;
    ph.start = ph.end = d.cur;
    a.phases.push_back(ph);
  }
}

// ---- Simulator --------------------------------------------------------------------------------

Simulator::Simulator(world::World truth, robot::RobotModel robot, robot::RobotState initial,
                     SimParams params, std::vector<Fault> faults)
    : impl_(std::make_unique<Impl>(std::move(truth), std::move(robot), std::move(params))) {
  Impl& m = *impl_;
  if (Status s = m.params.validate(); !s) throw std::invalid_argument("Simulator: " + s.error().message);
  m.full_names = m.robot.fullJointNames();
  m.dof = static_cast<int>(m.robot.armDof());
  m.has_gripper = !m.robot.gripperJointName().empty();
  m.tool_link = m.robot.linkIndex(m.robot.options().tool_link);
  if (m.dof < 1 || m.tool_link < 0) throw std::invalid_argument("Simulator: the robot has no arm / tool link");
  if (initial.arm.size() != static_cast<std::size_t>(m.dof)) {
    throw std::invalid_argument("Simulator: initial state has " + std::to_string(initial.arm.size()) +
                                " arm values, the robot has " + std::to_string(m.dof) + " arm joints");
  }
  m.joint_speed = armSpeedLimits(m.robot);  // the true robot's joints are not all equally fast
  m.computeBounds();
  m.idle = m.toVec(initial);
  if (!m.idle.allFinite()) throw std::invalid_argument("Simulator: initial state is not finite");
  if (const auto& h = m.world.held()) {
    if (h->link != m.robot.options().tool_link) {
      throw std::invalid_argument("Simulator: held object '" + h->object_id + "' is held by link '" + h->link +
                                  "', not by the tool link '" + m.robot.options().tool_link + "'");
    }
  }
  for (std::size_t i = 0; i < faults.size(); ++i) {
    if (Status s = faults[i].validate(true); !s) {
      throw std::invalid_argument("Simulator: faults[" + std::to_string(i) + "]." + s.error().message);
    }
  }
  m.scripted = std::move(faults);
  m.fired.assign(m.scripted.size(), false);
  m.rng.seed(m.params.seed);
  if (Status s = m.rebuildScene(); !s) throw std::invalid_argument("Simulator: " + s.error().message);
  m.epoch_s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

Simulator::~Simulator() = default;

Status Simulator::submit(const ActionCommand& command) {
  Impl& m = *impl_;
  if (const auto seen = m.logged.find(command.command_id); seen != m.logged.end()) {
    // Idempotent: an id accepted before is never executed again. Running: the sender joins it
    // (its result comes when it ends); finished: its recorded result comes again.
    const ActionLogEntry& e = m.log[seen->second];
    if (e.result) m.replayed.push_back(*e.result);
    logger()->info("'{}' repeated: {}", command.command_id,
                   e.result ? "executed before, its result again" : "running, joined");
    return Status::Ok();
  }
  if (m.active) {
    return Error(ErrorCode::kUnavailable,
                 "busy: action '" + m.active->cmd.command_id + "' is still running", SourceLocation{"", 0, 0, "command_id"});
  }
  const ActionCommand cmd = m.inTruthNames(command);
  auto cols = m.validate(cmd);
  if (!cols) return cols.error();
  auto planned = m.plan(cmd, *cols);
  if (!planned) return planned.error();
  Active& a = *planned;
  if (cmd.kind == ActionKind::kMoveBase && !cmd.object_id.empty()) {
    if (Status s = m.startPush(a); !s) return s;
  }
  m.logged[command.command_id] = m.log.size();
  m.log.push_back(ActionLogEntry{command.command_id, command.kind, a.step, m.now, std::nullopt});
  a.step = m.actions++;
  m.log.back().step = a.step;
  a.start = m.now;
  for (std::size_t i = 0; i < m.scripted.size(); ++i) {
    const Fault& f = m.scripted[i];
    if (m.fired[i] || !f.trigger.step) continue;
    if (f.type == FaultType::kDropHeldObject && f.action) {
      // Waits for the first carrying action of its kind (an action that ended before it fired
      // leaves it waiting for the next one).
      if (*f.trigger.step <= a.step && *f.action == a.cmd.kind && m.world.held())
        a.faults.push_back({i, f.trigger.fraction * a.total});
      continue;
    }
    if (f.trigger.step != a.step) continue;
    if (f.type == FaultType::kFailAction && f.action && *f.action != a.cmd.kind) {
      m.fired[i] = true;  // another kind: the first matching action from here on fails
      m.pending_fails.push_back(f);
      continue;
    }
    a.faults.push_back({i, f.trigger.fraction * a.total});
  }
  for (auto it = m.pending_fails.begin(); it != m.pending_fails.end(); ++it) {
    if (!it->action || *it->action == a.cmd.kind) {
      a.fail_fault = *it;
      a.fail_at = it->trigger.fraction * a.total;
      m.pending_fails.erase(it);
      break;
    }
  }
  m.active = std::move(a);
  if (auto stop = m.sweep(*m.active, 0.0)) {
    m.active->end = stop->first;
    m.active->outcome = Outcome::kBlocked;
    m.active->blocking = stop->second;
  }
  logger()->debug("'{}' ({}) accepted: {:.3f}s planned{}", command.command_id, toString(command.kind),
                m.active->total,
                m.active->outcome == Outcome::kBlocked ? ", will stop before '" + m.active->blocking + "'" : "");
  return Status::Ok();
}

Result<double> Simulator::nominalDuration(const ActionCommand& command) {
  Impl& m = *impl_;
  auto cols = m.validate(command);
  if (!cols) return cols.error();
  auto planned = m.plan(command, *cols, true);
  if (!planned) return planned.error();
  return planned->total;
}

std::unordered_map<std::string, double> armSpeedLimits(const robot::RobotModel& robot) {
  std::unordered_map<std::string, double> out;
  for (std::size_t j = 0; j < robot.armDof(); ++j) {
    if (robot.armLimits()[j].velocity > 0.0) out[robot.armJointNames()[j]] = robot.armLimits()[j].velocity;
  }
  return out;
}

Status Simulator::cancel(const std::string& command_id) {
  Impl& m = *impl_;
  if (!m.active || m.active->cmd.command_id != command_id) {
    return Error(ErrorCode::kNotFound, "no action '" + command_id + "' in progress");
  }
  Active& a = *m.active;
  const double rel = m.now - a.start;
  if (rel < a.end) {
    a.end = rel;
    a.outcome = Outcome::kCancelled;
    a.blocking.clear();
    a.reason = "cancelled";
  }
  return Status::Ok();
}

Status Simulator::inject(Fault fault) {
  Impl& m = *impl_;
  if (Status s = fault.validate(false); !s) return s;
  if (fault.type == FaultType::kSpawnObject && m.world.findObject(fault.object.id)) {
    return invalid("object.id", "an object '" + fault.object.id + "' exists already");
  }
  if (fault.type == FaultType::kRemoveObject && !m.world.findObject(fault.object_id)) {
    return Error(ErrorCode::kNotFound, "object_id: no object '" + fault.object_id + "'",
                 SourceLocation{"", 0, 0, "object_id"});
  }
  m.injected.push_back(std::move(fault));
  return Status::Ok();
}

StepEvents Simulator::step(double dt) {
  if (!(dt >= 0.0) || !std::isfinite(dt)) throw std::invalid_argument("Simulator::step: dt must be >= 0, got " + formatNumber(dt, 4));
  Impl& m = *impl_;
  StepEvents ev;
  ev.results = std::exchange(m.replayed, {});
  for (const Fault& f : std::exchange(m.injected, {})) ev.faults.push_back(m.fire(f, ev));
  const double target = m.now + dt;
  for (;;) {
    // The next event: a timed fault, a fault of this step, the gripper, a failure, the end.
    double next = target;
    int kind = -1;  // 0 timed fault, 1 step fault, 2 fail-next, 3 gripper, 4 end
    std::size_t which = 0;
    for (std::size_t i = 0; i < m.scripted.size(); ++i) {
      if (!m.fired[i] && m.scripted[i].trigger.time_s && *m.scripted[i].trigger.time_s < next + 1e-12 &&
          (kind == -1 || *m.scripted[i].trigger.time_s < next)) {
        next = std::max(m.now, *m.scripted[i].trigger.time_s);
        kind = 0;
        which = i;
      }
    }
    if (m.active) {
      Active& a = *m.active;
      for (std::size_t i = 0; i < a.faults.size(); ++i) {
        const double t = a.start + std::min(a.faults[i].rel_time, a.end);
        if (!m.fired[a.faults[i].index] && (t < next || (kind == -1 && t <= next))) {
          next = std::max(m.now, t);
          kind = 1;
          which = i;
        }
      }
      if (a.fail_fault) {
        const double t = a.start + std::min(a.fail_at, a.end);
        if (t < next || (kind == -1 && t <= next)) {
          next = std::max(m.now, t);
          kind = 2;
        }
      }
      if (a.gripper_phase >= 0 && !a.gripper_done) {
        const double t = a.start + a.phases[a.gripper_phase].t1;
        if (a.phases[a.gripper_phase].t1 <= a.end && (t < next || (kind == -1 && t <= next))) {
          next = std::max(m.now, t);
          kind = 3;
        }
      }
      const double t_end = a.start + a.end;
      if (t_end < next || (kind == -1 && t_end <= next)) {
        next = std::max(m.now, t_end);
        kind = 4;
      }
    }
    m.now = next;
    if (kind == -1) break;
    switch (kind) {
      case 0:
        m.fired[which] = true;
        ev.faults.push_back(m.fire(m.scripted[which], ev));
        break;
      case 1: {
        const std::size_t idx = m.active->faults[which].index;
        m.fired[idx] = true;
        ev.faults.push_back(m.fire(m.scripted[idx], ev));
        break;
      }
      case 2: {
        Fault f = *m.active->fail_fault;
        m.active->fail_fault.reset();
        ev.faults.push_back(m.fire(f, ev));
        break;
      }
      case 3:
        m.gripperEvent(*m.active, ev);
        break;
      case 4:
        m.finish(ev);
        break;
    }
  }
  m.syncHeldPose(m.current());
  return ev;
}

double Simulator::time() const { return impl_->now; }
double Simulator::epoch() const { return impl_->epoch_s; }
bool Simulator::busy() const { return impl_->active.has_value(); }
double Simulator::remainingActionTime() const {
  const Impl& m = *impl_;
  return m.active ? std::max(0.0, m.active->start + m.active->end - m.now) : 0.0;
}
int Simulator::actionCount() const { return impl_->actions; }

const std::vector<ActionLogEntry>& Simulator::actionLog() const { return impl_->log; }

SimSnapshot Simulator::snapshot() const {
  const Impl& m = *impl_;
  SimSnapshot s;
  s.time_s = m.now;
  s.epoch_s = m.epoch_s;
  s.robot = m.toState(m.current());
  s.held = m.world.held();
  for (const auto& o : m.world.objects()) s.objects.push_back(o);
  for (std::size_t i = 0; i < m.scripted.size(); ++i) {
    if (m.fired[i]) s.fired_faults.push_back(m.scripted[i].id);
  }
  for (const Fault& f : m.pending_fails) s.pending_faults.push_back(f.id);
  s.log = m.log;
  s.names = m.names;
  return s;
}

namespace {

/// The index of the scripted fault `id`, or nullopt.
std::optional<std::size_t> faultIndex(const std::vector<Fault>& scripted, const std::string& id) {
  for (std::size_t i = 0; i < scripted.size(); ++i) {
    if (scripted[i].id == id) return i;
  }
  return std::nullopt;
}

/// Ok when the log can be this simulator's: ids non-empty and unique, only the last entry
/// without a result, results carrying their entry's id.
Status checkLog(const std::vector<ActionLogEntry>& log) {
  std::set<std::string> ids;
  for (std::size_t i = 0; i < log.size(); ++i) {
    const std::string field = "log[" + std::to_string(i) + "]";
    const ActionLogEntry& e = log[i];
    if (e.command_id.empty()) return invalid(field + ".command_id", "empty");
    if (!ids.insert(e.command_id).second) return invalid(field + ".command_id", "'" + e.command_id + "' twice");
    if (!std::isfinite(e.start_s)) return invalid(field + ".start_s", "not finite");
    if (!e.result && i + 1 != log.size()) return invalid(field + ".result", "running, but not the last action");
    if (e.result && e.result->command_id != e.command_id) {
      return invalid(field + ".result.command_id", "'" + e.result->command_id + "' is not the entry's id");
    }
  }
  return Status::Ok();
}

}  // namespace

Status Simulator::resume(const SimSnapshot& snapshot) {
  Impl& m = *impl_;
  if (!m.log.empty() || m.active) throw std::logic_error("Simulator::resume: commands were accepted already");
  if (!std::isfinite(snapshot.time_s) || snapshot.time_s < 0.0) {
    return invalid("time_s", "must be finite and >= 0, got " + formatNumber(snapshot.time_s, 4));
  }
  if (!std::isfinite(snapshot.epoch_s) || snapshot.epoch_s <= 0.0) {
    return invalid("epoch_s", "must be a positive wall-clock time, got " + formatNumber(snapshot.epoch_s, 4));
  }
  if (snapshot.robot.arm.size() != static_cast<std::size_t>(m.dof)) {
    return invalid("robot.arm", std::to_string(snapshot.robot.arm.size()) + " values, the robot has " +
                                    std::to_string(m.dof) + " arm joints");
  }
  const Vec q = m.toVec(snapshot.robot);
  if (!q.allFinite()) return invalid("robot", "not finite");
  world::World w = m.world;
  for (const auto& o : m.world.objects()) (void)w.removeObject(o.id);
  for (const auto& o : snapshot.objects) {
    if (Status s = w.addObject(o); !s) return invalid("objects[" + o.id + "]", s.error().message);
  }
  if (snapshot.held) {
    if (snapshot.held->link != m.robot.options().tool_link) {
      return invalid("held", "held by link '" + snapshot.held->link + "', not by the tool link '" +
                                 m.robot.options().tool_link + "'");
    }
    if (Status s = w.setHeld(snapshot.held); !s) return invalid("held", s.error().message);
  }
  std::vector<bool> fired(m.scripted.size(), false);
  for (std::size_t i = 0; i < snapshot.fired_faults.size(); ++i) {
    const auto idx = faultIndex(m.scripted, snapshot.fired_faults[i]);
    if (!idx) return invalid("fired_faults[" + std::to_string(i) + "]", "no scripted fault '" + snapshot.fired_faults[i] + "'");
    fired[*idx] = true;
  }
  std::vector<Fault> pending;
  for (std::size_t i = 0; i < snapshot.pending_faults.size(); ++i) {
    const auto idx = faultIndex(m.scripted, snapshot.pending_faults[i]);
    if (!idx) return invalid("pending_faults[" + std::to_string(i) + "]", "no scripted fault '" + snapshot.pending_faults[i] + "'");
    pending.push_back(m.scripted[*idx]);
  }
  if (Status s = checkLog(snapshot.log); !s) return s;
  for (const auto& [commanded, truth] : snapshot.names) {
    if (w.findObject(truth) == nullptr) return invalid("names[" + commanded + "]", "no object '" + truth + "'");
  }

  const world::World before = m.world;
  m.world = std::move(w);
  m.idle = q;
  m.riding.clear();
  if (Status s = m.rebuildScene(); !s) {
    m.world = before;
    (void)m.rebuildScene();
    return invalid("held", s.error().message);
  }
  m.fired = std::move(fired);
  m.pending_fails = std::move(pending);
  m.epoch_s = snapshot.epoch_s;  // stamps go on, never back
  m.now = snapshot.time_s;
  m.log = snapshot.log;
  m.names = snapshot.names;
  m.logged.clear();
  for (std::size_t i = 0; i < m.log.size(); ++i) m.logged[m.log[i].command_id] = i;
  m.actions = static_cast<int>(m.log.size());
  for (ActionLogEntry& e : m.log) {
    if (e.result) continue;
    // The robot stopped where it stood: the command is over, as a failure the planner replans from.
    ActionResult r;
    r.command_id = e.command_id;
    r.outcome = Outcome::kFailed;
    r.duration_s = std::max(0.0, snapshot.time_s - e.start_s);
    r.reason = std::string(kRestartedMidAction) + ": the robot stopped where it stood; '" + e.command_id +
               "' is not executed again";
    e.result = r;
    m.replayed.push_back(r);
    logger()->warn("'{}' was running when the driver stopped: {}", e.command_id, r.reason);
  }
  return Status::Ok();
}

RobotStateSample Simulator::robotState() const {
  const Impl& m = *impl_;
  RobotStateSample s;
  s.time_s = m.now;
  const Vec q = m.current();
  s.state = m.toState(q);
  s.state.base.theta = wrapAngle(s.state.base.theta);
  s.joint_velocities.assign(m.full_names.size(), 0.0);
  if (m.active) {
    const Active& a = *m.active;
    const double rel = m.now - a.start;
    const double h = 1e-3;
    const double lo = std::max(0.0, rel - h), hi = std::min(a.end, rel + h);
    if (hi > lo) {
      const Vec dq = (m.stateAt(a, hi) - m.stateAt(a, lo)) / (hi - lo);
      for (std::size_t j = 0; j < m.full_names.size(); ++j) s.joint_velocities[j] = dq[static_cast<Eigen::Index>(j)];
      s.moving = dq.cwiseAbs().maxCoeff() > 1e-9;
    }
  }
  if (m.world.held()) s.held_object_id = m.commandedId(m.world.held()->object_id);
  return s;
}

const world::World& Simulator::world() const { return impl_->world; }
const robot::RobotModel& Simulator::robot() const { return impl_->robot; }
const SimParams& Simulator::params() const { return impl_->params; }

PointCloudFrame Simulator::captureCloud(std::int64_t stamp_ns, GroundTruthLabels* labels) {
  Impl& m = *impl_;
  const Vec q = m.current();
  m.syncHeldPose(q);
  return m.sensor.capture(m.world, m.robot, m.toState(q), stamp_ns, labels);
}

}  // namespace tamp::sim
