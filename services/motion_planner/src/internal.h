#pragma once
// Private to the motion planner library (included by its .cc files only): the robot binding, the
// OMPL state space of a planning group, the collision oracle over tamp::collision::Scene, and the
// path tools (segment evaluation, effort-aware roadmap search and shortcutting, blocking report,
// infeasibility proof). OMPL appears here and in the .cc files, never in the public headers.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <queue>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include <ompl/base/Planner.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateSpace.h>
#include <ompl/geometric/PathGeometric.h>

#include "tamp/collision/clearance_grid.h"
#include "tamp/collision/scene.h"
#include "tamp/core/geometry.h"
#include "tamp/core/termination.h"
#include "tamp/motion_planner/motion_planner.h"
#include "tamp/world/world.h"

namespace tamp::motion_planner::detail {

namespace ob = ompl::base;
namespace og = ompl::geometric;

// ---- robot ----------------------------------------------------------------------------------

/// The robot the planner moves: a RobotModel (mobile manipulator) or a planar geometry.
class RobotBinding {
 public:
  explicit RobotBinding(robot::RobotModel model);
  explicit RobotBinding(collision::RobotGeometry planar);

  bool hasArm() const { return model_.has_value(); }
  const robot::RobotModel* model() const { return model_ ? &*model_ : nullptr; }
  const collision::RobotGeometry& geometry() const { return geometry_; }
  std::size_t armDof() const { return model_ ? model_->armDof() : 0; }
  /// The link a held object is attached to: the tool link, or link 0 of a planar robot.
  const std::string& holdLink() const { return hold_link_; }
  /// World poses of every collision link (geometry().links order).
  void linkPoses(const robot::RobotState& s, std::vector<Eigen::Isometry3d>& out) const;
  /// Inscribed radius of the base footprint about the base origin and the z range of the base
  /// part that realises it (for the infeasibility proof); radius 0 when unknown.
  double inscribedRadius() const { return inscribed_radius_; }
  double inscribedZMin() const { return inscribed_zmin_; }
  double inscribedZMax() const { return inscribed_zmax_; }
  /// Largest xy distance from the base origin to the base's footprint, m.
  double footprintRadius() const { return footprint_radius_; }
  /// The base part that realises the inscribed radius (geometry().parts), or null.
  const collision::RobotPart* inscribedPart() const {
    return inscribed_part_ < geometry_.parts.size() ? &geometry_.parts[inscribed_part_] : nullptr;
  }
  /// Per arm joint (chain order): how far any point of the links that joint moves (links,
  /// gripper, fingers) moves per radian of it (m/rad): the chain's joint offsets out to the
  /// farthest link plus that link's parts. The displacement of any point for a joint motion dq is
  /// at most sum_j |dq_j| armJointRadii()[j]. Empty without an arm.
  const std::vector<double>& armJointRadii() const { return arm_joint_radii_; }
  /// Floor contact of an arm part (the planner's name for it in reasons and contacts).
  static constexpr const char* kFloor = "floor";
  /// Arm robots: the chain length from the first arm joint to `link`'s origin (m); -1 for a link
  /// that the arm does not move.
  double armReachTo(const std::string& link) const;

 private:
  void computeFootprint();
  void computeArmSweep();
  std::optional<robot::RobotModel> model_;
  collision::RobotGeometry geometry_;
  std::string hold_link_;
  double inscribed_radius_{0.0};
  double inscribed_zmin_{0.0};
  double inscribed_zmax_{0.0};
  double footprint_radius_{0.0};
  std::size_t inscribed_part_{static_cast<std::size_t>(-1)};
  std::vector<double> arm_joint_radii_;
  std::vector<std::pair<std::string, double>> arm_reach_;  // link -> chain length from the first arm joint
};

// ---- planning group -------------------------------------------------------------------------

/// The OMPL state space of one planning group for one request, and conversions between its
/// states, joint values and robot states.
class GroupSpace {
 public:
  /// `base_bounds`: xy bounds of the base (world frame). Throws std::invalid_argument when the
  /// group needs an arm the robot lacks.
  GroupSpace(const RobotBinding& robot, PlanningGroup group, const robot::RobotState& start,
             const Aabb& base_bounds, const SamplingParams& params);

