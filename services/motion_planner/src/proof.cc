// The `no path` proof of the full mode (ProofParams): a grid over the base bounds whose cells
// over-approximate the free space of the base's inscribed disc.
//
// A cell of edge h and centre c is kept when a disc of radius r_in - h/sqrt(2) (minus 1 mm
// against numerical contact tolerance) at c is free. If the robot is free at some base position
// p inside the cell, its inscribed disc at p is free, and that smaller disc at c lies inside it:
// so every cell containing a free base position is kept. A continuous path of free base positions
// visits a chain of such cells, consecutive ones sharing at least a corner (8-connectivity).
// Hence: if no 8-connected chain of kept cells joins the start's cell to a cell within the goal
// tolerance, no path exists for any orientation or arm configuration.
#include <cmath>
#include <deque>

#include "internal.h"

namespace tamp::motion_planner::detail {

ProofOutcome proveDisconnected(const collision::Scene& scene, const collision::Filter& filter,
                               const RobotBinding& robot, const Aabb& bounds, const Pose2D& start,
                               const Eigen::Vector2d& goal, double goal_tolerance, double cell, int max_cells,
                               const Termination& termination) {
  const double r_in = robot.inscribedRadius();
  const double r_test = r_in - cell * std::sqrt(0.5) - 1e-3;
  if (!(r_in > 0) || r_test <= 1e-3 || !(cell > 0)) return ProofOutcome::kSkipped;
  const double w = bounds.max.x() - bounds.min.x(), hgt = bounds.max.y() - bounds.min.y();
  if (!(w > 0) || !(hgt > 0)) return ProofOutcome::kSkipped;
  const long nx = static_cast<long>(std::ceil(w / cell)), ny = static_cast<long>(std::ceil(hgt / cell));
  if (nx * ny > static_cast<long>(max_cells)) return ProofOutcome::kSkipped;
  const double zmin = robot.inscribedZMin(), zmax = robot.inscribedZMax();
  const world::Shape disc = world::Shape::cylinder(r_test, std::max(1e-3, zmax - zmin));
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation().z() = 0.5 * (zmin + zmax);

  auto cellOf = [&](double x, double y, long& ix, long& iy) {
    ix = static_cast<long>(std::floor((x - bounds.min.x()) / cell));
    iy = static_cast<long>(std::floor((y - bounds.min.y()) / cell));
    return ix >= 0 && iy >= 0 && ix < nx && iy < ny;
  };
  long sx = 0, sy = 0;
  if (!cellOf(start.x, start.y, sx, sy)) return ProofOutcome::kSkipped;
  // Goal cells: those within goal_tolerance of the goal point.
  auto isGoalCell = [&](long ix, long iy) {
    const double x0 = bounds.min.x() + static_cast<double>(ix) * cell, y0 = bounds.min.y() + static_cast<double>(iy) * cell;
    const double dx = std::max({x0 - goal.x(), 0.0, goal.x() - (x0 + cell)});
    const double dy = std::max({y0 - goal.y(), 0.0, goal.y() - (y0 + cell)});
    return std::hypot(dx, dy) <= goal_tolerance;
  };
  // 0 unknown, 1 kept (possibly free), 2 dropped.
  std::vector<unsigned char> state(static_cast<std::size_t>(nx * ny), 0);
  auto keep = [&](long ix, long iy) {
    unsigned char& st = state[static_cast<std::size_t>(iy * nx + ix)];
    if (st == 0) {
      pose.translation().x() = bounds.min.x() + (static_cast<double>(ix) + 0.5) * cell;
      pose.translation().y() = bounds.min.y() + (static_cast<double>(iy) + 0.5) * cell;
      st = scene.shapeInCollision(disc, pose, filter) ? 2 : 1;
    }
    return st == 1;
  };
  std::deque<std::pair<long, long>> queue;
  state[static_cast<std::size_t>(sy * nx + sx)] = 1;  // contains the (free) start
  queue.emplace_back(sx, sy);
  std::size_t visited = 0;
  while (!queue.empty()) {
    if ((++visited & 255) == 0 && termination()) return ProofOutcome::kStopped;
    const auto [cx, cy] = queue.front();
    queue.pop_front();
    if (isGoalCell(cx, cy)) return ProofOutcome::kConnected;
    for (long dy = -1; dy <= 1; ++dy) {
      for (long dx = -1; dx <= 1; ++dx) {
        const long x = cx + dx, y = cy + dy;
        if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= nx || y >= ny) continue;
        if (state[static_cast<std::size_t>(y * nx + x)] != 0) continue;
        if (keep(x, y)) queue.emplace_back(x, y);
      }
    }
  }
  return ProofOutcome::kDisconnected;
}

}  // namespace tamp::motion_planner::detail
