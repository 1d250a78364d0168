#pragma once
/// @file
/// The world model every service plans and acts on: static obstacles, movable objects, support
/// regions (floor areas, table tops), named base locations, the object held by the gripper, and
/// objects hidden from the planner (known only to the simulator).
///
/// Frames and units: world frame z-up, metres, radians, kilograms. An object's `pose` places its
/// shape's frame (shapes are centred, see shape.h) in the world, so an upright object resting on
/// a surface at height h has `pose.translation().z() == h + shape.halfHeight()`.
///
/// Ids are stable strings usable as PDDL object names: a lower-case letter, then lower-case
/// letters, digits, '_' or '-' (at most 64 characters). Objects, regions and locations have
/// separate id spaces, but a scenario should keep them distinct (PDDL problems share one).
///
/// `World` is a value type with cheap copies: each object is held by a `shared_ptr<const Object>`
/// and a copy shares them (copy-on-write per object), so copying a world of n objects costs n
/// reference-count increments, and `diff()` between a world and an edited copy of it skips
/// unchanged objects by pointer comparison. Every successful mutation increments `version()`.
/// A `World` is not synchronised: share copies between threads, not one instance.

#include <cstdint>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/error.h"
#include "tamp/core/geometry.h"
#include "tamp/world/polygon.h"
#include "tamp/world/shape.h"

namespace tamp::world {

/// True when `id` is a valid world id (see the file comment).
bool isValidId(std::string_view id);

/// What an object is to the planner: static obstacles never move; movable objects may be pushed,
/// picked or placed (the paper's "movable objects" the lazy motion planner reports).
enum class ObjectKind { kStatic, kMovable };
std::string_view toString(ObjectKind kind);  ///< "static", "movable"
std::optional<ObjectKind> objectKindFromString(std::string_view name);

struct Object {
  std::string id;     ///< stable, unique among objects
  std::string label;  ///< free text: class or description ("can", "wall", "svg path123")
  ObjectKind kind{ObjectKind::kStatic};
  Shape shape;
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};  ///< shape frame in the world frame
  double mass{0.0};       ///< kg; > 0 for movable objects, 0 allowed for static ones
  bool graspable{false};  ///< the gripper can hold it (size and mass permitting)
  bool hidden{false};     ///< known only to the simulator; excluded from `plannerView()`
  std::string region;     ///< id of the region it rests on, or empty (drives PDDL `on` facts)

  /// World-frame bounding box of the shape at `pose`.
  Aabb aabb() const { return shape.aabb(pose); }
  /// Empty when usable; otherwise why not (names the field and value).
  std::optional<std::string> invalidReason() const;
  /// Every field equal (poses bitwise).
  friend bool operator==(const Object& a, const Object& b);
};

/// A support surface or floor area on which objects rest.
enum class RegionKind { kFloor, kTable };
std::string_view toString(RegionKind kind);  ///< "floor", "table"
std::optional<RegionKind> regionKindFromString(std::string_view name);

struct Region {
  std::string id;
  std::string label;
  RegionKind kind{RegionKind::kFloor};
  Polygon2 polygon;    ///< world xy, counter-clockwise, >= 3 vertices, non-zero area
  double height{0.0};  ///< z of the surface (m): 0 for the floor, ~0.75 for a table top

  /// True when world point (x, y) lies inside the polygon.
  bool contains(const Eigen::Vector2d& xy) const { return containsPoint(polygon, xy); }
  std::optional<std::string> invalidReason() const;
  friend bool operator==(const Region& a, const Region& b) = default;
};

/// A named base pose (PDDL `location`): where the robot's base frame can stand.
struct Location {
  std::string id;
  std::string label;
  Pose2D pose;  ///< base frame in the world's xy-plane
  friend bool operator==(const Location& a, const Location& b) = default;
};

/// The object rigidly held by the gripper. Its `Object::pose` in the world is kept consistent by
/// whoever moves the robot (simulator, perception); collision checking attaches it to the gripper.
struct HeldObject {
  std::string object_id;
  std::string link;  ///< gripper frame name (URDF link)
  Eigen::Isometry3d link_T_object{Eigen::Isometry3d::Identity()};  ///< object pose in that frame
  friend bool operator==(const HeldObject& a, const HeldObject& b);
};

/// Iteration over a sorted vector of shared_ptr<const T>, yielding `const T&`.
template <typename T>
class PtrRange {
 public:
  using Storage = std::vector<std::shared_ptr<const T>>;
  class iterator {
   public:
    using iterator_category = std::random_access_iterator_tag;
    using value_type = T;
    using difference_type = std::ptrdiff_t;
    using pointer = const T*;
    using reference = const T&;
    iterator() = default;
    explicit iterator(typename Storage::const_iterator it) : it_(it) {}
    reference operator*() const { return **it_; }
    pointer operator->() const { return it_->get(); }
    iterator& operator++() {
      ++it_;
      return *this;
    }
    iterator operator++(int) {
      iterator t = *this;
      ++it_;
      return t;
    }
    difference_type operator-(const iterator& o) const { return it_ - o.it_; }
    bool operator==(const iterator& o) const { return it_ == o.it_; }
    bool operator!=(const iterator& o) const { return it_ != o.it_; }

