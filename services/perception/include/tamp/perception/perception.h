#pragma once
/// @file
/// Perception: from depth frames to the planner's world model (issue 6; the world model of the
/// paper's loop, Castaman, Tosello, Pagello, "Conditional Task and Motion Planning through an
/// Effort-Based Approach", §"unpredictable faults": a new obstacle "perceived by sensors"
/// triggers online replanning).
///
/// ## Design overview
/// Perception is product code: it sees only what a real robot would -- depth frames (points in
/// the optical sensor frame + the sensor's pose in the world) and the scenario's priors (the
/// static map, the objects declared known, object classes with their sizes). It starts from the
/// prior world and adds, moves and removes objects. Per frame (`Perception::processFrame`):
///
/// 1. **Validate** the frame (`validateFrame`): malformed frames are rejected naming the field.
/// 1a. **The robot's own body** (`self_filter.h`), when the frame comes with the robot's state
///    (`RobotBody`): returns on its links' collision shapes (forward kinematics of the state)
///    and on the held object (attached to the tool link), grown by `self_filter.padding`, are
///    dropped before anything else sees them -- segmentation, tracking, the visibility test and
///    the occupancy map. The held object's track follows the gripper (its pose in the tool
///    frame is fixed when the grasp is first reported) and is neither associated nor tested for
///    being gone while held, so it is never reported as a new obstacle nor as gone from where it
///    was picked; when the state reports the gripper empty again it is tracked as before. An
///    object the state reports held that no track has (the planner was not told about it) is
///    seen as a new object at the gripper: confirmed within `self_filter.held_adopt_radius` of
///    the tool frame, it gets the robot's id for it and is filtered as held from then on. So is
///    an object reported held whose track is farther than that from the tool frame (perception
///    restarted from the prior while the robot carries it): its track is moved to the object seen
///    at the gripper, a grasp is fixed only from a plausible pose.
/// 2. **Transform and crop** to the world frame, the workspace box and the sensor's range.
/// 3. **Voxel grid** (PCL `VoxelGrid`): the leaf size bounds the cost of everything after.
/// 4. **Support planes** (PCL RANSAC, `SACMODEL_PERPENDICULAR_PLANE` about world z, several
///    planes): the floor and table tops. A plane is a support when it matches a prior region's
///    height or is large and fills >= 25 % of its hull (not a slice through walls); a table
///    region's polygon bounds what its plane removes.
/// 5. **Static map**: points inside the prior's static objects (walls, tables), grown by a margin
///    that follows the range noise, are theirs.
/// 6. **Euclidean clustering** (PCL): clusters big enough are object candidates; small ones are
///    unexplained occupied space; single stray returns are noise.
/// 7. **Shape fitting** (`shape_fit.h`): footprint by minimum-area rectangle and circle fit,
///    box-or-cylinder decision, height from the support surface below the cluster.
/// 8. **Association** (Hungarian method on gated costs): a detection matches a tracked object
///    when its size fits the object's shape and the shape fitted to it lies within the gate.
///    Matched objects are tracked (smoothed pose, confidence, last seen); a jump larger than
///    `snap_distance` replaces the pose (the object was moved).
/// 9. **New objects**: an unmatched detection becomes tentative and enters the world after
///    `confirm_hits` detections, as an object of the best-fitting class (full size and kind
///    from the prior) or, without one, as a movable/static object by size thresholds.
/// 10. **Gone objects**: an expected object that was not detected is tested against a range
///    image of the frame (`visibility.h`): only when enough of its volume is *seen through*
///    for `gone_frames` frames is it gone -- an object outside the view or hidden behind
///    another is never gone. Gone objects leave the world; one that shows up again (a new
///    detection fitting its shape) is reacquired under its id.
/// 11. **Occupancy** (`occupancy.h`, OctoMap): unexplained points are hits, rays from the
///    sensor clear free space; voxels inside known objects are cleared.
///
/// The output per frame is the updated `world::World` (a cheap copy) and the events
/// (added/moved/removed/gone). The library knows nothing of DDS: `PerceptionNode`
/// (services/perception/node) maps messages to frames and publishes the results.
///
/// Limits: objects stand upright on a support (no tilted or stacked-on-object poses); objects
/// in contact form one cluster; the robot's body is filtered only for frames given a
/// `RobotBody`, and a held object only when it is a tracked object (its shape is known).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/error.h"
#include "tamp/core/point_cloud.h"
#include "tamp/core/termination.h"
#include "tamp/perception/occupancy.h"
#include "tamp/perception/params.h"
#include "tamp/perception/segmentation.h"
#include "tamp/perception/self_filter.h"
#include "tamp/perception/shape_fit.h"
#include "tamp/world/world.h"

namespace tamp::perception {

enum class EventType {
  kAdded,    ///< a new object entered the world model (or a known one was reacquired)
  kMoved,    ///< a known object moved by more than move_event_distance/angle
  kRemoved,  ///< an object was removed from the world model on request (`removeObject`)
  kGone,     ///< an object is not where it was expected although that place is in view
};
std::string_view toString(EventType type);  ///< "added", "moved", "removed", "gone"

/// One change of the world model, with the object's pose (for kGone: where it was expected).
struct WorldEvent {
  EventType type{EventType::kAdded};
  std::string object_id;
  world::ObjectKind kind{world::ObjectKind::kMovable};
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};
  std::string description;  ///< human-readable reason ("new box 0.30 x 0.20 x 0.25 m at ...")
  int64_t stamp_ns{0};      ///< the frame's stamp
};