  PlanningGroup group() const { return group_; }
  const ob::StateSpacePtr& space() const { return space_; }
  bool hasBase() const { return group_ != PlanningGroup::kArm; }
  bool movesArm() const { return group_ != PlanningGroup::kBase; }
  const std::vector<std::string>& jointNames() const { return names_; }
  const robot::RobotState& start() const { return start_; }
  /// Length -> time factor of the path cost (s per unit of the space metric).
  double secondsPerUnit(const CostParams& c) const {
    return group_ == PlanningGroup::kArm ? 1.0 / c.arm_speed : 1.0 / c.base_speed;
  }

  std::vector<double> values(const ob::State* s) const;
  void setValues(const std::vector<double>& v, ob::State* s) const;
  robot::RobotState robotState(const ob::State* s) const;
  Pose2D basePose(const ob::State* s) const;
  /// Sets the robot's link poses in `scene` for state `s`.
  void placeRobot(const ob::State* s, collision::Scene& scene) const;
  /// After placeRobot(): whether every part that the arm moves is above the floor (z = 0; the
  /// robot stands on it and no scene object models it). True for the base group.
  bool armAboveFloor() const;
  bool inBounds(const ob::State* s) const { return space_->satisfiesBounds(s); }
  const Aabb& baseBounds() const { return base_bounds_; }

 private:
  const RobotBinding& robot_;
  PlanningGroup group_;
  robot::RobotState start_;
  Aabb base_bounds_;
  ob::StateSpacePtr space_;
  std::vector<std::string> names_;
  std::vector<Eigen::Isometry3d> base_T_link_;  // base group: rigid robot relative to the base
  std::vector<std::size_t> arm_parts_;          // arm groups: geometry parts that the arm moves
  mutable std::vector<Eigen::Isometry3d> poses_;
  mutable robot::RobotState scratch_;
};

// ---- collision oracle -----------------------------------------------------------------------

/// A movable object the path cost knows.
struct MovableInfo {
  std::string id;
  double mass{0.0};
  double effort_s{0.0};  ///< before the request's scale
  double cost_s{0.0};    ///< effort x object_cost_scale
  Aabb aabb;             ///< world frame
  std::shared_ptr<const world::Object> object;  ///< the world's record (roadmap movable cache); may be null
};

/// Collision queries of one request: static (+ unknown space + self) validity, full validity and
/// the movables touched, with ignored objects left out. Counts checks.
class Oracle {
 public:
  /// `reach_radius`: xy radius of the robot (and held object) about the base origin when the
  /// robot moves rigidly with the base (base group), enabling the AABB prefilter; 0 disables it.
  Oracle(collision::Scene& scene, const GroupSpace& gs, std::vector<std::string> ignored,
         std::vector<MovableInfo> movables, double reach_radius);

  bool staticFree(const ob::State* s);
  bool allFree(const ob::State* s);
  /// Indices into movables() of the objects touching the robot at `s`, sorted.
  void touched(const ob::State* s, std::vector<int>& out);
  /// Whether movable `index` touches the robot at `s`.
  bool touches(const ob::State* s, int index);
  /// Distance (m) from the robot at `s` to the nearest movable (0 or less in contact; +inf when
  /// there is none).
  double movableDistance(const ob::State* s);
  /// False when movable `index` cannot touch the robot at `s` (its AABB is outside the reach
  /// square about the base; rigid base groups only); true otherwise.
  bool mayTouch(const ob::State* s, int index) const;
  /// The first colliding object (static only or all) or "self:a/b"; empty when free.
  std::string collidingObject(const ob::State* s, bool include_movables);
  const std::vector<MovableInfo>& movables() const { return movables_; }
  /// Whether the robot moves rigidly with the base (base group with a known reach radius).
  bool rigid() const { return rigid_; }
  double reachRadius() const { return reach_radius_; }
  /// Movables whose AABB the robot may reach on the straight segment a-b (base groups with a
  /// rigid robot); all of them otherwise.
  void candidates(const ob::State* a, const ob::State* b, std::vector<int>& out) const;
  std::uint64_t checks() const { return checks_; }
  /// Static checks answered by the clearance grid (no FCL query).
  std::uint64_t gridAnswers() const { return grid_answers_; }
  /// A rigid base group's static and full checks ask `grid` first: where its clearance exceeds
  /// the radius of each circle of `cover` (x, y in the base frame, radius: together they cover
  /// the robot from above) the robot touches no static object (collision/clearance_grid.h), and
  /// only the movables within reach are asked of FCL. The grid must be of this scene's static
  /// objects, or more; the scene must have no unknown space. Null or an empty cover: off.
  void setClearance(std::shared_ptr<const collision::ClearanceGrid> grid, std::vector<Eigen::Vector3d> cover);
  const GroupSpace& group() const { return gs_; }
  collision::Scene& scene() { return scene_; }
  /// Contacts of the robot with itself are checked in `self` (placed at each state) instead of
  /// the scene: there the held object is as modelled, in the scene it has a margin. Null: the scene.
  void setSelfScene(collision::Scene* self) { self_scene_ = self; }

