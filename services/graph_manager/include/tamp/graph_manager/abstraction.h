#pragma once
/// @file
/// The symbolic abstraction of a live world for the mobile-manipulation domain
/// (config/pddl/mobile_manipulation.pddl): PDDL objects and facts of any world state, and symbols
/// made on the fly for sub-tasks.
///
/// - **Objects**: named locations, regions, one pre-grasp arm configuration `over_<region>` per
///   region (plus the constant `stow`), movable objects as items.
/// - **Symbols made on the fly**: a base pose (the robot's current one, or one beside a blocking
///   object from which the arm reaches it) becomes a location; a placement sampled by the motion
///   planner becomes a *slot*, a small region around the object's pose there, with its own
///   `over_<slot>` configuration. Every new symbol gets its static facts (`reaches` from inverse
///   kinematics at each location, `conf-over`).
/// - **Facts of a state**: `robot-at` (the location symbol of the base pose), `arm-at` (the
///   configuration symbol), `hand-empty`/`holding`, `on` (a slot whose pose the object occupies,
///   else its region, else the region below it), `occludes` (objects in the corridor between the
///   approach location and the object on the same support), `graspable` (movable, flagged
///   graspable, within the robot's payload).
/// - **Binding**: the reverse map from a symbolic state to geometry (base pose, object poses of
///   objects in slots, the held object), so that each node of the reachability graph is a symbolic
///   state plus its geometric binding.

#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/geometry.h"
#include "tamp/robot/robot_model.h"
#include "tamp/world/world.h"

namespace tamp::graph_manager {

struct AbstractionParams {
  double location_tolerance_m{0.05};    ///< a base pose this close to a location is that location
  double location_tolerance_rad{0.15};
  double slot_tolerance_m{0.06};        ///< an object this close to a slot's pose is on the slot
  double slot_half_size_m{0.06};        ///< half the side of a slot's square region
  /// Graspable objects weigh at most the robot's payload and at most this cap (kg).
  double payload_cap_kg{std::numeric_limits<double>::infinity()};
};

/// A placement made a symbol: the object `object_id` at `pose` on `parent_region`.
struct Slot {
  std::string id;
  std::string object_id;
  std::string parent_region;
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};
};

/// What a symbolic state means geometrically.
struct Binding {
  Pose2D base;
  std::string location;
  std::string armconf;                                   ///< "stow" or "over_<region>"
  std::string held;                                      ///< object id or empty
  std::map<std::string, Eigen::Isometry3d> object_poses;  ///< objects not where the world has them
};

class Abstraction {
 public:
  /// `world` is the planner's view at the start (locations, regions, objects).
  Abstraction(world::World world, robot::RobotModel robot, AbstractionParams params = {});

  const world::World& world() const { return world_; }
  const robot::RobotModel& robot() const { return robot_; }
  const AbstractionParams& params() const { return params_; }
  /// Replaces the world geometry (a newer world model); symbols stay.
  void setWorld(world::World world);

