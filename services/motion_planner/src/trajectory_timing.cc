#include "tamp/motion_planner/trajectory_timing.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tamp/core/geometry.h"

namespace tamp::motion_planner {
namespace {

/// Normalized profile s(t) of a stop-to-stop move over [0, 1] with peak speed V and accel A.
struct Profile {
  double V{0}, A{0};          // limits in s-units
  double t_acc{0}, t_flat{0}; // duration of acceleration (= deceleration) and cruise phases
  double v_peak{0};
  double duration() const { return 2 * t_acc + t_flat; }
  void make(double v, double a) {
    V = v;
    A = a;
    if (1.0 >= v * v / a) {  // trapezoid
      t_acc = v / a;
      v_peak = v;
      t_flat = (1.0 - v * v / a) / v;
    } else {  // triangle
      t_acc = std::sqrt(1.0 / a);
      v_peak = a * t_acc;
      t_flat = 0.0;
    }
  }
  void at(double t, double& s, double& ds) const {
    const double T = duration();
    t = std::clamp(t, 0.0, T);
    if (t <= t_acc) {
      s = 0.5 * A * t * t;
      ds = A * t;
    } else if (t <= t_acc + t_flat) {
      s = 0.5 * A * t_acc * t_acc + v_peak * (t - t_acc);
      ds = v_peak;
    } else {
      const double r = T - t;
      s = 1.0 - 0.5 * A * r * r;
      ds = A * r;
    }
  }
};

}  // namespace

double trapezoidDuration(double d, double v, double a) {
  if (d <= 0) return 0.0;
  return d >= v * v / a ? d / v + v / a : 2.0 * std::sqrt(d / a);
}

Result<Trajectory> timeParameterize(const JointPath& path, const TimingLimits& limits) {
  const auto bad = [](std::string msg) { return Error(ErrorCode::kInvalidArgument, std::move(msg)); };
  if (path.waypoints.empty()) return bad("time parameterization: the path has no waypoints");
  if (!(limits.sample_period > 0) || !std::isfinite(limits.sample_period)) {
    return bad("time parameterization: sample_period must be positive");
  }
  if (limits.joint_names.size() != limits.joints.size()) {
    return bad("time parameterization: joint_names and joints of the limits differ in size");
  }
  const std::size_t n = path.joint_names.size();
  for (std::size_t i = 0; i < path.waypoints.size(); ++i) {
    if (path.waypoints[i].size() != n) {
      return bad("time parameterization: waypoint " + std::to_string(i) + " has " +
                 std::to_string(path.waypoints[i].size()) + " values for " + std::to_string(n) +
                 " joints");
    }
    for (double v : path.waypoints[i]) {
      if (!std::isfinite(v)) {
        return bad("time parameterization: waypoint " + std::to_string(i) + " is not finite");
      }
    }
  }
  const auto okLimit = [](const JointLimit& l) {
    return std::isfinite(l.max_velocity) && l.max_velocity > 0 && std::isfinite(l.max_acceleration) &&
           l.max_acceleration > 0;
  };
  // Per joint: -1 = translation part (x or y), -2 = yaw, else index into limits.joints.
  int ix = -1, iy = -1, ith = -1;
  std::vector<const JointLimit*> lim(n, nullptr);
  for (std::size_t j = 0; j < n; ++j) {
    const std::string& name = path.joint_names[j];
    if (name == "base_x") {
      ix = static_cast<int>(j);
    } else if (name == "base_y") {
      iy = static_cast<int>(j);
    } else if (name == "base_theta") {
      ith = static_cast<int>(j);
      lim[j] = &limits.base_angular;
    } else {
      auto it = std::find(limits.joint_names.begin(), limits.joint_names.end(), name);
      if (it == limits.joint_names.end()) {
        return bad("time parameterization: no limits for joint '" + name + "'");
      }
      lim[j] = &limits.joints[static_cast<std::size_t>(it - limits.joint_names.begin())];
    }
    if (lim[j] && !okLimit(*lim[j])) {
      return bad("time parameterization: limits of joint '" + name + "' must be positive");
    }
  }
  if ((ix >= 0 || iy >= 0) && !okLimit(limits.base_linear)) {
    return bad("time parameterization: base linear limits must be positive");
  }

  // Unwrap yaw so consecutive waypoints differ by less than pi.
  std::vector<std::vector<double>> wp = path.waypoints;
  if (ith >= 0) {
    for (std::size_t i = 1; i < wp.size(); ++i) {
      const double prev = wp[i - 1][static_cast<std::size_t>(ith)];
      double& cur = wp[i][static_cast<std::size_t>(ith)];
      cur = prev + angleDiff(cur, prev);
    }
  }

  Trajectory traj;
  traj.joint_names = path.joint_names;
  auto push = [&](double t, const std::vector<double>& q, const std::vector<double>& v) {
    if (!traj.points.empty() && t <= traj.points.back().time_from_start + 1e-12) {
      traj.points.back().positions = q;  // same instant (a phase change on a sample): keep one
      traj.points.back().velocities = v;
      return;
    }
    traj.points.push_back(TrajectoryPoint{t, q, v});
  };
  push(0.0, wp.front(), std::vector<double>(n, 0.0));
  double t0 = 0.0;
  std::vector<double> q(n), v(n), D(n);
  for (std::size_t i = 0; i + 1 < wp.size(); ++i) {
    const auto& a = wp[i];
    const auto& b = wp[i + 1];
    double V = std::numeric_limits<double>::infinity();
    double A = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < n; ++j) D[j] = b[j] - a[j];
    if (ix >= 0 || iy >= 0) {
      const double dx = ix >= 0 ? D[static_cast<std::size_t>(ix)] : 0.0;
      const double dy = iy >= 0 ? D[static_cast<std::size_t>(iy)] : 0.0;
      const double d = std::hypot(dx, dy);
      if (d > 0) {
        V = std::min(V, limits.base_linear.max_velocity / d);
        A = std::min(A, limits.base_linear.max_acceleration / d);
      }
    }
    for (std::size_t j = 0; j < n; ++j) {
      if (!lim[j]) continue;
      const double d = std::abs(D[j]);
      if (d > 0) {
        V = std::min(V, lim[j]->max_velocity / d);
        A = std::min(A, lim[j]->max_acceleration / d);
      }
    }
    if (!std::isfinite(V)) continue;  // no motion: duplicate waypoint
    Profile p;
    p.make(V, A);
    const double T = p.duration();
    // Sample times: the period grid, the phase changes, the end.
    std::vector<double> times;
    for (double t = limits.sample_period; t < T; t += limits.sample_period) times.push_back(t);
    times.push_back(p.t_acc);
    times.push_back(p.t_acc + p.t_flat);
    times.push_back(T);
    std::sort(times.begin(), times.end());
    for (double t : times) {
      if (t <= 0) continue;
      double s = 0, ds = 0;
      p.at(t, s, ds);
      if (t >= T) {
        s = 1.0;
        ds = 0.0;
      }
      for (std::size_t j = 0; j < n; ++j) {
        q[j] = (t >= T) ? b[j] : a[j] + s * D[j];
        v[j] = ds * D[j];
      }
      push(t0 + t, q, v);
    }
    t0 += T;
  }
  return traj;
}

}  // namespace tamp::motion_planner