 private:
  bool selfFree(const ob::State* s);
  /// Whether the clearance grid shows no static object within reach at `s` (counted).
  bool clearOfStatics(const ob::State* s);
  std::vector<std::pair<std::string, std::string>> selfContacts(const ob::State* s);
  collision::Scene& scene_;
  collision::Scene* self_scene_{nullptr};
  const GroupSpace& gs_;
  collision::Filter static_filter_, all_filter_, movable_filter_;
  std::vector<MovableInfo> movables_;
  std::unordered_map<std::string, int> index_;
  bool self_check_{false};
  double reach_radius_{0.0};  // xy radius of the robot (+ held object) around the base origin
  bool rigid_{false};
  std::shared_ptr<const collision::ClearanceGrid> clearance_;
  std::vector<Eigen::Vector3d> cover_;  ///< circles (x, y in the base frame, radius)
  std::uint64_t checks_{0};
  std::uint64_t grid_answers_{0};
};

/// Fractions of the motion a -> b at the corners of a stop-and-turn base's motion (where a turn
/// ends and the drive begins, where the drive ends); empty for other spaces.
std::vector<double> turnCorners(const ob::StateSpace& space, const ob::State* a, const ob::State* b);
/// How far the robot's farthest point travels from a to b: for a stop-and-turn base the turns
/// (at its circumradius) plus the drive, which the SE(2) distance under-counts when a segment
/// turns away and back (its end yaws agree); otherwise the space's distance.
double sweptLength(const ob::StateSpace& space, const ob::State* a, const ob::State* b);
/// Whether `space` is the stop-and-turn SE(2) (sampling.base_turn_in_place).
bool isStopAndTurn(const ob::StateSpace& space);

/// OMPL's discrete motion check plus the corner states of a stop-and-turn motion: the uniform
/// samples step over the corner, where the base stands farthest out (it missed 2 mm into a table
/// at the final turn, which the robot then touched).
class CornerMotionValidator : public ob::MotionValidator {
 public:
  explicit CornerMotionValidator(const ob::SpaceInformationPtr& si) : ob::MotionValidator(si) {}
  bool checkMotion(const ob::State* s1, const ob::State* s2) const override;
  bool checkMotion(const ob::State* s1, const ob::State* s2, std::pair<ob::State*, double>& last_valid) const override;
};

/// Arm group: OMPL's discrete motion check, with at least as many states as keep every point of
/// the robot (and the held object) within `step_m` of the last checked state: the joint motion's
/// motion weighted per joint by how far its links reach (RobotBinding::armJointRadii, grown by a
/// held object) bounds any point's displacement. The robot sweeps every commanded motion at such a resolution and stops
/// before the first contact, so a coarser check (0.02 in joint space moves a fingertip 3-5 cm)
/// let planned paths clip a box's corner between two checked states (tests/contract).
class SweptArmMotionValidator : public ob::MotionValidator {
 public:
  /// `radii_m`: per arm joint, how far a point moves per radian of that joint (armJointRadii,
  /// each grown by the held object's extent).
  SweptArmMotionValidator(const ob::SpaceInformationPtr& si, const GroupSpace& gs, std::vector<double> radii_m,
                          double step_m)
      : ob::MotionValidator(si), gs_(gs), radii_(std::move(radii_m)), step_(step_m) {}
  bool checkMotion(const ob::State* s1, const ob::State* s2) const override;
  bool checkMotion(const ob::State* s1, const ob::State* s2, std::pair<ob::State*, double>& last_valid) const override;

