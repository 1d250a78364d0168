#include "tamp/dds/convert.h"

#include <chrono>
#include <cmath>

namespace tamp::dds {
namespace {
Error bad(const std::string& field, const std::string& what) {
  return Error(ErrorCode::kInvalidArgument, what, SourceLocation{"", 0, 0, field});
}
bool finite(double v) { return std::isfinite(v); }
}  // namespace

msg::StatusCode toMsg(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidArgument: return msg::STATUS_INVALID_ARGUMENT;
    case ErrorCode::kParseError: return msg::STATUS_PARSE_ERROR;
    case ErrorCode::kUnsupported: return msg::STATUS_UNSUPPORTED;
    case ErrorCode::kNotFound: return msg::STATUS_NOT_FOUND;
    case ErrorCode::kIo: return msg::STATUS_IO_ERROR;
    case ErrorCode::kTimeout: return msg::STATUS_TIMEOUT;
    case ErrorCode::kCancelled: return msg::STATUS_CANCELLED;
    case ErrorCode::kUnavailable: return msg::STATUS_UNAVAILABLE;
    case ErrorCode::kInfeasible: return msg::STATUS_INFEASIBLE;
    case ErrorCode::kInternal: return msg::STATUS_INTERNAL;
    case ErrorCode::kNotReady: return msg::STATUS_NOT_READY;
  }
  return msg::STATUS_INTERNAL;
}

ErrorCode fromMsg(msg::StatusCode code) {
  switch (code) {
    case msg::STATUS_OK: return ErrorCode::kInternal;  // not an error; callers check OK first
    case msg::STATUS_INVALID_ARGUMENT: return ErrorCode::kInvalidArgument;
    case msg::STATUS_PARSE_ERROR: return ErrorCode::kParseError;
    case msg::STATUS_UNSUPPORTED: return ErrorCode::kUnsupported;
    case msg::STATUS_NOT_FOUND: return ErrorCode::kNotFound;
    case msg::STATUS_IO_ERROR: return ErrorCode::kIo;
    case msg::STATUS_TIMEOUT: return ErrorCode::kTimeout;
    case msg::STATUS_CANCELLED: return ErrorCode::kCancelled;
    case msg::STATUS_UNAVAILABLE: return ErrorCode::kUnavailable;
    case msg::STATUS_INFEASIBLE: return ErrorCode::kInfeasible;
    case msg::STATUS_INTERNAL: return ErrorCode::kInternal;
    case msg::STATUS_NOT_READY: return ErrorCode::kNotReady;
  }
  return ErrorCode::kInternal;
}

msg::ActionKind toMsg(ActionKind kind) {
  switch (kind) {
    case ActionKind::kMoveBase: return msg::ACTION_MOVE_BASE;
    case ActionKind::kMoveArm: return msg::ACTION_MOVE_ARM;
    case ActionKind::kPick: return msg::ACTION_PICK;
    case ActionKind::kPlace: return msg::ACTION_PLACE;
  }
  return msg::ACTION_MOVE_BASE;
}

ActionKind fromMsg(msg::ActionKind kind) {
  switch (kind) {
    case msg::ACTION_MOVE_BASE: return ActionKind::kMoveBase;
    case msg::ACTION_MOVE_ARM: return ActionKind::kMoveArm;
    case msg::ACTION_PICK: return ActionKind::kPick;
    case msg::ACTION_PLACE: return ActionKind::kPlace;
  }
  return ActionKind::kMoveBase;
}

msg::Pose2D toMsg(const Pose2D& p) {
  msg::Pose2D m;
  m.x(p.x);
  m.y(p.y);
  m.theta(p.theta);
  return m;
}

Result<Pose2D> fromMsg(const msg::Pose2D& m, const std::string& field) {
  if (!finite(m.x()) || !finite(m.y()) || !finite(m.theta())) return bad(field, "pose has a non-finite value");
  return Pose2D{m.x(), m.y(), m.theta()};
}

msg::Pose3D toMsg(const Eigen::Isometry3d& T) {
  msg::Pose3D m;
  m.position().x(T.translation().x());
  m.position().y(T.translation().y());
  m.position().z(T.translation().z());
  Eigen::Quaterniond q(T.linear());
  m.orientation().x(q.x());
  m.orientation().y(q.y());
  m.orientation().z(q.z());
  m.orientation().w(q.w());
  return m;
}

Result<Eigen::Isometry3d> fromMsg(const msg::Pose3D& m, const std::string& field) {
  const auto& p = m.position();
  const auto& o = m.orientation();
  if (!finite(p.x()) || !finite(p.y()) || !finite(p.z())) return bad(field + ".position", "non-finite value");
  Eigen::Quaterniond q(o.w(), o.x(), o.y(), o.z());
  if (!finite(q.norm()) || q.norm() < 1e-9) return bad(field + ".orientation", "quaternion is zero or non-finite");
  q.normalize();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.x(), p.y(), p.z());
  return T;
}