  /// The location symbol of `pose`: an existing one within tolerance, else a new one named
  /// `<hint>`, `<hint>_2`, ... with its `reaches` facts.
  std::string locationFor(const Pose2D& pose, const std::string& hint);
  /// As locationFor, but an existing location is taken only within `reuse_within_m` (and the
  /// angle tolerance): a pose that must be reached to the centimetre (where the base stands to
  /// push) gets a symbol of its own beside a stale one a few centimetres off.
  std::string locationFor(const Pose2D& pose, const std::string& hint, double reuse_within_m);
  /// The location within tolerance of `pose`, or empty.
  std::string findLocation(const Pose2D& pose) const;
  /// The nearest location within `within_m` of `pose` (and the angle tolerance), or empty.
  std::string findLocation(const Pose2D& pose, double within_m) const;
  std::optional<Pose2D> locationPose(const std::string& id) const;
  /// A new slot for `object_id` at `pose` on `parent_region` (existing one if the same pose).
  std::string addSlot(const std::string& object_id, const std::string& parent_region,
                      const Eigen::Isometry3d& pose);
  const Slot* slot(const std::string& id) const;
  std::size_t slotCount() const { return slots_.size(); }
  /// The slot of `object_id` nearest to `xy` within slot_tolerance_m (of `parent_region` only,
  /// when given); "" when none. Two slots of one object may lie closer than twice the tolerance:
  /// the nearest one is where the object stands.
  std::string slotAt(const std::string& object_id, const Eigen::Vector2d& xy, const std::string& parent_region = {}) const;
  /// Whether some location reaches `armconf`.
  bool isReached(const std::string& armconf) const;
  /// `atoms` with every `(on o r)` whose object stands on a slot of r (within slot_tolerance_m,
  /// in the current world) replaced by `(on o slot)`.
  std::vector<std::string> refinedSupports(const std::vector<std::string>& atoms) const;
  /// Records that from `location` the arm reaches `armconf` (proved by a grasp or IK elsewhere).
  void addReach(const std::string& location, const std::string& armconf);
  /// Records that from `from` the base pushes `object` (on `support`) straight to `slot`, ending
  /// at `to` (a static `push-to` fact, proven collision-free by the motion planner).
  void addPush(const std::string& object, const std::string& support, const std::string& from,
               const std::string& to, const std::string& slot);
  /// True when the region or slot `id` exists.
  bool isRegion(const std::string& id) const;
  /// The geometry of region or slot `id` (a slot: a square of slot_half_size_m round its pose),
  /// or null.
  const world::Region* region(const std::string& id) const;
  /// A PDDL item that stands for an object not known yet (the conditional branch "the gripper
  /// holds something the planner does not know"): `hint`, or `hint_2`, ... if a world id has it.
  /// Listed by objects(); no static facts (it is never picked, only put down).
  std::string addPlaceholder(const std::string& hint);
  bool isPlaceholder(const std::string& id) const { return placeholders_.count(id) > 0; }
  /// An arm configuration symbol for an arm that is neither stowed nor at a known pre-grasp (a
  /// mission taken up after a restart, a robot handed over with its arm out): `hint`, or
  /// `hint_2`, ... Listed by objects(); no static facts, so a plan can only leave it.
  std::string addObservedArmconf(const std::string& hint);

  static std::string armconfOver(const std::string& region) { return "over_" + region; }
  /// The region of an `over_<region>` configuration (empty for stow or unknown).
  std::string regionOfArmconf(const std::string& armconf) const;

  /// PDDL objects ("name - type"), every symbol known so far.
  std::vector<std::string> objects() const;
  /// Static facts (reaches, conf-over, graspable, push-to), sorted.
  std::vector<std::string> staticAtoms() const;
  /// Dynamic facts of a live state: the robot at `base` (a location symbol, made if needed), the
  /// arm at `armconf`, holding `held` (or hand-empty), objects of `world` on regions or slots
  /// (an object on the floor, within kOnTheFloor_m, but on no known region gets a slot where it
  /// stands).
  static constexpr double kOnTheFloor_m = 0.05;
  std::vector<std::string> dynamicAtoms(const world::World& world, const Pose2D& base,
                                        const std::string& armconf, const std::string& held);
  /// The geometry of a symbolic state (dynamic atoms).
  Binding bind(const std::vector<std::string>& atoms) const;
  /// Whether the object is graspable for this robot (movable, flagged, within the payload).
  bool graspable(const world::Object& o) const;
  /// Why the object is not graspable ("" when it is), for failure reasons.
  std::string whyNotGraspable(const world::Object& o) const;

 private:
  void addReaches(const std::string& location, const Pose2D& pose);
  void addRegionReaches(const std::string& region_symbol, const world::Region& region);
  world::Region slotRegion(const Slot& s) const;

  world::World world_;
  robot::RobotModel robot_;
  AbstractionParams params_;
  std::map<std::string, Pose2D> locations_;
  std::map<std::string, world::Region> regions_;  ///< world regions and slot regions
  std::map<std::string, Slot> slots_;
  std::set<std::string> reaches_;                 ///< "(reaches l c)"
  std::map<std::string, std::string> pushes_;     ///< "(push-to o r from to s)" -> o
  std::set<std::string> placeholders_;
  std::set<std::string> observed_armconfs_;
  int slot_counter_{0};
};

/// Tokens of an atom "(p a b)" -> {"p", "a", "b"}.
std::vector<std::string> atomTokens(const std::string& atom);

}  // namespace tamp::graph_manager