 private:
  unsigned segments(const ob::State* s1, const ob::State* s2) const;
  const GroupSpace& gs_;
  std::vector<double> radii_;
  double step_;
};

/// Full-mode base requests: everything free, as OracleValidityChecker, and a clearance kept where
/// the robot has room for it: away from the request's start and goal (within `near_ends_m` of
/// either only the plain check applies: a robot parked beside a table must still leave it), a
/// state must also be free for the robot grown sideways by the clearance (`padded`, an oracle over
/// a scene with the grown robot; null: no clearance). relax() drops that once no path kept the
/// clearance in time. With a start floor (`setStartFloor`), a state within `near_ends_m` of the
/// start must also stand at least that far from every movable; relax() keeps it.
class ClearanceValidityChecker : public ob::StateValidityChecker {
 public:
  /// `ends`: the start first, then the goal if it has a base position.
  /// `padded_contains_plain`: the grown robot contains the robot and `padded`'s scene has every
  /// object of `oracle`'s, so a state free for the former is free for the latter (one check).
  ClearanceValidityChecker(const ob::SpaceInformationPtr& si, Oracle& oracle, Oracle* padded, const GroupSpace& gs,
                           std::vector<Eigen::Vector2d> ends, double near_ends_m, bool padded_contains_plain)
      : ob::StateValidityChecker(si), oracle_(oracle), padded_(padded), gs_(gs), ends_(std::move(ends)),
        near_(near_ends_m), implied_(padded_contains_plain), relaxed_(padded == nullptr) {}
  bool isValid(const ob::State* s) const override;
  void relax() { relaxed_ = true; }
  bool relaxed() const { return relaxed_; }
  /// m, > 0: the least distance to the movables near the start; 0: none.
  void setStartFloor(double floor_m) { floor_ = floor_m; }

 private:
  bool nearEnd(const Eigen::Vector2d& at, std::size_t from) const;
  Oracle& oracle_;
  Oracle* padded_;
  const GroupSpace& gs_;
  std::vector<Eigen::Vector2d> ends_;
  double near_;
  bool implied_;
  bool relaxed_;
  double floor_{0.0};
};

/// OMPL validity checker over the oracle (static only, or everything).
class OracleValidityChecker : public ob::StateValidityChecker {
 public:
  OracleValidityChecker(const ob::SpaceInformationPtr& si, Oracle& oracle, bool full)
      : ob::StateValidityChecker(si), oracle_(oracle), full_(full) {}
  bool isValid(const ob::State* s) const override {
    if (!si_->satisfiesBounds(s)) return false;
    return full_ ? oracle_.allFree(s) : oracle_.staticFree(s);
  }

