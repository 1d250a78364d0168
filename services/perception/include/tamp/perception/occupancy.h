#pragma once
/// @file
/// The OctoMap of occupied space that no known object explains (unknown obstacles: a chair leg,
/// a cluster too small or too large to be an object, anything not yet confirmed as an object).
/// Free space is cleared by ray insertion from the sensor origin to the frame's returns (one
/// endpoint per `free_space_voxel`, up to `max_ray_range`), so an obstacle that went away is
/// erased when the space it occupied is seen through; because rays are sparse, occupied voxels
/// are also tested against the frame's range image (`clearSeenThrough`), so a thin obstacle
/// that went away is cleared even when no ray happened to cross it. Space inside known objects is cleared
/// whenever they are added or move. OctoMap stays inside the .cc (pimpl).

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/perception/params.h"
#include "tamp/perception/visibility.h"
#include "tamp/world/world.h"

namespace tamp::perception {

enum class CellState { kUnknown, kFree, kOccupied };

class OccupancyMap {
 public:
  /// Throws std::invalid_argument for an invalid resolution or probabilities.
  explicit OccupancyMap(const OccupancyParams& params);
  ~OccupancyMap();
  OccupancyMap(const OccupancyMap&) = delete;
  OccupancyMap& operator=(const OccupancyMap&) = delete;

  /// One frame: rays from `origin` to every endpoint of `scan` clear free space (the endpoints
  /// themselves are not cleared); every point of `occupied` (unexplained returns) is a hit.
  /// World frame, metres.
  void integrate(const Eigen::Vector3d& origin, const std::vector<Eigen::Vector3f>& scan,
                 const std::vector<Eigen::Vector3f>& occupied);
  /// Complements the (sparse) rays: every occupied voxel seen through as a whole in `image`
  /// (`RangeImage::seenThrough`: every ray across it went on beyond it + `margin`) gets a miss.
  /// Cost: O(voxels that received hits). Returns how many voxels were updated.
  std::size_t clearSeenThrough(const RangeImage& image, double margin);
  /// Marks occupied voxels inside `object` grown by `explained_margin` free (known object, not
  /// unknown space). Returns how many.
  std::size_t clearObject(const world::Object& object);
  /// Refreshes the inner nodes of the octree after the calls above (lazy OctoMap updates). The
  /// leaves, and so every query of this class, are up to date without it; call it once per frame
  /// (a walk of the whole tree), not after each update.
  void updateInnerNodes();
  void clear();

  CellState state(const Eigen::Vector3d& p) const;
  /// Centres of the occupied leaves (at the map resolution), world frame.
  std::vector<Eigen::Vector3d> occupiedVoxels() const;
  /// Number of occupied leaves (walks the whole tree: for tests and statistics).
  std::size_t occupiedCount() const;
  /// Voxels that received hits and were not cleared since (cheap; >= occupiedCount()).
  std::size_t hitVoxels() const;
  double resolution() const;
  /// The map as an OctoMap binary stream (`# Octomap OcTree binary file` header +
  /// `writeBinaryData`), readable by `octomap::OcTree::readBinary` and hence by
  /// `collision::Scene::setUnknownSpaceFromOctomapBinary`.
  std::string toBinary() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tamp::perception
