#include "tamp/perception/perception.h"

#include "tamp/core/log.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>

#include "tamp/core/geometry.h"
#include "tamp/perception/assignment.h"
#include "tamp/perception/validation.h"
#include "tamp/perception/visibility.h"
#include "tamp/world/polygon.h"

namespace tamp::perception {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// A released object whose bottom is at most this far above the support below rests on it (m).
constexpr double kRestingGap = 0.03;

std::string describePose(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d t = T.translation();
  char buf[96];
  std::snprintf(buf, sizeof(buf), "(%.2f, %.2f, %.2f) yaw %.2f", t.x(), t.y(), t.z(), yawOf(T));
  return buf;
}

std::string describeShape(const world::Shape& s) {
  char buf[96] = "shape";
  switch (s.kind) {
    case world::ShapeKind::kBox:
      std::snprintf(buf, sizeof(buf), "box %.2f x %.2f x %.2f m", s.size.x(), s.size.y(), s.size.z());
      break;
    case world::ShapeKind::kCylinder:
      std::snprintf(buf, sizeof(buf), "cylinder r %.2f h %.2f m", s.radius, s.height);
      break;
    case world::ShapeKind::kSphere:
      std::snprintf(buf, sizeof(buf), "sphere r %.2f m", s.radius);
      break;
    case world::ShapeKind::kPrism:
      std::snprintf(buf, sizeof(buf), "prism h %.2f m", s.height);
      break;
  }
  return buf;
}

/// A lower-case id prefix from a free-text label ("Red Crate" -> "red_crate").
std::string idPrefix(const std::string& label) {
  std::string out;
  for (char c : label) {
    const auto u = static_cast<unsigned char>(c);
    if (std::isalnum(u)) {
      out += static_cast<char>(std::tolower(u));
    } else if (!out.empty() && out.back() != '_') {
      out += '_';
    }
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  if (out.empty() || !std::isalpha(static_cast<unsigned char>(out[0]))) out = "object" + (out.empty() ? "" : "_" + out);
  if (out.size() > 48) out.resize(48);
  return out;
}

double footprintMajor(const world::Shape& s) {
  const Aabb b = s.localAabb();
  return std::max(b.max.x() - b.min.x(), b.max.y() - b.min.y());
}
/// The farthest point of the footprint from the shape's centre (m).
double footprintReach(const world::Shape& s) {
  double r = 0.0;
  for (const auto& v : s.footprint(16)) r = std::max(r, v.norm());
  return r;
}
double footprintMinor(const world::Shape& s) {
  const Aabb b = s.localAabb();
  return std::min(b.max.x() - b.min.x(), b.max.y() - b.min.y());
}

/// The footprint of `shape` at `world_T_shape` in the world's xy-plane (upright shapes).
world::Polygon2 worldFootprint(const world::Shape& shape, const Eigen::Isometry3d& world_T_shape) {
  world::Polygon2 out = shape.footprint(16);
  for (auto& v : out) v = (world_T_shape * Eigen::Vector3d(v.x(), v.y(), 0.0)).head<2>();
  return out;
}

/// Whether two convex polygons overlap by more than `depth` (separating axes).
bool convexOverlap(const world::Polygon2& a, const world::Polygon2& b, double depth) {
  for (const world::Polygon2* poly : {&a, &b}) {
    for (std::size_t i = 0; i < poly->size(); ++i) {
      const Eigen::Vector2d e = (*poly)[(i + 1) % poly->size()] - (*poly)[i];
      if (e.norm() < 1e-12) continue;
      const Eigen::Vector2d n = Eigen::Vector2d(-e.y(), e.x()).normalized();
      double a0 = kInf, a1 = -kInf, b0 = kInf, b1 = -kInf;
      for (const auto& v : a) a0 = std::min(a0, n.dot(v)), a1 = std::max(a1, n.dot(v));
      for (const auto& v : b) b0 = std::min(b0, n.dot(v)), b1 = std::max(b1, n.dot(v));
      if (a1 - b0 <= depth || b1 - a0 <= depth) return false;
    }
  }
  return true;
}

struct Track {
  std::string id;
  std::string label;
  TrackInfo::State state{TrackInfo::State::kTentative};
  bool from_prior{false};
  bool size_known{false};  ///< shape from a class or the prior; otherwise grown from what is seen
  world::ObjectKind kind{world::ObjectKind::kMovable};
  world::Shape shape;
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d event_pose{Eigen::Isometry3d::Identity()};  ///< at the last added/moved event
  double confidence{0.0};
  int64_t last_seen_ns{0};
  int64_t first_seen_ns{0};
  int hits{0};
  int misses{0};
  int settling{0};  ///< frames before a pose set outright is held against partial views
  double mass{0.0};
  bool graspable{false};
  int cylinder_votes{0};
  int box_votes{0};
  const ObjectClass* cls{nullptr};
  // This frame's measurement (tentatives: for the confirmation).
  bool matched{false};
  bool pushed{false};  ///< moved out of the base this frame (keepOutOfBase)
};

/// Fraction of `points` on the surface of the track's shape at its pose, within `margin` plus the
/// range noise where each point was seen (`noise(range)`: from afar a face spreads over a band
/// many centimetres deep, which is no evidence that the object moved). On, not inside: a face seen
/// 10 cm inside the estimate (a pushed box whose estimate lags) is evidence that it moved.
template <typename Noise>
double explainedFraction(const Track& t, const std::vector<Eigen::Vector3d>& points, double margin,
                         const Eigen::Vector3d& sensor, Noise noise) {
  if (points.empty()) return 0.0;
  std::size_t inside = 0;
  for (const auto& p : points) inside += pointNearSurface(t.shape, t.pose, p, margin + noise((p - sensor).norm())) ? 1 : 0;
  return static_cast<double>(inside) / static_cast<double>(points.size());
}

}  // namespace

std::string_view toString(EventType type) {
  switch (type) {
    case EventType::kAdded:
      return "added";
    case EventType::kMoved:
      return "moved";
    case EventType::kRemoved:
      return "removed";
    case EventType::kGone:
      return "gone";
  }
  return "?";
}

PoseError poseError(const world::Shape& shape, const Eigen::Isometry3d& truth, const Eigen::Isometry3d& estimate) {
  PoseError e;
  const Eigen::Vector3d d = estimate.translation() - truth.translation();
  e.xy = d.head<2>().norm();
  e.z = std::abs(d.z());
  e.yaw = yawError(shape, yawOf(truth), yawOf(estimate));
  return e;
}

struct Perception::Impl {
  PerceptionParams params;
  std::vector<ObjectClass> classes;
  world::World prior;
  world::World world;
  Segmenter segmenter;
  std::unique_ptr<OccupancyMap> occupancy;
  std::map<std::string, Track> tracks;  // by id (tentatives: "tentative_<n>")
  std::uint64_t frames{0};
  int64_t last_stamp{std::numeric_limits<int64_t>::min()};
  int next_tentative{1};
  double floor_height{0.0};
  // The object in the gripper (self filter): its track follows the tool link at a fixed grasp.
  std::string held_id;
  Eigen::Isometry3d tool_T_held{Eigen::Isometry3d::Identity()};

