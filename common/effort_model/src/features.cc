#include "tamp/core/format.h"
#include "tamp/effort_model/features.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "tamp/core/geometry.h"

namespace tamp::effort_model {
namespace {

Error invalid(std::string message, std::string field = "") {
  return Error(ErrorCode::kInvalidArgument, std::move(message), SourceLocation{"", 0, 0, std::move(field)});
}

bool knownKind(ActionKind k) {
  return std::find(kAllActionKinds.begin(), kAllActionKinds.end(), k) != kAllActionKinds.end();
}

bool isBaseJoint(const std::string& name) {
  return std::find(kBaseJointNames.begin(), kBaseJointNames.end(), name) != kBaseJointNames.end();
}

/// Common path checks: non-empty, sizes match, finite values.
Status checkPath(const JointPath& path) {
  if (path.waypoints.empty()) return invalid("empty path (no waypoints)", "path.waypoints");
  if (path.joint_names.empty()) return invalid("path has no joint names", "path.joint_names");
  for (std::size_t i = 0; i < path.joint_names.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (path.joint_names[i] == path.joint_names[j]) {
        return invalid("duplicate joint name '" + path.joint_names[i] + "'", "path.joint_names");
      }
    }
  }
  for (std::size_t i = 0; i < path.waypoints.size(); ++i) {
    const auto& w = path.waypoints[i];
    const std::string field = "path.waypoints[" + std::to_string(i) + "]";
    if (w.size() != path.joint_names.size()) {
      return invalid("waypoint has " + std::to_string(w.size()) + " values for " +
                         std::to_string(path.joint_names.size()) + " joints",
                     field);
    }
    for (std::size_t j = 0; j < w.size(); ++j) {
      if (!std::isfinite(w[j])) {
        return invalid("value of joint '" + path.joint_names[j] + "' is not finite", field);
      }
      if (std::abs(w[j]) > InputLimits::kMaxAbsPathValue) {
        return invalid("value " + formatNumber(w[j]) + " of joint '" + path.joint_names[j] + "' exceeds the limit of " +
                           formatNumber(InputLimits::kMaxAbsPathValue),
                       field);
      }
    }
  }
  return Status::Ok();
}

Result<ActionFeatures> baseFeatures(const ActionDescription& a) {
  const JointPath& path = a.path;
  if (Status s = checkPath(path); !s) return s.error();
  for (const auto& name : path.joint_names) {
    if (!isBaseJoint(name)) {
      return invalid("move_base path has non-base joint '" + name +
                         "' (expected exactly base_x, base_y, base_theta)",
                     "path.joint_names");
    }
  }
  const int ix = path.indexOf(kBaseJointNames[0]);
  const int iy = path.indexOf(kBaseJointNames[1]);
  const int it = path.indexOf(kBaseJointNames[2]);
  if (ix < 0 || iy < 0 || it < 0) {
    return invalid("move_base path needs joints base_x, base_y and base_theta", "path.joint_names");
  }
  std::vector<Pose2D> poses;
  poses.reserve(path.waypoints.size());
  for (const auto& w : path.waypoints) {
    poses.push_back(Pose2D{w[static_cast<std::size_t>(ix)], w[static_cast<std::size_t>(iy)], w[static_cast<std::size_t>(it)]});
  }
  std::vector<double> moves;
  std::vector<double> turns;
  for (const BaseStep& step : baseSteps(poses)) {
    (step.kind == BaseStep::Kind::kDrive ? moves : turns).push_back(step.amount);
  }

  ActionFeatures f;
  f.kind = ActionKind::kMoveBase;
  f.moves = MoveSet(std::move(moves));
  f.turns = MoveSet(std::move(turns));
  f.object_mass_kg = a.object_mass_kg;
  return f;
}

Result<ActionFeatures> armFeatures(const ActionDescription& a, const FeatureOptions& options) {
  const JointPath& path = a.path;
  if (Status s = checkPath(path); !s) return s.error();
  for (const auto& name : path.joint_names) {
    if (isBaseJoint(name)) {
      return invalid("move_arm path has base joint '" + name + "' (use move_base for the base)",
                     "path.joint_names");
    }
  }
  std::vector<double> moves;
  for (const ArmRun& run : armRuns(path.waypoints, path.joint_names, options)) moves.push_back(run.length);
  ActionFeatures f;
  f.kind = ActionKind::kMoveArm;
  f.moves = MoveSet(std::move(moves));
  f.object_mass_kg = a.object_mass_kg;
  return f;
}

}  // namespace

