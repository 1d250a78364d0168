#pragma once
/// @file
/// The simulated depth camera: a pinhole sensor mounted on a robot link that ray-casts the
/// ground-truth world (every object, hidden ones included, the floor plane and optionally the
/// robot's own collision geometry) and produces an organised `tamp::PointCloudFrame`.
///
/// Camera model: `width` x `height` pixels, square pixels, horizontal field of view `hfov`:
/// fx = fy = (width / 2) / tan(hfov / 2), principal point at the image centre
/// (cx = (width - 1) / 2, cy = (height - 1) / 2). Pixel (u, v) (column, row, row-major layout,
/// point index v * width + u) looks along ((u - cx) / fx, (v - cy) / fy, 1) in the optical frame
/// (z forward, x right, y down; the URDF's `camera_optical_frame`).
///
/// Returns: a point is the first surface along its pixel's ray, in the sensor frame, metres.
/// Its depth z (not the Euclidean range) must lie in [min_range_m, max_range_m], like a real
/// depth camera; otherwise, and for dropped pixels, the point is a NaN triplet.
///
/// Noise (deterministic for a given `seed` and frame number): the depth is perturbed along the
/// pixel's ray by a Gaussian of stddev `noise_stddev_m + noise_quadratic * z^2` (the axial noise
/// of structured-light and stereo sensors grows with the square of the depth), and each pixel
/// drops out with probability `dropout_probability`. Noise is drawn from a counter-based hash of
/// (seed, frame number, pixel), so a frame's noise does not depend on the order of computation.
///
/// Cost: shapes outside the view frustum are culled, then a bounding-volume hierarchy over the
/// rest plus analytic intersections (see ray_scene.h), rebuilt per frame (objects move). Single
/// threaded; ~35 ms for 640 x 480 on this project's 2-vCPU VM (bench/sim_bench.cc,
/// docs/benchmarks.md "Simulated depth sensor").

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/error.h"
#include "tamp/core/point_cloud.h"
#include "tamp/robot/robot_model.h"
#include "tamp/world/world.h"

namespace tamp::sim {

/// Parameters of the simulated depth camera (YAML: the `sensor` block of config/services/sim.yaml).
struct DepthSensorParams {
  std::string sensor_id{"camera"};                ///< PointCloudFrame::sensor_id
  std::string frame{"camera_optical_frame"};      ///< URDF link of the optical frame
  int width{320};                                 ///< pixels, in [1, 4096]
  int height{240};                                ///< pixels, in [1, 4096]
  double horizontal_fov_rad{1.0472};              ///< in (0, pi); 60 deg
  double min_range_m{0.2};                        ///< >= 0; nearer returns are dropped
  double max_range_m{6.0};                        ///< > min_range_m; farther returns are dropped
  double noise_stddev_m{0.001};                   ///< >= 0; depth noise at zero distance
  double noise_quadratic{0.0015};                 ///< >= 0 (1/m); extra stddev per depth^2
  double dropout_probability{0.005};              ///< in [0, 1)
  bool see_robot{false};                          ///< ray-cast the robot's own links too
  std::uint64_t seed{1};                          ///< noise seed

  /// Ok, or one kInvalidArgument error naming every bad field ("sensor.width: ...").
  Status validate() const;
  /// Vertical field of view implied by the aspect ratio (square pixels), rad.
  double verticalFovRad() const;
  /// Focal length in pixels.
  double focalPx() const;
};

/// Per-pixel ground truth of a frame: what each pixel's ray hit before noise and dropouts.
struct GroundTruthLabels {
  /// Per pixel: an index into `ids`, or one of the tags below.
  std::vector<std::int32_t> pixel;
  std::vector<std::string> ids;  ///< object ids (and robot link names when the robot is seen)
  static constexpr std::int32_t kNone = -1;   ///< no surface within max_range_m
  static constexpr std::int32_t kFloor = -2;  ///< the floor plane
};

class DepthSensor {
 public:
  /// @throws std::invalid_argument when `params.validate()` fails (names the field).
  explicit DepthSensor(DepthSensorParams params);

  const DepthSensorParams& params() const { return params_; }
  /// Frames captured so far (the noise stream index of the next frame).
  std::uint64_t frameCount() const { return frames_; }

  /// Captures a frame of `world` from the sensor at `world_T_sensor` (optical frame). Objects of
  /// `world` are all seen, hidden ones included. The robot is not seen (use the overload below).
  /// `labels`, when given, receives the per-pixel ground truth.
  PointCloudFrame capture(const world::World& world, const Eigen::Isometry3d& world_T_sensor,
                          std::int64_t stamp_ns, GroundTruthLabels* labels = nullptr);

  /// Captures from the sensor mounted on `robot` in state `state`: the sensor pose is the world
  /// pose of link `params().frame`; with `see_robot` the robot's collision shapes are cast too
  /// (a solid containing the sensor, e.g. its housing, is not seen: rays start inside it).
  /// @throws std::invalid_argument when the robot has no link `params().frame` or `state` does
  ///   not fit the robot.
  PointCloudFrame capture(const world::World& world, const robot::RobotModel& robot,
                          const robot::RobotState& state, std::int64_t stamp_ns,
                          GroundTruthLabels* labels = nullptr);

  /// Unit-depth ray direction (z = 1) of pixel (u, v) in the optical frame.
  Eigen::Vector3d pixelRay(int u, int v) const;

 private:
  struct RobotView {
    const robot::RobotModel* robot;
    const robot::RobotState* state;
  };
  PointCloudFrame render(const world::World& world, const Eigen::Isometry3d& world_T_sensor,
                         std::int64_t stamp_ns, const RobotView* robot,
                         GroundTruthLabels* labels);

  DepthSensorParams params_;
  double fx_{1.0}, cx_{0.0}, cy_{0.0};
  std::uint64_t frames_{0};
};

}  // namespace tamp::sim