  Impl(world::World prior_world, PerceptionParams p)
      : params(std::move(p)), prior(std::move(prior_world)), world(prior), segmenter(params, prior) {}

  // ---- the frame (processFrame) -----------------------------------------------------------------

  struct SelfFilter;
  struct FrameUpdate;
  /// The robot's body and the held object cut from `input` (when a robot is given and the self
  /// filter is on); result.stats.robot_points counts what was cut.
  SelfFilter filterSelf(const PointCloudFrame& input, const RobotBody* robot, FrameResult& result);

  // ---- helpers ----------------------------------------------------------------------------------

  bool idTaken(const std::string& id) const { return tracks.count(id) > 0 || world.findObject(id) != nullptr; }

  std::string newId(const std::string& label) const {
    const std::string prefix = idPrefix(label);
    for (int n = 1;; ++n) {
      std::string id = prefix + "_" + std::to_string(n);
      if (!idTaken(id)) return id;
    }
  }

  /// Height of the surface under a cluster whose lowest point is at `zmin`.
  double supportBelow(const Eigen::Vector2d& xy, double zmin, const std::vector<SupportPlane>& planes) const {
    const double tol = 0.05;
    double best = -kInf;
    for (const auto& pl : planes) {
      if (pl.height > zmin + tol) continue;
      if (pl.hull.size() >= 3 && !world::containsPoint(pl.hull, xy)) continue;
      best = std::max(best, pl.height);
    }
    for (const auto& r : prior.regions()) {
      if (r.height <= zmin + tol && r.contains(xy)) best = std::max(best, r.height);
    }
    for (const auto& o : prior.objects()) {
      if (o.kind != world::ObjectKind::kStatic) continue;
      const Aabb b = o.aabb();
      if (b.max.z() > zmin + tol || b.max.z() <= best) continue;
      const Eigen::Vector3d top(xy.x(), xy.y(), b.max.z() - 1e-3);
      if (pointInShape(o.shape, o.pose, top, 0.0)) best = b.max.z();
    }
    return std::isfinite(best) ? best : floor_height;
  }

  /// The object just released (`held_id`): placed, it rests on its support already; dropped, it
  /// is in the air where it was carried and falls onto the support below it. Often the camera
  /// cannot see there (right in front of the base), so that is where the world model keeps it
  /// until a view corrects it: seen elsewhere, reacquired; seen empty there, gone.
  void settleReleased(FrameResult& result, std::int64_t stamp, const RobotBody* body) {
    auto it = tracks.find(held_id);
    if (it == tracks.end() || it->second.state == TrackInfo::State::kGone) return;
    // Where the gripper let it go, when the robot's states say (the last frame that saw it held
    // may be half a second of driving earlier: the estimate fell 19 cm short, transport_drop).
    if (body != nullptr && body->world_T_tool_at_release && body->released_object_id == held_id)
      it->second.pose = *body->world_T_tool_at_release * tool_T_held;
    if (settleIfUnsupported(it->second, result, stamp, "released") && body != nullptr) keepOutOfBody(it->second, *body);
  }

  /// A fallen object cannot be inside the robot: the estimate of where it fell (from where it was
  /// believed carried) can put it there, and the camera often cannot see right in front of the
  /// base to correct it. It is moved straight away from the part it overlaps (horizontally, in
  /// 1 cm steps, at most 0.5 m) until their boxes are apart.
  void keepOutOfBody(Track& t, const RobotBody& body) {
    constexpr double kStep = 0.01, kMaxShift = 0.5;
    for (double moved = 0.0; moved <= kMaxShift; moved += kStep) {
      const Aabb box = objectOf(t).aabb();
      const BodyPart* hit = nullptr;
      for (const auto& part : body.parts) {
        world::Object solid;
        solid.shape = part.shape;
        solid.pose = part.world_T_shape;
        if (solid.aabb().overlaps(box)) hit = &part;
      }
      if (hit == nullptr) {
        if (moved > 0.0) (void)world.updateObject(objectOf(t));
        return;
      }
      Eigen::Vector2d away = t.pose.translation().head<2>() - hit->world_T_shape.translation().head<2>();
      if (away.norm() < 1e-9) away = body.world_T_tool.translation().head<2>() - hit->world_T_shape.translation().head<2>();
      if (away.norm() < 1e-9) return;
      t.pose.translation().head<2>() += kStep * away.normalized();
      t.event_pose = t.pose;
    }
  }

  /// Which way a track overlapping the base part `base` (world footprint, pose) leaves it: along
  /// the base's heading when its centre is ahead of the part and within the part's width (the
  /// base drives into it: pushed), else straight away from the part's centre. An estimate beside
  /// the base (a box growing from partial views as the robot drives past it) is no push: moved
  /// along the heading, it was carried ahead of the robot until it left the object it stands for.
  static Eigen::Vector2d pushDirection(const Track& t,
                                       const std::pair<world::Polygon2, Eigen::Isometry3d>& base) {
    const Eigen::Vector2d centre = base.second.translation().head<2>();
    const Eigen::Vector2d away = t.pose.translation().head<2>() - centre;
    const Eigen::Vector2d heading = base.second.linear().col(0).head<2>().normalized();
    const Eigen::Vector2d side(-heading.y(), heading.x());
    double half_width = 0.0;
    for (const auto& v : base.first) half_width = std::max(half_width, std::abs(side.dot(v - centre)));
    if (away.dot(heading) > 0.0 && std::abs(side.dot(away)) <= half_width) return heading;
    return away.norm() > 1e-9 ? away.normalized() : heading;
  }

  /// An object cannot be inside the robot's base: the base drives into what it pushes, whose
  /// near face is filtered as the robot's own and whose smoothed (or kept, for a partial view)
  /// estimate lags behind. A track whose footprint the base's overlaps by more than `depth` is
  /// moved out (`pushDirection`) in 1 cm steps, at most 0.6 m. True when it moved.
  bool keepOutOfBase(Track& t, const RobotBody& body, double depth) {
    constexpr double kStep = 0.01, kMaxShift = 0.6;
    const double z0 = t.pose.translation().z() - t.shape.halfHeight(), z1 = t.pose.translation().z() + t.shape.halfHeight();
    std::vector<std::pair<world::Polygon2, Eigen::Isometry3d>> base;
    for (const auto& part : body.parts) {
      if (part.owner != body.base_link) continue;
      const Aabb b = part.shape.aabb(part.world_T_shape);
      if (b.max.z() <= z0 || b.min.z() >= z1) continue;  // not at the object's height
      base.emplace_back(worldFootprint(part.shape, part.world_T_shape), part.world_T_shape);
    }
    if (base.empty() || !world::isConvex(t.shape.footprint(16))) return false;
    Eigen::Vector2d dir = Eigen::Vector2d::Zero();
    double moved = 0.0;
    for (; moved <= kMaxShift; moved += kStep) {
      // Deeper than `depth` to start (an estimate beside the base may graze it), then out of it.
      const world::Polygon2 fp = worldFootprint(t.shape, t.pose);
      const std::pair<world::Polygon2, Eigen::Isometry3d>* hit = nullptr;
      for (const auto& b : base)
        if (convexOverlap(fp, b.first, moved > 0.0 ? 0.0 : depth)) hit = &b;
      if (hit == nullptr) break;
      if (dir.isZero()) dir = pushDirection(t, *hit);
      t.pose.translation().head<2>() += kStep * dir;
    }
    return moved > 0.0;
  }

