#include "tamp/effort_estimator/effort_estimator.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <random>
#include <thread>

#include "synthetic.h"
#include "tamp/effort_estimator/store.h"
#include "test_dir.h"

namespace tamp::effort_estimator {
namespace {

using ::testing::HasSubstr;
using testing_support::TempDir;

// Generous: only a wait for the background worker, never a performance assertion.
constexpr double kWaitS = 60.0;

EstimatorParams paramsFor(const std::filesystem::path& dir, int batch = 10, double period_s = 1000.0) {
  EstimatorParams p;
  p.store_directory = dir.string();
  p.refit_batch_size = batch;
  p.refit_period_s = period_s;
  p.surprise_sigma = 0.0;  // batches and periods only (SurprisingRecordIsRefittedAtOnce turns it on)
  return p;
}

TEST(EstimatorTest, EstimatesFromDefaultsBeforeAnyRecord) {
  EffortEstimator est(paramsFor(""), false);
  EXPECT_FALSE(est.persistent());
  EXPECT_TRUE(est.startupWarnings().empty());
  std::mt19937_64 rng(1);
  for (ActionKind kind : kAllActionKinds) {
    const ActionDescription a = synthetic::randomAction(kind, rng);
    auto e = est.estimate(a);
    ASSERT_TRUE(e.ok()) << e.error().toString();
    EXPECT_DOUBLE_EQ(e->nominal_s, *predictDuration(a, modelSpec(kind).defaults()));
    EXPECT_GT(e->stddev_s, 0.0);
    EXPECT_EQ(e->model_version, 0u);
    EXPECT_EQ(e->kind, kind);
  }
  EXPECT_EQ(est.snapshot().version, 0u);
  EXPECT_EQ(est.counters().estimates, 4u);
}

TEST(EstimatorTest, BadRequestsAndRecordsAreRejectedWithAReason) {
  EffortEstimator est(paramsFor(""), false);
  ActionDescription empty;
  empty.kind = ActionKind::kMoveArm;
  auto e = est.estimate(empty);
  ASSERT_FALSE(e.ok());
  EXPECT_THAT(e.error().message, HasSubstr("empty path"));

  std::mt19937_64 rng(2);
  ExecutionRecord r = synthetic::records(ActionKind::kPick, 1, rng)[0];
  r.duration_s = -3.0;
  Status s = est.addRecord(r);
  ASSERT_FALSE(s.ok());
  EXPECT_THAT(s.error().message, HasSubstr("duration must be positive"));
  EXPECT_EQ(s.error().where.field, "duration_s");
  r.duration_s = std::nan("");
  EXPECT_THAT(est.addRecord(r).error().message, HasSubstr("NaN"));
  EXPECT_EQ(est.counters().records_rejected, 2u);
  EXPECT_EQ(est.recordCount(ActionKind::kPick), 0u);
}

TEST(EstimatorTest, BatchEstimatesUseOneSnapshotAndKeepPerRequestErrors) {
  EffortEstimator est(paramsFor(""), false);
  std::mt19937_64 rng(12);
  std::vector<EstimateRequest> reqs;
  for (ActionKind k : kAllActionKinds) reqs.push_back(synthetic::randomAction(k, rng));
  reqs.push_back(EstimateRequest{});  // move_base without a path
  const BatchEstimate b = est.estimateBatch(reqs);
  ASSERT_EQ(b.estimates.size(), 5u);
  EXPECT_EQ(b.snapshot_version, 0u);
  for (std::size_t i = 0; i < 4; ++i) {
    ASSERT_TRUE(b.estimates[i].ok());
    EXPECT_DOUBLE_EQ(b.estimates[i]->mean_s, est.estimate(reqs[i])->mean_s);
  }
  ASSERT_FALSE(b.estimates[4].ok());
  EXPECT_THAT(b.estimates[4].error().message, HasSubstr("empty path"));
}

TEST(EstimatorTest, RefitMovesEstimatesTowardTheTruthAndBumpsVersions) {
  EffortEstimator est(paramsFor(""), false);
  std::mt19937_64 rng(3);
  for (const auto& r : synthetic::records(ActionKind::kMoveBase, 40, rng)) ASSERT_TRUE(est.addRecord(r).ok());
  EXPECT_EQ(est.pendingCount(ActionKind::kMoveBase), 40u);
  const auto reports = est.refitNow();
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_TRUE(reports[0].status.ok());
  EXPECT_EQ(reports[0].version, 1u);
  EXPECT_EQ(est.pendingCount(ActionKind::kMoveBase), 0u);
  const ModelSnapshot snap = est.snapshot();
  EXPECT_EQ(snap.version, 1u);
  EXPECT_EQ(snap.model(ActionKind::kMoveBase).version, 1u);
  EXPECT_EQ(snap.model(ActionKind::kMoveBase).record_count, 40u);
  EXPECT_EQ(snap.model(ActionKind::kPick).version, 0u);

  const std::vector<double> truth = synthetic::trueParameters(ActionKind::kMoveBase);
  const std::vector<double> defaults = modelSpec(ActionKind::kMoveBase).defaults();
  double err_fit = 0, err_default = 0;
  for (int i = 0; i < 100; ++i) {
    const ActionDescription a = synthetic::randomAction(ActionKind::kMoveBase, rng);
    const double t = *predictDuration(a, truth);
    auto e = est.estimate(a);
    ASSERT_TRUE(e.ok());
    EXPECT_EQ(e->model_version, 1u);
    err_fit += std::abs(e->nominal_s - t) / t;
    err_default += std::abs(*predictDuration(a, defaults) - t) / t;
  }
  EXPECT_LT(err_fit / 100, 0.03);
  EXPECT_GT(err_default / 100, 0.10);
}

TEST(EstimatorTest, OnlineWorkerRefitsInBatchesAndBumpsTheVersion) {
  EffortEstimator est(paramsFor("", /*batch=*/5, /*period_s=*/1000.0), true);
  std::atomic<int> callbacks{0};
  std::atomic<std::uint64_t> last_published{0};
  est.setModelUpdateCallback([&](std::shared_ptr<const ModelSnapshot> s) {
    last_published = s->version;
    ++callbacks;
  });
  std::mt19937_64 rng(4);
  const auto recs = synthetic::records(ActionKind::kMoveArm, 10, rng);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(est.addRecord(recs[i]).ok());
  ASSERT_TRUE(est.waitForVersion(ActionKind::kMoveArm, 1, Deadline::in(kWaitS)));
  EXPECT_EQ(est.snapshot().model(ActionKind::kMoveArm).record_count, 5u);
  // Four more stay pending: below the batch size and far from the period.
  for (int i = 5; i < 9; ++i) ASSERT_TRUE(est.addRecord(recs[i]).ok());
  EXPECT_EQ(est.pendingCount(ActionKind::kMoveArm), 4u);
  EXPECT_EQ(est.snapshot().model(ActionKind::kMoveArm).version, 1u);
  ASSERT_TRUE(est.addRecord(recs[9]).ok());
  ASSERT_TRUE(est.waitForVersion(ActionKind::kMoveArm, 2, Deadline::in(kWaitS)));
  EXPECT_EQ(est.snapshot().model(ActionKind::kMoveArm).record_count, 10u);
  EXPECT_EQ(est.snapshot().version, 2u);
  EXPECT_EQ(callbacks.load(), 2);
  EXPECT_EQ(last_published.load(), 2u);
  EXPECT_EQ(est.counters().refits, 2u);
}

TEST(EstimatorTest, ARecordFarOffItsEstimateIsSurprising) {
  Estimate e;
  e.mean_s = 8.0;
  e.stddev_s = 0.5;
  EXPECT_TRUE(surprising(e, 20.4, 3.0));   // a push of a 58 kg chair, priced as a light one
  EXPECT_TRUE(surprising(e, 6.0, 3.0));    // as far below
  EXPECT_FALSE(surprising(e, 9.4, 3.0));   // within 3 stddevs
  EXPECT_FALSE(surprising(e, 20.4, 0.0));  // off
  e.stddev_s = 0.01;                       // a tiny stddev: at least 5 % of the mean counts
  EXPECT_FALSE(surprising(e, 9.1, 3.0));
  EXPECT_TRUE(surprising(e, 9.3, 3.0));
}

TEST(EstimatorTest, ASurprisingRecordIsRefittedAtOnce) {
  // Neither a batch (1000) nor the period (1000 s) would refit: the record's surprise does.
  EstimatorParams p = paramsFor("", /*batch=*/1000, /*period_s=*/1000.0);
  p.surprise_sigma = 3.0;
  EffortEstimator est(p, true);
  std::mt19937_64 rng(11);
  ExecutionRecord r = synthetic::records(ActionKind::kMoveBase, 1, rng)[0];
  const auto features = extractFeatures(r.action, p.features);
  ASSERT_TRUE(features.ok()) << features.error().toString();
  const Estimate before = est.estimate(*features);
  r.duration_s = 3.0 * before.mean_s;  // the robot took three times the estimate
  ASSERT_TRUE(surprising(before, r.duration_s, 3.0));
  ASSERT_TRUE(est.addRecord(r).ok());
  ASSERT_TRUE(est.waitForVersion(ActionKind::kMoveBase, 1, Deadline::in(kWaitS)));
  EXPECT_EQ(est.counters().surprises, 1u);
  EXPECT_EQ(est.pendingCount(ActionKind::kMoveBase), 0u);
  // The refitted model moved towards what the robot did.
  EXPECT_GT(est.estimate(*features).mean_s, 1.3 * before.mean_s);
}

TEST(EstimatorTest, OnlineWorkerRefitsAfterThePeriodWithFewRecords) {
  EffortEstimator est(paramsFor("", /*batch=*/1000, /*period_s=*/0.2), true);
  std::mt19937_64 rng(5);
  ASSERT_TRUE(est.addRecord(synthetic::records(ActionKind::kPlace, 1, rng)[0]).ok());
  ASSERT_TRUE(est.waitForVersion(ActionKind::kPlace, 1, Deadline::in(kWaitS)));
  EXPECT_EQ(est.pendingCount(ActionKind::kPlace), 0u);
}

TEST(EstimatorTest, EstimatesRunConcurrentlyWithRefits) {
  EffortEstimator est(paramsFor("", /*batch=*/10, /*period_s=*/1000.0), true);
  std::mt19937_64 rng(6);
  const ActionDescription probe = synthetic::randomAction(ActionKind::kMoveBase, rng);
  const auto recs = synthetic::records(ActionKind::kMoveBase, 200, rng);
  std::atomic<bool> done{false};
  std::atomic<int> bad{0};
  std::atomic<long> count{0};
  std::thread reader([&] {
    std::uint64_t last_version = 0;
    while (!done) {
      auto e = est.estimate(probe);
      if (!e.ok() || !std::isfinite(e->mean_s) || !(e->stddev_s > 0) || e->model_version < last_version) ++bad;
      if (e.ok()) last_version = e->model_version;
      ++count;
    }
  });
  for (const auto& r : recs) ASSERT_TRUE(est.addRecord(r).ok());
  const bool reached = est.waitForVersion(ActionKind::kMoveBase, 1, Deadline::in(kWaitS));
  // Let the worker drain what is pending before stopping the reader.
  for (int i = 0; i < 600 && est.pendingCount(ActionKind::kMoveBase) >= 10; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  done = true;
  reader.join();
  EXPECT_TRUE(reached);
  EXPECT_EQ(bad.load(), 0);
  EXPECT_GT(count.load(), 0);
  EXPECT_LT(est.pendingCount(ActionKind::kMoveBase), 10u);
  EXPECT_GE(est.snapshot().model(ActionKind::kMoveBase).version, 1u);
}

TEST(EstimatorTest, ModelsAndRecordsSurviveARestart) {
  TempDir dir;
  std::mt19937_64 rng(7);
  ModelSnapshot before;
  {
    EffortEstimator est(paramsFor(dir.path()), false);
    EXPECT_TRUE(est.persistent());
    for (ActionKind k : kAllActionKinds) {
      int i = 0;
      for (auto r : synthetic::records(k, 12, rng)) {
        r.record_id = std::string(toString(k)) + "-" + std::to_string(i++);
        ASSERT_TRUE(est.addRecord(r).ok());
      }
    }
    ASSERT_EQ(est.refitNow().size(), 4u);
    before = est.snapshot();
    EXPECT_EQ(before.version, 4u);
  }
  EffortEstimator est(paramsFor(dir.path()), false);
  EXPECT_TRUE(est.startupWarnings().empty());
  const ModelSnapshot after = est.snapshot();
  EXPECT_EQ(after.version, before.version);
  for (ActionKind k : kAllActionKinds) {
    EXPECT_EQ(after.model(k).values, before.model(k).values) << toString(k);
    EXPECT_EQ(after.model(k).log_covariance, before.model(k).log_covariance) << toString(k);
    EXPECT_EQ(after.model(k).version, 1u);
    EXPECT_EQ(est.recordCount(k), 12u);
    EXPECT_EQ(est.pendingCount(k), 0u);
  }
  // A re-delivered record (same id) is not counted twice; a new one is.
  auto again = synthetic::records(ActionKind::kPick, 1, rng)[0];
  again.record_id = "pick-3";
  EXPECT_TRUE(est.addRecord(again).ok());
  EXPECT_EQ(est.recordCount(ActionKind::kPick), 12u);
  EXPECT_EQ(est.counters().records_duplicate, 1u);
  again.record_id = "pick-new";
  EXPECT_TRUE(est.addRecord(again).ok());
  EXPECT_EQ(est.recordCount(ActionKind::kPick), 13u);
  // The next refit continues the version sequence.
  const auto reports = est.refitNow();
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].version, 2u);
  EXPECT_EQ(est.snapshot().version, 5u);
}

TEST(EstimatorTest, RecordsWithoutAFittedModelAreRefittedAfterARestart) {
  TempDir dir;
  std::mt19937_64 rng(8);
  {
    EffortEstimator est(paramsFor(dir.path()), false);
    for (const auto& r : synthetic::records(ActionKind::kMoveArm, 7, rng)) ASSERT_TRUE(est.addRecord(r).ok());
    // destroyed before any refit (a crash before the batch was full)
  }
  EffortEstimator est(paramsFor(dir.path()), false);
  EXPECT_EQ(est.pendingCount(ActionKind::kMoveArm), 7u);
  EXPECT_EQ(est.snapshot().model(ActionKind::kMoveArm).version, 0u);
  const auto reports = est.refitNow();
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].version, 1u);
  EXPECT_EQ(est.snapshot().model(ActionKind::kMoveArm).record_count, 7u);
}

