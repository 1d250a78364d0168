#pragma once
/// @file
/// Collision checking through FCL 0.7 for the world model, the robot, held objects and unknown
/// occupied space.
///
/// A `Scene` mirrors a `world::World`: static and movable objects live in two FCL dynamic AABB
/// trees (broad phase); the robot is a set of shapes rigidly attached to links whose world poses
/// the caller sets (`setLinkPoses`) before each query -- this updates only the robot's own FCL
/// objects, never the broad phase, so a check costs a few broad-phase descents plus narrow-phase
/// tests of the candidate pairs. Objects attached to a link (a grasped object) move with it and
/// are checked like robot parts; they leave the movable tree while attached. Unknown occupied
/// space (from perception) is an `fcl::OcTree`.
///
/// Queries say *which* objects collide (ids, sorted, unique), with an optional `Filter`
/// (static only, movable only, unknown space, a set of ids, ids to ignore); `inCollision`
/// variants stop at the first contact. Distance queries return the nearest object and points.
///
/// Geometry: box, cylinder and sphere map to the FCL primitives. A prism (extruded polygon) maps
/// to one `fcl::Box` when its polygon is a rectangle, to one `fcl::Convex` when convex, else to
/// convex pieces (an ear-clipping triangulation merged by Hertel-Mehlhorn). Convex pieces are
/// the default: they are solids, and on a NAMO-like world a disc check costs ~1.1 us against
/// ~2.6 us with `PrismMode::kMesh` (one `fcl::BVHModel<OBBRSS>` triangle mesh per prism;
/// bench/collision_bench.cc). A mesh is a *surface*: a shape entirely inside a mesh prism does
/// not collide with it. kMesh is kept for comparison only.
///
/// Thread safety: const queries may run concurrently with each other; mutations need exclusive
/// access. The OMPL validity checker pattern is one `Scene` per planning thread.

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/error.h"
#include "tamp/world/shape.h"
#include "tamp/world/world.h"

namespace tamp::collision {

/// Groups of things a query may consider (bit mask).
enum Group : std::uint8_t {
  kStaticObjects = 1,   ///< world objects of kind static
  kMovableObjects = 2,  ///< world objects of kind movable (not attached ones)
  kUnknownSpace = 4,    ///< the occupancy octree
  kAllGroups = 7,
};

/// The id reported for a collision with unknown occupied space.
inline constexpr const char* kUnknownSpaceId = "__unknown_space__";

/// Which objects a query considers.
struct Filter {
  std::uint8_t groups{kAllGroups};  ///< bit mask of `Group`
  std::vector<std::string> only;    ///< when non-empty: only these object ids (within `groups`)
  std::vector<std::string> ignore;  ///< never these object ids

  static Filter all() { return {}; }
  static Filter staticOnly() { return Filter{kStaticObjects, {}, {}}; }
  static Filter movableOnly() { return Filter{kMovableObjects, {}, {}}; }
  static Filter objects(std::vector<std::string> ids) {
    return Filter{kAllGroups, std::move(ids), {}};
  }
  static Filter allBut(std::vector<std::string> ids) {
    return Filter{kAllGroups, {}, std::move(ids)};
  }
};

/// One collision shape rigidly attached to a robot link.
struct RobotPart {
  int link{0};  ///< index into `RobotGeometry::links` (and into the poses of `setLinkPoses`)
  world::Shape shape;
  Eigen::Isometry3d link_T_shape{Eigen::Isometry3d::Identity()};
};

/// The robot's collision model: link names and shapes on them. `allowed_self_collisions` are
/// link-index pairs never checked against each other (adjacent links, always-touching parts).
struct RobotGeometry {
  std::vector<std::string> links;
  std::vector<RobotPart> parts;
  std::vector<std::pair<int, int>> allowed_self_collisions;

  /// A planar disc robot (NAMO): one link "base" with a cylinder of `radius` and `height`,
  /// standing on the floor (centre at z = height/2 in the base frame).
  static RobotGeometry disc(double radius, double height = 1.0);
  /// A box robot: one link "base" with a box `sx` x `sy` x `sz` standing on the floor.
  static RobotGeometry box(double sx, double sy, double sz);
};

/// A robot-part (or attached object) / world-object contact.
struct Contact {
  std::string robot;   ///< link name, or the id of the attached object
  std::string object;  ///< world object id, or `kUnknownSpaceId`
  friend bool operator==(const Contact&, const Contact&) = default;
};

/// Result of a distance query. `distance` <= 0 means in contact (the value is then a
/// penetration estimate: 0 or negative); +inf when nothing matched the filter.
struct DistanceResult {
  double distance{std::numeric_limits<double>::infinity()};
  std::string robot;   ///< robot link / attached object id (robot queries), or empty
  std::string object;  ///< nearest world object id (or `kUnknownSpaceId`), empty when none
  Eigen::Vector3d point_on_robot{Eigen::Vector3d::Zero()};   ///< world frame
  Eigen::Vector3d point_on_object{Eigen::Vector3d::Zero()};  ///< world frame
  bool found() const { return !object.empty(); }
};

/// How non-rectangular prisms become FCL geometry (see the file comment).
enum class PrismMode { kConvexPieces, kMesh };

struct SceneOptions {
  PrismMode prism_mode{PrismMode::kConvexPieces};
};

class Scene {
 public:
  using Options = SceneOptions;
  using PrismMode = collision::PrismMode;