  /// An object whose bottom is above the support below it falls onto that support (a MOVED
  /// event); false when it rests. Also for an object seen empty where it was in the air: the
  /// robot released it before perception saw it held (a drop right after start-up).
  bool settleIfUnsupported(Track& t, FrameResult& result, std::int64_t stamp, const char* what) {
    const Eigen::Vector3d c = t.pose.translation();
    const double bottom = c.z() - t.shape.halfHeight();
    const double support = supportBelow(c.head<2>(), bottom, {});
    if (bottom - support <= kRestingGap) return false;
    t.pose = uprightPose(c.x(), c.y(), support + t.shape.halfHeight(), yawOf(t.pose));
    t.event_pose = t.pose;
    t.misses = 0;
    t.settling = params.tracking.settle_frames;
    (void)world.updateObject(objectOf(t));
    char why[200];
    std::snprintf(why, sizeof(why), "%s %.2f m above its support: fell to %s", what, bottom - support,
                  describePose(t.pose).c_str());
    pushEvent(result, EventType::kMoved, t, t.pose, why, stamp);
    return true;
  }

  /// The class a detection fits best (compatible size, least mismatch), or nullptr.
  const ObjectClass* bestClass(const Detection& d, const Eigen::Vector3d& sensor) const {
    const ObjectClass* best = nullptr;
    double best_cost = kInf;
    for (const auto& c : classes) {
      const ShapeFit f = fitShape(d, c.shape, sensor, params.tracking);
      if (!f.compatible) continue;
      const bool round = c.shape.kind == world::ShapeKind::kCylinder || c.shape.kind == world::ShapeKind::kSphere;
      const bool det_round = d.kind == world::ShapeKind::kCylinder;
      const double h = std::max(params.tracking.height_tolerance, 0.1 * 2 * c.shape.halfHeight());
      const double cost = std::abs(f.height_error) / h + f.deficit / std::max(params.tracking.size_tolerance, 0.01) * 0.5 +
                          f.residual / 0.01 + (round != det_round ? 1.0 : 0.0);
      if (cost < best_cost) {
        best_cost = cost;
        best = &c;
      }
    }
    return best;
  }

  world::Object objectOf(const Track& t) const {
    world::Object o;
    o.id = t.id;
    o.label = t.label;
    o.kind = t.kind;
    o.shape = t.shape;
    o.pose = t.pose;
    o.mass = t.kind == world::ObjectKind::kMovable ? std::max(t.mass, params.classify.min_mass) : std::max(t.mass, 0.0);
    o.graspable = t.graspable;
    const double bottom = t.pose.translation().z() - t.shape.halfHeight();
    if (const world::Region* r = world.regionBelow(Eigen::Vector3d(t.pose.translation().x(), t.pose.translation().y(), bottom + 0.01), 0.05)) {
      o.region = r->id;
    }
    return o;
  }

  /// `held`, reported in the gripper but tracked elsewhere, is the confirmed new object `seen` at
  /// the gripper: moved there (a MOVED event), its grasp fixed from the next frame on.
  void relearnHeld(Track& held, const Track& seen, FrameResult& result, std::int64_t stamp) {
    const Eigen::Isometry3d was = held.pose;
    held.pose = seen.pose;
    held.event_pose = seen.pose;
    held.settling = params.tracking.settle_frames;
    held.hits += seen.hits;
    held.misses = 0;
    held.last_seen_ns = stamp;
    held.confidence = std::max(held.confidence, seen.confidence);
    if (held.state == TrackInfo::State::kGone) {
      held.state = TrackInfo::State::kActive;
      (void)world.addObject(objectOf(held));
    } else {
      (void)world.updateObject(objectOf(held));
    }
    char why[200];
    std::snprintf(why, sizeof(why), "held by the robot: relearned at the gripper at %s, %.2f m from where it was tracked",
                  describePose(held.pose).c_str(), (held.pose.translation() - was.translation()).norm());
    pushEvent(result, EventType::kMoved, held, held.pose, why, stamp);
  }

  /// Mass, graspability and kind of a track without a class (size thresholds).
  void classifyBySize(Track& t) const {
    const ClassifyParams& c = params.classify;
    const double major = footprintMajor(t.shape), minor = footprintMinor(t.shape);
    const double height = 2 * t.shape.halfHeight();
    t.kind = major <= c.movable_max_extent && height <= c.movable_max_height ? world::ObjectKind::kMovable
                                                                              : world::ObjectKind::kStatic;
    t.mass = std::max(c.min_mass, c.density * t.shape.volume());
    t.graspable = t.kind == world::ObjectKind::kMovable && minor <= c.graspable_max_width && t.mass <= c.graspable_max_mass;
  }

  /// Shape of a size-unknown track grown by a new detection (never shrinks: partial views).
  void growShape(Track& t, const Detection& d) const {
    (d.kind == world::ShapeKind::kCylinder ? t.cylinder_votes : t.box_votes) += 1;
    const bool cylinder = t.cylinder_votes > t.box_votes;
    const double h = std::max(2 * t.shape.halfHeight(), d.height);
    const double max_size = params.clusters.max_size;
    if (cylinder) {
      const double r_old = t.shape.kind == world::ShapeKind::kCylinder ? t.shape.radius : 0.0;
      const double r = std::min(std::max(r_old, d.kind == world::ShapeKind::kCylinder ? d.shape.radius : d.majorExtent() / 2), max_size / 2);
      t.shape = world::Shape::cylinder(std::max(r, 1e-3), std::max(h, 1e-3));
    } else {
      Eigen::Vector2d e = d.rect.extents;
      if (t.shape.kind == world::ShapeKind::kBox) {
        // Keep the track's axis order: match the detection's extents to the closer assignment.
        const Eigen::Vector2d old(t.shape.size.x(), t.shape.size.y());
        const Eigen::Vector2d sw(e.y(), e.x());
        const double yaw_t = yawOf(t.pose), yaw_d = d.rect.yaw;
        const double dyaw = std::abs(std::remainder(yaw_t - yaw_d, std::numbers::pi));
        if (dyaw > std::numbers::pi / 4) e = sw;
        e = e.cwiseMax(old);
      }
      e = e.cwiseMin(max_size);
      t.shape = world::Shape::box(std::max(e.x(), 1e-3), std::max(e.y(), 1e-3), std::max(h, 1e-3));
    }
  }

