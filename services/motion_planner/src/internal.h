#pragma once
// Private to the motion planner library (included by its .cc files only): the robot binding, the
// OMPL state space of a planning group, the collision oracle over tamp::collision::Scene, and the
// path tools (segment evaluation, effort-aware roadmap search and shortcutting, blocking report,
// infeasibility proof). OMPL appears here and in the .cc files, never in the public headers.

#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateSpace.h>
#include <ompl/geometric/PathGeometric.h>

#include "tamp/collision/scene.h"
#include "tamp/core/geometry.h"
#include "tamp/core/termination.h"
#include "tamp/motion_planner/motion_planner.h"

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

 private:
  void computeFootprint();
  std::optional<robot::RobotModel> model_;
  collision::RobotGeometry geometry_;
  std::string hold_link_;
  double inscribed_radius_{0.0};
  double inscribed_zmin_{0.0};
  double inscribed_zmax_{0.0};
  double footprint_radius_{0.0};
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
  /// The first colliding object (static only or all) or "self:a/b"; empty when free.
  std::string collidingObject(const ob::State* s, bool include_movables);
  const std::vector<MovableInfo>& movables() const { return movables_; }
  /// Movables whose AABB the robot may reach on the straight segment a-b (base groups with a
  /// rigid robot); all of them otherwise.
  void candidates(const ob::State* a, const ob::State* b, std::vector<int>& out) const;
  std::uint64_t checks() const { return checks_; }
  const GroupSpace& group() const { return gs_; }
  collision::Scene& scene() { return scene_; }

 private:
  bool selfFree();
  collision::Scene& scene_;
  const GroupSpace& gs_;
  collision::Filter static_filter_, all_filter_, movable_filter_;
  std::vector<MovableInfo> movables_;
  std::unordered_map<std::string, int> index_;
  bool self_check_{false};
  double reach_radius_{0.0};  // xy radius of the robot (+ held object) around the base origin
  bool rigid_{false};
  std::uint64_t checks_{0};
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

/// Evaluates every segment of a statically valid path, after cutting segments longer than
/// `max_segment` (space metric; 0: no cutting).
EvaluatedPath evaluatePath(Oracle& oracle, const og::PathGeometric& path, double resolution,
                           double max_segment);

/// The effort-aware roadmap search of the design overview (LazySP over a k-NN roadmap seeded
/// with `seed_path`). Returns the best fully evaluated path, or nothing when the budget ran out
/// first. Fills the roadmap fields of `stats`.
std::optional<og::PathGeometric> effortRoadmapSearch(Oracle& oracle, const ob::SpaceInformationPtr& si,
                                                     const og::PathGeometric& seed_path,
                                                     const LazyParams& params, double resolution,
                                                     double seconds_per_unit,
                                                     const Termination& termination,
                                                     PlanningStats& stats);

/// Effort-aware shortcutting: replaces vertices i..j by the straight segment when it is
/// statically valid and lowers J. `attempts` random pairs (fixed-seed rng).
void effortShortcut(Oracle& oracle, EvaluatedPath& path, int attempts, double resolution,
                    double seconds_per_unit, std::mt19937& rng, const Termination& termination);

/// Dense check of `path` against movables: the blocking report (by first contact).
std::vector<BlockingObject> blockingReport(Oracle& oracle, const og::PathGeometric& path,
                                           double resolution, double swept_spacing);

/// Outcome of the infeasibility proof.
enum class ProofOutcome { kDisconnected, kConnected, kSkipped, kStopped };

/// Grid flood fill of the base's inscribed disc from start to goal (see ProofParams) with cell
/// edge `cell`, objects of `filter`. kDisconnected proves that no base path exists.
ProofOutcome proveDisconnected(const collision::Scene& scene, const collision::Filter& filter,
                               const RobotBinding& robot, const Aabb& bounds, const Pose2D& start,
                               const Eigen::Vector2d& goal, double goal_tolerance, double cell,
                               int max_cells, const Termination& termination);

/// xy length of the base part of a path (base groups), or its length in the space metric.
double reportedLength(const GroupSpace& gs, const og::PathGeometric& path);

/// Group joint values along the path (yaw unwrapped).
JointPath toJointPath(const GroupSpace& gs, const og::PathGeometric& path);

}  // namespace tamp::motion_planner::detail