 private:
  Oracle& oracle_;
  bool full_;
};

// ---- a start touching movables --------------------------------------------------------------

/// Where a start that touches movable objects only can leave to: `out` is set to a state that
/// `free_si` finds valid (it touches nothing), reached from `start` by a straight motion that
/// `escape_si` finds valid (it checks everything but the objects touched at the start). Samples
/// `attempts` states uniformly near `start`, in four rings of growing radius up to
/// `max_distance` (space metric), nearest ring first. False when none is found.
bool escapeStart(const ob::SpaceInformationPtr& free_si, const ob::SpaceInformationPtr& escape_si,
                 const ob::State* start, double max_distance, int attempts, ob::State* out);

// ---- paths ----------------------------------------------------------------------------------

/// Objects touched along a straight segment and whether it is statically valid.
struct SegmentInfo {
  bool valid{true};
  double length{0.0};
  std::vector<int> touched;  ///< sorted, endpoints included
};

/// Evaluates the straight segment a-b at `resolution` (space metric): static validity of the
/// interior samples (endpoints assumed checked) unless `static_known_valid`, then the movables
/// touched at every sample including both ends. `cost_cap` > 0: stop the movable pass once the
/// new objects (not in `already`) cost more than it (the segment is then reported invalid).
SegmentInfo evaluateSegment(Oracle& oracle, const ob::State* a, const ob::State* b,
                            double resolution, bool static_known_valid,
                            const std::vector<int>* already = nullptr, double cost_cap = 0.0);

/// Sum of the costs of distinct objects in `ids`.
double objectsCost(const Oracle& oracle, const std::vector<int>& ids);

/// The lazy path's cost: length x seconds_per_unit + sum of distinct objects' costs.
struct PathCost {
  double length{0.0};
  std::vector<int> objects;  ///< sorted, distinct
  double cost{0.0};
};

/// A path with per-segment evaluations (segments[i] joins states i and i+1).
struct EvaluatedPath {
  og::PathGeometric path;
  std::vector<SegmentInfo> segments;
  explicit EvaluatedPath(const ob::SpaceInformationPtr& si) : path(si) {}
  PathCost cost(const Oracle& oracle, double seconds_per_unit) const;
};

/// Re-checks every segment of `path` with `fine_si` (its motion validator, e.g. the swept arm
/// check) and plans each segment that fails again in `fine_si` (a planner from `make`, in slices
/// of growing length until `termination`, between the segment's two states; then shortened
/// there), splicing the result in. The first and last states are kept. Returns the number of
/// segments re-planned, or -1 when one could not be (`path` is then unchanged).
int repairSegments(const ob::SpaceInformationPtr& fine_si, og::PathGeometric& path,
                   const std::function<ob::PlannerPtr(const ob::SpaceInformationPtr&)>& make,
                   const Termination& termination);

/// Evaluates every segment of a statically valid path, after cutting segments longer than
/// `max_segment` (space metric; 0: no cutting).
EvaluatedPath evaluatePath(Oracle& oracle, const og::PathGeometric& path, double resolution,
                           double max_segment);

/// What the static free space of one planning group depends on (the cache key of a
/// StaticRoadmap): the static objects that are not ignored (by pointer, else by value), the held
/// object (its id and geometry -- not its world pose: it moves with the robot -- and where it
/// sits on which link), and the joints the group does not
/// move (base group: arm + gripper; arm group: base pose + gripper; whole body: gripper). The
/// robot is fixed per planner. Movables are not part of it: they are only costs.
struct StaticWorldKey {
  PlanningGroup group{PlanningGroup::kBase};
  std::vector<std::shared_ptr<const world::Object>> statics;  ///< sorted by id
  std::shared_ptr<const world::Object> held;                  ///< or null; compared by id and shape
  std::string held_link;
  Eigen::Isometry3d link_T_held{Eigen::Isometry3d::Identity()};
  std::vector<double> fixed;
  bool operator==(const StaticWorldKey& o) const;
  /// Equal to `base` but for more static objects (base's statics a strict subset of these):
  /// the world of a request whose fixed objects became obstacles. `added` receives the extra ones.
  bool extends(const StaticWorldKey& base, std::vector<std::shared_ptr<const world::Object>>& added) const;
};

/// A roadmap of the static free space of one group and StaticWorldKey, kept across requests
/// (see motion_planner.h, "Roadmap cache"): nodes (uniform samples, request starts and goals,
/// lazy KPIECE paths) are static-free; k-nearest-neighbour edges carry their static validity
/// once evaluated (lazily, when an edge is on a candidate path), so later requests pay only for
/// the movables along the edges they consider. Not thread-safe (the planner it belongs to is not).
class StaticRoadmap {
 public:
  StaticRoadmap(ob::StateSpacePtr space, StaticWorldKey key, std::uint32_t seed, int neighbors);
  ~StaticRoadmap();
  StaticRoadmap(const StaticRoadmap&) = delete;
  StaticRoadmap& operator=(const StaticRoadmap&) = delete;

  const StaticWorldKey& key() const { return key_; }
  std::size_t nodeCount() const { return nodes_.size(); }
  std::size_t edgeCount() const { return edges_.size(); }
  std::size_t uniformSamples() const { return uniform_; }  ///< uniform + bridge-test samples
  std::size_t plainSamples() const { return plain_; }      ///< uniform samples
  std::size_t bridgeSamples() const { return bridges_; }   ///< bridge-test samples
  /// The last addSamples() stopped on its termination (not on its counts).
  bool samplingInterrupted() const { return sampling_interrupted_; }