/// What perception believes about one object.
struct TrackInfo {
  enum class State {
    kTentative,  ///< detected, not yet confirmed (not in the world model)
    kActive,     ///< in the world model
    kGone,       ///< seen absent; out of the world model, may be reacquired
  };
  std::string id;  ///< world id (tentatives: "tentative_<n>")
  std::string label;
  State state{State::kTentative};
  bool from_prior{false};  ///< declared by the scenario
  world::ObjectKind kind{world::ObjectKind::kMovable};
  world::Shape shape;
  Eigen::Isometry3d pose{Eigen::Isometry3d::Identity()};  ///< smoothed estimate
  double confidence{0.0};  ///< in [0, 1]: rises with detections, falls when seen absent
  int64_t last_seen_ns{0};  ///< stamp of the last frame it was detected in (0: never)
  int hits{0};              ///< detections so far
  int misses{0};            ///< consecutive frames its place was seen empty
};

/// Wall-clock milliseconds per stage of one frame.
struct StageTimes {
  double validate{0}, self_filter{0}, transform_crop{0}, voxel{0}, planes{0}, static_objects{0}, clustering{0};
  double fitting{0}, visibility{0}, tracking{0}, occupancy{0}, total{0};
};

/// Counts of one frame.
struct FrameStats {
  std::size_t input_points{0}, valid_points{0}, cropped_points{0}, voxel_points{0}, plane_points{0};
  std::size_t static_points{0}, unexplained_points{0};
  std::size_t robot_points{0};  ///< returns on the robot's body or held object (dropped)
  int planes{0}, clusters{0}, detections{0}, matched{0}, tentative{0};
};

struct FrameResult {
  std::vector<WorldEvent> events;
  std::vector<Detection> detections;  ///< this frame's fitted clusters (world frame)
  std::vector<SupportPlane> planes;
  bool world_changed{false};          ///< the world model differs from the previous frame's
  StageTimes times;
  FrameStats stats;
};

class Perception {
 public:
  /// `prior`: the static map and the objects the scenario declares known (its planner view:
  /// hidden objects are refused). Object classes: `params.classes` plus `classesFromWorld(prior)`.
  /// Throws std::invalid_argument for invalid parameters or a prior with hidden objects.
  Perception(world::World prior, PerceptionParams params);
  ~Perception();
  Perception(const Perception&) = delete;
  Perception& operator=(const Perception&) = delete;

  /// Processes one frame. `robot`: the robot's body at the frame's instant (from its state:
  /// `robotBodyAt`); with `params().self_filter.enabled` its returns and the held object's are
  /// dropped and the held object follows the gripper (see the overview). nullptr: no state is
  /// known for this frame, nothing is filtered and a held object stays as it was.
  /// Errors: kInvalidArgument for a malformed frame (naming the field) or a frame older than the
  /// previous one (`stamp_ns`); kTimeout/kCancelled when `term` fires (the world model is then
  /// unchanged). Not thread-safe: one caller at a time.
  Result<FrameResult> processFrame(const PointCloudFrame& frame, const Termination& term = Termination(),
                                   const RobotBody* robot = nullptr);
  /// The object perception believes is in the gripper (from the last frame given a RobotBody
  /// with the self filter on), or empty.
  const std::string& heldObject() const;

  /// The grasp perception holds: the object in the gripper and where it sits in the tool frame.
  struct HeldGrasp {
    std::string object_id;
    Eigen::Isometry3d tool_T_object{Eigen::Isometry3d::Identity()};
  };
  /// The grasp held now, or nullopt with the gripper empty (to checkpoint it).
  std::optional<HeldGrasp> heldGrasp() const;
  /// Takes up a grasp held before a restart (from a checkpoint), as if this perception had seen
  /// it: from the next frame whose robot state reports the object held, it follows the gripper
  /// at `tool_T_object`, with no new grasp decided from its tracked pose (which lags behind a
  /// grasp that lifted it). A state that reports the gripper empty releases it as usual.
  /// kNotFound when the object is not tracked; kInvalidArgument for a non-finite transform.
  Status resumeGrasp(const HeldGrasp& grasp);

  /// The current world model (prior + perceived, minus gone objects).
  const world::World& world() const;
  /// Every track (tentative, active, gone), sorted by id.
  std::vector<TrackInfo> tracks() const;
  std::optional<TrackInfo> track(std::string_view id) const;
  /// Removes an object from the world model (e.g. an operator's decision) with a kRemoved
  /// event. kNotFound when absent; kInvalidArgument for a prior static object.
  Result<WorldEvent> removeObject(std::string_view id, const std::string& reason);

  /// The occupancy map of unexplained space (nullptr when disabled).
  const OccupancyMap* occupancy() const;
  /// `occupancy()->toBinary()`, or empty when disabled.
  std::string occupancyBinary() const;

  const PerceptionParams& params() const;
  /// Object classes in use (configured + from the prior).
  const std::vector<ObjectClass>& classes() const;
  /// Frames processed successfully.
  std::uint64_t frames() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Position and yaw error of an estimated pose against the truth for `shape` (yaw modulo the
/// shape's symmetry). For benchmarks and tests.
struct PoseError {
  double xy{0.0};   ///< m
  double z{0.0};    ///< m, absolute
  double yaw{0.0};  ///< rad, absolute, modulo symmetry
};
PoseError poseError(const world::Shape& shape, const Eigen::Isometry3d& truth, const Eigen::Isometry3d& estimate);

}  // namespace tamp::perception
