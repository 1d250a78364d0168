// The `no path` proof of the full mode (ProofParams): a grid whose cells over-approximate the
// free configurations of the base.
//
// xy cells (the inscribed disc). A cell of edge h and centre c is kept when a disc of radius
// r_in - h/sqrt(2) (minus 1 mm against numerical contact tolerance) at c is free. If the robot is
// free at some base position p inside the cell, its inscribed disc at p is free, and that smaller
// disc at c lies inside it: so every cell containing a free base position is kept. A continuous
// path of free base positions visits a chain of such cells, consecutive ones sharing at least a
// corner (8-connectivity). Hence: if no chain of kept cells joins the start's cell to a cell
// within the goal tolerance, no path exists for any orientation or arm configuration.
//
// (x, y, yaw) cells (the base box). The disc cannot see that a rectangular base has no room to
// turn. A cell of edge h and yaw width d keeps the base box shrunk on every side by
// e = h/sqrt(2) + R d/2 + 1 mm, placed at the cell's centre (R: the farthest xy point of the box
// from the base origin). For any configuration (p, yaw) in the cell, a point u of the shrunk box
// lands, in the frame of the box at (p, yaw), within |c - p| + 2 sin(|yaw - yaw_c|/2) R <= e of
// where it would at the centre: so the shrunk box lies inside the box at every configuration of
// the cell, and a cell whose shrunk box touches something holds no free configuration. Chains are
// 26-connected, yaw wrapping round; the goal is its xy cells at every yaw.
//
// A shape carried at a fixed place on the base (the held or pushed object, the arm still) is a
// second probe of the (x, y, yaw) cells, by the same argument: eroded by its own e (R: its
// farthest xy point from the base origin) in the directions its points move in (the base plane
// when it stands upright on the base, else every direction), it lies inside the carried shape
// at every configuration of the cell. A cell is kept when every probe is free. A base whose
// inscribed part is no box tests its disc (yaw plays no part in it) beside the carried shape.
//
// The search grows from both ends in turn, the end that has expanded fewer cells first: when
// the start or the goal is in a pocket, the pocket is exhausted after about its own cells,
// however large the rest of the map. Each end expands the cell nearest the other end first
// (greedy best-first): where they are connected through open space they meet after about the
// cells along the way, not the area between them. The order does not matter to the proof,
// which holds once either end has run out of cells. Where the static clearance grid shows no
// static footprint within reach of the cell's shape, only the other groups (movables, unknown
// space) are asked of FCL.
#include <algorithm>
#include <cmath>

#include "internal.h"
#include "tamp/world/polygon.h"