  /// Draws uniform states of `gs`'s space (own seeded generator: deterministic) until `count`
  /// static-free ones were added or 4 x `count` were drawn; then up to `bridge_count` bridge-test
  /// samples (narrow passages; at most 20 x `bridge_count` attempts).
  void addSamples(Oracle& oracle, const GroupSpace& gs, int count, const Termination& termination,
                  int bridge_count = 0, double bridge_distance = 1.0);
  /// Evaluates the static validity of every edge not known yet (at `resolution`); returns
  /// {evaluated, invalid}; `complete` tells whether every edge is known afterwards.
  std::pair<std::size_t, std::size_t> evaluateEdges(Oracle& oracle, double resolution,
                                                    const Termination& termination, bool& complete);
  /// Adds a static-free state (or finds the node already there) connected to its k nearest nodes.
  int addState(const ob::State* s);
  /// addState() for a request's start or goal: a node it creates is a *request node*, stamped
  /// with `request` (a counter of the caller); an existing request node gets the new stamp.
  int addRequestState(const ob::State* s, std::uint64_t request);
  std::size_t requestNodeCount() const { return request_nodes_; }
  /// Bounds the roadmap's growth over a long mission: when more than `max_request_nodes`
  /// request nodes exist, the least recently used are removed (with their edges and cached
  /// movables) until half of that many remain. Samples and lazy KPIECE path nodes are kept.
  /// Returns the number of nodes removed. Never call during a search (indices change).
  std::size_t pruneRequestNodes(std::size_t max_request_nodes);
  /// Movable-aware densification (rigid base groups): for each movable `objects` (request
  /// indices into oracle.movables()) not densified yet at its current box, up to `per_object`
  /// static-free samples with the base just outside the box (0.5-1.5 x the reach radius away,
  /// any yaw): the gaps between movables and walls that uniform samples miss, where a route
  /// crossing fewer or lighter objects may pass. Returns the number of nodes added.
  int addObjectRingSamples(Oracle& oracle, const GroupSpace& gs, const std::vector<int>& objects, int per_object,
                           const Termination& termination);
  /// Adds a statically valid path cut every `spacing` (its edges are known valid); returns the
  /// nodes of its first and last states.
  std::pair<int, int> addPath(const og::PathGeometric& path, double spacing);
  /// Makes this (empty) roadmap of a world with more static obstacles (`added`, their boxes) from
  /// `base`'s: its nodes that stay static-free (checked by `oracle`, of this world, when near an
  /// added box), its edges between them, its samples' counts and its movable cache. An edge that
  /// base knew valid and whose swept box (its ends' base positions grown by the reach radius)
  /// meets an added box is unknown again (`recheck`), evaluated when a search needs it; found
  /// invalid, it does not count towards the search's `max_new_invalid` (the sign of a roadmap that
  /// does not connect: these are the added obstacles, known). The others keep base's static
  /// validity. Rigid base groups only (`oracle.rigid()`). Returns the number of base nodes dropped.
  std::size_t deriveFrom(const StaticRoadmap& base, Oracle& oracle, const std::vector<Aabb>& added);