   private:
    typename Storage::const_iterator it_;
  };
  explicit PtrRange(const Storage& s) : s_(&s) {}
  iterator begin() const { return iterator(s_->begin()); }
  iterator end() const { return iterator(s_->end()); }
  std::size_t size() const { return s_->size(); }
  bool empty() const { return s_->empty(); }
  const T& operator[](std::size_t i) const { return *(*s_)[i]; }

 private:
  const Storage* s_;
};

class World {
 public:
  World() = default;
  explicit World(std::string name) : name_(std::move(name)) {}

  const std::string& name() const { return name_; }
  void setName(std::string name) {
    name_ = std::move(name);
    ++version_;
  }
  /// Incremented by every successful mutation. Copies keep the version they were made at.
  std::uint64_t version() const { return version_; }

  // ---- objects (sorted by id) ----------------------------------------------------------------
  PtrRange<Object> objects() const { return PtrRange<Object>(objects_); }
  std::size_t objectCount() const { return objects_.size(); }
  /// nullptr when absent.
  const Object* findObject(std::string_view id) const;
  /// @throws std::invalid_argument when absent.
  const Object& object(std::string_view id) const;
  /// The shared handle (for structure sharing, e.g. by the collision scene); nullptr when absent.
  std::shared_ptr<const Object> objectPtr(std::string_view id) const;
  /// Adds a new object. kInvalidArgument when the id is invalid or taken, or the object invalid.
  Status addObject(Object object);
  /// Replaces the object with the same id. kNotFound when absent; kInvalidArgument when invalid.
  Status updateObject(Object object);
  /// Moves an object. kNotFound when absent; kInvalidArgument for a non-finite pose.
  Status setObjectPose(std::string_view id, const Eigen::Isometry3d& pose);
  /// Removes an object (and clears `held()` if it was the held one). kNotFound when absent.
  Status removeObject(std::string_view id);

  // ---- regions and locations (sorted by id) ----------------------------------------------------
  PtrRange<Region> regions() const { return PtrRange<Region>(regions_); }
  const Region* findRegion(std::string_view id) const;
  Status addRegion(Region region);
  Status updateRegion(Region region);
  Status removeRegion(std::string_view id);
  /// The table region whose polygon contains (x, y) with the highest surface not above `z`
  /// (+ tolerance), else a floor region containing it, else nullptr.
  const Region* regionBelow(const Eigen::Vector3d& point, double tolerance = 0.02) const;

  PtrRange<Location> locations() const { return PtrRange<Location>(locations_); }
  const Location* findLocation(std::string_view id) const;
  Status addLocation(Location location);
  Status updateLocation(Location location);
  Status removeLocation(std::string_view id);

  // ---- gripper
  // -----------------------------------------------------------------------------------
  const std::optional<HeldObject>& held() const { return held_; }
  /// Sets or clears the held object; kNotFound when the object does not exist, kInvalidArgument
  /// when it is not movable.
  Status setHeld(std::optional<HeldObject> held);

  // ---- workspace
  // ---------------------------------------------------------------------------------
  /// Explicit workspace bounds (e.g. a NAMO map's extent), if set.
  const std::optional<Aabb>& workspace() const { return workspace_; }
  void setWorkspace(std::optional<Aabb> bounds) {
    workspace_ = std::move(bounds);
    ++version_;
  }
  /// `workspace()` when set, else the union of all objects' and regions' bounding boxes.
  Aabb bounds() const;

  // ---- views
  // -------------------------------------------------------------------------------------
  /// The planner's view: a copy without hidden objects (and without `held` if it is hidden).
  /// Shares every remaining object with this world.
  World plannerView() const;
  std::size_t hiddenCount() const;

 private:
  std::string name_;
  std::uint64_t version_{0};
  std::vector<std::shared_ptr<const Object>> objects_;
  std::vector<std::shared_ptr<const Region>> regions_;
  std::vector<std::shared_ptr<const Location>> locations_;
  std::optional<HeldObject> held_;
  std::optional<Aabb> workspace_;
};

/// A new pose for an object whose other fields did not change.
struct ObjectMove {
  std::string id;
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};
};

/// What changed from one world to another, complete enough to replay with `applyDiff()` (and to
/// send as an incremental world-model update). Lists are sorted by id.
struct WorldDiff {
  std::vector<Object> added;         ///< in `to`, not in `from`
  std::vector<std::string> removed;  ///< in `from`, not in `to`
  std::vector<ObjectMove> moved;     ///< only the pose differs
  std::vector<Object> changed;       ///< any other field differs (the full new object)
  std::vector<Region> regions_added_or_changed;
  std::vector<std::string> regions_removed;
  std::vector<Location> locations_added_or_changed;
  std::vector<std::string> locations_removed;
  bool held_changed{false};
  std::optional<HeldObject> held;  ///< the new held object when `held_changed`
  bool workspace_changed{false};
  std::optional<Aabb> workspace;

  bool empty() const;
  /// Ids of every object added, removed, moved or changed.
  std::vector<std::string> touchedObjects() const;
};

/// The difference `to - from`. Objects shared by pointer are skipped without comparison.
/// `pose_tolerance` (m / rotation-matrix element) ignores smaller pose changes.
WorldDiff diff(const World& from, const World& to, double pose_tolerance = 0.0);

/// Applies `d` to `w` (the version increases). Fails without modifying `w` when an added id
/// exists already or a removed/moved/changed id does not.
Status applyDiff(World& w, const WorldDiff& d);

}  // namespace tamp::world
