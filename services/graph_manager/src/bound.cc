// Admissible bounds of Traverse's branch-and-bound: what an edge without a motion costs at least,
// and what the rest of a branch costs at least from a node to the goal.
//
// The effort of a base motion is the effort model's prediction for its path. For move_base the
// model (common/effort_model/models.h) is
//   T = overhead + settle * (moves + turns) + sum trap(d_i; v/f, a/f) + sum trap(turns; ...),
// f = 1 + slowdown * mass >= 1, and the estimator answers its log-normal mean
//   mean = T * exp(var / 2),  stddev = mean * sqrt(expm1(var)),
// so T = mean / sqrt(1 + (stddev / mean)^2) is read back from any answer. For a path whose
// endpoints are d apart (at least one move, total length >= d): trap is concave with trap(0) = 0,
// hence subadditive, and increasing, so sum trap(d_i) >= trap(d); turns, extra stops, a load and
// the variance only add. So the nominal time N(d) of ONE straight move of length d, empty-handed
// and without turns, bounds the mean effort of every base motion between two poses d apart.
// N is concave on d > 0 (a constant plus trap), with N(0) = overhead below N(0+): the chords
// between samples of N lie below it, and so does their interpolation, which is itself concave
// and increasing, hence subadditive: a chain of drives from A to B costs at least the bound of
// |AB|. That is the bound to the goal (toGoalBound).
//
// The samples are asked of the estimator once per model version (calibrateBounds, at the start
// and after a refit) and checked: increasing with non-increasing chord slopes, else they are not
// used (a pricing that is not of that form: the distance at lower_bound_base_speed stays). The
// bound is never below that distance bound, which holds for any robot slower than that speed.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "tamp/core/log.h"
#include "tamp/graph_manager/bound.h"
#include "tamp/graph_manager/graph_manager.h"

namespace tamp::graph_manager {
namespace {
/// Increasing, with chord slopes that do not increase (within a relative tolerance for the
/// estimator's rounding): what the model's N is.
bool concaveIncreasing(const std::vector<std::pair<double, double>>& s) {
  double slope = kInfinity;
  for (std::size_t i = 1; i < s.size(); ++i) {
    const double dd = s[i].first - s[i - 1].first, dt = s[i].second - s[i - 1].second;
    if (!(dt >= -1e-9) || !(dd > 0.0)) return false;
    const double k = dt / dd;
    if (i > 1 && k > slope * (1.0 + 1e-6) + 1e-9) return false;
    slope = k;
  }
  return true;
}
}  // namespace

DriveBound::DriveBound(double top_speed) : top_speed_(top_speed) {
  if (!(top_speed > 0.0)) throw std::invalid_argument("DriveBound: top speed must be > 0");
}

std::vector<double> DriveBound::lengths() {
  std::vector<double> d{0.0};
  for (double x = 0.05; x < 250.0; x *= 2.0) d.push_back(x);
  return d;
}

std::vector<EffortQuery> DriveBound::queries() {
  std::vector<EffortQuery> out;
  for (double d : lengths()) {
    EffortQuery q;
    q.kind = ActionKind::kMoveBase;
    q.path.joint_names = {"base_x", "base_y", "base_theta"};
    q.path.waypoints = {{0.0, 0.0, 0.0}, {d, 0.0, 0.0}};
    out.push_back(std::move(q));
  }
  return out;
}

Status DriveBound::calibrate(const std::vector<EffortAnswer>& answers) {
  samples_.clear();
  const std::vector<double> d = lengths();
  if (answers.size() != d.size())
    return Error(ErrorCode::kInvalidArgument, "drive bound: " + std::to_string(answers.size()) + " answers for " +
                                                  std::to_string(d.size()) + " drives");
  std::vector<std::pair<double, double>> s;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const EffortAnswer& a = answers[i];
    if (!a.ok || !std::isfinite(a.mean_s) || !(a.mean_s >= 0.0) || !std::isfinite(a.stddev_s) || !(a.stddev_s >= 0.0))
      return Error(ErrorCode::kUnavailable, "drive bound: no usable estimate for a drive of " + std::to_string(d[i]) +
                                                " m" + (a.message.empty() ? std::string() : ": " + a.message));
    const double m = a.mean_s, sd = a.stddev_s;
    s.emplace_back(d[i], m > 0.0 ? m / std::sqrt(1.0 + (sd / m) * (sd / m)) : 0.0);
  }
  if (!concaveIncreasing(s))
    return Error(ErrorCode::kInvalidArgument, "drive bound: the drive times are not concave and increasing in the length");
  samples_ = std::move(s);
  return Status::Ok();
}