  void pushEvent(FrameResult& r, EventType type, const Track& t, const Eigen::Isometry3d& pose, std::string why,
                 int64_t stamp) const {
    WorldEvent e;
    e.type = type;
    e.object_id = t.id;
    e.kind = t.kind;
    e.pose = pose;
    e.description = std::move(why);
    e.stamp_ns = stamp;
    r.events.push_back(std::move(e));
  }
};

// ---- construction -------------------------------------------------------------------------------

Perception::Perception(world::World prior, PerceptionParams params) {
  if (Status s = params.validate(); !s.ok()) throw std::invalid_argument(s.error().toString());
  if (prior.hiddenCount() > 0) {
    throw std::invalid_argument("Perception: the prior world has " + std::to_string(prior.hiddenCount()) +
                                " hidden object(s); pass its plannerView()");
  }
  impl_ = std::make_unique<Impl>(std::move(prior), std::move(params));
  Impl& I = *impl_;
  I.classes = I.params.classes;
  for (auto& c : classesFromWorld(I.prior)) {
    const bool known = std::any_of(I.classes.begin(), I.classes.end(), [&](const ObjectClass& k) { return k.label == c.label; });
    if (!known) I.classes.push_back(std::move(c));
  }
  if (I.params.occupancy.enabled) I.occupancy = std::make_unique<OccupancyMap>(I.params.occupancy);
  for (const auto& r : I.prior.regions()) {
    if (r.kind == world::RegionKind::kFloor) I.floor_height = r.height;
  }
  for (const auto& o : I.prior.objects()) {
    if (o.kind != world::ObjectKind::kMovable) continue;
    Track t;
    t.id = o.id;
    t.label = o.label;
    t.state = TrackInfo::State::kActive;
    t.from_prior = true;
    t.size_known = true;
    t.kind = o.kind;
    t.shape = o.shape;
    t.pose = o.pose;
    t.event_pose = o.pose;
    t.confidence = 1.0;
    t.mass = o.mass;
    t.graspable = o.graspable;
    I.tracks.emplace(t.id, std::move(t));
  }
}

Perception::~Perception() = default;

const world::World& Perception::world() const { return impl_->world; }
const PerceptionParams& Perception::params() const { return impl_->params; }
const std::vector<ObjectClass>& Perception::classes() const { return impl_->classes; }
std::uint64_t Perception::frames() const { return impl_->frames; }
const OccupancyMap* Perception::occupancy() const { return impl_->occupancy.get(); }
const std::string& Perception::heldObject() const { return impl_->held_id; }

std::optional<Perception::HeldGrasp> Perception::heldGrasp() const {
  if (impl_->held_id.empty()) return std::nullopt;
  return HeldGrasp{impl_->held_id, impl_->tool_T_held};
}

Status Perception::resumeGrasp(const HeldGrasp& grasp) {
  Impl& I = *impl_;
  auto it = I.tracks.find(grasp.object_id);
  if (it == I.tracks.end() || it->second.state == TrackInfo::State::kGone)
    return Error(ErrorCode::kNotFound, "resumeGrasp: '" + grasp.object_id + "' is not tracked");
  if (!grasp.tool_T_object.matrix().allFinite())
    return Error(ErrorCode::kInvalidArgument, "resumeGrasp: the tool_T_object of '" + grasp.object_id + "' is not finite");
  I.held_id = grasp.object_id;
  I.tool_T_held = grasp.tool_T_object;
  return Status::Ok();
}
std::string Perception::occupancyBinary() const { return impl_->occupancy ? impl_->occupancy->toBinary() : std::string(); }

namespace {
TrackInfo infoOf(const Track& t) {
  TrackInfo i;
  i.id = t.id;
  i.label = t.label;
  i.state = t.state;
  i.from_prior = t.from_prior;
  i.kind = t.kind;
  i.shape = t.shape;
  i.pose = t.pose;
  i.confidence = t.confidence;
  i.last_seen_ns = t.last_seen_ns;
  i.hits = t.hits;
  i.misses = t.misses;
  return i;
}
}  // namespace

std::vector<TrackInfo> Perception::tracks() const {
  std::vector<TrackInfo> out;
  for (const auto& [id, t] : impl_->tracks) out.push_back(infoOf(t));
  return out;
}

std::optional<TrackInfo> Perception::track(std::string_view id) const {
  auto it = impl_->tracks.find(std::string(id));
  if (it == impl_->tracks.end()) return std::nullopt;
  return infoOf(it->second);
}

Result<WorldEvent> Perception::removeObject(std::string_view id, const std::string& reason) {
  Impl& I = *impl_;
  const world::Object* o = I.world.findObject(id);
  if (o == nullptr) return Error(ErrorCode::kNotFound, "no object '" + std::string(id) + "' in the world model");
  if (I.prior.findObject(id) != nullptr && o->kind == world::ObjectKind::kStatic) {
    return Error(ErrorCode::kInvalidArgument, "'" + std::string(id) + "' is part of the static map");
  }
  WorldEvent e;
  e.type = EventType::kRemoved;
  e.object_id = o->id;
  e.kind = o->kind;
  e.pose = o->pose;
  e.description = "removed on request: " + reason;
  e.stamp_ns = I.last_stamp == std::numeric_limits<int64_t>::min() ? 0 : I.last_stamp;
  if (Status s = I.world.removeObject(id); !s.ok()) return s.error();
  I.tracks.erase(std::string(id));
  return e;
}

// ---- the frame ----------------------------------------------------------------------------------

/// What the self filter (self_filter.h) decided for a frame: the robot's body and the held object
/// cut from its points. Applied to the tracks only once the frame is committed (FrameUpdate).
struct Perception::Impl::SelfFilter {
  bool enabled{false};
  Track* held{nullptr};
  // Reported held, but tracked implausibly far from the gripper (perception restarted from the
  // prior while the robot carries it): no grasp to fix yet; it is relearned from the points at
  // the gripper, as an object held but unknown is (FrameUpdate).
  Track* held_elsewhere{nullptr};
  Eigen::Isometry3d tool_T_held{Eigen::Isometry3d::Identity()};
  std::optional<PointCloudFrame> filtered;  ///< the input without the robot's points, when enabled
};

Perception::Impl::SelfFilter Perception::Impl::filterSelf(const PointCloudFrame& input, const RobotBody* robot,
                                                          FrameResult& result) {
  const PerceptionParams& P = params;
  SelfFilter f;
  f.enabled = robot != nullptr && P.self_filter.enabled;
  f.tool_T_held = tool_T_held;
  if (!f.enabled) return f;
  if (auto it = tracks.find(robot->held_object_id);
      !robot->held_object_id.empty() && it != tracks.end() && it->second.state != TrackInfo::State::kTentative) {
    f.held = &it->second;
    // A new grasp: the object is where it was last tracked, now rigidly on the tool link --
    // when that is at the gripper at all.
    if (held_id != f.held->id) {
      if (pointInShape(f.held->shape, f.held->pose, robot->world_T_tool.translation(), P.self_filter.held_adopt_radius)) {
        f.tool_T_held = robot->world_T_tool.inverse() * f.held->pose;
      } else {
        f.held_elsewhere = f.held;
        f.held = nullptr;
      }
    }
  }
  world::Object held_solid;
  if (f.held != nullptr) {
    held_solid.shape = f.held->shape;
    held_solid.pose = robot->world_T_tool * f.tool_T_held;
  }
  f.filtered = input;
  result.stats.robot_points = removeBodyPoints(*f.filtered, *robot, f.held != nullptr ? &held_solid : nullptr,
                                               P.self_filter.padding);
  return f;
}

namespace {

/// Copies the segmentation's stage times, counts and support planes into `result`.
void reportSegmentation(const Segmentation& S, FrameResult& result) {
  result.times.transform_crop = S.times.transform_crop;
  result.times.voxel = S.times.voxel;
  result.times.planes = S.times.planes;
  result.times.static_objects = S.times.static_objects;
  result.times.clustering = S.times.clustering;
  result.stats.valid_points = S.valid_points;
  result.stats.cropped_points = S.cropped_points;
  result.stats.voxel_points = S.scan.size();
  result.stats.plane_points = S.plane_points;
  result.stats.static_points = S.static_points;
  result.stats.planes = static_cast<int>(S.planes.size());
  result.stats.clusters = static_cast<int>(S.clusters.size());
  result.planes = S.planes;
}

}  // namespace

/// The steps of a committed frame (processFrame), in order: the held object, detections,
/// association, tentative objects, undetected tracks, confirmations, world updates, occupancy;
/// and the state they hand on.
struct Perception::Impl::FrameUpdate {
  FrameUpdate(Impl& impl, const RobotBody* robot_body, const SelfFilter& self, const PointCloudFrame& committed,
              const Segmentation& segmentation, FrameResult& frame_result)
      : I(impl),
        P(impl.params),
        T(impl.params.tracking),
        robot(robot_body),
        self_filter(self.enabled),
        held(self.held),
        held_elsewhere(self.held_elsewhere),
        tool_T_held(self.tool_T_held),
        frame(committed),
        S(segmentation),
        result(frame_result),
        stamp(committed.stamp_ns),
        sensor(committed.world_T_sensor.translation()) {}