TEST(EstimatorTest, CorruptStoreStartsFromDefaultsWithAClearMessage) {
  TempDir dir;
  std::ofstream(dir.path() / EffortStore::kFileName) << "this is not an SQLite database, it is a note";
  EffortEstimator est(paramsFor(dir.path()), false);
  ASSERT_EQ(est.startupWarnings().size(), 1u);
  EXPECT_THAT(est.startupWarnings()[0], HasSubstr("is unusable"));
  EXPECT_THAT(est.startupWarnings()[0], HasSubstr("started from default models"));
  EXPECT_TRUE(est.persistent());
  EXPECT_EQ(est.snapshot().version, 0u);
  std::mt19937_64 rng(9);
  EXPECT_TRUE(est.addRecord(synthetic::records(ActionKind::kPick, 1, rng)[0]).ok());
}

TEST(EstimatorTest, MissingStoreDirectoryIsCreated) {
  TempDir dir;
  EffortEstimator est(paramsFor(dir.path() / "new" / "store"), false);
  ASSERT_EQ(est.startupWarnings().size(), 1u);
  EXPECT_THAT(est.startupWarnings()[0], HasSubstr("did not exist; created it"));
  EXPECT_TRUE(est.persistent());
}

TEST(EstimatorTest, InvalidParamsAreMisuse) {
  EstimatorParams p = paramsFor("");
  p.refit_batch_size = 0;
  EXPECT_THROW(EffortEstimator(p, false), std::invalid_argument);
}

}  // namespace
}  // namespace tamp::effort_estimator