msg::JointPath toMsg(const JointPath& p) {
  msg::JointPath m;
  m.joint_names(p.joint_names);
  std::vector<double> values;
  values.reserve(p.waypoints.size() * p.joint_names.size());
  for (const auto& w : p.waypoints) values.insert(values.end(), w.begin(), w.end());
  m.values(std::move(values));
  return m;
}

Result<JointPath> fromMsg(const msg::JointPath& m, const std::string& field) {
  const size_t n = m.joint_names().size();
  if (n == 0) {
    if (!m.values().empty()) return bad(field + ".values", "values given without joint names");
    return JointPath{};
  }
  if (m.values().size() % n != 0) {
    return bad(field + ".values", std::to_string(m.values().size()) + " values are not a multiple of " +
                                      std::to_string(n) + " joints");
  }
  JointPath p;
  p.joint_names = m.joint_names();
  for (size_t i = 0; i < m.values().size(); i += n) {
    std::vector<double> w(m.values().begin() + static_cast<long>(i), m.values().begin() + static_cast<long>(i + n));
    for (double v : w) {
      if (!finite(v)) return bad(field + ".values", "non-finite value in waypoint " + std::to_string(i / n));
    }
    p.waypoints.push_back(std::move(w));
  }
  return p;
}

msg::JointTrajectory toMsg(const Trajectory& t) {
  msg::JointTrajectory m;
  m.joint_names(t.joint_names);
  std::vector<double> times, pos, vel;
  bool has_vel = !t.points.empty() && !t.points.front().velocities.empty();
  for (const auto& p : t.points) {
    times.push_back(p.time_from_start);
    pos.insert(pos.end(), p.positions.begin(), p.positions.end());
    if (has_vel) vel.insert(vel.end(), p.velocities.begin(), p.velocities.end());
  }
  m.times(std::move(times));
  m.positions(std::move(pos));
  m.velocities(std::move(vel));
  return m;
}

Result<Trajectory> fromMsg(const msg::JointTrajectory& m, const std::string& field) {
  const size_t n = m.joint_names().size();
  const size_t k = m.times().size();
  if (m.positions().size() != n * k) {
    return bad(field + ".positions", "expected " + std::to_string(n * k) + " values (" + std::to_string(k) +
                                         " points x " + std::to_string(n) + " joints), got " +
                                         std::to_string(m.positions().size()));
  }
  if (!m.velocities().empty() && m.velocities().size() != n * k) {
    return bad(field + ".velocities", "expected 0 or " + std::to_string(n * k) + " values");
  }
  Trajectory t;
  t.joint_names = m.joint_names();
  double last = -INFINITY;
  for (size_t i = 0; i < k; ++i) {
    TrajectoryPoint p;
    p.time_from_start = m.times()[i];
    if (!finite(p.time_from_start) || p.time_from_start < last) {
      return bad(field + ".times", "times must be finite and non-decreasing (point " + std::to_string(i) + ")");
    }
    last = p.time_from_start;
    p.positions.assign(m.positions().begin() + static_cast<long>(i * n),
                       m.positions().begin() + static_cast<long>((i + 1) * n));
    if (!m.velocities().empty()) {
      p.velocities.assign(m.velocities().begin() + static_cast<long>(i * n),
                          m.velocities().begin() + static_cast<long>((i + 1) * n));
    }
    for (double v : p.positions) {
      if (!finite(v)) return bad(field + ".positions", "non-finite value at point " + std::to_string(i));
    }
    t.points.push_back(std::move(p));
  }
  return t;
}

msg::PointCloudFrame toMsg(const PointCloudFrame& f, std::uint64_t seq) {
  msg::PointCloudFrame m;
  m.header().stamp_ns(f.stamp_ns);
  m.header().frame_id(f.sensor_id);
  m.header().seq(seq);
  m.sensor_id(f.sensor_id);
  m.sensor_pose(toMsg(f.world_T_sensor));
  m.width(f.width);
  m.height(f.height);
  m.points(f.xyz);
  return m;
}

Result<PointCloudFrame> fromMsg(const msg::PointCloudFrame& m) {
  const std::size_t values = m.points().size();
  if (values % 3 != 0) {
    return bad("points", "size " + std::to_string(values) + " is not a multiple of 3 (x y z triplets)");
  }
  const std::uint64_t n = values / 3;
  if (m.width() != 0 && static_cast<std::uint64_t>(m.width()) * m.height() != n) {
    return bad(m.height() == 0 ? "height" : "width", "width x height = " + std::to_string(m.width()) + " x " +
                                                         std::to_string(m.height()) + " does not match the " +
                                                         std::to_string(n) + " points");
  }
  auto pose = fromMsg(m.sensor_pose(), "sensor_pose");
  if (!pose) return pose.error();
  PointCloudFrame f;
  f.sensor_id = m.sensor_id();
  f.stamp_ns = m.header().stamp_ns();
  f.world_T_sensor = *pose;
  f.width = m.width();
  f.height = m.height();
  f.xyz = m.points();
  return f;
}

int64_t nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace tamp::dds