  Impl& I;
  const PerceptionParams& P;
  const TrackingParams& T;
  const RobotBody* robot;
  const bool self_filter;
  Track* held;
  Track* held_elsewhere;  ///< relearned at most once per frame (confirmTentatives)
  const Eigen::Isometry3d tool_T_held;
  const PointCloudFrame& frame;
  const Segmentation& S;
  FrameResult& result;
  const int64_t stamp;
  const Eigen::Vector3d sensor;
  /// Held, but unknown to every track (the planner was not told about it): see detect().
  bool held_unknown{false};
  Eigen::Vector3d tool{Eigen::Vector3d::Zero()};  ///< the tool link's position, when a robot is given
  std::vector<Eigen::Vector3f> unexplained;       ///< points for the occupancy map
  std::vector<std::size_t> det_cluster;           ///< detection -> cluster index
  std::vector<char> det_used;                     ///< detection -> matched or a fragment of a track
  // Returns binned by direction, built when first asked: is a place seen free, hidden, or out of
  // the image (the fits of tracked boxes ask whether a seen end is a face; gone objects below).
  std::optional<RangeImage> image;

  RangeImage& rangeImage() {
    if (!image) image.emplace(frame, T.visibility_bin);
    return *image;
  }

  bool seenFree(const Eigen::Vector3d& p) {
    const Eigen::Vector3d half(0.01, 0.01, 0.01);
    return rangeImage().seenThrough(p - half, p + half, T.visibility_margin);
  }

  bool atTheGripper(const Eigen::Vector2d& xy, double zmin, double zmax) const {
    const double r = P.self_filter.held_adopt_radius;
    return held_unknown && (xy - tool.head<2>()).norm() <= r && tool.z() >= zmin - r && tool.z() <= zmax + r;
  }

  /// The held object follows the gripper; a release (the state reports the gripper empty, or
  /// another object) leaves it where it was last carried, tracked as any other from then on.
  void followHeld() {
    if (self_filter) {
      if (!I.held_id.empty() && (held == nullptr || held->id != I.held_id)) I.settleReleased(result, stamp, robot);
      I.held_id = held != nullptr ? held->id : std::string();
      I.tool_T_held = held != nullptr ? tool_T_held : Eigen::Isometry3d::Identity();
    }
    if (held == nullptr) return;
    held->pose = robot->world_T_tool * tool_T_held;
    held->misses = 0;
    if (held->state == TrackInfo::State::kGone) {
      held->state = TrackInfo::State::kActive;  // the robot holds it: it is back
      (void)I.world.addObject(I.objectOf(*held));
    } else if (const world::Object* o = I.world.findObject(held->id)) {
      const double dpos = (o->pose.translation() - held->pose.translation()).norm();
      const double dang = Eigen::AngleAxisd(o->pose.linear().transpose() * held->pose.linear()).angle();
      if (dpos > T.update_distance || dang > T.update_angle) (void)I.world.updateObject(I.objectOf(*held));
    }
  }

  /// Clusters described as detections (result.detections); the rest unexplained points.
  void detect() {
    // Unexplained points: small clusters that stand clearly above their support (a few returns
    // hugging the floor are range noise, not an obstacle).
    for (const auto& c : S.small_clusters) {
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      double zmin = kInf, zmax = -kInf;
      for (const auto& p : c) {
        mean += p.head<2>().cast<double>();
        zmin = std::min(zmin, double(p.z()));
        zmax = std::max(zmax, double(p.z()));
      }
      mean /= static_cast<double>(c.size());
      if (zmax > I.supportBelow(mean, zmin, S.planes) + P.clusters.min_height) {
        unexplained.insert(unexplained.end(), c.begin(), c.end());
      }
    }
    // Held, but unknown to every track (the planner was not told about it): the cluster at the
    // gripper hangs from it, it does not stand on a support, and it is the object the robot holds.
    held_unknown = self_filter && held == nullptr && !robot->held_object_id.empty() &&
                   (held_elsewhere != nullptr || (I.tracks.count(robot->held_object_id) == 0 &&
                                                  I.world.findObject(robot->held_object_id) == nullptr));
    if (robot != nullptr) tool = robot->world_T_tool.translation();
    for (std::size_t ci = 0; ci < S.clusters.size(); ++ci) {
      const auto& c = S.clusters[ci];
      std::vector<Eigen::Vector3d> pts;
      pts.reserve(c.size());
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      double zmin = kInf, zmax = -kInf;
      for (const auto& p : c) {
        pts.emplace_back(p.cast<double>());
        mean += p.head<2>().cast<double>();
        zmin = std::min(zmin, double(p.z()));
        zmax = std::max(zmax, double(p.z()));
      }
      mean /= static_cast<double>(c.size());
      const double support = atTheGripper(mean, zmin, zmax) ? zmin : I.supportBelow(mean, zmin, S.planes);
      Detection d = describeCluster(std::move(pts), support, P.clusters);
      const double major = d.majorExtent();
      if (d.height < P.clusters.min_height || major < P.clusters.min_size) {
        // Too flat or too small to be an object: noise unless clearly above its support.
        if (d.height > P.clusters.min_height) unexplained.insert(unexplained.end(), c.begin(), c.end());
        continue;
      }
      if (major > P.clusters.max_size) {
        unexplained.insert(unexplained.end(), c.begin(), c.end());
        continue;
      }
      result.detections.push_back(std::move(d));
      det_cluster.push_back(ci);
    }
    result.stats.detections = static_cast<int>(result.detections.size());
  }

