#pragma once
/// @file
/// What the effort estimator needs to know about an action, and the features it extracts from it.
///
/// An `ActionDescription` is what a caller has: the action kind, the geometric path the motion
/// planner produced (move_base, move_arm) or the approach/retreat distances (pick, place), and
/// the mass of the object in the gripper. `extractFeatures()` turns it once into
/// `ActionFeatures`: the sorted lengths of the stop-to-stop moves the robot will make, with prefix
/// sums, so that evaluating a time model on them costs O(log n) whatever the number of waypoints
/// (see `MoveSet`). Features are what execution records store and what the fits use.

#include <cstddef>
#include <string>
#include <unordered_map>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/core/geometry.h"
#include "tamp/core/trajectory.h"

namespace tamp::effort_model {

/// An action as the planner or the executive describes it. Maps field by field to an IDL struct.
///
/// - move_base: `path` over exactly `base_x` (m), `base_y` (m), `base_theta` (rad), world frame,
///   in any column order; at least one waypoint.
/// - move_arm: `path` over the arm joints (rad, or m for prismatic joints), no base joints; at
///   least one waypoint.
/// - pick/place: `path` empty; `approach_m`/`retreat_m` are the straight gripper motions (m)
///   between the pre-grasp configuration and the grasp pose, before and after closing/opening.
/// `object_mass_kg` is the mass of the object being picked, placed or carried (0 = none).
struct ActionDescription {
  ActionKind kind{ActionKind::kMoveBase};
  JointPath path;
  double approach_m{0.0};
  double retreat_m{0.0};
  double object_mass_kg{0.0};
};

/// A multiset of stop-to-stop move lengths (m or rad), kept sorted ascending with prefix sums of
/// the lengths and of their square roots. That is a sufficient statistic for the sum of
/// trapezoidal move times: with vmax `v` and amax `a`, a move of length d takes
/// `d/v + v/a` when `d >= v^2/a` and `2*sqrt(d/a)` otherwise, so the sum over all moves is
/// `2*R_k/sqrt(a) + (S_n - S_k)/v + (n-k)*v/a` where k counts the moves shorter than `v^2/a`
/// (a binary search) and S, R are the prefix sums.
class MoveSet {
 public:
  MoveSet() = default;
  /// @throws std::invalid_argument if a length is negative or not finite.
  explicit MoveSet(std::vector<double> lengths);

  std::size_t size() const { return lengths_.size(); }
  bool empty() const { return lengths_.empty(); }
  /// Sorted ascending.
  const std::vector<double>& lengths() const { return lengths_; }
  /// prefixSum()[k] = sum of the k shortest lengths; size() + 1 entries.
  const std::vector<double>& prefixSum() const { return prefix_; }
  /// prefixSqrtSum()[k] = sum of sqrt of the k shortest lengths; size() + 1 entries.
  const std::vector<double>& prefixSqrtSum() const { return prefix_sqrt_; }
  double total() const { return prefix_.back(); }
  /// Number of moves strictly shorter than `threshold`.
  std::size_t countBelow(double threshold) const;

  friend bool operator==(const MoveSet& a, const MoveSet& b) { return a.lengths_ == b.lengths_; }

 private:
  std::vector<double> lengths_;
  std::vector<double> prefix_{0.0};
  std::vector<double> prefix_sqrt_{0.0};
};

/// The features of one action, the input of its time model.
struct ActionFeatures {
  ActionKind kind{ActionKind::kMoveBase};
  /// move_base: straight drives (m); move_arm: per merged path segment, the largest scaled joint
  /// displacement (rad); pick/place: empty.
  MoveSet moves;
  /// move_base: turns in place (rad, absolute); otherwise empty.
  MoveSet turns;
  double approach_m{0.0};      ///< pick/place only
  double retreat_m{0.0};       ///< pick/place only
  double object_mass_kg{0.0};  ///< >= 0

