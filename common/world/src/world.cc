#include "tamp/world/world.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tamp::world {

bool isValidId(std::string_view id) {
  if (id.empty() || id.size() > 64) return false;
  if (id[0] < 'a' || id[0] > 'z') return false;
  for (char c : id) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

std::string_view toString(ObjectKind kind) {
  return kind == ObjectKind::kStatic ? "static" : "movable";
}
std::optional<ObjectKind> objectKindFromString(std::string_view name) {
  if (name == "static") return ObjectKind::kStatic;
  if (name == "movable") return ObjectKind::kMovable;
  return std::nullopt;
}
std::string_view toString(RegionKind kind) {
  return kind == RegionKind::kFloor ? "floor" : "table";
}
std::optional<RegionKind> regionKindFromString(std::string_view name) {
  if (name == "floor") return RegionKind::kFloor;
  if (name == "table") return RegionKind::kTable;
  return std::nullopt;
}

namespace {

std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

std::string badId(std::string_view what, std::string_view id) {
  return std::string(what) + " id '" + std::string(id) +
         "' is invalid (expected a lower-case letter, then lower-case letters, digits, '_' or '-', "
         "at most 64 characters)";
}

bool finitePose(const Eigen::Isometry3d& T) {
  if (!T.matrix().allFinite()) return false;
  // A rotation: orthonormal within a loose tolerance.
  return (T.linear() * T.linear().transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <
         1e-6;
}

template <typename V>
auto lowerBound(V& v, std::string_view id) {
  return std::lower_bound(v.begin(), v.end(), id,
                          [](const auto& p, std::string_view k) { return p->id < k; });
}

template <typename T>
const T* findIn(const std::vector<std::shared_ptr<const T>>& v, std::string_view id) {
  auto it = lowerBound(v, id);
  return it != v.end() && (*it)->id == id ? it->get() : nullptr;
}

template <typename T>
Status insertIn(std::vector<std::shared_ptr<const T>>& v, T value, std::string_view what) {
  auto it = lowerBound(v, value.id);
  if (it != v.end() && (*it)->id == value.id) {
    return Error(ErrorCode::kInvalidArgument,
                 std::string(what) + " id '" + value.id + "' is already taken");
  }
  v.insert(it, std::make_shared<const T>(std::move(value)));
  return Status::Ok();
}

template <typename T>
Status replaceIn(std::vector<std::shared_ptr<const T>>& v, T value, std::string_view what) {
  auto it = lowerBound(v, value.id);
  if (it == v.end() || (*it)->id != value.id) {
    return Error(ErrorCode::kNotFound, std::string(what) + " '" + value.id + "' does not exist");
  }
  *it = std::make_shared<const T>(std::move(value));
  return Status::Ok();
}

template <typename T>
Status eraseIn(std::vector<std::shared_ptr<const T>>& v, std::string_view id,
               std::string_view what) {
  auto it = lowerBound(v, id);
  if (it == v.end() || (*it)->id != id) {
    return Error(ErrorCode::kNotFound,
                 std::string(what) + " '" + std::string(id) + "' does not exist");
  }
  v.erase(it);
  return Status::Ok();
}

}  // namespace

// ---- Object / Region ----------------------------------------------------------------------------

std::optional<std::string> Object::invalidReason() const {
  if (!isValidId(id)) return badId("object", id);
  if (auto why = shape.invalidReason()) return "shape: " + *why;
  if (!finitePose(pose)) return "pose must be finite with an orthonormal rotation";
  if (!std::isfinite(mass) || mass < 0) return "mass must be finite and >= 0, got " + num(mass);
  if (kind == ObjectKind::kMovable && mass <= 0)
    return "a movable object needs a positive mass, got " + num(mass);
  if (kind == ObjectKind::kStatic && graspable) return "a static object cannot be graspable";
  if (!region.empty() && !isValidId(region)) return badId("region", region);
  return std::nullopt;
}

bool operator==(const Object& a, const Object& b) {
  return a.id == b.id && a.label == b.label && a.kind == b.kind && a.shape == b.shape &&
         a.pose.matrix() == b.pose.matrix() && a.mass == b.mass && a.graspable == b.graspable &&
         a.hidden == b.hidden && a.region == b.region;
}

bool operator==(const HeldObject& a, const HeldObject& b) {
  return a.object_id == b.object_id && a.link == b.link &&
         a.link_T_object.matrix() == b.link_T_object.matrix();
}

std::optional<std::string> Region::invalidReason() const {
  if (!isValidId(id)) return badId("region", id);
  if (polygon.size() < 3)
    return "region polygon needs at least 3 vertices, got " + std::to_string(polygon.size());
  for (const auto& p : polygon) {
    if (!p.allFinite()) return "region polygon has a non-finite vertex";
  }
  if (std::abs(signedArea(polygon)) < 1e-12) return "region polygon has zero area";
  if (!std::isfinite(height)) return "region height must be finite";
  return std::nullopt;
}

// ---- World: objects -----------------------------------------------------------------------------

const Object* World::findObject(std::string_view id) const { return findIn(objects_, id); }

const Object& World::object(std::string_view id) const {
  const Object* o = findObject(id);
  if (o == nullptr)
    throw std::invalid_argument("World::object: no object '" + std::string(id) + "'");
  return *o;
}

std::shared_ptr<const Object> World::objectPtr(std::string_view id) const {
  auto it = lowerBound(objects_, id);
  return it != objects_.end() && (*it)->id == id ? *it : nullptr;
}

Status World::addObject(Object object) {
  if (auto why = object.invalidReason()) {
    return Error(ErrorCode::kInvalidArgument, "object '" + object.id + "': " + *why);
  }
  Status s = insertIn(objects_, std::move(object), "object");
  if (s) ++version_;
  return s;
}

Status World::updateObject(Object object) {
  if (auto why = object.invalidReason()) {
    return Error(ErrorCode::kInvalidArgument, "object '" + object.id + "': " + *why);
  }
  if (held_ && held_->object_id == object.id && object.kind != ObjectKind::kMovable) {
    return Error(ErrorCode::kInvalidArgument,
                 "object '" + object.id + "' is held and must stay movable");
  }
  Status s = replaceIn(objects_, std::move(object), "object");
  if (s) ++version_;
  return s;
}

Status World::setObjectPose(std::string_view id, const Eigen::Isometry3d& pose) {
  if (!finitePose(pose)) {
    return Error(ErrorCode::kInvalidArgument,
                 "object '" + std::string(id) + "': pose must be finite and rigid");
  }
  auto it = lowerBound(objects_, id);
  if (it == objects_.end() || (*it)->id != id) {
    return Error(ErrorCode::kNotFound, "object '" + std::string(id) + "' does not exist");
  }
  auto copy = std::make_shared<Object>(**it);
  copy->pose = pose;
  *it = std::move(copy);
  ++version_;
  return Status::Ok();
}

Status World::removeObject(std::string_view id) {
  Status s = eraseIn(objects_, id, "object");
  if (!s) return s;
  if (held_ && held_->object_id == id) held_.reset();
  ++version_;
  return s;
}

// ---- World: regions, locations ------------------------------------------------------------------

const Region* World::findRegion(std::string_view id) const { return findIn(regions_, id); }

Status World::addRegion(Region region) {
  if (auto why = region.invalidReason())
    return Error(ErrorCode::kInvalidArgument, "region '" + region.id + "': " + *why);
  Status s = insertIn(regions_, std::move(region), "region");
  if (s) ++version_;
  return s;
}

Status World::updateRegion(Region region) {
  if (auto why = region.invalidReason())
    return Error(ErrorCode::kInvalidArgument, "region '" + region.id + "': " + *why);
  Status s = replaceIn(regions_, std::move(region), "region");
  if (s) ++version_;
  return s;
}

Status World::removeRegion(std::string_view id) {
  Status s = eraseIn(regions_, id, "region");
  if (s) ++version_;
  return s;
}

const Region* World::regionBelow(const Eigen::Vector3d& point, double tolerance) const {
  const Region* best = nullptr;
  const Eigen::Vector2d xy = point.head<2>();
  for (const auto& r : regions_) {
    if (r->height > point.z() + tolerance || !r->contains(xy)) continue;
    if (best == nullptr) {
      best = r.get();
      continue;
    }
    // Prefer tables over floors, then the highest surface.
    const bool r_table = r->kind == RegionKind::kTable, b_table = best->kind == RegionKind::kTable;
    if ((r_table && !b_table) || (r_table == b_table && r->height > best->height)) best = r.get();
  }
  return best;
}

const Location* World::findLocation(std::string_view id) const { return findIn(locations_, id); }

namespace {
std::optional<std::string> locationInvalid(const Location& l) {
  if (!isValidId(l.id)) return badId("location", l.id);
  if (!std::isfinite(l.pose.x) || !std::isfinite(l.pose.y) || !std::isfinite(l.pose.theta)) {
    return "location pose must be finite";
  }
  return std::nullopt;
}
}  // namespace

Status World::addLocation(Location location) {
  if (auto why = locationInvalid(location)) return Error(ErrorCode::kInvalidArgument, *why);
  Status s = insertIn(locations_, std::move(location), "location");
  if (s) ++version_;
  return s;
}

Status World::updateLocation(Location location) {
  if (auto why = locationInvalid(location)) return Error(ErrorCode::kInvalidArgument, *why);
  Status s = replaceIn(locations_, std::move(location), "location");
  if (s) ++version_;
  return s;
}

Status World::removeLocation(std::string_view id) {
  Status s = eraseIn(locations_, id, "location");
  if (s) ++version_;
  return s;
}

// ---- World: held, bounds, views -----------------------------------------------------------------

Status World::setHeld(std::optional<HeldObject> held) {
  if (held) {
    const Object* o = findObject(held->object_id);
    if (o == nullptr)
      return Error(ErrorCode::kNotFound, "held object '" + held->object_id + "' does not exist");
    if (o->kind != ObjectKind::kMovable) {
      return Error(ErrorCode::kInvalidArgument,
                   "held object '" + held->object_id + "' is not movable");
    }
    if (!finitePose(held->link_T_object)) {
      return Error(ErrorCode::kInvalidArgument,
                   "held object '" + held->object_id + "': grasp transform must be rigid");
    }
  }
  held_ = std::move(held);
  ++version_;
  return Status::Ok();
}

Aabb World::bounds() const {
  if (workspace_) return *workspace_;
  Aabb b;
  for (const auto& o : objects_) b.extend(o->aabb());
  for (const auto& r : regions_) {
    for (const auto& p : r->polygon) b.extend(Eigen::Vector3d(p.x(), p.y(), r->height));
  }
  return b;
}

World World::plannerView() const {
  World v(*this);
  v.objects_.erase(std::remove_if(v.objects_.begin(), v.objects_.end(),
                                  [](const std::shared_ptr<const Object>& o) { return o->hidden; }),
                   v.objects_.end());
  if (v.held_ && v.findObject(v.held_->object_id) == nullptr) v.held_.reset();
  return v;
}

std::size_t World::hiddenCount() const {
  return static_cast<std::size_t>(
      std::count_if(objects_.begin(), objects_.end(), [](const auto& o) { return o->hidden; }));
}

// ---- diff ---------------------------------------------------------------------------------------

bool WorldDiff::empty() const {
  return added.empty() && removed.empty() && moved.empty() && changed.empty() &&
         regions_added_or_changed.empty() && regions_removed.empty() &&
         locations_added_or_changed.empty() && locations_removed.empty() && !held_changed &&
         !workspace_changed;
}

std::vector<std::string> WorldDiff::touchedObjects() const {
  std::vector<std::string> ids;
  for (const auto& o : added) ids.push_back(o.id);
  ids.insert(ids.end(), removed.begin(), removed.end());
  for (const auto& m : moved) ids.push_back(m.id);
  for (const auto& o : changed) ids.push_back(o.id);
  std::sort(ids.begin(), ids.end());
  return ids;
}

namespace {

bool sameExceptPose(const Object& a, const Object& b) {
  return a.id == b.id && a.label == b.label && a.kind == b.kind && a.shape == b.shape &&
         a.mass == b.mass && a.graspable == b.graspable && a.hidden == b.hidden &&
         a.region == b.region;
}

bool sameAabb(const std::optional<Aabb>& a, const std::optional<Aabb>& b) {
  if (a.has_value() != b.has_value()) return false;
  return !a || (a->min == b->min && a->max == b->max);
}

}  // namespace

WorldDiff diff(const World& from, const World& to, double pose_tolerance) {
  WorldDiff d;
  // Merge-walk over the id-sorted ranges; an object shared by both worlds has one address.
  auto walkObjects = [&](auto onlyA, auto onlyB, auto both) {
    auto a = from.objects(), b = to.objects();
    auto ia = a.begin(), ib = b.begin();
    while (ia != a.end() || ib != b.end()) {
      if (ib == b.end() || (ia != a.end() && ia->id < ib->id)) {
        onlyA(*ia++);
      } else if (ia == a.end() || ib->id < ia->id) {
        onlyB(*ib++);
      } else {
        if (&*ia != &*ib) both(*ia, *ib);  // shared objects have the same address
        ++ia;
        ++ib;
      }
    }
  };
  walkObjects([&](const Object& o) { d.removed.push_back(o.id); },
              [&](const Object& o) { d.added.push_back(o); },
              [&](const Object& a, const Object& b) {
                if (!sameExceptPose(a, b)) {
                  d.changed.push_back(b);
                } else if (!samePose(a.pose, b.pose, pose_tolerance)) {
                  d.moved.push_back(ObjectMove{b.id, b.pose});
                }
              });
  auto walk = [](auto ra, auto rb, auto onlyA, auto onlyB, auto both) {
    auto ia = ra.begin(), ib = rb.begin();
    while (ia != ra.end() || ib != rb.end()) {
      if (ib == rb.end() || (ia != ra.end() && ia->id < ib->id)) {
        onlyA(*ia++);
      } else if (ia == ra.end() || ib->id < ia->id) {
        onlyB(*ib++);
      } else {
        if (&*ia != &*ib) both(*ia, *ib);
        ++ia;
        ++ib;
      }
    }
  };
  walk(
      from.regions(), to.regions(), [&](const Region& r) { d.regions_removed.push_back(r.id); },
      [&](const Region& r) { d.regions_added_or_changed.push_back(r); },
      [&](const Region& a, const Region& b) {
        if (!(a == b)) d.regions_added_or_changed.push_back(b);
      });
  walk(
      from.locations(), to.locations(),
      [&](const Location& l) { d.locations_removed.push_back(l.id); },
      [&](const Location& l) { d.locations_added_or_changed.push_back(l); },
      [&](const Location& a, const Location& b) {
        if (!(a == b)) d.locations_added_or_changed.push_back(b);
      });
  if (from.held() != to.held()) {
    d.held_changed = true;
    d.held = to.held();
  }
  if (!sameAabb(from.workspace(), to.workspace())) {
    d.workspace_changed = true;
    d.workspace = to.workspace();
  }
  return d;
}

Status applyDiff(World& w, const WorldDiff& d) {
  // Validate against a copy so that a failure leaves `w` untouched (copies are cheap).
  World next(w);
  for (const auto& id : d.removed) {
    if (Status s = next.removeObject(id); !s) return s;
  }
  for (const auto& o : d.added) {
    if (Status s = next.addObject(o); !s) return s;
  }
  for (const auto& m : d.moved) {
    if (Status s = next.setObjectPose(m.id, m.pose); !s) return s;
  }
  for (const auto& o : d.changed) {
    if (Status s = next.updateObject(o); !s) return s;
  }
  for (const auto& id : d.regions_removed) {
    if (Status s = next.removeRegion(id); !s) return s;
  }
  for (const auto& r : d.regions_added_or_changed) {
    Status s = next.findRegion(r.id) ? next.updateRegion(r) : next.addRegion(r);
    if (!s) return s;
  }
  for (const auto& id : d.locations_removed) {
    if (Status s = next.removeLocation(id); !s) return s;
  }
  for (const auto& l : d.locations_added_or_changed) {
    Status s = next.findLocation(l.id) ? next.updateLocation(l) : next.addLocation(l);
    if (!s) return s;
  }
  if (d.held_changed) {
    if (Status s = next.setHeld(d.held); !s) return s;
  }
  if (d.workspace_changed) next.setWorkspace(d.workspace);
  w = std::move(next);
  return Status::Ok();
}

}  // namespace tamp::world