  /// Detections assigned to the tracks they fit best (least cost), and those tracks updated.
  void associate() {
    std::vector<Track*> candidates;
    for (auto& [id, t] : I.tracks) {
      t.matched = false;
      t.pushed = false;
      if (t.state != TrackInfo::State::kGone && id != I.held_id) candidates.push_back(&t);
    }
    const auto& dets = result.detections;
    auto seen_free = [this](const Eigen::Vector3d& p) { return seenFree(p); };
    std::vector<std::vector<double>> cost(dets.size(), std::vector<double>(candidates.size(), kInf));
    std::vector<std::vector<ShapeFit>> fits(dets.size(), std::vector<ShapeFit>(candidates.size()));
    for (std::size_t i = 0; i < dets.size(); ++i) {
      for (std::size_t j = 0; j < candidates.size(); ++j) {
        const Track& t = *candidates[j];
        ShapeFit f;
        if (t.size_known) {
          f = fitShape(dets[i], t.shape, sensor, T, yawOf(t.pose), t.pose.translation().head<2>(), seen_free);
          if (!f.compatible) continue;
        } else {
          f.pose = dets[i].pose;
          f.height_error = dets[i].height - 2 * t.shape.halfHeight();
          if (std::abs(f.height_error) > std::max(T.height_tolerance, 0.3 * dets[i].height)) continue;
          // The detection's observed centre is biased towards the sensor; compare it with the
          // track's by their footprints' overlap instead of their centres alone.
        }
        const double dist = (f.pose.translation().head<2>() - t.pose.translation().head<2>()).norm();
        double gate = T.gate_distance;
        if (!t.size_known) gate += 0.5 * footprintMajor(t.shape);
        if (dist > gate) continue;
        const bool round = t.shape.kind == world::ShapeKind::kCylinder || t.shape.kind == world::ShapeKind::kSphere;
        const bool det_round = dets[i].kind == world::ShapeKind::kCylinder;
        cost[i][j] = dist + 0.5 * f.residual + (t.state == TrackInfo::State::kTentative ? 0.05 : 0.0) +
                     (round != det_round ? 0.05 : 0.0);
        fits[i][j] = f;
      }
    }
    const std::vector<int> assign = solveAssignment(cost);

    det_used.assign(dets.size(), 0);
    for (std::size_t i = 0; i < dets.size(); ++i) {
      if (assign[i] < 0) continue;
      det_used[i] = 1;
      Track& t = *candidates[static_cast<std::size_t>(assign[i])];
      updateMatched(t, dets[i], fits[i][static_cast<std::size_t>(assign[i])]);
      result.stats.matched += t.state == TrackInfo::State::kActive ? 1 : 0;
    }
  }

  /// Track `t` seen again as `d`, fitted by `f`: its pose follows (snapped or smoothed).
  void updateMatched(Track& t, const Detection& d, const ShapeFit& f) {
    t.matched = true;
    ++t.hits;
    t.misses = 0;
    t.last_seen_ns = stamp;
    t.confidence = t.confidence + (1.0 - t.confidence) * 0.3;
    Eigen::Isometry3d meas = f.pose;
    const world::Shape shape_before = t.shape;
    if (!t.size_known) {
      I.growShape(t, d);
      // Refit the grown shape (anchored on the seen faces) for the pose.
      meas = fitShape(d, t.shape, sensor, T, yawOf(t.pose), t.pose.translation().head<2>(),
                      [this](const Eigen::Vector3d& p) { return seenFree(p); }, /*known_size=*/false)
                 .pose;
      log::get("perception")->debug("{} grown to {:.2f} x {:.2f}: detection rect {:.2f} x {:.2f} yaw {:.2f} at ({:.2f}, {:.2f}); fit ({:.2f}, {:.2f}) yaw {:.2f}, track ({:.2f}, {:.2f})",
                                    t.id, t.shape.size.x(), t.shape.size.y(), d.rect.extents.x(), d.rect.extents.y(),
                                    d.rect.yaw, d.pose.translation().x(), d.pose.translation().y(),
                                    meas.translation().x(), meas.translation().y(), yawOf(meas), t.pose.translation().x(),
                                    t.pose.translation().y());
    }
    double jump = (meas.translation() - t.pose.translation()).norm();
    // A partial view (one end hidden, the object seen edge-on) pulls a known-size fit towards
    // the visible part. Points that the object where it stands explains are no evidence that it
    // moved: the pose stays. So too for a shape grown from what was seen, once this view no
    // longer grows it: seen close, part of a crate out of the image, the fit anchored on the
    // seen end slid the whole estimate 0.2 m a frame off the crate (namo_room_hidden).
    if (jump > T.explained_margin && t.settling == 0 && (t.size_known || t.shape == shape_before) &&
        (t.from_prior || t.hits > 2) &&
        explainedFraction(t, d.points, T.explained_margin, sensor,
                          [&](double range) { return P.planes.noise_sigmas * P.sensor.stddev(range); }) >=
            T.explained_fraction) {
      meas = t.pose;
      jump = 0.0;
    }
    if (jump > T.snap_distance || t.hits <= 1) {
      if (jump > T.snap_distance) t.settling = T.settle_frames;
      t.pose = meas;
    } else {
      t.settling = std::max(0, t.settling - 1);
      const double a = T.smoothing;
      const Eigen::Vector3d pos = t.pose.translation() + a * (meas.translation() - t.pose.translation());
      double yaw_t = yawOf(t.pose), yaw_m = yawOf(meas);
      const double sym = yawSymmetry(t.shape);
      double dy = sym > 0 ? yaw_m - yaw_t - sym * std::round((yaw_m - yaw_t) / sym) : 0.0;
      t.pose = uprightPose(pos.x(), pos.y(), meas.translation().z(), sym > 0 ? wrapAngle(yaw_t + a * dy) : 0.0);
    }
  }

  /// Movable objects cannot be inside the base (keepOutOfBase): what it pushes stays ahead of it.
  /// The world model follows in updateWorld, with the other tracks' updates.
  void keepOutOfBase() {
    if (!self_filter) return;
    for (auto& [id, t] : I.tracks) {
      if (t.state != TrackInfo::State::kActive || t.kind != world::ObjectKind::kMovable || id == I.held_id ||
          id == robot->held_object_id)
        continue;
      const Eigen::Vector3d was = t.pose.translation();
      t.pushed = I.keepOutOfBase(t, *robot, P.self_filter.padding);
      if (t.pushed)
        log::get("perception")->debug("{} kept out of the base: ({:.2f}, {:.2f}) -> ({:.2f}, {:.2f}), sensor at ({:.2f}, {:.2f})",
                                      id, was.x(), was.y(), t.pose.translation().x(), t.pose.translation().y(),
                                      sensor.x(), sensor.y());
    }
  }

