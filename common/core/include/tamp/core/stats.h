#pragma once
/// @file
/// Percentiles for benchmark tools: `q` in [0, 1] over a copy of the samples.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace tamp {

/// Linear interpolation between the closest ranks (NumPy's default); NaN when `v` is empty.
inline double interpolatedPercentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double idx = q * (static_cast<double>(v.size()) - 1);
  const auto lo = static_cast<std::size_t>(std::floor(idx));
  const auto hi = static_cast<std::size_t>(std::ceil(idx));
  return v[lo] + (v[hi] - v[lo]) * (idx - static_cast<double>(lo));
}

/// The sample at the rounded rank q * (n - 1) (a value that was measured); NaN when `v` is empty.
inline double nearestRankPercentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5));
  return v[i];
}

}  // namespace tamp