  Scene();
  explicit Scene(Options options);
  /// A scene over every object of `world` (pass `world.plannerView()` to leave hidden ones out).
  explicit Scene(const world::World& world, Options options = Options());
  ~Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;
  /// Deep copy (rebuilds the FCL objects): for one scene per planning thread.
  Scene(const Scene& other);
  Scene& operator=(const Scene& other);

  // ---- world -----------------------------------------------------------------------------------
  /// Replaces all objects by those of `world` (full rebuild). Attachments whose object is absent
  /// from `world` are dropped.
  void setWorld(const world::World& world);
  /// Brings the scene to `world` incrementally: diffs against the last world given and adds,
  /// removes, moves or rebuilds only what changed (a moved object is one broad-phase update).
  void syncWorld(const world::World& world);
  /// The last world given (objects currently attached keep their world entry here).
  const world::World& world() const;
  std::size_t staticCount() const;
  std::size_t movableCount() const;
  /// Convex pieces / boxes / meshes in the broad phase (for diagnostics and benchmarks).
  std::size_t fclObjectCount() const;

  // ---- robot -----------------------------------------------------------------------------------
  /// Sets the robot model; link poses start at identity. Throws std::invalid_argument when a part
  /// names a link index out of range or has an invalid shape.
  void setRobot(RobotGeometry geometry);
  const RobotGeometry& robot() const;
  /// Sets the world pose of every link (size must equal `robot().links.size()`, else throws
  /// std::invalid_argument). Cheap: updates the robot's FCL transforms only.
  void setLinkPoses(std::span<const Eigen::Isometry3d> world_T_link);
  /// Convenience for single-link robots (NAMO disc/box): sets link 0 to the planar pose.
  void setBasePose(const Pose2D& pose);

  /// Attaches world object `object_id` to link `link` at `link_T_object`: it leaves the movable
  /// tree and moves with the link. kNotFound when the object or link is absent,
  /// kInvalidArgument when the object is static or already attached.
  Status attach(const std::string& object_id, const std::string& link,
                const Eigen::Isometry3d& link_T_object);
  /// Attaches the world's held object (`world().held()`), if any, by its link name.
  Status attachHeld();
  /// Detaches `object_id`; it returns to the movable tree at its pose in `world()` (callers that
  /// placed it elsewhere sync a world where it moved). kNotFound when not attached.
  Status detach(const std::string& object_id);
  std::vector<std::string> attachedObjects() const;

  // ---- unknown occupied space ------------------------------------------------------------------
  /// Replaces the unknown-space octree with occupied voxels at `centres` (world frame) of edge
  /// `resolution` (m, > 0, else throws std::invalid_argument).
  void setUnknownSpace(const std::vector<Eigen::Vector3d>& centres, double resolution);
  /// Same from an OctoMap binary stream (`octomap::OcTree::writeBinary`); kParseError when the
  /// bytes are not one.
  Status setUnknownSpaceFromOctomapBinary(const std::string& bytes);
  void clearUnknownSpace();
  bool hasUnknownSpace() const;

  // ---- queries: robot --------------------------------------------------------------------------
  /// True when any robot part or attached object touches an object allowed by `filter`.
  bool robotInCollision(const Filter& filter = {}) const;
  /// Ids of the objects touching the robot or an attached object (sorted, unique).
  std::vector<std::string> robotCollisions(const Filter& filter = {}) const;
  /// Every (robot link / attached object, object) pair in contact.
  std::vector<Contact> robotContacts(const Filter& filter = {}) const;
  /// Robot parts (and attached objects) touching each other, except allowed pairs and parts of
  /// the same link. Pairs of names, each pair sorted, the list sorted.
  std::vector<std::pair<std::string, std::string>> selfCollisions() const;
  /// Nearest allowed object to the robot (and attached objects).
  DistanceResult robotDistance(const Filter& filter = {}) const;

  // ---- queries: a free shape -------------------------------------------------------------------
  bool shapeInCollision(const world::Shape& shape, const Eigen::Isometry3d& pose,
                        const Filter& filter = {}) const;
  /// Ids of the objects `shape` at `pose` touches (sorted, unique). To test a world object
  /// against the others, pass its shape and pose with `Filter::allBut({id})`.
  std::vector<std::string> shapeCollisions(const world::Shape& shape, const Eigen::Isometry3d& pose,
                                           const Filter& filter = {}) const;
  DistanceResult shapeDistance(const world::Shape& shape, const Eigen::Isometry3d& pose,
                               const Filter& filter = {}) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tamp::collision
