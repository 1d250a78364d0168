// libFuzzer target: arbitrary execution records and estimate requests (as they arrive from DDS):
// kind, joint names, waypoints (any doubles, NaN/inf included), distances, mass, duration. Must
// never crash; an accepted request must give a finite, positive estimate.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>

#include "fuzz_input.h"
#include "tamp/effort_estimator/effort_estimator.h"

namespace ee = tamp::effort_estimator;

namespace {

using Reader = tamp::fuzz::Input;

ee::EffortEstimator& estimator() {
  static ee::EffortEstimator* est = [] {
    ee::EstimatorParams p;
    p.store_directory = "";
    p.refit_batch_size = 64;
    return new ee::EffortEstimator(p, /*start_worker=*/false);
  }();
  return *est;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader r{data, size};
  ee::ExecutionRecord rec;
  rec.action.kind = static_cast<tamp::ActionKind>(r.byte() % 6);  // includes invalid kinds
  const int joints = r.byte() % 5;
  static const char* kNames[] = {"base_x", "base_y", "base_theta", "j1", "j2", "j1"};
  for (int j = 0; j < joints; ++j) rec.action.path.joint_names.push_back(kNames[r.byte() % 6]);
  const int waypoints = r.byte() % 8;
  for (int w = 0; w < waypoints; ++w) {
    std::vector<double> q(static_cast<std::size_t>(r.byte() % 5));
    for (double& v : q) v = r.byte() % 4 == 0 ? r.number() : (r.byte() - 128) / 16.0;
    rec.action.path.waypoints.push_back(q);
  }
  if (r.byte() % 2 == 0) {
    rec.action.approach_m = r.number();
    rec.action.retreat_m = r.number();
  }
  rec.action.object_mass_kg = r.byte() % 2 == 0 ? r.number() : r.byte() / 50.0;
  rec.duration_s = r.byte() % 2 == 0 ? r.number() : r.byte() / 10.0;
  rec.timestamp_s = r.byte();
  auto e = estimator().estimate(rec.action);
  if (e.ok() && !(std::isfinite(e->mean_s) && e->mean_s > 0 && std::isfinite(e->stddev_s))) std::abort();
  (void)estimator().addRecord(rec);
  if (estimator().pendingCount(tamp::ActionKind::kMoveBase) >= 64) (void)estimator().refitNow();
  return 0;
}
