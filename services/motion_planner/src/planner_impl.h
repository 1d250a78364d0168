#pragma once
// Private: the state of a MotionPlanner, shared by motion_planner.cc, planning*.cc, placement.cc, grasps.cc.

#include <optional>
#include <string>
#include <vector>

#include "internal.h"
#include "tamp/motion_planner/trajectory_timing.h"

namespace tamp::motion_planner {

struct MotionPlanner::Impl {
  MotionPlannerParams params;
  detail::RobotBinding robot;
  collision::Scene scene;
  world::World world;  // planner view
  ObjectEffortFn effort;
  /// Cached static roadmaps (motion_planner.h, "Roadmap cache"), least recently used first.
  std::vector<std::unique_ptr<detail::StaticRoadmap>> roadmaps;
  std::uint64_t requests{0};  ///< roadmap-first searches so far (stamps of request nodes)

  Impl(MotionPlannerParams p, detail::RobotBinding r);

  /// Attaches an object to the hold link for the lifetime of the guard (or nothing).
  class AttachGuard {
   public:
    AttachGuard() = default;
    AttachGuard(collision::Scene* s, std::string id) : scene_(s), id_(std::move(id)) {}
    AttachGuard(AttachGuard&& o) noexcept : scene_(o.scene_), id_(std::move(o.id_)) { o.scene_ = nullptr; }
    AttachGuard& operator=(AttachGuard&& o) noexcept {
      if (this != &o) {
        release();
        scene_ = o.scene_;
        id_ = std::move(o.id_);
        o.scene_ = nullptr;
      }
      return *this;
    }
    AttachGuard(const AttachGuard&) = delete;
    AttachGuard& operator=(const AttachGuard&) = delete;
    ~AttachGuard() { release(); }
    void release() {
      if (scene_) (void)scene_->detach(id_);
      scene_ = nullptr;
    }

   private:
    collision::Scene* scene_{nullptr};
    std::string id_;
  };
  /// Attaches `object_id` (validated by the caller) in state `start`: at `grasp` when given, else
  /// with the world's held record when it names the same object, else where the object is now
  /// relative to the hold link. Errors name the field `field`. `link_out`/`link_T_object_out`
  /// receive where it was attached.
  Result<AttachGuard> attach(const std::string& object_id, const robot::RobotState& start,
                             const std::string& field, const HeldGrasp* grasp = nullptr,
                             std::string* link_out = nullptr, Eigen::Isometry3d* link_T_object_out = nullptr);
  /// The cached roadmap for `key` (moved to most recently used; `reused` tells whether it
  /// existed), or a new one, evicting the least recently used beyond
  /// LazyParams::roadmap_cache_entries; with 0 entries the new one lives in `scratch`.
  detail::StaticRoadmap* roadmapFor(detail::StaticWorldKey key, const detail::ob::StateSpacePtr& space,
                                    bool& reused, std::unique_ptr<detail::StaticRoadmap>& scratch);

  /// The clearance grid of the world's static objects (SamplingParams::clearance_grid_resolution),
  /// kept for the last few sets of static objects; null when off.
  std::shared_ptr<const collision::ClearanceGrid> clearanceGrid();
  struct ClearanceEntry {
    std::vector<std::shared_ptr<const world::Object>> statics;
    std::shared_ptr<const collision::ClearanceGrid> grid;
  };
  std::vector<ClearanceEntry> clearance_grids;  ///< least recently used first

  /// The robot's xy radius about its base origin in state `s`, the object `held` (or none)
  /// included where it sits on `link` at `link_T_held`.
  double reachRadius(const robot::RobotState& s, const std::string& held = {}, const std::string& link = {},
                     const Eigen::Isometry3d& link_T_held = Eigen::Isometry3d::Identity()) const;
  /// Circles (x, y in the base frame, radius) that together cover the robot and the object
  /// `held` seen from above in state `s` (the clearance grid's test of a rigid base): the xy box
  /// of its parts in the base frame cut along its longer side into near-square slabs, each in
  /// the circle through its corners.
  std::vector<Eigen::Vector3d> reachCover(const robot::RobotState& s, const std::string& held = {},
                                          const std::string& link = {},
                                          const Eigen::Isometry3d& link_T_held = Eigen::Isometry3d::Identity()) const;
  /// World pose of `link` (a collision geometry link) in state `s`; nothing when unknown.
  std::optional<Eigen::Isometry3d> linkPose(const robot::RobotState& s, const std::string& link) const;
  /// Base xy bounds: the world's bounds plus `extra` points, grown by the workspace margin.
  Aabb baseBounds(const std::vector<Eigen::Vector2d>& extra) const;
  /// Timing limits of a group's joints.
  TimingLimits timingLimits() const;
};

/// Collision-free (all objects but `ignore`) IK from a given base; empty when none.
std::optional<std::vector<double>> solveIk(MotionPlanner::Impl& impl, const Pose2D& base,
                                           const Eigen::Isometry3d& world_T_tool,
                                           const std::vector<double>& seed, const collision::Filter& filter,
                                           double gripper, std::uint32_t seed_rng, int attempts,
                                           const Termination& termination);

/// `base` with the added objects, then the overrides applied; errors name the field
/// (`added_objects[i]...`, `object_overrides[i]...`). `held_object` may be moved but not removed.
Result<world::World> overriddenWorld(const world::World& base, const AddedObjects& added,
                                     const std::vector<ObjectOverride>& overrides, const std::string& held_object);

/// A grasp candidate in the object's frame (see grasps.h).
struct GraspCandidate {
  GraspType type{GraspType::kTop};
  Eigen::Isometry3d object_T_tool{Eigen::Isometry3d::Identity()};
  double width{0.0};  ///< m, between the fingers
};
/// Candidates for a box or cylinder whose width fits `max_opening` (m per finger) with the margin;
/// top grasps first. Other shapes: none.
std::vector<GraspCandidate> graspCandidates(const world::Shape& shape, const GraspParams& params,
                                            double max_opening);

}  // namespace tamp::motion_planner
