#include "tamp/core/trajectory.h"

#include <algorithm>
#include <stdexcept>

namespace tamp {

std::string_view toString(ActionKind kind) {
  switch (kind) {
    case ActionKind::kMoveBase: return "move_base";
    case ActionKind::kMoveArm: return "move_arm";
    case ActionKind::kPick: return "pick";
    case ActionKind::kPlace: return "place";
  }
  return "unknown";
}

std::optional<ActionKind> actionKindFromString(std::string_view name) {
  for (ActionKind k : kAllActionKinds) {
    if (toString(k) == name) return k;
  }
  return std::nullopt;
}

namespace {
int indexIn(const std::vector<std::string>& names, std::string_view joint) {
  auto it = std::find(names.begin(), names.end(), joint);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}
}  // namespace

int JointPath::indexOf(std::string_view joint) const { return indexIn(joint_names, joint); }

void JointPath::validate() const {
  for (size_t i = 0; i < waypoints.size(); ++i) {
    if (waypoints[i].size() != joint_names.size()) {
      throw std::invalid_argument("JointPath waypoint " + std::to_string(i) + " has " +
                                  std::to_string(waypoints[i].size()) + " values for " +
                                  std::to_string(joint_names.size()) + " joints");
    }
  }
}

int Trajectory::indexOf(std::string_view joint) const { return indexIn(joint_names, joint); }

JointPath Trajectory::path() const {
  JointPath p;
  p.joint_names = joint_names;
  p.waypoints.reserve(points.size());
  for (const auto& pt : points) p.waypoints.push_back(pt.positions);
  return p;
}

std::vector<double> Trajectory::sample(double t) const {
  if (points.empty()) return {};
  if (t <= points.front().time_from_start) return points.front().positions;
  if (t >= points.back().time_from_start) return points.back().positions;
  auto it = std::upper_bound(points.begin(), points.end(), t,
                             [](double v, const TrajectoryPoint& p) { return v < p.time_from_start; });
  const TrajectoryPoint& b = *it;
  const TrajectoryPoint& a = *(it - 1);
  const double span = b.time_from_start - a.time_from_start;
  const double s = span > 0 ? (t - a.time_from_start) / span : 1.0;
  std::vector<double> out(a.positions.size());
  for (size_t i = 0; i < out.size(); ++i) out[i] = a.positions[i] + s * (b.positions[i] - a.positions[i]);
  return out;
}

void Trajectory::validate() const {
  double last = -1.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const auto& p = points[i];
    if (p.positions.size() != joint_names.size()) {
      throw std::invalid_argument("Trajectory point " + std::to_string(i) + " has " +
                                  std::to_string(p.positions.size()) + " positions for " +
                                  std::to_string(joint_names.size()) + " joints");
    }
    if (!p.velocities.empty() && p.velocities.size() != joint_names.size()) {
      throw std::invalid_argument("Trajectory point " + std::to_string(i) + " has " +
                                  std::to_string(p.velocities.size()) + " velocities");
    }
    if (!(p.time_from_start >= last)) {
      throw std::invalid_argument("Trajectory point " + std::to_string(i) +
                                  " time_from_start is not non-decreasing");
    }
    last = p.time_from_start;
  }
}

}  // namespace tamp
