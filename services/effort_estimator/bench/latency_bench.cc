// Effort estimation latency (issue 5): one estimate from precomputed features and from a path
// (feature extraction included), the pure model function, recording, and a refit.
//   tamp_effort_estimator_latency [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>
#include <unistd.h>

#include "synthetic.h"
#include "tamp/core/log.h"
#include "tamp/effort_estimator/effort_estimator.h"

namespace ee = tamp::effort_estimator;
using tamp::ActionKind;

namespace {

ee::EstimatorParams memoryParams() {
  ee::EstimatorParams p;
  p.store_directory = "";
  return p;
}

/// An estimator whose models were fitted (non-trivial covariance), shared by the benchmarks.
ee::EffortEstimator& fittedEstimator() {
  static ee::EffortEstimator* est = [] {
    tamp::log::setLevel("warn");
    auto* e = new ee::EffortEstimator(memoryParams(), false);
    std::mt19937_64 rng(1);
    for (ActionKind k : tamp::kAllActionKinds) {
      for (const auto& r : ee::synthetic::records(k, 100, rng)) (void)e->addRecord(r);
    }
    (void)e->refitNow();
    return e;
  }();
  return *est;
}

/// A base path of `n` waypoints: a random polyline with corners every few waypoints.
ee::ActionDescription basePath(int n, std::mt19937_64& rng) {
  ee::ActionDescription a;
  a.kind = ActionKind::kMoveBase;
  a.path.joint_names = {"base_x", "base_y", "base_theta"};
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double x = 0, y = 0, h = 0;
  for (int i = 0; i < n; ++i) {
    if (i % 4 == 0) h += u(rng);
    x += 0.3 * std::cos(h);
    y += 0.3 * std::sin(h);
    a.path.waypoints.push_back({x, y, h});
  }
  return a;
}

void BM_EstimateFromFeatures(benchmark::State& state) {
  const auto kind = tamp::kAllActionKinds[static_cast<std::size_t>(state.range(0))];
  ee::EffortEstimator& est = fittedEstimator();
  std::mt19937_64 rng(2);
  std::vector<ee::ActionFeatures> fs;
  for (int i = 0; i < 64; ++i) fs.push_back(*ee::extractFeatures(ee::synthetic::randomAction(kind, rng)));
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(est.estimate(fs[i++ & 63]));
  }
  state.SetLabel(std::string(tamp::toString(kind)));
}
BENCHMARK(BM_EstimateFromFeatures)->DenseRange(0, 3)->ThreadRange(1, 2);

void BM_EstimateFromBasePath(benchmark::State& state) {
  ee::EffortEstimator& est = fittedEstimator();
  std::mt19937_64 rng(3);
  const ee::ActionDescription a = basePath(static_cast<int>(state.range(0)), rng);
  for (auto _ : state) {
    auto e = est.estimate(a);
    benchmark::DoNotOptimize(e);
  }
  state.SetLabel(std::to_string(state.range(0)) + " waypoints");
}
BENCHMARK(BM_EstimateFromBasePath)->Arg(3)->Arg(20)->Arg(100)->Arg(1000);

void BM_EstimateFromArmPath(benchmark::State& state) {
  ee::EffortEstimator& est = fittedEstimator();
  std::mt19937_64 rng(4);
  ee::ActionDescription a = ee::synthetic::randomAction(ActionKind::kMoveArm, rng);
  // Densify to state.range(0) waypoints by linear interpolation (as a planner's output is).
  const auto coarse = a.path.waypoints;
  a.path.waypoints.clear();
  const int n = static_cast<int>(state.range(0));
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1) * static_cast<double>(coarse.size() - 1);
    const std::size_t k = std::min(static_cast<std::size_t>(s), coarse.size() - 2);
    const double t = s - static_cast<double>(k);
    std::vector<double> q(coarse[k].size());
    for (std::size_t j = 0; j < q.size(); ++j) q[j] = (1 - t) * coarse[k][j] + t * coarse[k + 1][j];
    a.path.waypoints.push_back(q);
  }
  for (auto _ : state) {
    auto e = est.estimate(a);
    benchmark::DoNotOptimize(e);
  }
  state.SetLabel("6 joints, " + std::to_string(n) + " waypoints");
}
BENCHMARK(BM_EstimateFromArmPath)->Arg(10)->Arg(100);

void BM_PredictDurationPure(benchmark::State& state) {
  std::mt19937_64 rng(5);
  const auto f = *ee::extractFeatures(basePath(100, rng));
  const std::vector<double> p = ee::synthetic::trueParameters(ActionKind::kMoveBase);
  for (auto _ : state) benchmark::DoNotOptimize(ee::predictDuration(f, p));
  state.SetLabel("move_base, " + std::to_string(f.moves.size() + f.turns.size()) + " moves");
}
BENCHMARK(BM_PredictDurationPure);

void BM_AddRecord(benchmark::State& state) {
  const bool sqlite = state.range(0) != 0;
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("tamp_effort_bench_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ee::EstimatorParams p = memoryParams();
  if (sqlite) p.store_directory = dir.string();
  p.refit_batch_size = 1 << 30;  // no refit during the measurement
  p.max_records_per_kind = 1 << 20;
  {
    ee::EffortEstimator est(p, false);
    std::mt19937_64 rng(6);
    const auto recs = ee::synthetic::records(ActionKind::kMoveBase, 256, rng);
    std::size_t i = 0;
    for (auto _ : state) {
      benchmark::DoNotOptimize(est.addRecord(recs[i++ & 255]));
    }
  }
  std::filesystem::remove_all(dir);
  state.SetLabel(sqlite ? "SQLite store (WAL, synchronous=NORMAL)" : "memory only");
}
BENCHMARK(BM_AddRecord)->Arg(0)->Arg(1);

void BM_Refit(benchmark::State& state) {
  const auto kind = ActionKind::kMoveBase;
  std::mt19937_64 rng(7);
  const auto recs = ee::synthetic::featureRecords(kind, static_cast<int>(state.range(0)), rng,
                                                  {.log_stddev = 0.03, .outlier_fraction = 0.05});
  const ee::ModelPrior prior = ee::ModelPrior::defaults(kind);
  const ee::KindModel start = ee::priorModel(prior, {});
  for (auto _ : state) {
    auto m = ee::fitModel(start, recs, prior, {});
    benchmark::DoNotOptimize(m);
  }
  state.SetLabel("move_base from the prior, " + std::to_string(state.range(0)) + " records");
}
BENCHMARK(BM_Refit)->Arg(20)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
