#pragma once
/// @file
/// Parameters of the perception pipeline, loaded from YAML (`config/services/perception.yaml`,
/// every key optional, unknown keys refused). Units: metres, radians, seconds, kilograms; the
/// world frame is z-up. Defaults suit a mast-mounted depth camera 1-2 m above the floor seeing
/// table-top and floor objects of 5 cm to 1 m at up to 6 m.
///
/// Object classes are the scenario's priors: named shapes with their kind and mass. A detection
/// whose size and shape fit a class becomes an object of that class (full size, even when only
/// one side was seen); other detections are classified by size thresholds.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/geometry.h"
#include "tamp/world/shape.h"
#include "tamp/world/world.h"

namespace tamp::perception {

/// A known class of objects (from the scenario): detections that fit it take its full shape.
struct ObjectClass {
  std::string label;  ///< class name: label of new objects and prefix of their ids ("crate")
  world::Shape shape;  ///< full-size shape: box or cylinder (others fitted by bounding box)
  world::ObjectKind kind{world::ObjectKind::kMovable};
  double mass{1.0};        ///< kg, > 0 for movable classes
  bool graspable{false};
  std::optional<std::string> invalidReason() const;
};

/// The depth sensor's noise model (datasheet or calibration): the stddev of a return's range
/// along its ray is `noise_stddev + noise_quadratic * range^2`. Widens the support-plane band
/// with range, so the far floor's noise does not become obstacles.
struct SensorNoise {
  double noise_stddev{0.001};     ///< m, >= 0
  double noise_quadratic{0.0015}; ///< 1/m, >= 0
  double stddev(double range) const { return noise_stddev + noise_quadratic * range * range; }
};

/// Which points are looked at.
struct CropParams {
  /// World-frame box of interest. Empty: the prior world's bounds() grown by `workspace_margin`
  /// (and unbounded when the prior world is empty).
  std::optional<Aabb> workspace;
  double workspace_margin{0.5};  ///< m, >= 0
  double min_range{0.15};        ///< m from the sensor, >= 0
  double max_range{6.0};         ///< m from the sensor, > min_range
  double min_z{-0.10};           ///< m, world z; points below are dropped (below-floor noise)
  double max_z{2.50};            ///< m, world z, > min_z
};

/// Support planes (floor, table tops): RANSAC with a normal constraint, several planes.
struct PlaneParams {
  double voxel_size{0.02};           ///< m, voxel-grid leaf for the whole pipeline, > 0
  int max_planes{4};                 ///< support planes accepted per frame, >= 0
  int max_attempts{8};               ///< RANSAC runs per frame (rejected planes count), >= max_planes
  int ransac_iterations{150};        ///< per run, >= 1
  double distance_threshold{0.015};  ///< m, RANSAC inlier band (and the least removal band), > 0
  /// Points within this many noise stddevs of a support plane (the along-ray noise projected on
  /// the plane normal, see SensorNoise) are removed with it, >= 0.
  double noise_sigmas{3.0};
  /// RANSAC runs on at most this many points (an even subsample); inliers are then classified
  /// over every point. >= 100.
  int ransac_max_points{6000};
  double max_tilt{0.12};             ///< rad, largest angle between a plane normal and world z
  int min_points{150};               ///< inliers of a plane, >= 3
  /// A horizontal plane is a support surface when its inliers cover at least this area (in xy,
  /// at voxel resolution), or when its height matches a prior region (table, floor).
  double min_support_area{0.50};     ///< m^2, > 0
  double region_height_tolerance{0.04};  ///< m, plane vs prior region height
  /// Inliers of a plane matched to a prior region are removed only inside the region's polygon
  /// grown by this margin (a box top at table height elsewhere stays an object).
  double region_margin{0.05};        ///< m, >= 0
};

/// Euclidean clustering and the size filter of detections.
struct ClusterParams {
  double tolerance{0.05};        ///< m, neighbour distance, > 0 (> voxel_size)
  int min_points{25};            ///< smaller clusters are noise (and go to the occupancy map), >= 1
  int max_points{200000};        ///< >= min_points
  double min_height{0.04};       ///< m above its support, smaller = noise
  double min_size{0.05};         ///< m, largest footprint extent, smaller = noise
  double max_size{2.5};          ///< m, larger footprint = not an object (occupancy map only)
  double static_margin{0.03};    ///< m, points this close to prior static objects are theirs
  /// Cylinder when the circle fit's residual is below this fraction of the rectangle fit's and
  /// the circle is not much larger than the points' spread.
  double cylinder_residual_ratio{0.7};
};

/// Association, tracking, new and gone objects.
struct TrackingParams {
  double gate_distance{0.35};      ///< m, largest xy jump to still associate a detection, > 0
  double size_tolerance{0.05};     ///< m, a detection may exceed a shape by this much, >= 0
  double height_tolerance{0.03};   ///< m, and at least 10 % of the height
  int confirm_hits{2};             ///< detections before a new object enters the world, >= 1
  double tentative_timeout_s{5.0}; ///< a tentative object not seen again for this long is dropped
  int gone_frames{2};              ///< frames its place is seen empty before an object is gone, >= 1
  double smoothing{0.5};           ///< weight of a new measurement in (0, 1]
  double snap_distance{0.08};      ///< m, a larger jump replaces the pose (the object was moved)
  /// A known-size object (or one grown from views that no longer grow it) keeps its pose when at
  /// least `explained_fraction` of a detection's points lie within `explained_margin` of it where
  /// it stands (a partial view is no motion).
  double explained_margin{0.02};   ///< m, > 0
  double explained_fraction{0.9};  ///< in (0, 1]
  /// A pose set outright from one frame (a snap, a fall, the gripper's) is not yet held this way:
  /// it follows the next `settle_frames` measurements first (a frame taken while the robot moves
  /// can be centimetres off), >= 0.
  int settle_frames{3};
  double update_distance{0.01};    ///< m, world pose updated when the track moved this much
  double update_angle{0.05};       ///< rad
  double move_event_distance{0.10};  ///< m, a MOVED event when the object moved this much
  /// rad: ... or turned this much, and its footprint's farthest point by `move_event_distance`
  double move_event_angle{0.35};
  // Visibility test of an expected object (is its place seen, empty, or hidden?).
  double visibility_bin{0.01};     ///< angular bin, tangent units (~0.6 deg), > 0
  double visibility_margin{0.05};  ///< m, range margin of the see-through/occluded tests, > 0
  double gone_fraction{0.6};       ///< of testable samples seen through, in (0, 1]
  double present_fraction{0.25};   ///< of testable samples with a return on the object, in (0, 1]
  int gone_min_samples{8};         ///< testable samples needed to decide, >= 1
  /// Reacquire a gone object (same id, MOVED) when a new detection fits its shape.
  bool reacquire{true};
};

/// Kind, mass and graspability of new objects that fit no class (size thresholds).
struct ClassifyParams {
  double movable_max_extent{0.8};   ///< m, largest footprint extent of a movable object
  double movable_max_height{1.2};   ///< m
  double density{150.0};            ///< kg/m^3, mass of unknown movables = density x volume
  double min_mass{0.1};             ///< kg, > 0
  double graspable_max_width{0.12}; ///< m, smallest footprint extent the gripper can hold
  double graspable_max_mass{5.0};   ///< kg
};

/// The OctoMap of occupied space not explained by known objects.
struct OccupancyParams {
  bool enabled{true};
  double resolution{0.05};        ///< m, > 0
  double free_space_voxel{0.20};  ///< m, rays are cast to one endpoint per voxel of this size
  double max_ray_range{5.0};      ///< m, free space is cleared up to this range, > 0
  double explained_margin{0.04};  ///< m, voxels inside known objects grown by this are cleared
  double prob_hit{0.7};           ///< in (0.5, 1)
  double prob_miss{0.4};          ///< in (0, 0.5)
  /// A voxel is occupied above this probability, in [0.5, 1): 0.75 needs two hits (one noisy
  /// return is not an obstacle).
  double occupancy_threshold{0.75};
  /// Unexplained clusters smaller than this are sensor noise, not obstacles, >= 1.
  int min_cluster_points{3};
};

/// The robot's own body and held object (self_filter.h): their returns are dropped before
/// segmentation when the frame comes with the robot's state (`Perception::processFrame`).
struct SelfFilterParams {
  bool enabled{true};
  /// m, >= 0: the link shapes and the held object are grown by this much (state latency, encoder
  /// and calibration error, range noise).
  double padding{0.03};
  /// m, > 0: the robot reports an object in the gripper that no track has (the planner was not
  /// told about it): a new object confirmed with its centre this close to the tool frame is that
  /// object, tracked under the robot's id from then on. Also the plausibility of a new grasp: a
  /// held object tracked farther than this from the tool frame is relearned at the gripper.
  double held_adopt_radius{0.15};
};

struct PerceptionParams {
  SensorNoise sensor;
  CropParams crop;
  PlaneParams planes;
  ClusterParams clusters;
  TrackingParams tracking;
  ClassifyParams classify;
  OccupancyParams occupancy;
  SelfFilterParams self_filter;
  std::vector<ObjectClass> classes;  ///< scenario priors, any order
  std::size_t max_points{5'000'000};  ///< larger frames are rejected (field xyz)

  /// Ok, or one kInvalidArgument error naming every bad field ("planes.voxel_size: ...").
  Status validate() const;
};

/// Loads parameters from YAML; every error names file, line, column and field; unknown keys are
/// refused; a missing file is kNotFound. The YAML layout mirrors the structs:
/// `crop: {max_range: 5}`, `planes: {voxel_size: 0.02}`, ..., and
/// `classes: [{label: crate, shape: box, size: [0.4, 0.3, 0.3], kind: movable, mass: 3}]`
/// (`shape: cylinder` takes `radius` and `height`). A top-level `node:` section is left to the
/// DDS node (services/perception/node).
Result<PerceptionParams> loadPerceptionParams(const std::filesystem::path& file);
/// Same from text; `name` is the file name used in messages.
Result<PerceptionParams> parsePerceptionParams(const std::string& yaml_text, const std::string& name);

/// Classes implied by a prior world: one per distinct (label, shape) of its movable objects,
/// with their kind, mass and graspability. Perception adds them to the configured classes.
std::vector<ObjectClass> classesFromWorld(const world::World& prior);

}  // namespace tamp::perception
