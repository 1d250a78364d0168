#pragma once
/// @file
/// The point-level stages of the pipeline (PCL inside the .cc only): transform to the world
/// frame and crop, voxel grid, support planes (RANSAC with a normal constraint, several planes),
/// removal of points that belong to the prior's static objects, Euclidean clustering.

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/core/error.h"
#include "tamp/core/point_cloud.h"
#include "tamp/core/termination.h"
#include "tamp/perception/params.h"
#include "tamp/world/world.h"

namespace tamp::perception {

/// A horizontal support surface found in the frame (floor, table top).
struct SupportPlane {
  Eigen::Vector4d coefficients{0, 0, 1, 0};  ///< a x + b y + c z + d = 0, unit normal, c > 0
  double height{0.0};            ///< support height, m: the matched prior region's, else measured
  double measured_height{0.0};   ///< z of the fitted plane at its inliers' centroid, m
  int inliers{0};
  double area{0.0};                          ///< xy area covered by the inliers, m^2
  world::Polygon2 hull;                      ///< convex hull of the inliers in xy
  std::string region;                        ///< prior region whose height it matches, or empty
};

/// Wall-clock time per stage, milliseconds.
struct SegmentationTimes {
  double transform_crop{0}, voxel{0}, planes{0}, static_objects{0}, clustering{0};
};

struct Segmentation {
  std::vector<SupportPlane> planes;
  /// Clusters large enough to be objects (>= clusters.min_points), world frame.
  std::vector<std::vector<Eigen::Vector3f>> clusters;
  /// Smaller clusters (>= occupancy.min_cluster_points points, and clusters above
  /// clusters.max_points): not objects, candidates for the occupancy map.
  std::vector<std::vector<Eigen::Vector3f>> small_clusters;
  /// The cropped, voxel-filtered returns (free-space rays are cast to them), world frame.
  std::vector<Eigen::Vector3f> scan;
  std::size_t valid_points{0}, cropped_points{0}, plane_points{0}, static_points{0};
  SegmentationTimes times;
};

class Segmenter {
 public:
  /// `prior` supplies the static objects whose points are removed and the regions (floor,
  /// tables) planes are matched to. Parameters must be valid (throws std::invalid_argument).
  Segmenter(const PerceptionParams& params, const world::World& prior);
  ~Segmenter();
  Segmenter(Segmenter&&) noexcept;
  Segmenter& operator=(Segmenter&&) noexcept;

  /// Runs the point-level stages on a validated frame. kCancelled/kTimeout when `term` fires
  /// between stages.
  Result<Segmentation> run(const PointCloudFrame& frame, const Termination& term) const;

  /// The crop box in use (world frame).
  const Aabb& workspace() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

namespace detail {
// The segmenter's replacements of PCL stages and the PCL stages they stand for (tests check that
// they agree; PCL stays in the .cc).

/// Centroid of every occupied leaf of a `leaf`-sized voxel grid, in pcl::VoxelGrid's order.
std::vector<Eigen::Vector3f> voxelGrid(const std::vector<Eigen::Vector3f>& points, float leaf);
/// The same with pcl::VoxelGrid<pcl::PointXYZ>.
std::vector<Eigen::Vector3f> voxelGridPcl(const std::vector<Eigen::Vector3f>& points, float leaf);
/// Euclidean clusters (indices ascending; largest cluster first) of at least `min_size` points.
std::vector<std::vector<int>> euclideanClusters(const std::vector<Eigen::Vector3f>& points, double tolerance,
                                                int min_size);
/// The same with pcl::EuclideanClusterExtraction (kd-tree radius search).
std::vector<std::vector<int>> euclideanClustersPcl(const std::vector<Eigen::Vector3f>& points, double tolerance,
                                                   int min_size);

}  // namespace detail

}  // namespace tamp::perception