  /// Whether most of `d`'s points are inside a tracked object: a fragment of it, e.g. a side face
  /// split off by range noise, or the part of it the image cuts off, too short to match it.
  /// Inside within the size tolerance plus the range noise where the point was seen: from afar a
  /// face spreads over a band a dozen centimetres deep, and the track may be a few centimetres off.
  bool isFragment(const Detection& d) const {
    std::vector<double> margins;  // per point, the same for every track
    margins.reserve(d.points.size());
    for (const auto& p : d.points)
      margins.push_back(T.size_tolerance + P.planes.noise_sigmas * P.sensor.stddev((p - sensor).norm()));
    for (const auto& [id, t] : I.tracks) {
      if (t.state == TrackInfo::State::kGone) continue;
      std::size_t inside = 0;
      for (std::size_t k = 0; k < d.points.size(); ++k)
        inside += pointInShape(t.shape, t.pose, d.points[k], margins[k]) ? 1 : 0;
      if (2 * inside >= d.points.size()) return true;
    }
    return false;
  }

  /// Unmatched detections become tentative objects (class from the priors, else by size),
  /// unless they are fragments of a tracked object (isFragment).
  void addTentatives() {
    const auto& dets = result.detections;
    for (std::size_t i = 0; i < dets.size(); ++i) {
      if (det_used[i]) continue;
      const Detection& d = dets[i];
      if (isFragment(d)) {
        det_used[i] = 1;
        continue;
      }
      Track t;
      t.id = "tentative_" + std::to_string(I.next_tentative++);
      t.state = TrackInfo::State::kTentative;
      t.hits = 1;
      t.first_seen_ns = stamp;
      t.last_seen_ns = stamp;
      t.confidence = 0.3;
      t.matched = true;
      if (const ObjectClass* c = I.bestClass(d, sensor)) {
        t.cls = c;
        t.label = c->label;
        t.size_known = true;
        t.shape = c->shape;
        t.kind = c->kind;
        t.mass = c->mass;
        t.graspable = c->graspable;
        t.pose = fitShape(d, c->shape, sensor, T).pose;
      } else {
        t.size_known = false;
        t.shape = d.shape;
        (d.kind == world::ShapeKind::kCylinder ? t.cylinder_votes : t.box_votes) = 1;
        t.pose = d.pose;
        t.label = d.kind == world::ShapeKind::kCylinder ? "cylinder" : "box";
      }
      log::get("perception")->debug("{}: a detection no track explains, rect {:.2f} x {:.2f} yaw {:.2f} at ({:.2f}, {:.2f}), "
                                    "{} points, sensor at ({:.2f}, {:.2f}, {:.2f})",
                                    t.id, d.rect.extents.x(), d.rect.extents.y(), d.rect.yaw, d.pose.translation().x(),
                                    d.pose.translation().y(), d.points.size(), sensor.x(), sensor.y(), sensor.z());
      I.tracks.emplace(t.id, std::move(t));
    }
  }

  /// Expected objects not detected: seen empty (missed, then gone), hidden, or out of view.
  void checkUndetected() {
    std::vector<std::string> dropped;
    for (auto& [id, t] : I.tracks) {
      if (t.matched || t.state == TrackInfo::State::kGone || id == I.held_id || &t == held_elsewhere) continue;
      world::Object o;
      o.shape = t.shape;
      o.pose = t.pose;
      const ObjectVisibility v = rangeImage().checkObject(o, T.visibility_margin);
      const bool decidable = v.testable >= T.gone_min_samples;
      const bool seen_empty = decidable && v.throughFraction() >= T.gone_fraction && v.presentFraction() < T.present_fraction;
      if (t.state == TrackInfo::State::kTentative) {
        if (seen_empty || stamp - t.last_seen_ns > static_cast<int64_t>(T.tentative_timeout_s * 1e9)) dropped.push_back(id);
        continue;
      }
      if (seen_empty && I.settleIfUnsupported(t, result, stamp, "seen empty in the air")) continue;
      if (seen_empty) {
        ++t.misses;
        t.confidence *= 0.5;
        if (t.misses >= T.gone_frames) {
          t.state = TrackInfo::State::kGone;
          (void)I.world.removeObject(t.id);
          char why[160];
          std::snprintf(why, sizeof(why), "not at %s although in view: %d of %d samples seen through in %d frame(s)",
                        describePose(t.pose).c_str(), v.through, v.testable, t.misses);
          I.pushEvent(result, EventType::kGone, t, t.pose, why, stamp);
        }
      } else if (decidable && v.presentFraction() >= T.present_fraction) {
        t.misses = 0;  // something is there though no cluster matched (e.g. merged with a neighbour)
      }
    }
    for (const auto& id : dropped) I.tracks.erase(id);
  }

  /// Tentative objects seen often enough: the held object relearned, a gone object reacquired,
  /// or a new object in the world model.
  void confirmTentatives() {
    std::vector<std::string> confirmed;
    for (auto& [id, t] : I.tracks) {
      if (t.state == TrackInfo::State::kTentative && t.matched && t.hits >= T.confirm_hits) confirmed.push_back(id);
    }
    for (const auto& tid : confirmed) {
      Track t = std::move(I.tracks.at(tid));
      I.tracks.erase(tid);
      if (held_elsewhere != nullptr &&
          atTheGripper(t.pose.translation().head<2>(), t.pose.translation().z() - t.shape.halfHeight(),
                       t.pose.translation().z() + t.shape.halfHeight())) {
        I.relearnHeld(*held_elsewhere, t, result, stamp);
        held_elsewhere = nullptr;  // once per frame
        continue;
      }
      if (reacquire(t)) continue;
      addConfirmed(std::move(t));
    }
  }

  /// A gone object of the same shape as the confirmed `t` (the nearest): reacquired under its id.
  bool reacquire(const Track& t) {
    Track* lost = nullptr;
    if (T.reacquire) {
      double best = kInf;
      for (auto& [gid, g] : I.tracks) {
        if (g.state != TrackInfo::State::kGone || !(g.shape == t.shape) || g.label != t.label) continue;
        const double d = (g.pose.translation() - t.pose.translation()).norm();
        if (d < best) {
          best = d;
          lost = &g;
        }
      }
    }
    if (lost == nullptr) return false;
    const Eigen::Isometry3d was = lost->pose;
    lost->state = TrackInfo::State::kActive;
    lost->pose = t.pose;
    lost->event_pose = t.pose;
    lost->hits += t.hits;
    lost->misses = 0;
    lost->last_seen_ns = stamp;
    lost->confidence = std::max(lost->confidence, t.confidence);
    (void)I.world.addObject(I.objectOf(*lost));
    char why[200];
    std::snprintf(why, sizeof(why), "reacquired at %s, %.2f m from where it was lost",
                  describePose(t.pose).c_str(), (t.pose.translation() - was.translation()).norm());
    I.pushEvent(result, EventType::kMoved, *lost, lost->pose, why, stamp);
    return true;
  }

