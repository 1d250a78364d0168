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
//
// The search grows from both ends in turn, the end that has expanded fewer cells first: when
// the start or the goal is in a pocket, the pocket is exhausted after about its own cells,
// however large the rest of the map. Each end expands the cell nearest the other end first
// (greedy best-first): where they are connected through open space they meet after about the
// cells along the way, not the area between them. The order does not matter to the proof,
// which holds once either end has run out of cells. Where the static clearance grid shows no static footprint within the test radius, only
// the other groups (movables, unknown space) are asked of FCL.
#include <cmath>

#include "internal.h"

namespace tamp::motion_planner::detail {

namespace {
constexpr unsigned char kTested = 1, kFree = 2, kFromStart = 4, kFromGoal = 8;
}  // namespace

DisconnectionProof::DisconnectionProof(const collision::Scene& scene, const collision::Filter& filter,
                                       const collision::ClearanceGrid* statics, const RobotBinding& robot,
                                       const Aabb& bounds, const Pose2D& start, const Eigen::Vector2d& goal,
                                       double goal_tolerance, double cell, int max_cells)
    : scene_(scene), filter_(filter), statics_(statics), min_(bounds.min.head<2>()), cell_(cell) {
  r_test_ = robot.inscribedRadius() - cell * std::sqrt(0.5) - 1e-3;
  const double w = bounds.max.x() - bounds.min.x(), hgt = bounds.max.y() - bounds.min.y();
  if (!(robot.inscribedRadius() > 0) || r_test_ <= 1e-3 || !(cell > 0) || !(w > 0) || !(hgt > 0)) return;
  nx_ = static_cast<long>(std::ceil(w / cell));
  ny_ = static_cast<long>(std::ceil(hgt / cell));
  if (nx_ * ny_ > static_cast<long>(max_cells)) return;
  long sx = 0, sy = 0;
  if (!cellOf(start.x, start.y, sx, sy)) return;
  const double zmin = robot.inscribedZMin(), zmax = robot.inscribedZMax();
  disc_ = world::Shape::cylinder(r_test_, std::max(1e-3, zmax - zmin));
  pose_.translation().z() = 0.5 * (zmin + zmax);
  others_ = filter_;
  others_.groups = static_cast<std::uint8_t>(filter_.groups & ~collision::kStaticObjects);
  state_.assign(static_cast<std::size_t>(nx_ * ny_), 0);
  // The start cell contains the (free) start.
  state_[index(sx, sy)] = kTested | kFree | kFromStart;
  start_ = {start.x, start.y};
  goal_ = goal;
  push(from_start_, goal_, sx, sy);
  // The goal side: the kept cells within goal_tolerance of the goal point.
  long gx0 = 0, gy0 = 0, gx1 = 0, gy1 = 0;
  cellOf(goal.x() - goal_tolerance, goal.y() - goal_tolerance, gx0, gy0);
  cellOf(goal.x() + goal_tolerance, goal.y() + goal_tolerance, gx1, gy1);
  for (long iy = std::max(0L, gy0); iy <= std::min(ny_ - 1, gy1); ++iy) {
    for (long ix = std::max(0L, gx0); ix <= std::min(nx_ - 1, gx1); ++ix) {
      const double x0 = min_.x() + static_cast<double>(ix) * cell, y0 = min_.y() + static_cast<double>(iy) * cell;
      const double dx = std::max({x0 - goal.x(), 0.0, goal.x() - (x0 + cell)});
      const double dy = std::max({y0 - goal.y(), 0.0, goal.y() - (y0 + cell)});
      if (std::hypot(dx, dy) > goal_tolerance) continue;
      if (state_[index(ix, iy)] & kFromStart) {
        decided_ = ProofOutcome::kConnected;
        return;
      }
      if (!kept(ix, iy)) continue;
      state_[index(ix, iy)] |= kFromGoal;
      push(from_goal_, start_, ix, iy);
    }
  }
  decided_ = from_goal_.empty() ? ProofOutcome::kDisconnected : ProofOutcome::kStopped;
}

bool DisconnectionProof::cellOf(double x, double y, long& ix, long& iy) const {
  ix = static_cast<long>(std::floor((x - min_.x()) / cell_));
  iy = static_cast<long>(std::floor((y - min_.y()) / cell_));
  return ix >= 0 && iy >= 0 && ix < nx_ && iy < ny_;
}

void DisconnectionProof::push(Frontier& frontier, const Eigen::Vector2d& towards, long ix, long iy) {
  const double x = min_.x() + (static_cast<double>(ix) + 0.5) * cell_;
  const double y = min_.y() + (static_cast<double>(iy) + 0.5) * cell_;
  frontier.push({std::hypot(x - towards.x(), y - towards.y()), ix, iy});
}

bool DisconnectionProof::kept(long ix, long iy) {
  unsigned char& st = state_[index(ix, iy)];
  if (!(st & kTested)) {
    const double x = min_.x() + (static_cast<double>(ix) + 0.5) * cell_;
    const double y = min_.y() + (static_cast<double>(iy) + 0.5) * cell_;
    pose_.translation().x() = x;
    pose_.translation().y() = y;
    bool free = false;
    if (statics_ && statics_->clearance(x, y) > r_test_) {
      ++grid_answers_;
      free = others_.groups == 0 || !scene_.shapeInCollision(disc_, pose_, others_);
    } else {
      free = !scene_.shapeInCollision(disc_, pose_, filter_);
    }
    ++tested_;
    st = static_cast<unsigned char>(kTested | (free ? kFree : 0));
  }
  return st & kFree;
}

ProofOutcome DisconnectionProof::advance(const Termination& termination) {
  if (decided_ != ProofOutcome::kStopped) return decided_;
  std::size_t popped = 0;
  while (!from_start_.empty() && !from_goal_.empty()) {
    if ((++popped & 127) == 0 && termination()) return ProofOutcome::kStopped;
    const bool start_side = expanded_start_ <= expanded_goal_;
    Frontier& frontier = start_side ? from_start_ : from_goal_;
    const Eigen::Vector2d& towards = start_side ? goal_ : start_;
    const unsigned char mine = start_side ? kFromStart : kFromGoal;
    const unsigned char theirs = start_side ? kFromGoal : kFromStart;
    ++(start_side ? expanded_start_ : expanded_goal_);
    const Entry e = frontier.top();
    frontier.pop();
    for (long dy = -1; dy <= 1; ++dy) {
      for (long dx = -1; dx <= 1; ++dx) {
        const long x = e.ix + dx, y = e.iy + dy;
        if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= nx_ || y >= ny_) continue;
        unsigned char& st = state_[index(x, y)];
        if (st & mine) continue;
        if (!kept(x, y)) continue;
        if (st & theirs) return decided_ = ProofOutcome::kConnected;
        st |= mine;
        push(frontier, towards, x, y);
      }
    }
  }
  return decided_ = ProofOutcome::kDisconnected;
}

}  // namespace tamp::motion_planner::detail
