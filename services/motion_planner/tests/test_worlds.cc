#include "test_worlds.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace tamp::motion_planner::testing {

world::Object box(const std::string& id, double cx, double cy, double sx, double sy, bool movable, double height,
                  double mass) {
  world::Object o;
  o.id = id;
  o.label = id;
  o.kind = movable ? world::ObjectKind::kMovable : world::ObjectKind::kStatic;
  o.shape = world::Shape::box(sx, sy, height);
  o.pose.translation() = Eigen::Vector3d(cx, cy, height / 2);
  o.mass = movable ? mass : 0.0;
  o.graspable = movable && mass <= 25.0;
  return o;
}

namespace {
void add(world::World& w, const world::Object& o) {
  if (!w.addObject(o).ok()) throw std::runtime_error("test world: cannot add " + o.id);
}
void room(world::World& w, double width, double height) {
  add(w, box("wall_south", width / 2, -0.1, width + 0.4, 0.2, false));
  add(w, box("wall_north", width / 2, height + 0.1, width + 0.4, 0.2, false));
  add(w, box("wall_west", -0.1, height / 2, 0.2, height, false));
  add(w, box("wall_east", width + 0.1, height / 2, 0.2, height, false));
  world::Region floor;
  floor.id = "floor";
  floor.label = "floor";
  floor.kind = world::RegionKind::kFloor;
  floor.polygon = {{0, 0}, {width, 0}, {width, height}, {0, height}};
  floor.height = 0.0;
  if (!w.addRegion(floor).ok()) throw std::runtime_error("test world: region");
}
}  // namespace

MotionPlanner discPlanner(const world::World& w, const MotionPlannerParams& p) {
  MotionPlanner mp(collision::RobotGeometry::disc(kDiscRadius, 1.0), p);
  mp.setWorld(w);
  return mp;
}

MotionPlannerParams untimedParams() {
  MotionPlannerParams p;
  p.lazy.optimize_budget_s = 30.0;
  p.lazy.roadmap_max_evaluations = 1000000;
  return p;
}

MotionRequest baseRequest(Pose2D from, Pose2D to, MotionMode mode) {
  MotionRequest r;
  r.group = PlanningGroup::kBase;
  r.mode = mode;
  r.start.base = from;
  r.goal = MotionGoal::basePoseGoal(to);
  return r;
}

std::vector<std::string> blockingIds(const std::vector<BlockingObject>& blocking) {
  std::vector<std::string> out;
  for (const auto& o : blocking) out.push_back(o.object_id);
  std::sort(out.begin(), out.end());
  return out;
}

world::World corridorWorld(bool door_blocked) {
  world::World w("corridor");
  room(w, 10, 4);
  add(w, box("wall_mid_low", 5, 0.75, 0.2, 1.5, false));
  add(w, box("wall_mid_high", 5, 3.25, 0.2, 1.5, false));
  if (door_blocked) add(w, box("crate", 5, 2, 0.4, 1.0, true, 0.8, 8.0));
  add(w, box("far_box", 8.8, 3.4, 0.6, 0.6, true, 0.5, 4.0));
  return w;
}

world::World twoDoorWorld() {
  world::World w("two_doors");
  room(w, 10, 4);
  add(w, box("wall_mid_a", 5, 0.2, 0.2, 0.4, false));
  add(w, box("wall_mid_b", 5, 2.0, 0.2, 1.2, false));
  add(w, box("wall_mid_c", 5, 3.8, 0.2, 0.4, false));
  add(w, box("heavy_a", 4.6, 0.9, 0.6, 1.0, true, 1.0, 120.0));
  add(w, box("heavy_b", 5.4, 0.9, 0.6, 1.0, true, 1.0, 120.0));
  add(w, box("light", 5.0, 3.1, 0.4, 1.0, true, 0.6, 3.0));
  return w;
}

world::World pocketWorld() {
  world::World w("pocket");
  room(w, 30, 30);
  add(w, box("pocket_west", 24, 25, 0.2, 2.2, false));
  add(w, box("pocket_east", 26, 25, 0.2, 2.2, false));
  add(w, box("pocket_north", 25, 26, 2.2, 0.2, false));
  add(w, box("pocket_south_a", 24.25, 24, 0.5, 0.2, false));
  add(w, box("pocket_south_b", 25.75, 24, 0.5, 0.2, false));
  add(w, box("crate", 25, 24, 1.0, 0.2, true, 0.8, 8.0));
  return w;
}

world::World openRoomWorld() {
  world::World w("open_room");
  room(w, 10, 6);
  add(w, box("obstacle", 5, 3, 0.6, 0.6, true, 0.5, 3.0));
  return w;
}

namespace {
/// Distance from a point to a box footprint (rotated rectangle), 0 inside; negative depth inside.
double pointBoxDistance(const Eigen::Vector2d& p, const world::Object& o) {
  const Eigen::Isometry3d inv = o.pose.inverse();
  const Eigen::Vector3d q = inv * Eigen::Vector3d(p.x(), p.y(), o.pose.translation().z());
  const double hx = o.shape.size.x() / 2, hy = o.shape.size.y() / 2;
  const double dx = std::abs(q.x()) - hx, dy = std::abs(q.y()) - hy;
  if (dx <= 0 && dy <= 0) return std::max(dx, dy);
  return std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
}

template <typename F>
void walk(const JointPath& path, double step, F&& f) {
  const int ix = path.indexOf("base_x"), iy = path.indexOf("base_y");
  if (ix < 0 || iy < 0) throw std::invalid_argument("walk: not a base path");
  for (std::size_t i = 0; i < path.waypoints.size(); ++i) {
    const Eigen::Vector2d a(path.waypoints[i][static_cast<std::size_t>(ix)], path.waypoints[i][static_cast<std::size_t>(iy)]);
    if (i + 1 == path.waypoints.size()) {
      f(a);
      break;
    }
    const Eigen::Vector2d b(path.waypoints[i + 1][static_cast<std::size_t>(ix)],
                            path.waypoints[i + 1][static_cast<std::size_t>(iy)]);
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int k = 0; k < n; ++k) f(a + (b - a) * (static_cast<double>(k) / n));
  }
}
}  // namespace

double discClearance(const world::World& w, const JointPath& path, double radius, double step,
                     const std::vector<std::string>& skip, bool movables) {
  double best = std::numeric_limits<double>::infinity();
  walk(path, step, [&](const Eigen::Vector2d& p) {
    for (const auto& o : w.objects()) {
      if (std::find(skip.begin(), skip.end(), o.id) != skip.end()) continue;
      if (!movables && o.kind == world::ObjectKind::kMovable) continue;
      if (o.shape.kind != world::ShapeKind::kBox) throw std::invalid_argument("discClearance: boxes only");
      best = std::min(best, pointBoxDistance(p, o) - radius);
    }
  });
  return best;
}

std::vector<std::string> discTouches(const world::World& w, const JointPath& path, double radius, double step,
                                     bool movables_only) {
  std::vector<std::string> out;
  walk(path, step, [&](const Eigen::Vector2d& p) {
    for (const auto& o : w.objects()) {
      if (movables_only && o.kind != world::ObjectKind::kMovable) continue;
      if (pointBoxDistance(p, o) < radius - 1e-6) out.push_back(o.id);
    }
  });
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

}  // namespace tamp::motion_planner::testing
