#pragma once
// The time models as templates over the scalar type, so that the same code gives durations
// (double), and durations with derivatives (ceres::Jet) for the fits and the covariance
// propagation. Private to the library: no Ceres here, the Jet instantiations live in the .cc files.

#include <cmath>
#include <cstddef>

#include "tamp/effort_model/features.h"

namespace tamp::effort_model::detail {

inline double scalarOf(double x) { return x; }
template <typename J>
double scalarOf(const J& x) {
  return x.a;  // ceres::Jet: the value part
}

/// Stop-to-stop move time of one move of length d >= 0 (see models.h).
template <typename T>
T trapezoid(double d, const T& v, const T& a) {
  using std::sqrt;
  if (!(d > 0.0)) return T(0.0);
  const double threshold = scalarOf(v) * scalarOf(v) / scalarOf(a);
  if (d >= threshold) return d / v + v / a;
  return 2.0 * sqrt(d / a);
}

/// Sum of trapezoid times over a MoveSet in O(log n) (see MoveSet).
template <typename T>
T trapezoidSum(const MoveSet& s, const T& v, const T& a) {
  using std::sqrt;
  const std::size_t n = s.size();
  T out(0.0);
  if (n == 0) return out;
  const double threshold = scalarOf(v) * scalarOf(v) / scalarOf(a);
  const std::size_t k = s.countBelow(threshold);
  if (k > 0) out += (2.0 * s.prefixSqrtSum()[k]) / sqrt(a);
  if (k < n) out += (s.total() - s.prefixSum()[k]) / v + static_cast<double>(n - k) * (v / a);
  return out;
}

/// The model of `f.kind` for physical parameters `p` (modelSpec order). Preconditions (checked
/// by the callers): p has the model's size, every p[i] > 0.
template <typename T>
T duration(const ActionFeatures& f, const T* p) {
  switch (f.kind) {
    case ActionKind::kMoveBase: {
      const double stops = static_cast<double>(f.moves.size() + f.turns.size());
      const T slow = 1.0 + p[6] * f.object_mass_kg;
      return p[5] + p[4] * stops + trapezoidSum(f.moves, T(p[0] / slow), T(p[1] / slow)) +
             trapezoidSum(f.turns, T(p[2] / slow), T(p[3] / slow));
    }
    case ActionKind::kMoveArm: {
      const T slow = 1.0 + p[4] * f.object_mass_kg;
      return p[3] + p[2] * static_cast<double>(f.moves.size()) +
             trapezoidSum(f.moves, T(p[0] / slow), T(p[1] / slow));
    }
    case ActionKind::kPick: {
      const T slow = 1.0 + p[3] * f.object_mass_kg;
      return trapezoid(f.approach_m, p[0], p[1]) + p[2] +
             trapezoid(f.retreat_m, T(p[0] / slow), T(p[1] / slow));
    }
    case ActionKind::kPlace: {
      const T slow = 1.0 + p[3] * f.object_mass_kg;
      return trapezoid(f.approach_m, T(p[0] / slow), T(p[1] / slow)) + p[2] +
             trapezoid(f.retreat_m, p[0], p[1]);
    }
  }
  return T(0.0);
}

}  // namespace tamp::effort_model::detail