std::vector<BaseStep> baseSteps(const std::vector<Pose2D>& poses) {
  using Tol = FeatureTolerances;
  std::vector<BaseStep> steps;
  if (poses.empty()) return steps;
  double heading = poses.front().theta;
  BaseStep run{BaseStep::Kind::kDrive, 0.0, 0.0, {}};  // the straight run being accumulated
  // A turn right after a turn the same way is the same turn in place, only sampled at more
  // waypoints (a time-parameterized trajectory has one every sample period): one rest-to-rest
  // turn, not one stop per sample. A turn back the other way is a new step.
  double last_turn = 0.0;  // signed angle of steps.back() when it is a turn
  auto turnTo = [&](double target) {
    const double signed_turn = angleDiff(target, heading);
    const double turn = std::abs(signed_turn);
    if (turn > Tol::kMinTurnRad) {
      if (!steps.empty() && steps.back().kind == BaseStep::Kind::kTurn && last_turn * signed_turn > 0.0) {
        steps.back().target_heading = target;
        steps.back().amount += turn;
        last_turn += signed_turn;
      } else {
        steps.push_back(BaseStep{BaseStep::Kind::kTurn, target, turn, {}});
        last_turn = signed_turn;
      }
    }
    heading = target;
  };
  auto flushRun = [&]() {
    if (run.amount > 0.0) steps.push_back(std::move(run));
    run = BaseStep{BaseStep::Kind::kDrive, 0.0, 0.0, {}};
  };
  // Unit direction of the current run; a segment continues the run when its direction is within
  // kCollinearRad of it (cross product test, so atan2 is only paid at the start of a run).
  double run_ux = 0.0, run_uy = 0.0;
  const double sin_tol = std::sin(Tol::kCollinearRad);
  for (std::size_t i = 1; i < poses.size(); ++i) {
    const Pose2D& p = poses[i - 1];
    const Pose2D& q = poses[i];
    const double dx = q.x - p.x;
    const double dy = q.y - p.y;
    const double d = std::sqrt(dx * dx + dy * dy);
    if (d < Tol::kMinTranslationM) {
      // Turn in place to this waypoint's heading (if it asks for one).
      if (std::abs(angleDiff(q.theta, heading)) > Tol::kMinTurnRad) {
        flushRun();
        turnTo(q.theta);
      }
      continue;
    }
    if (run.amount > 0.0) {
      const double dot = run_ux * dx + run_uy * dy;
      const double cross = run_ux * dy - run_uy * dx;
      if (dot > 0.0 && std::abs(cross) <= sin_tol * d) {
        run.amount += d;
        run.points.push_back(i);
        continue;
      }
    }
    flushRun();
    // Forwards or backwards, whichever turns less.
    const double forwards = std::atan2(dy, dx);
    const double backwards = std::remainder(forwards + M_PI, 2.0 * M_PI);
    turnTo(std::abs(angleDiff(backwards, heading)) < std::abs(angleDiff(forwards, heading)) ? backwards : forwards);
    run_ux = dx / d;
    run_uy = dy / d;
    run.amount = d;
    run.points = {i};
  }
  flushRun();
  turnTo(poses.back().theta);
  return steps;
}

