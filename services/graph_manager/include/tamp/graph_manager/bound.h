#pragma once
/// @file
/// DriveBound: an admissible lower bound of the predicted effort of a base motion, from the effort
/// model itself (why it is admissible: services/graph_manager/src/bound.cc).
#include <utility>
#include <vector>

#include "tamp/core/error.h"
#include "tamp/graph_manager/clients.h"

namespace tamp::graph_manager {

class DriveBound {
 public:
  /// The distance bound only: d / top_speed, for any robot slower than top_speed (m/s, > 0).
  /// @throws std::invalid_argument when top_speed is not > 0.
  explicit DriveBound(double top_speed);

  /// The drive lengths whose times calibrate the bound: 0, then 5 cm doubling to about 200 m.
  static std::vector<double> lengths();
  /// One straight drive per length, from the origin along x, heading along it: no turn.
  static std::vector<EffortQuery> queries();

  /// Takes the estimator's answers to queries(): the nominal time of each drive (the log-normal
  /// mean divided by sqrt(1 + (stddev/mean)^2)), interpolated. An error, and the distance bound
  /// kept, when an answer is missing or failed, or the times are not concave and increasing in
  /// the length (then they are not the model's, and the interpolation would not be a bound).
  Status calibrate(const std::vector<EffortAnswer>& answers);

  /// At least the predicted effort of any base motion between poses `d` m apart, and at least
  /// d / top_speed. Concave and increasing in d, hence subadditive.
  double operator()(double d) const;
  bool calibrated() const { return !samples_.empty(); }

 private:
  double top_speed_;
  std::vector<std::pair<double, double>> samples_;  ///< (length m, nominal s)
};

}  // namespace tamp::graph_manager