  friend bool operator==(const ActionFeatures&, const ActionFeatures&) = default;
};

/// Tolerances of the path-to-moves reduction (documented, shared by the simulator through
/// `extractFeatures`).
struct FeatureTolerances {
  /// Base translations shorter than this (m) are treated as no translation.
  static constexpr double kMinTranslationM = 1e-4;
  /// Base turns smaller than this (rad) are not executed as a separate turn in place.
  static constexpr double kMinTurnRad = 1e-3;
  /// Consecutive base segments whose heading differs from the heading at the start of the
  /// current straight run by at most this (rad) are driven as one straight move, without a stop.
  static constexpr double kCollinearRad = 0.02;
  /// Arm segments whose largest joint displacement is below this (rad) are ignored.
  static constexpr double kMinJointMove = 1e-6;
  /// Consecutive arm segments whose directions (unit vectors in joint space) have a dot product
  /// of at least 1 - this are one move without a stop (a densely sampled straight line).
  static constexpr double kArmCollinearCos = 1e-6;
};

/// Robot-specific knowledge the path-to-moves reduction needs.
struct FeatureOptions {
  /// Relative speed and acceleration limit of each arm joint, by joint name (e.g. its URDF
  /// velocity limit divided by that of the fastest joint); joints not listed have scale 1; every
  /// scale > 0 and finite. With per-joint limits v_j = s_j v and a_j = s_j a, joint j needs
  /// trap(|dq_j|; s_j v, s_j a) = trap(|dq_j| / s_j; v, a), so a segment's synchronized time is
  /// that of its largest scaled displacement max_j |dq_j| / s_j.
  std::unordered_map<std::string, double> joint_scales;

  /// Ok, or kInvalidArgument naming the joint with a bad scale.
  Status validate() const;
};

/// One step of the stop-and-turn execution of a base path (see baseSteps).
struct BaseStep {
  enum class Kind { kTurn, kDrive };
  Kind kind{Kind::kTurn};
  double target_heading{0.0};        ///< kTurn: the heading turned to (rad)
  double amount{0.0};                ///< kTurn: |turn| (rad, > kMinTurnRad); kDrive: run length (m)
  std::vector<std::size_t> points;   ///< kDrive: the waypoints driven through, in order
};

/// The stop-and-turn steps of a base path (`poses`: its waypoints' base poses): for each straight
/// run of the polyline (merged per FeatureTolerances::kCollinearRad), a turn in place to the
/// run's heading (driven forwards or backwards, whichever turns less), then the drive; a waypoint without translation but with a new heading is a turn
/// in place to it (consecutive turns the same way are one turn: a trajectory samples one turn at
/// many waypoints); at the end a turn to the last heading. Turns up to kMinTurnRad and
/// translations below kMinTranslationM are not steps. The segmentation the move_base features and
/// the simulator's base timeline share.
std::vector<BaseStep> baseSteps(const std::vector<Pose2D>& poses);

/// A straight run of an arm path: consecutive segments in one joint-space direction (within
/// FeatureTolerances::kArmCollinearCos), executed as one synchronized move.
struct ArmRun {
  std::vector<double> delta;  ///< joint displacement over the run, per joint of the path
  double length{0.0};         ///< largest scaled joint displacement (FeatureOptions::joint_scales)
};

/// The straight runs of an arm path whose waypoints are over `joint_names`: the segmentation the
/// move_arm features (one move per run) and the simulator's arm timeline share. Segments and runs
/// shorter than FeatureTolerances::kMinJointMove are dropped. Waypoints must all have
/// `joint_names.size()` values (not checked here: actionFeatures() validates paths).
std::vector<ArmRun> armRuns(const std::vector<std::vector<double>>& waypoints,
                            const std::vector<std::string>& joint_names, const FeatureOptions& options);

/// Plausibility limits of action inputs: beyond them a request is rejected (a value of 1e300 m is
/// a corrupt message, not an action, and would overflow the models).
struct InputLimits {
  static constexpr double kMaxAbsPathValue = 1e5;   ///< |waypoint value|: m for the base, rad/m for joints
  static constexpr double kMaxDistanceM = 100.0;    ///< approach_m, retreat_m
  static constexpr double kMaxObjectMassKg = 1e4;   ///< object_mass_kg
};

/// Reduces an action to its features.
///
/// move_base is executed stop-and-turn: from the first waypoint's pose, for each straight run of
/// the polyline (merged per `kCollinearRad`), turn in place to the run's heading, then drive it;
/// at the end turn in place to the last waypoint's `base_theta`. A waypoint without translation
/// but with a new `base_theta` is a turn in place to that angle. move_arm: each merged segment is
/// one synchronized move whose length is its largest scaled joint displacement (see
/// FeatureOptions::joint_scales).
///
/// @return the features, or a kInvalidArgument error whose message says what is wrong (unknown
///   kind, empty path, waypoint size mismatch, missing or unexpected joints, non-finite values,
///   negative distances or mass, values beyond `InputLimits`, a path given to pick/place or
///   distances to a motion).
/// @throws std::invalid_argument if `options.validate()` fails (misuse).
Result<ActionFeatures> extractFeatures(const ActionDescription& action, const FeatureOptions& options = {});

/// Checks features built by hand (e.g. read from a store): finite, non-negative, kind-consistent.
Status validateFeatures(const ActionFeatures& features);

}  // namespace tamp::effort_model