  /// The effort-aware LazySP search (see roadmap.cc) from node `start` to any of `goals` under
  /// the request's movables; nothing when they are not connected within the budgets
  /// (LazyParams::roadmap_max_evaluations edge evaluations, `max_new_invalid` edges newly found
  /// statically invalid when > 0 -- the sign of a roadmap that does not connect them --,
  /// optimize_budget_s, `termination`). When the evaluation budget runs out, the best path
  /// over the edges known to be statically valid is returned if they connect start and goal.
  /// `route_objects`, when given, receives the movables the returned path crosses (request
  /// indices, sorted): its edges are all evaluated by then, so this costs no check.
  std::optional<og::PathGeometric> search(Oracle& oracle, const ob::SpaceInformationPtr& si, int start,
                                          const std::vector<int>& goals, const LazyParams& params,
                                          double resolution, double seconds_per_unit,
                                          const Termination& termination, PlanningStats& stats,
                                          int max_new_invalid = 0, std::vector<int>* route_objects = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  ob::StateSpacePtr space_;
  StaticWorldKey key_;
  std::vector<ob::State*> nodes_;
  struct Edge {
    int a{0}, b{0};
    double len{0.0};
    enum Status : unsigned char { kUnknown, kValid, kInvalid } status{kUnknown};  // static validity
    bool recheck{false};  // unknown again in a derived roadmap (deriveFrom): near an added obstacle
  };
  std::vector<Edge> edges_;
  std::vector<std::vector<int>> adj_;
  /// Cross-request cache of the movables touched at nodes and along valid edges (rigid base
  /// groups): entries are dropped when a movable near them changes (syncMovables).
  struct MovableCache;
  std::unique_ptr<MovableCache> mcache_;
  /// One request's search (roadmap_search.cc).
  class Search;
  /// Brings the cache to the request's movables; returns false when it cannot be used.
  bool syncMovables(const Oracle& oracle, std::vector<int>& global_to_request);
  std::vector<std::uint64_t> request_stamp_;  ///< per node: 0, or the last request using it
  std::vector<std::pair<std::string, Aabb>> densified_;  ///< movables ring-sampled, at their box then
  std::size_t request_nodes_{0};
  std::size_t uniform_{0};
  std::size_t plain_{0};
  std::size_t bridges_{0};
  bool sampling_interrupted_{false};
  int neighbors_{12};
  void addEdge(int a, int b, bool valid);
  int pushNode(const ob::State* s);
};

/// Touched movables are stored by roadmap-wide movable number (`ids`), so that entries survive
/// requests whose movable lists (ignored objects, new objects) differ.
struct StaticRoadmap::MovableCache {
  struct Entry {
    bool cached{false};
    std::vector<int> touched;  ///< roadmap movable numbers, sorted
    double x0{0}, y0{0}, x1{0}, y1{0};  ///< xy box of the base positions (node, edge ends)
  };
  std::vector<Entry> nodes, edges;
  std::unordered_map<std::string, int> ids;
  std::vector<std::shared_ptr<const world::Object>> seen;  ///< as last present (null: absent since)
  std::vector<Aabb> last_box;                               ///< where it was when last present
  double reach{-1.0};
};

/// Effort-aware shortcutting: replaces vertices i..j by the straight segment when it is
/// statically valid and lowers J. `attempts` random pairs (fixed-seed rng).
void effortShortcut(Oracle& oracle, EvaluatedPath& path, int attempts, double resolution,
                    double seconds_per_unit, std::mt19937& rng, const Termination& termination);

/// Dense check of `path` against movables: the blocking report (by first contact).
std::vector<BlockingObject> blockingReport(Oracle& oracle, const og::PathGeometric& path,
                                           double resolution, double swept_spacing);

/// Outcome of the infeasibility proof.
enum class ProofOutcome { kDisconnected, kConnected, kSkipped, kStopped };

/// The `no path` proof on one grid (see ProofParams and proof.cc), grown from the start and from
/// the goal region at once, objects of `filter`. Two kinds of cells:
///  - `yaw_cells` <= 1: xy cells of edge `cell`, the base's inscribed disc (any orientation);
///  - `yaw_cells` > 1: (x, y, yaw) cells, the base part that realises the inscribed radius (a
///    box) shrunk by how far any of its points moves within a cell: it proves what needs the
///    robot's orientation (it cannot turn where it stands). Cells are kept sparsely.
/// Resumable: advance() works until it decides or `termination` says stop (kStopped, undecided
/// so far; the next call goes on). kDisconnected proves that no base path exists; kSkipped: this
/// grid cannot say (too many cells, cells too coarse, no box part, the start outside the bounds).
/// `statics`, when given, is a clearance grid of (at least) the scene's static objects: where it
/// shows none within reach of the cell's shape, FCL is asked of the other groups only.
/// `carried`, when given, is a shape fixed to the base (the held object, the arm still): the
/// (x, y, yaw) cells test it too, shrunk the same way, so that a base that cannot turn or pass
/// with what it holds or pushes is proven so.
class DisconnectionProof {
 public:
  /// A shape at a fixed place on the base.
  struct Carried {
    world::Shape shape;
    Eigen::Isometry3d base_T_shape{Eigen::Isometry3d::Identity()};
  };
  DisconnectionProof(const collision::Scene& scene, const collision::Filter& filter,
                     const collision::ClearanceGrid* statics, const RobotBinding& robot, const Aabb& bounds,
                     const Pose2D& start, const Eigen::Vector2d& goal, double goal_tolerance, double cell,
                     int yaw_cells, int max_cells, const std::optional<Carried>& carried = std::nullopt);
  ProofOutcome advance(const Termination& termination);
  double cell() const { return cell_; }
  int yawCells() const { return nt_; }
  /// Cells whose shape was tested, and of those the ones the clearance grid cleared of statics.
  std::size_t tested() const { return tested_; }
  std::size_t gridAnswers() const { return grid_answers_; }

