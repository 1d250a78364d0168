#pragma once
// Synthetic actions and simulated executions for tests and benchmarks: random but plausible
// paths for each action kind, executed with "true" parameters (different from the defaults)
// through the same pure model functions the simulator uses, plus multiplicative log-normal noise
// and optional outliers (stalls). Deterministic for a given RNG state.

#include <random>
#include <span>
#include <vector>

#include "tamp/effort_estimator/features.h"
#include "tamp/effort_estimator/records.h"

namespace tamp::effort_estimator::synthetic {

/// How random actions are drawn.
struct ActionDistribution {
  bool short_moves_only{false};  ///< only short base drives/turns and small arm moves (little excitation)
};

/// A random action of `kind` (move_base: 2-12 waypoints with long and short drives, some densely
/// sampled; move_arm: 6 joints, 2-6 waypoints; pick/place: 3-30 cm approach/retreat, 0-3 kg).
ActionDescription randomAction(ActionKind kind, std::mt19937_64& rng, const ActionDistribution& dist = {});

/// The "true" parameters of the simulated robot: the defaults times fixed factors in 0.6-2.0.
std::vector<double> trueParameters(ActionKind kind);

/// Per-joint speed scales of the mismatched robot's arm (what its URDF velocity limits say), as
/// the estimator would be configured for it: 1, 1, 0.8, 0.8, 1.3, 1.3 for arm_joint_1..6.
FeatureOptions urdfJointScales();

/// Noise of a simulated execution.
struct ExecutionNoise {
  double log_stddev{0.03};      ///< multiplicative noise, stddev of log(duration)
  double outlier_fraction{0.0}; ///< probability of a stall
  double outlier_min{1.5};      ///< a stall multiplies the duration by U(min, max)
  double outlier_max{3.0};
  /// Execute with a robot that does NOT follow the estimator's model exactly (unmodelled
  /// effects): arm joints whose acceleration limits do not scale like their speed limits
  /// (speed scales `urdfJointScales()`, acceleration scales 1, 0.9, 0.8, 0.7, 1.3, 1.5), a 0.08 s
  /// re-targeting pause per base waypoint, and a gripper time that grows with the square of the
  /// mass (+0.1 s/kg^2).
  bool mismatch{false};
};

/// Executes `action` with `params`: the model's duration (or the mismatched robot's, see
/// ExecutionNoise::mismatch) times exp(N(0, log_stddev)), sometimes times a stall factor.
ExecutionRecord simulate(const ActionDescription& action, std::span<const double> params,
                         const ExecutionNoise& noise, std::mt19937_64& rng, double timestamp_s = 0.0);

/// `n` simulated records of `kind` with the true parameters.
std::vector<ExecutionRecord> records(ActionKind kind, int n, std::mt19937_64& rng,
                                     const ExecutionNoise& noise = {}, const ActionDistribution& dist = {});

/// The same as feature records (for fitModel).
std::vector<FeatureRecord> featureRecords(ActionKind kind, int n, std::mt19937_64& rng,
                                          const ExecutionNoise& noise = {}, const ActionDistribution& dist = {});

}  // namespace tamp::effort_estimator::synthetic
