#pragma once
/// @file
/// A distance grid of the floor plane: per cell, a lower bound of the distance from any point of
/// the cell to the nearest obstacle footprint (the obstacle's projection on the floor).
///
/// What it is for: a robot that moves rigidly with its base (the arm still, the held object
/// fixed in the hand) whose every point lies within `r` of the base origin (xy) cannot touch an
/// obstacle where the grid's clearance exceeds `r`, whatever its yaw and height. Motion planning
/// answers "free" there without an FCL query; elsewhere it asks FCL as before. Obstacles are
/// projected whole (a table the robot could pass under counts as a column), so the answer errs
/// only towards asking FCL.
///
/// Footprints are polygons (a NAMO map's walls are one weakly simple outline round the whole map:
/// its bounding box would cover everything). A cell is occupied when its centre lies inside a
/// footprint (even-odd) or an edge passes through it or next to it. The exact Euclidean distance
/// transform (Felzenszwalb and Huttenlocher 2012) then gives the distance between cell centres;
/// a point lies within h/sqrt(2) of its cell's centre and every obstacle point within h/sqrt(2) of
/// an occupied cell's, so the bound is the centres' distance less h*sqrt(2). Footprints beyond
/// the grid are clamped onto its border cells (nearer than they are: still a lower bound).
/// Outside the grid the clearance is 0.

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "tamp/core/geometry.h"
#include "tamp/world/polygon.h"
#include "tamp/world/world.h"

namespace tamp::collision {

class ClearanceGrid {
 public:
  /// The grid over `bounds` (xy of it) with cells of `resolution` m (> 0), of the footprints
  /// (world xy; fewer than 3 vertices: their edges only). More cells than `max_cells` make the
  /// cells coarser. Throws std::invalid_argument on a resolution that is not positive and finite,
  /// on empty or infinite bounds, or on a footprint vertex that is not finite.
  ClearanceGrid(const std::vector<world::Polygon2>& footprints, const Aabb& bounds, double resolution,
                std::size_t max_cells = 4'000'000);

  /// A lower bound (m) of the distance from (x, y) to every obstacle's footprint: 0 inside or
  /// next to one and outside the grid; +infinity when there is no obstacle.
  double clearance(double x, double y) const;

  double resolution() const { return h_; }
  int cellsX() const { return nx_; }
  int cellsY() const { return ny_; }

 private:
  Eigen::Vector2d origin_{Eigen::Vector2d::Zero()};
  double h_{0.0};
  int nx_{0};
  int ny_{0};
  std::vector<float> lower_;  ///< per cell, row-major (y, x)
};

/// A polygon in the world's xy plane that covers the object's projection on the floor: the
/// footprint of an upright shape (a cylinder's or sphere's circle by a circumscribed 24-gon),
/// the xy rectangle of its bounding box when the object is tilted.
world::Polygon2 floorFootprint(const world::Object& object);

}  // namespace tamp::collision