 private:
  struct Cell {
    long ix, iy, it;
  };
  struct Entry {
    double to_other_end;  ///< m, from the cell's centre to the other end's point
    Cell c;
    bool operator<(const Entry& o) const { return to_other_end > o.to_other_end; }  // nearest on top
  };
  using Frontier = std::priority_queue<Entry>;
  /// A shape tested at each cell's centre (in the base frame).
  struct Probe {
    world::Shape shape;
    Eigen::Isometry3d base_T_shape{Eigen::Isometry3d::Identity()};
  };
  bool setUpShapes(const RobotBinding& robot, const std::optional<Carried>& carried);
  bool addRobotProbe(const RobotBinding& robot);
  void addCarriedProbe(const Carried& carried);
  /// Whether every probe is free with the base at (x, y, yaw).
  bool probesFree(double x, double y, double yaw);
  void push(Frontier& frontier, const Eigen::Vector2d& towards, const Cell& c);
  bool cellOf(double x, double y, long& ix, long& iy) const;
  std::uint64_t key(const Cell& c) const {
    return (static_cast<std::uint64_t>(c.it) * static_cast<std::uint64_t>(ny_) + static_cast<std::uint64_t>(c.iy)) *
               static_cast<std::uint64_t>(nx_) +
           static_cast<std::uint64_t>(c.ix);
  }
  unsigned char& state(const Cell& c);
  /// Whether cell `c`, whose state is `st`, may hold a free robot (tested once, then recorded in `st`).
  bool kept(unsigned char& st, const Cell& c);

  const collision::Scene& scene_;
  collision::Filter filter_;
  collision::Filter others_;  ///< filter_ without the static objects
  const collision::ClearanceGrid* statics_;
  Eigen::Vector2d min_;
  double cell_;
  long nx_{0}, ny_{0}, nt_{1};
  std::size_t max_cells_{0};
  std::vector<Probe> probes_;
  double reach_{0.0};  ///< xy distance from the base origin that the probes stay within
  std::vector<unsigned char> dense_;                         ///< xy cells
  std::unordered_map<std::uint64_t, unsigned char> sparse_;  ///< (x, y, yaw) cells
  Eigen::Vector2d start_{Eigen::Vector2d::Zero()}, goal_{Eigen::Vector2d::Zero()};
  Frontier from_start_, from_goal_;
  std::size_t expanded_start_{0}, expanded_goal_{0};
  ProofOutcome decided_{ProofOutcome::kSkipped};
  std::size_t tested_{0}, grid_answers_{0};
};

/// xy length of the base part of a path (base groups), or its length in the space metric.
double reportedLength(const GroupSpace& gs, const og::PathGeometric& path);

/// Group joint values along the path (yaw unwrapped).
JointPath toJointPath(const GroupSpace& gs, const og::PathGeometric& path);

/// A stop-and-turn base path made to say what the robot will do: each inner waypoint takes the
/// heading the robot drives the next segment with (forwards or backwards, whichever turns less
/// from the heading it arrives with), so the turns the motions were checked with are the turns
/// executed (effort_model::baseSteps). Kept only when every changed motion is still valid
/// (`si`'s motion validator); returns whether the path changed. Base group paths only.
bool alignBaseHeadings(const ob::SpaceInformationPtr& si, og::PathGeometric& path);
/// A stop-and-turn base path with the corners of each motion (where its first turn in place ends,
/// where its drive ends) made waypoints: the robot turns in place exactly where and as far as the
/// motion was checked. The executor (effort_model::baseSteps: the simulator, the monitor) turns only
/// at waypoints that do not move, straight from the heading it arrives with to the next drive's:
/// an inner waypoint whose heading is neither (alignBaseHeadings could not change it: the aligned
/// motion touched something) was turned through the other way round, unchecked, and the simulator
/// stopped the robot before a wall (docs/reliability.md, session 18). Other spaces: unchanged.
void explicitBaseTurns(const ob::SpaceInformationPtr& si, og::PathGeometric& path);

}  // namespace tamp::motion_planner::detail