std::vector<ArmRun> armRuns(const std::vector<std::vector<double>>& waypoints,
                            const std::vector<std::string>& joint_names, const FeatureOptions& options) {
  using Tol = FeatureTolerances;
  const std::size_t n = joint_names.size();
  std::vector<double> inv_scale(n, 1.0);
  for (std::size_t j = 0; j < n && !options.joint_scales.empty(); ++j) {
    const auto it = options.joint_scales.find(joint_names[j]);
    if (it != options.joint_scales.end()) inv_scale[j] = 1.0 / it->second;
  }
  std::vector<ArmRun> runs;
  std::vector<double> run_delta(n, 0.0);  // joint displacement of the current straight run
  std::vector<double> last_dir;           // unit direction of the last segment (empty = none)
  std::vector<double> delta(n);
  auto flushRun = [&]() {
    double largest = 0.0;
    for (std::size_t j = 0; j < n; ++j) largest = std::max(largest, std::abs(run_delta[j]) * inv_scale[j]);
    if (largest >= Tol::kMinJointMove) runs.push_back(ArmRun{run_delta, largest});
    std::fill(run_delta.begin(), run_delta.end(), 0.0);
    last_dir.clear();
  };
  for (std::size_t i = 1; i < waypoints.size(); ++i) {
    double largest = 0.0;
    double norm2 = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      delta[j] = waypoints[i][j] - waypoints[i - 1][j];
      largest = std::max(largest, std::abs(delta[j]));
      norm2 += delta[j] * delta[j];
    }
    if (largest < Tol::kMinJointMove) continue;
    const double norm = std::sqrt(norm2);
    double dot = 0.0;
    if (!last_dir.empty()) {
      for (std::size_t j = 0; j < n; ++j) dot += last_dir[j] * delta[j] / norm;
    }
    if (last_dir.empty() || dot < 1.0 - Tol::kArmCollinearCos) flushRun();
    last_dir.resize(n);
    for (std::size_t j = 0; j < n; ++j) {
      run_delta[j] += delta[j];
      last_dir[j] = delta[j] / norm;
    }
  }
  flushRun();
  return runs;
}

MoveSet::MoveSet(std::vector<double> lengths) : lengths_(std::move(lengths)) {
  for (double d : lengths_) {
    if (!std::isfinite(d) || d < 0.0) {
      throw std::invalid_argument("MoveSet: move length must be finite and >= 0, got " + formatNumber(d));
    }
  }
  std::sort(lengths_.begin(), lengths_.end());
  prefix_.resize(lengths_.size() + 1);
  prefix_sqrt_.resize(lengths_.size() + 1);
  prefix_[0] = prefix_sqrt_[0] = 0.0;
  for (std::size_t i = 0; i < lengths_.size(); ++i) {
    prefix_[i + 1] = prefix_[i] + lengths_[i];
    prefix_sqrt_[i + 1] = prefix_sqrt_[i] + std::sqrt(lengths_[i]);
  }
}

std::size_t MoveSet::countBelow(double threshold) const {
  return static_cast<std::size_t>(std::lower_bound(lengths_.begin(), lengths_.end(), threshold) -
                                  lengths_.begin());
}

Status FeatureOptions::validate() const {
  for (const auto& [joint, scale] : joint_scales) {
    if (!(std::isfinite(scale) && scale > 0.0)) {
      return invalid("scale of joint '" + joint + "' must be positive and finite, got " + formatNumber(scale),
                     "joint_scales." + joint);
    }
  }
  return Status::Ok();
}

