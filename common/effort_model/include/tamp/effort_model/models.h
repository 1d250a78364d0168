#pragma once
/// @file
/// The execution-time models: one small physical model per action kind, with named parameters,
/// units, defaults and bounds, and the model as a pure function of (features, parameters).
///
/// Every move is a stop-to-stop trapezoidal (or, if short, triangular) velocity profile:
///   trap(d; v, a) = d/v + v/a   if d >= v^2/a,   2*sqrt(d/a) otherwise      (d >= 0)
/// which is continuous and continuously differentiable in d, v and a.
///
/// - **move_base** (differential drive executed stop-and-turn, see `extractFeatures`):
///   `T = overhead + settle*(n_moves + n_turns) + sum trap(d_i; v/f, a/f) + sum trap(|phi_j|; w/f, alpha/f)`,
///   `f = 1 + payload_slowdown * m` (m: the mass carried in the gripper or pushed ahead)
///   parameters: max_linear_speed v (m/s), max_linear_accel a (m/s^2), max_angular_speed w
///   (rad/s), max_angular_accel alpha (rad/s^2), settle_time (s per stop), overhead (s),
///   payload_slowdown (1/kg).
/// - **move_arm** (joint trapezoids synchronized to the slowest joint; with common joint limits the
///   slowest joint is the one with the largest displacement D_i of the segment):
///   `T = overhead + settle*n + sum trap(D_i; v/f, a/f)`, `f = 1 + payload_slowdown * m`
///   parameters: max_joint_speed (rad/s), max_joint_accel (rad/s^2), settle_time (s per
///   segment), overhead (s), payload_slowdown (1/kg).
/// - **pick**: approach empty-handed, close the gripper, retreat carrying the object:
///   `T = trap(approach; v, a) + gripper_time + trap(retreat; v/f, a/f)`
/// - **place**: approach carrying the object, open the gripper, retreat empty-handed:
///   `T = trap(approach; v/f, a/f) + gripper_time + trap(retreat; v, a)`
///   parameters (each kind its own set): approach_speed (m/s), approach_accel (m/s^2),
///   gripper_time (s, includes the fixed overhead of the action), payload_slowdown (1/kg).
///
/// All parameters are positive; the fits work on their logarithms, bounded by `lower`/`upper`,
/// with a Gaussian prior on log(value) centred on the default (`prior_log_stddev`).
///
/// Identifiability: a parameter only shows in records that excite it. Cruise speeds need moves
/// longer than v^2/a; accelerations need moves shorter than that (a long move's v/a term is
/// confounded with the per-stop settle time); payload_slowdown needs records with and without
/// loads. Gripper approaches (a few cm at a few cm/s) are practically always cruise-limited, so
/// pick/place approach_accel is confounded with gripper_time: the prior keeps it at its default,
/// which costs nothing in prediction accuracy on such actions.

#include <span>
#include <string>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/trajectory.h"
#include "tamp/effort_model/features.h"

namespace tamp::effort_model {

/// Largest number of parameters of any model (move_base).
inline constexpr int kMaxModelParameters = 7;

/// One named, positive model parameter.
struct ParameterSpec {
  std::string name;         ///< snake_case, unique within a model
  std::string unit;         ///< "m/s", "s", "1/kg", ...
  double default_value{};   ///< prior mean (in log space: log(default_value)); lower < default < upper
  double lower{};           ///< > 0
  double upper{};           ///< > lower
  double prior_log_stddev{};  ///< stddev of the prior on log(value); > 0
  std::string description;
};

/// The parameters of one action kind's model, in the order of the parameter vectors.
struct ModelSpec {
  ActionKind kind{ActionKind::kMoveBase};
  std::vector<ParameterSpec> parameters;

  int size() const { return static_cast<int>(parameters.size()); }
  /// Index of a parameter name, or -1.
  int indexOf(const std::string& name) const;
  std::vector<std::string> names() const;
  std::vector<double> defaults() const;
};

/// The model definition of `kind` (a static table; the reference stays valid).
/// @throws std::invalid_argument for a value outside the ActionKind enumerators.
const ModelSpec& modelSpec(ActionKind kind);

/// Trapezoidal stop-to-stop move time (s) of a move of length `d` >= 0 with max speed `v` > 0 and
/// max acceleration `a` > 0 (any consistent units).
double trapezoidTime(double d, double v, double a);

/// The model's execution time (s) of an action with `features`, for `params` in physical units in
/// `modelSpec(features.kind)` order. A pure function: the simulator calls it with its true
/// parameters, the estimator with fitted ones.
/// @throws std::invalid_argument if params has the wrong size or a non-positive/non-finite value.
double predictDuration(const ActionFeatures& features, std::span<const double> params);

/// Same, from an action description (features extracted first with `options`; errors as
/// `extractFeatures`).
Result<double> predictDuration(const ActionDescription& action, std::span<const double> params,
                               const FeatureOptions& options = {});

/// Execution time and its gradient with respect to log(params) (s per unit log change), for the
/// propagation of parameter covariance. `gradient` gets `params.size()` entries.
/// @throws std::invalid_argument as predictDuration.
double predictDurationWithLogGradient(const ActionFeatures& features, std::span<const double> params,
                                      std::span<double> gradient);

}  // namespace tamp::effort_model
