#pragma once
/// @file
/// The OctoMap of occupied space that no known object explains (unknown obstacles: a chair leg,
/// a cluster too small or too large to be an object, anything not yet confirmed as an object).
/// Free space is cleared by ray insertion from the sensor origin to the frame's returns (one
/// endpoint per `free_space_voxel`, up to `max_ray_range`), so an obstacle that went away is
/// erased when the space it occupied is seen through. Space inside known objects is cleared
/// whenever they are added or move. OctoMap stays inside the .cc (pimpl).

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tamp/perception/params.h"
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
  /// Deletes occupied voxels inside `object` grown by `explained_margin`. Returns how many.
  std::size_t clearObject(const world::Object& object);
  void clear();

  CellState state(const Eigen::Vector3d& p) const;
  /// Centres of the occupied leaves (at the map resolution), world frame.
  std::vector<Eigen::Vector3d> occupiedVoxels() const;
  std::size_t occupiedCount() const;
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
