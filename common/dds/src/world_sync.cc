#include "tamp/dds/world_sync.h"

#include "tamp/msg_validation/validate.h"

#include <thread>

#include "tamp/core/log.h"

namespace tamp::dds {
namespace {
Error bad(const std::string& field, const std::string& what) {
  return Error(ErrorCode::kInvalidArgument, what, SourceLocation{"", 0, 0, field});
}
}  // namespace

msg::ShapeSpec toMsg(const world::Shape& s) {
  msg::ShapeSpec m;
  switch (s.kind) {
    case world::ShapeKind::kBox:
      m.type(msg::SHAPE_BOX);
      m.dimensions({s.size.x(), s.size.y(), s.size.z()});
      break;
    case world::ShapeKind::kCylinder:
      m.type(msg::SHAPE_CYLINDER);
      m.dimensions({s.radius, s.height});
      break;
    case world::ShapeKind::kSphere:
      m.type(msg::SHAPE_SPHERE);
      m.dimensions({s.radius});
      break;
    case world::ShapeKind::kPrism: {
      m.type(msg::SHAPE_PRISM);
      std::vector<msg::Point2> poly;
      for (const auto& p : s.polygon) {
        msg::Point2 q;
        q.x(p.x());
        q.y(p.y());
        poly.push_back(q);
      }
      m.polygon(std::move(poly));
      m.height(s.height);
      break;
    }
  }
  return m;
}

Result<world::Shape> fromMsg(const msg::ShapeSpec& m, const std::string& field) {
  const auto& d = m.dimensions();
  world::Shape s;
  switch (m.type()) {
    case msg::SHAPE_BOX:
      if (d.size() != 3) return bad(field + ".dimensions", "a box needs 3 dimensions, got " + std::to_string(d.size()));
      s = world::Shape::box(d[0], d[1], d[2]);
      break;
    case msg::SHAPE_CYLINDER:
      if (d.size() != 2) return bad(field + ".dimensions", "a cylinder needs [radius, height]");
      s = world::Shape::cylinder(d[0], d[1]);
      break;
    case msg::SHAPE_SPHERE:
      if (d.size() != 1) return bad(field + ".dimensions", "a sphere needs [radius]");
      s = world::Shape::sphere(d[0]);
      break;
    case msg::SHAPE_PRISM: {
      world::Polygon2 poly;
      for (const auto& p : m.polygon()) poly.emplace_back(p.x(), p.y());
      s = world::Shape::prism(std::move(poly), m.height());
      break;
    }
    default:
      return bad(field + ".type", "unknown shape type " + std::to_string(static_cast<int>(m.type())));
  }
  if (auto why = s.invalidReason()) return bad(field, *why);
  return s;
}

msg::WorldObject toMsg(const world::Object& o, uint64_t version) {
  msg::WorldObject m;
  m.id(o.id);
  m.label(o.label);
  m.kind(o.hidden ? msg::OBJECT_HIDDEN : o.kind == world::ObjectKind::kMovable ? msg::OBJECT_MOVABLE : msg::OBJECT_STATIC);
  m.shape(toMsg(o.shape));
  m.pose(toMsg(o.pose));
  m.mass(o.mass);
  m.graspable(o.graspable);
  m.supported_by(o.region);
  m.version(version);
  m.confidence(1.0);
  m.last_seen_ns(nowNs());
  return m;
}

Result<world::Object> fromMsg(const msg::WorldObject& m) {
  const std::string f = "objects[" + m.id() + "]";
  world::Object o;
  o.id = m.id();
  o.label = m.label();
  o.kind = m.kind() == msg::OBJECT_STATIC ? world::ObjectKind::kStatic : world::ObjectKind::kMovable;
  o.hidden = m.kind() == msg::OBJECT_HIDDEN;
  auto shape = fromMsg(m.shape(), f + ".shape");
  if (!shape) return shape.error();
  o.shape = *shape;
  auto pose = fromMsg(m.pose(), f + ".pose");
  if (!pose) return pose.error();
  o.pose = *pose;
  o.mass = m.mass();
  o.graspable = m.graspable();
  o.region = m.supported_by();
  if (auto why = o.invalidReason()) return bad(f, *why);
  return o;
}

msg::Region toMsg(const world::Region& r) {
  msg::Region m;
  m.id(r.id);
  m.label(r.label + (r.kind == world::RegionKind::kTable ? "#table" : "#floor"));
  std::vector<msg::Point2> poly;
  for (const auto& p : r.polygon) {
    msg::Point2 q;
    q.x(p.x());
    q.y(p.y());
    poly.push_back(q);
  }
  m.polygon(std::move(poly));
  m.height(r.height);
  return m;
}

Result<world::Region> fromMsg(const msg::Region& m) {
  world::Region r;
  r.id = m.id();
  std::string label = m.label();
  r.kind = world::RegionKind::kFloor;
  if (auto pos = label.rfind('#'); pos != std::string::npos) {
    if (auto k = world::regionKindFromString(label.substr(pos + 1))) r.kind = *k;
    label = label.substr(0, pos);
  }
  r.label = label;
  for (const auto& p : m.polygon()) r.polygon.emplace_back(p.x(), p.y());
  r.height = m.height();
  if (auto why = r.invalidReason()) return bad("regions[" + m.id() + "]", *why);
  return r;
}

msg::WorldMeta metaToMsg(const world::World& w, const std::string& world_id) {
  msg::WorldMeta m;
  m.world_id(world_id);
  m.version(w.version());
  m.frame_id("world");
  std::vector<msg::Region> regions;
  for (const auto& r : w.regions()) regions.push_back(toMsg(r));
  m.regions(std::move(regions));
  std::vector<msg::NamedLocation> locations;
  for (const auto& l : w.locations()) {
    msg::NamedLocation nl;
    nl.id(l.id);
    nl.pose(toMsg(l.pose));
    locations.push_back(nl);
  }
  m.locations(std::move(locations));
  if (w.workspace()) {
    const auto& b = *w.workspace();
    m.bounds({b.min.x(), b.min.y(), b.max.x(), b.max.y()});
  }
  return m;
}

// ---- publisher -------------------------------------------------------------------------------

WorldPublisher::WorldPublisher(std::shared_ptr<Participant> p, std::string world_id)
    : world_id_(std::move(world_id)), objects_(p, topics::kWorldObjects), meta_(p, topics::kWorldMeta) {}

Status WorldPublisher::publish(const world::World& w) {
  if (w.hiddenCount() > 0) {
    return Error(ErrorCode::kInvalidArgument, "refusing to publish a world with " + std::to_string(w.hiddenCount()) +
                                                  " hidden object(s): publish its plannerView()");
  }
  const uint64_t v = versionOf(w);
  for (const auto& o : w.objects()) {
    const world::Object* before = last_ ? last_->findObject(o.id) : nullptr;
    if (before != nullptr && *before == o) continue;
    if (Status s = objects_.write(toMsg(o, v)); !s.ok()) return s;
    written_[o.id] = v;
  }
  if (last_) {
    for (const auto& o : last_->objects()) {
      if (w.findObject(o.id) == nullptr) {
        if (Status s = objects_.dispose(toMsg(o, v)); !s.ok()) return s;
        written_.erase(o.id);
      }
    }
  }
  msg::WorldMeta meta = metaToMsg(w, world_id_);
  meta.version(v);
  std::vector<std::string> ids;
  std::vector<uint64_t> versions;
  ids.reserve(written_.size());
  versions.reserve(written_.size());
  for (const auto& [id, version] : written_) {
    ids.push_back(id);
    versions.push_back(version);
  }
  meta.object_ids(std::move(ids));
  meta.object_versions(std::move(versions));
  if (Status s = meta_.write(meta); !s.ok()) return s;
  last_ = w;
  published_version_ = v;
  return Status::Ok();
}

// ---- mirror ----------------------------------------------------------------------------------

WorldMirror::WorldMirror(std::shared_ptr<Participant> p, std::string world_id)
    : world_id_(std::move(world_id)),
      objects_(p, topics::kWorldObjects, [this](const msg::WorldObject& m, const SampleMeta& s) { onObject(m, s); }),
      meta_(p, topics::kWorldMeta, [this](const msg::WorldMeta& m, const SampleMeta& s) { onMeta(m, s); }) {}

namespace {
/// Malformed world samples, logged once per kind (rate-limited): every service mirrors the world.
msgv::RejectLog& worldRejects() {
  static msgv::RejectLog log("world");
  return log;
}
}  // namespace

void WorldMirror::onObject(const msg::WorldObject& m, const SampleMeta& meta) {
  {
    std::lock_guard lock(mutex_);
    if (!meta.alive) {
      received_.erase(m.id());
      updateCompleteLocked();
      if (world_.findObject(m.id()) == nullptr) return;
      (void)world_.removeObject(m.id());
    } else {
      received_[m.id()] = m.version();  // received, even if it turns out malformed below
      updateCompleteLocked();
      if (!msgv::accept(m, topics::kWorldObjects.name, worldRejects())) return;
      auto o = fromMsg(m);
      if (!o) {
        log::get("world")->warn("ignoring a malformed world object: {}", o.error().toString());
        return;
      }
      if (o->hidden) return;  // never part of a planner's world
      Status s = world_.findObject(o->id) ? world_.updateObject(*o) : world_.addObject(*o);
      if (!s.ok()) {
        log::get("world")->warn("ignoring world object {}: {}", m.id(), s.error().toString());
        return;
      }
    }
    ++changes_;
  }
  notify();
}

void WorldMirror::onMeta(const msg::WorldMeta& m, const SampleMeta& meta) {
  if (!meta.alive || m.world_id() != world_id_) return;
  if (!msgv::accept(m, topics::kWorldMeta.name, worldRejects())) return;  // keep the last good one
  {
    std::lock_guard lock(mutex_);
    // Replace regions and locations by the published set.
    std::vector<std::string> old_regions, old_locations;
    for (const auto& r : world_.regions()) old_regions.push_back(r.id);
    for (const auto& l : world_.locations()) old_locations.push_back(l.id);
    for (const auto& id : old_regions) (void)world_.removeRegion(id);
    for (const auto& id : old_locations) (void)world_.removeLocation(id);
    for (const auto& rm : m.regions()) {
      auto r = fromMsg(rm);
      if (!r) {
        log::get("world")->warn("ignoring a malformed region: {}", r.error().toString());
        continue;
      }
      (void)world_.addRegion(*r);
    }
    for (const auto& lm : m.locations()) {
      auto pose = fromMsg(lm.pose(), "locations[" + lm.id() + "].pose");
      if (!pose) continue;
      (void)world_.addLocation(world::Location{lm.id(), lm.id(), *pose});
    }
    if (m.bounds().size() == 4) {
      Aabb b;
      b.extend(Eigen::Vector3d(m.bounds()[0], m.bounds()[1], 0.0));
      b.extend(Eigen::Vector3d(m.bounds()[2], m.bounds()[3], 2.0));
      world_.setWorkspace(b);
    }
    manifest_version_ = m.version();
    manifest_.clear();
    if (m.object_ids().size() == m.object_versions().size()) {
      for (std::size_t i = 0; i < m.object_ids().size(); ++i) manifest_[m.object_ids()[i]] = m.object_versions()[i];
    } else {
      log::get("world")->warn("world meta {}: {} object ids but {} versions; manifest ignored", m.version(),
                              m.object_ids().size(), m.object_versions().size());
    }
    updateCompleteLocked();
    ++changes_;
  }
  notify();
}

void WorldMirror::updateCompleteLocked() {
  if (manifest_version_ <= published_version_) return;
  for (const auto& [id, version] : manifest_) {
    auto it = received_.find(id);
    if (it == received_.end() || it->second < version) return;  // not here yet
  }
  for (const auto& [id, version] : received_) {
    // An object outside the manifest is either newer (fine) or removed but not yet disposed here.
    if (manifest_.count(id) == 0 && version <= manifest_version_) return;
  }
  published_version_ = manifest_version_;
}

void WorldMirror::notify() {
  std::function<void()> cb;
  {
    std::lock_guard lock(mutex_);
    cb = cb_;
  }
  if (cb) cb();
}

world::World WorldMirror::snapshot() const {
  std::lock_guard lock(mutex_);
  return world_;
}

uint64_t WorldMirror::changes() const {
  std::lock_guard lock(mutex_);
  return changes_;
}

uint64_t WorldMirror::publishedVersion() const {
  std::lock_guard lock(mutex_);
  return published_version_;
}

bool WorldMirror::waitForPublishedVersion(uint64_t version, const Termination& until) const {
  while (publishedVersion() < version) {
    if (until()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

void WorldMirror::onChange(std::function<void()> cb) {
  std::lock_guard lock(mutex_);
  cb_ = std::move(cb);
}

}  // namespace tamp::dds