namespace tamp::motion_planner::detail {

namespace {
constexpr unsigned char kTested = 1, kFree = 2, kFromStart = 4, kFromGoal = 8;

long yawCellOf(double yaw, long nt) {
  const double u = (yaw + M_PI) / (2.0 * M_PI);
  const long it = static_cast<long>(std::floor((u - std::floor(u)) * static_cast<double>(nt)));
  return std::clamp(it, 0L, nt - 1);
}
}  // namespace

DisconnectionProof::DisconnectionProof(const collision::Scene& scene, const collision::Filter& filter,
                                       const collision::ClearanceGrid* statics, const RobotBinding& robot,
                                       const Aabb& bounds, const Pose2D& start, const Eigen::Vector2d& goal,
                                       double goal_tolerance, double cell, int yaw_cells, int max_cells,
                                       const std::optional<Carried>& carried)
    : scene_(scene), filter_(filter), statics_(statics), min_(bounds.min.head<2>()), cell_(cell),
      nt_(std::max(1, yaw_cells)), max_cells_(static_cast<std::size_t>(std::max(1, max_cells))) {
  const double w = bounds.max.x() - bounds.min.x(), hgt = bounds.max.y() - bounds.min.y();
  if (!(cell > 0) || !(w > 0) || !(hgt > 0) || !setUpShapes(robot, carried)) return;
  nx_ = static_cast<long>(std::ceil(w / cell));
  ny_ = static_cast<long>(std::ceil(hgt / cell));
  if (nt_ == 1) {
    if (nx_ * ny_ > static_cast<long>(max_cells)) return;
    dense_.assign(static_cast<std::size_t>(nx_ * ny_), 0);
  }
  others_ = filter_;
  others_.groups = static_cast<std::uint8_t>(filter_.groups & ~collision::kStaticObjects);
  Cell s{0, 0, nt_ == 1 ? 0 : yawCellOf(start.theta, nt_)};
  if (!cellOf(start.x, start.y, s.ix, s.iy)) return;
  start_ = {start.x, start.y};
  goal_ = goal;
  // The start cell contains the (free) start.
  state(s) = kTested | kFree | kFromStart;
  push(from_start_, goal_, s);
  // The goal side: the kept cells within goal_tolerance of the goal point, at every yaw.
  long gx0 = 0, gy0 = 0, gx1 = 0, gy1 = 0;
  cellOf(goal.x() - goal_tolerance, goal.y() - goal_tolerance, gx0, gy0);
  cellOf(goal.x() + goal_tolerance, goal.y() + goal_tolerance, gx1, gy1);
  for (long iy = std::max(0L, gy0); iy <= std::min(ny_ - 1, gy1); ++iy) {
    for (long ix = std::max(0L, gx0); ix <= std::min(nx_ - 1, gx1); ++ix) {
      const double x0 = min_.x() + static_cast<double>(ix) * cell, y0 = min_.y() + static_cast<double>(iy) * cell;
      const double dx = std::max({x0 - goal.x(), 0.0, goal.x() - (x0 + cell)});
      const double dy = std::max({y0 - goal.y(), 0.0, goal.y() - (y0 + cell)});
      if (std::hypot(dx, dy) > goal_tolerance) continue;
      for (long it = 0; it < nt_; ++it) {
        const Cell g{ix, iy, it};
        unsigned char& st = state(g);
        if (st & kFromStart) {
          decided_ = ProofOutcome::kConnected;
          return;
        }
        if (!kept(st, g)) continue;
        st |= kFromGoal;
        push(from_goal_, start_, g);
      }
    }
  }
  decided_ = from_goal_.empty() ? ProofOutcome::kDisconnected : ProofOutcome::kStopped;
}

bool DisconnectionProof::setUpShapes(const RobotBinding& robot, const std::optional<Carried>& carried) {
  if (!addRobotProbe(robot)) return false;
  if (nt_ == 1) return true;
  const bool box = probes_.front().shape.kind == world::ShapeKind::kBox;
  if (carried) addCarriedProbe(*carried);
  return box || probes_.size() > 1;  // a disc alone: the xy levels say all it can
}

/// The robot's probe: its inscribed disc (xy cells, and (x, y, yaw) cells of a base whose
/// inscribed part is no box), or its base box shrunk by how far its points move within a cell.
bool DisconnectionProof::addRobotProbe(const RobotBinding& robot) {
  const collision::RobotPart* part = robot.inscribedPart();
  if (nt_ == 1 || part == nullptr || part->shape.kind != world::ShapeKind::kBox) {
    const double r = robot.inscribedRadius() - cell_ * std::sqrt(0.5) - 1e-3;
    if (!(robot.inscribedRadius() > 0) || r <= 1e-3) return false;
    const double zmin = robot.inscribedZMin(), zmax = robot.inscribedZMax();
    Probe disc{world::Shape::cylinder(r, std::max(1e-3, zmax - zmin)), Eigen::Isometry3d::Identity()};
    disc.base_T_shape.translation().z() = 0.5 * (zmin + zmax);
    probes_.push_back(std::move(disc));
    reach_ = r;
    return true;
  }
  const Eigen::Vector3d half = 0.5 * part->shape.size;
  double far = 0.0;
  for (const double sx : {-1.0, 1.0}) {
    for (const double sy : {-1.0, 1.0}) {
      const Eigen::Vector3d corner = part->link_T_shape * Eigen::Vector3d(sx * half.x(), sy * half.y(), 0.0);
      far = std::max(far, corner.head<2>().norm());
    }
  }
  const double yaw_width = 2.0 * M_PI / static_cast<double>(nt_);
  const double e = cell_ * std::sqrt(0.5) + far * 0.5 * yaw_width + 1e-3;
  if (half.x() - e <= 1e-3 || half.y() - e <= 1e-3) return false;
  probes_.push_back({world::Shape::box(2.0 * (half.x() - e), 2.0 * (half.y() - e), part->shape.size.z()),
                     part->link_T_shape});
  reach_ = far;
  return true;
}

namespace {
/// The farthest xy distance from the base origin of a point of `shape` at `base_T_shape` (of its
/// bounding box: an upper bound), or nothing for shapes without one here.
std::optional<double> farthestXY(const world::Shape& shape, const Eigen::Isometry3d& base_T_shape) {
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
  double far = 0.0;
  switch (shape.kind) {
    case world::ShapeKind::kBox: half = 0.5 * shape.size; break;
    case world::ShapeKind::kCylinder: half = Eigen::Vector3d(shape.radius, shape.radius, 0.5 * shape.height); break;
    case world::ShapeKind::kSphere: half = Eigen::Vector3d::Constant(shape.radius); break;
    case world::ShapeKind::kPrism:
      for (const auto& v : shape.polygon)
        for (const double sz : {-1.0, 1.0})
          far = std::max(far, (base_T_shape * Eigen::Vector3d(v.x(), v.y(), sz * 0.5 * shape.height)).head<2>().norm());
      return far;
  }
  for (const double sx : {-1.0, 1.0})
    for (const double sy : {-1.0, 1.0})
      for (const double sz : {-1.0, 1.0})
        far = std::max(far, (base_T_shape * Eigen::Vector3d(sx * half.x(), sy * half.y(), sz * half.z())).head<2>().norm());
  return far;
}

/// `shape` eroded by `e` in the directions its points move in: the base plane when it stands
/// upright in the base frame (`upright`), else every direction; nothing when too little is left
/// (or for a prism that does not stand upright). A prism keeps its largest convex piece.
std::optional<world::Shape> eroded(world::Shape shape, bool upright, double e) {
  constexpr double kLeft = 1e-3;
  switch (shape.kind) {
    case world::ShapeKind::kBox:
      shape.size.x() -= 2.0 * e;
      shape.size.y() -= 2.0 * e;
      if (!upright) shape.size.z() -= 2.0 * e;
      if (shape.size.minCoeff() <= kLeft) return std::nullopt;
      return shape;
    case world::ShapeKind::kCylinder:
      shape.radius -= e;
      if (!upright) shape.height -= 2.0 * e;
      if (shape.radius <= kLeft || shape.height <= kLeft) return std::nullopt;
      return shape;
    case world::ShapeKind::kSphere:
      shape.radius -= e;
      if (shape.radius <= kLeft) return std::nullopt;
      return shape;
    case world::ShapeKind::kPrism: {
      // Its largest convex piece, inset (a part of the shape is as sound a probe as the whole).
      if (!upright) return std::nullopt;
      std::vector<world::Polygon2> pieces{shape.polygon};
      if (!world::isConvex(shape.polygon)) pieces = world::convexDecomposition(shape.polygon);
      const auto largest = std::max_element(pieces.begin(), pieces.end(), [](const auto& a, const auto& b) {
        return world::signedArea(a) < world::signedArea(b);
      });
      if (largest == pieces.end()) return std::nullopt;
      auto inset = world::insetConvex(*largest, e);
      if (!inset) return std::nullopt;
      return world::Shape::prism(std::move(*inset), shape.height);
    }
  }
  return std::nullopt;
}
}  // namespace

/// The carried shape's probe ((x, y, yaw) cells only); none when too small once eroded.
void DisconnectionProof::addCarriedProbe(const Carried& carried) {
  const auto far = farthestXY(carried.shape, carried.base_T_shape);
  if (!far) return;
  const double yaw_width = 2.0 * M_PI / static_cast<double>(nt_);
  const double e = cell_ * std::sqrt(0.5) + *far * 0.5 * yaw_width + 1e-3;
  const bool upright = std::abs(carried.base_T_shape.linear()(2, 2)) > 1.0 - 1e-9;
  if (auto shape = eroded(carried.shape, upright, e)) {
    probes_.push_back({std::move(*shape), carried.base_T_shape});
    reach_ = std::max(reach_, *far);
  }
}

bool DisconnectionProof::cellOf(double x, double y, long& ix, long& iy) const {
  ix = static_cast<long>(std::floor((x - min_.x()) / cell_));
  iy = static_cast<long>(std::floor((y - min_.y()) / cell_));
  return ix >= 0 && iy >= 0 && ix < nx_ && iy < ny_;
}

unsigned char& DisconnectionProof::state(const Cell& c) {
  return nt_ == 1 ? dense_[static_cast<std::size_t>(key(c))] : sparse_[key(c)];
}

void DisconnectionProof::push(Frontier& frontier, const Eigen::Vector2d& towards, const Cell& c) {
  const double x = min_.x() + (static_cast<double>(c.ix) + 0.5) * cell_;
  const double y = min_.y() + (static_cast<double>(c.iy) + 0.5) * cell_;
  frontier.push({std::hypot(x - towards.x(), y - towards.y()), c});
}

bool DisconnectionProof::kept(unsigned char& st, const Cell& c) {
  if (!(st & kTested)) {
    const double x = min_.x() + (static_cast<double>(c.ix) + 0.5) * cell_;
    const double y = min_.y() + (static_cast<double>(c.iy) + 0.5) * cell_;
    const double yaw = -M_PI + (static_cast<double>(c.it) + 0.5) * 2.0 * M_PI / static_cast<double>(nt_);
    const bool free = probesFree(x, y, nt_ == 1 ? 0.0 : yaw);
    ++tested_;
    st = static_cast<unsigned char>(kTested | (free ? kFree : 0));
  }
  return st & kFree;
}

bool DisconnectionProof::probesFree(double x, double y, double yaw) {
  const Eigen::Isometry3d base = Pose2D{x, y, yaw}.toIsometry();
  // Where the clearance grid shows no static footprint within the probes' reach, only the other
  // groups are asked.
  const bool grid = statics_ && statics_->clearance(x, y) > reach_;
  if (grid) ++grid_answers_;
  const collision::Filter& f = grid ? others_ : filter_;
  if (f.groups == 0) return true;
  for (const Probe& p : probes_)
    if (scene_.shapeInCollision(p.shape, base * p.base_T_shape, f)) return false;
  return true;
}

ProofOutcome DisconnectionProof::advance(const Termination& termination) {
  if (decided_ != ProofOutcome::kStopped) return decided_;
  const long dyaw = nt_ == 1 ? 0 : 1;
  std::size_t popped = 0;
  while (!from_start_.empty() && !from_goal_.empty()) {
    if ((++popped & 127) == 0 && termination()) return ProofOutcome::kStopped;
    if (sparse_.size() > max_cells_) return decided_ = ProofOutcome::kSkipped;  // (x, y, yaw): too many
    const bool start_side = expanded_start_ <= expanded_goal_;
    Frontier& frontier = start_side ? from_start_ : from_goal_;
    const Eigen::Vector2d& towards = start_side ? goal_ : start_;
    const unsigned char mine = start_side ? kFromStart : kFromGoal;
    const unsigned char theirs = start_side ? kFromGoal : kFromStart;
    ++(start_side ? expanded_start_ : expanded_goal_);
    const Cell at = frontier.top().c;
    frontier.pop();
    for (long dt = -dyaw; dt <= dyaw; ++dt) {
      for (long dy = -1; dy <= 1; ++dy) {
        for (long dx = -1; dx <= 1; ++dx) {
          const Cell n{at.ix + dx, at.iy + dy, (at.it + dt + nt_) % nt_};
          if ((dx == 0 && dy == 0 && dt == 0) || n.ix < 0 || n.iy < 0 || n.ix >= nx_ || n.iy >= ny_) continue;
          if (nt_ == 2 && dt == 1) continue;  // two yaw cells: -1 and +1 are the same neighbour
          unsigned char& st = state(n);  // a reference that stays valid: the map is node-based
          if (st & mine) continue;
          if (!kept(st, n)) continue;
          if (st & theirs) return decided_ = ProofOutcome::kConnected;
          st |= mine;
          push(frontier, towards, n);
        }
      }
    }
  }
  return decided_ = ProofOutcome::kDisconnected;
}

}  // namespace tamp::motion_planner::detail