  /// The confirmed `t` as a new object of the world model, under a fresh id (the held object's,
  /// when it is the unknown object at the gripper).
  void addConfirmed(Track t) {
    if (!t.size_known) I.classifyBySize(t);
    // Held, but unknown to every track: the new object at the gripper is the one the robot holds.
    const double half = t.shape.halfHeight();
    const bool adopt = atTheGripper(t.pose.translation().head<2>(), t.pose.translation().z() - half,
                                    t.pose.translation().z() + half) &&
                       I.tracks.count(robot->held_object_id) == 0;  // not adopted earlier in this frame
    t.id = adopt ? robot->held_object_id : I.newId(t.label);
    t.state = TrackInfo::State::kActive;
    t.event_pose = t.pose;
    const world::Object o = I.objectOf(t);
    if (Status s = I.world.addObject(o); !s.ok()) return;  // cannot happen: ids are fresh, shapes valid
    std::string why = std::string("new ") + std::string(world::toString(t.kind)) + " " + describeShape(t.shape) +
                      " at " + describePose(t.pose) + (t.cls != nullptr ? ", class " + t.cls->label : ", by size");
    I.pushEvent(result, EventType::kAdded, t, t.pose, why, stamp);
    I.tracks.emplace(t.id, std::move(t));
  }

  /// Active tracks seen or pushed in this frame: the world model follows them when they moved,
  /// turned or grew, and a far enough move or turn is an event.
  void updateWorld() {
    for (auto& [id, t] : I.tracks) {
      if (t.state != TrackInfo::State::kActive || !(t.matched || t.pushed)) continue;
      const world::Object* o = I.world.findObject(id);
      if (o == nullptr) continue;
      const double dpos = (o->pose.translation() - t.pose.translation()).norm();
      const double dyaw = yawError(t.shape, yawOf(o->pose), yawOf(t.pose));
      const bool grew = !(o->shape == t.shape);
      if (dpos > T.update_distance || dyaw > T.update_angle || grew) {
        world::Object updated = I.objectOf(t);
        if (!t.from_prior && !t.size_known && t.cls == nullptr) {
          // Keep mass/kind consistent with the grown size.
          Track tmp = t;
          I.classifyBySize(tmp);
          t.kind = tmp.kind;
          t.mass = tmp.mass;
          t.graspable = tmp.graspable;
          updated = I.objectOf(t);
        }
        (void)I.world.updateObject(updated);
      }
      const double moved = (t.event_pose.translation() - t.pose.translation()).norm();
      const double turned = yawError(t.shape, yawOf(t.event_pose), yawOf(t.pose));
      // A turn is an event when it also moves the footprint's farthest point as far as a move
      // would: the fitted yaw of a small box wobbles by more than the angle without moving it.
      const bool turned_far = turned > T.move_event_angle && turned * footprintReach(t.shape) > T.move_event_distance;
      if (moved > T.move_event_distance || turned_far) {
        char why[200];
        std::snprintf(why, sizeof(why), "moved %.2f m, turned %.2f rad, now at %s", moved, turned,
                      describePose(t.pose).c_str());
        t.event_pose = t.pose;
        I.pushEvent(result, EventType::kMoved, t, t.pose, why, stamp);
      }
    }
    for (const auto& [id, t] : I.tracks) result.stats.tentative += t.state == TrackInfo::State::kTentative ? 1 : 0;
  }

  /// Occupancy of unexplained space: detections not (yet) part of a world object stay
  /// unexplained space until confirmed.
  void integrateOccupancy() {
    const auto& dets = result.detections;
    for (std::size_t i = 0; i < dets.size(); ++i) {
      bool explained = false;
      for (const auto& o : I.world.objects()) {
        if (pointInShape(o.shape, o.pose, dets[i].pose.translation(), P.occupancy.explained_margin)) {
          explained = true;
          break;
        }
      }
      if (!explained) {
        const auto& c = S.clusters[det_cluster[i]];
        unexplained.insert(unexplained.end(), c.begin(), c.end());
      }
    }
    result.stats.unexplained_points = unexplained.size();
    if (!I.occupancy) return;
    I.occupancy->integrate(sensor, S.scan, unexplained);
    if (I.occupancy->hitVoxels() > 0) I.occupancy->clearSeenThrough(rangeImage(), T.visibility_margin);
    for (const auto& o : I.world.objects()) {
      if (o.kind == world::ObjectKind::kMovable || I.prior.findObject(o.id) == nullptr) I.occupancy->clearObject(o);
    }
    I.occupancy->updateInnerNodes();  // once per frame (see OccupancyMap)
  }
};

Result<FrameResult> Perception::processFrame(const PointCloudFrame& input, const Termination& term,
                                             const RobotBody* robot) {
  Impl& I = *impl_;
  FrameResult result;
  Stopwatch total, watch;

  if (Status s = validateFrame(input, I.params.max_points); !s.ok()) return s.error();
  if (input.stamp_ns < I.last_stamp) {
    return Error(ErrorCode::kInvalidArgument,
                 "frame is older than the previous one (" + std::to_string(input.stamp_ns) + " < " +
                     std::to_string(I.last_stamp) + " ns)",
                 SourceLocation{"", 0, 0, "stamp_ns"});
  }
  result.times.validate = watch.millis();
  result.stats.input_points = input.size();

  watch.reset();
  const Impl::SelfFilter self = I.filterSelf(input, robot, result);
  const PointCloudFrame& frame = self.filtered ? *self.filtered : input;
  result.times.self_filter = watch.millis();

  auto seg = I.segmenter.run(frame, term);
  if (!seg) return seg.error();
  reportSegmentation(*seg, result);
  if (term()) {
    return Error(term.reason() == StopReason::kStopRequested ? ErrorCode::kCancelled : ErrorCode::kTimeout,
                 "stopped before shape fitting");
  }

  // Committed from here on: the rest is bounded and quick.
  I.last_stamp = frame.stamp_ns;
  ++I.frames;
  const world::World before = I.world;
  Impl::FrameUpdate update(I, robot, self, frame, *seg, result);
  update.followHeld();

  watch.reset();
  update.detect();
  result.times.fitting = watch.millis();

  watch.reset();
  update.associate();
  update.keepOutOfBase();
  update.addTentatives();
  double tracking_ms = watch.millis();

  watch.reset();
  update.checkUndetected();
  result.times.visibility = watch.millis();

  watch.reset();
  update.confirmTentatives();
  update.updateWorld();
  tracking_ms += watch.millis();
  result.times.tracking = tracking_ms;

  watch.reset();
  update.integrateOccupancy();
  result.times.occupancy = watch.millis();

  result.world_changed = !world::diff(before, I.world).empty();
  result.times.total = total.millis();
  return result;
}

}  // namespace tamp::perception