Result<ActionFeatures> extractFeatures(const ActionDescription& action, const FeatureOptions& options) {
  for (const auto& [joint, scale] : options.joint_scales) {
    if (!(std::isfinite(scale) && scale > 0.0)) {
      throw std::invalid_argument("extractFeatures: " + options.validate().error().toString());
    }
  }
  if (!knownKind(action.kind)) {
    return invalid("unknown action kind " + std::to_string(static_cast<int>(action.kind)), "kind");
  }
  if (!std::isfinite(action.object_mass_kg) || action.object_mass_kg < 0.0 ||
      action.object_mass_kg > InputLimits::kMaxObjectMassKg) {
    return invalid("object mass must be finite and in [0, " + formatNumber(InputLimits::kMaxObjectMassKg) + "] kg, got " +
                       formatNumber(action.object_mass_kg),
                   "object_mass_kg");
  }
  const bool manipulation = action.kind == ActionKind::kPick || action.kind == ActionKind::kPlace;
  const std::string kind_name(toString(action.kind));
  if (manipulation) {
    if (!action.path.empty() || !action.path.joint_names.empty()) {
      return invalid(kind_name + " takes approach_m/retreat_m, not a path", "path");
    }
    for (auto [value, field] : {std::pair{action.approach_m, "approach_m"},
                                std::pair{action.retreat_m, "retreat_m"}}) {
      if (!std::isfinite(value) || value < 0.0 || value > InputLimits::kMaxDistanceM) {
        return invalid(kind_name + ": distance must be finite and in [0, " + formatNumber(InputLimits::kMaxDistanceM) +
                           "] m, got " + formatNumber(value),
                       field);
      }
    }
    ActionFeatures f;
    f.kind = action.kind;
    f.approach_m = action.approach_m;
    f.retreat_m = action.retreat_m;
    f.object_mass_kg = action.object_mass_kg;
    return f;
  }
  if (action.approach_m != 0.0 || action.retreat_m != 0.0) {
    return invalid(kind_name + " takes a path; approach_m/retreat_m are for pick/place only",
                   action.approach_m != 0.0 ? "approach_m" : "retreat_m");
  }
  return action.kind == ActionKind::kMoveBase ? baseFeatures(action) : armFeatures(action, options);
}

Status validateFeatures(const ActionFeatures& f) {
  if (!knownKind(f.kind)) return invalid("unknown action kind " + std::to_string(static_cast<int>(f.kind)), "kind");
  if (!std::isfinite(f.object_mass_kg) || f.object_mass_kg < 0.0 || f.object_mass_kg > InputLimits::kMaxObjectMassKg) {
    return invalid("object mass must be finite and in [0, " + formatNumber(InputLimits::kMaxObjectMassKg) + "] kg, got " +
                       formatNumber(f.object_mass_kg),
                   "object_mass_kg");
  }
  const bool manipulation = f.kind == ActionKind::kPick || f.kind == ActionKind::kPlace;
  if (manipulation) {
    if (!f.moves.empty() || !f.turns.empty()) return invalid("pick/place features have no moves", "moves");
    for (auto [value, field] : {std::pair{f.approach_m, "approach_m"}, std::pair{f.retreat_m, "retreat_m"}}) {
      if (!std::isfinite(value) || value < 0.0 || value > InputLimits::kMaxDistanceM) {
        return invalid("distance must be finite and in [0, " + formatNumber(InputLimits::kMaxDistanceM) + "] m, got " +
                           formatNumber(value),
                       field);
      }
    }
    return Status::Ok();
  }
  if (f.approach_m != 0.0 || f.retreat_m != 0.0) {
    return invalid("motion features have no approach/retreat distances", "approach_m");
  }
  if (f.kind == ActionKind::kMoveArm && !f.turns.empty()) {
    return invalid("move_arm features have no turns", "turns");
  }
  // MoveSet guarantees finite, non-negative lengths; bound them as extraction would.
  const double max_move = 2.0 * InputLimits::kMaxAbsPathValue * std::sqrt(2.0);
  for (const MoveSet* set : {&f.moves, &f.turns}) {
    if (!set->empty() && set->lengths().back() > max_move) {
      return invalid("move of " + formatNumber(set->lengths().back()) + " exceeds the input limits", set == &f.moves ? "moves" : "turns");
    }
  }
  return Status::Ok();
}

}  // namespace tamp::effort_model