double DriveBound::operator()(double d) const {
  d = std::max(0.0, d);
  const double by_distance = d / top_speed_;
  if (samples_.empty()) return by_distance;
  if (d >= samples_.back().first) return std::max(by_distance, samples_.back().second);
  const auto hi = std::upper_bound(samples_.begin(), samples_.end(), d, [](double x, const auto& p) { return x < p.first; });
  const auto lo = std::prev(hi);
  const double w = (d - lo->first) / (hi->first - lo->first);
  return std::max(by_distance, lo->second + w * (hi->second - lo->second));
}

// ---- the graph manager's use -------------------------------------------------------------------------

void GraphManager::boundsForCurrentModels() {
  const std::optional<std::uint64_t> version = services_.effortModelVersion();
  if (bounds_calibrated_ && version == bound_version_) return;
  calibrateBounds();
  bounds_calibrated_ = true;
  bound_version_ = version;
  // Edges bounded with the former models are bounded again when a branch reaches them.
  for (const Edge& e : graph_.edges())
    if (e.state == EdgeState::kUnevaluated) graph_.edge(e.id).lower_bound_s = 0.0;
}

void GraphManager::calibrateBounds() {
  drive_bound_ = DriveBound(params_.lower_bound_base_speed);
  to_goal_bound_.clear();
  if (!params_.model_bounds) return;
  const std::vector<EffortQuery> queries = DriveBound::queries();
  counters_.effort_calls += static_cast<int>(queries.size());
  if (Status s = drive_bound_.calibrate(services_.effort(queries)); !s) {
    log::get("graph_manager")->info("{}; base motions are bounded by their distance only", s.error().message);
    return;
  }
  log::get("graph_manager")
      ->debug("drive bound: {:.2f} s at 0 m, {:.2f} s at 1 m, {:.2f} s at 10 m", drive_bound_(0.0), drive_bound_(1.0),
              drive_bound_(10.0));
}

double GraphManager::lowerBound(const Edge& e) const {
  if (e.kind != ActionKind::kMoveBase || e.tokens.size() < 3) return 0.0;
  const bool push = isPush(e) && e.tokens.size() == 6;  // (push ?o ?r ?from ?to ?s)
  const auto a = abstraction_.locationPose(e.tokens[push ? 3 : 1]);
  const auto b = abstraction_.locationPose(e.tokens[push ? 4 : 2]);
  if (!a || !b) return 0.0;
  // A location stands for base poses within its tolerance: the drive may be that much shorter.
  const double slack = 2.0 * abstraction_.params().location_tolerance_m;
  return drive_bound_(std::max(0.0, std::hypot(a->x - b->x, a->y - b->y) - slack));
}

double GraphManager::toGoalBound(NodeId v) {
  if (!params_.goal_bound) return 0.0;
  if (auto it = to_goal_bound_.find(v); it != to_goal_bound_.end()) return it->second;
  double h = 0.0;
  std::string goal_location;
  for (const auto& a : goal_.atoms) {
    const auto t = atomTokens(a);
    if (t.size() == 2 && t[0] == "robot-at") goal_location = t[1];
  }
  if (!goal_location.empty()) {
    const std::string here = abstraction_.bind(graph_.node(v).atoms).location;
    const auto a = abstraction_.locationPose(here);
    const auto b = abstraction_.locationPose(goal_location);
    // Where the robot stands is the goal's location, or the rest of the branch drives there.
    if (a && b && here != goal_location) {
      const double slack = 2.0 * abstraction_.params().location_tolerance_m;
      h = drive_bound_(std::max(0.0, std::hypot(a->x - b->x, a->y - b->y) - slack));
    }
  }
  to_goal_bound_[v] = h;
  return h;
}

}  // namespace tamp::graph_manager
