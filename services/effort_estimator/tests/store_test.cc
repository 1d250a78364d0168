#include "tamp/effort_estimator/store.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <fstream>
#include <random>

#include "synthetic.h"
#include "test_dir.h"

namespace tamp::effort_estimator {
namespace {

using ::testing::HasSubstr;
using testing_support::TempDir;
namespace fs = std::filesystem;

std::vector<fs::path> filesIn(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path());
  return out;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "\n";
  return s;
}

TEST(StoreTest, RecordsAndModelsSurviveReopening) {
  TempDir dir;
  std::mt19937_64 rng(4);
  std::vector<FeatureRecord> written;
  KindModel model;
  {
    StoreOpenResult opened = EffortStore::open(dir.path());
    EXPECT_TRUE(opened.warnings.empty()) << joined(opened.warnings);
    ASSERT_TRUE(opened.store->persistent());
    EXPECT_TRUE(opened.records.empty());
    for (ActionKind kind : kAllActionKinds) {
      for (auto& r : synthetic::featureRecords(kind, 5, rng)) {
        r.record_id = "id-" + std::to_string(written.size());
        ASSERT_TRUE(opened.store->appendRecord(r).ok());
        written.push_back(r);
      }
    }
    const ModelPrior prior = ModelPrior::defaults(ActionKind::kMoveArm);
    auto fitted = fitModel(priorModel(prior, {}), synthetic::featureRecords(ActionKind::kMoveArm, 20, rng), prior, {});
    ASSERT_TRUE(fitted.ok());
    model = *fitted;
    ASSERT_TRUE(opened.store->saveModel(model).ok());
  }
  StoreOpenResult again = EffortStore::open(dir.path());
  EXPECT_TRUE(again.warnings.empty()) << joined(again.warnings);
  ASSERT_EQ(again.records.size(), written.size());
  for (std::size_t i = 0; i < written.size(); ++i) EXPECT_EQ(again.records[i], written[i]) << i;
  ASSERT_EQ(again.models.size(), 1u);
  const KindModel& m = again.models[0];
  EXPECT_EQ(m.kind, ActionKind::kMoveArm);
  EXPECT_EQ(m.values, model.values);
  EXPECT_EQ(m.log_covariance, model.log_covariance);
  EXPECT_EQ(m.noise_log_stddev, model.noise_log_stddev);
  EXPECT_EQ(m.version, model.version);
  EXPECT_EQ(m.record_count, model.record_count);
  EXPECT_EQ(m.summary.iterations, model.summary.iterations);
}

TEST(StoreTest, CorruptFileIsMovedAsideAndAFreshStoreStarts) {
  TempDir dir;
  {
    std::ofstream garbage(dir.path() / EffortStore::kFileName, std::ios::binary);
    for (int i = 0; i < 4096; ++i) garbage.put(static_cast<char>((i * 7919) % 251));
  }
  StoreOpenResult opened = EffortStore::open(dir.path());
  ASSERT_EQ(opened.warnings.size(), 1u);
  EXPECT_THAT(opened.warnings[0], HasSubstr("is unusable"));
  EXPECT_THAT(opened.warnings[0], HasSubstr("moved it to"));
  EXPECT_THAT(opened.warnings[0], HasSubstr("started from default models"));
  EXPECT_TRUE(opened.store->persistent());
  EXPECT_TRUE(opened.records.empty());
  bool found_aside = false;
  for (const auto& f : filesIn(dir.path())) {
    if (f.filename().string().find(".corrupt-") != std::string::npos) {
      found_aside = true;
      EXPECT_EQ(fs::file_size(f), 4096u);  // the bad file is kept for inspection, untouched
    }
  }
  EXPECT_TRUE(found_aside);
  // The fresh store works.
  std::mt19937_64 rng(1);
  EXPECT_TRUE(opened.store->appendRecord(synthetic::featureRecords(ActionKind::kPick, 1, rng)[0]).ok());
}

TEST(StoreTest, TruncatedDatabaseIsDetected) {
  TempDir dir;
  {
    StoreOpenResult opened = EffortStore::open(dir.path());
    std::mt19937_64 rng(2);
    for (const auto& r : synthetic::featureRecords(ActionKind::kMoveBase, 200, rng)) {
      ASSERT_TRUE(opened.store->appendRecord(r).ok());
    }
  }
  const fs::path file = dir.path() / EffortStore::kFileName;
  ASSERT_GT(fs::file_size(file), 8192u);
  fs::resize_file(file, fs::file_size(file) / 2);
  StoreOpenResult opened = EffortStore::open(dir.path());
  ASSERT_FALSE(opened.warnings.empty());
  EXPECT_THAT(opened.warnings[0], HasSubstr("is unusable"));
  EXPECT_TRUE(opened.store->persistent());
}

TEST(StoreTest, ForeignDatabaseIsMovedAside) {
  TempDir dir;
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir.path() / EffortStore::kFileName).c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "CREATE TABLE records(x INTEGER); INSERT INTO records VALUES(1);", nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  StoreOpenResult opened = EffortStore::open(dir.path());
  ASSERT_EQ(opened.warnings.size(), 1u);
  EXPECT_THAT(opened.warnings[0], HasSubstr("unexpected table layout"));
  EXPECT_TRUE(opened.store->persistent());
}

TEST(StoreTest, MissingDirectoryIsCreated) {
  TempDir dir;
  const fs::path nested = dir.path() / "a" / "b";
  StoreOpenResult opened = EffortStore::open(nested);
  ASSERT_EQ(opened.warnings.size(), 1u);
  EXPECT_THAT(opened.warnings[0], HasSubstr("did not exist; created it"));
  EXPECT_TRUE(opened.store->persistent());
  EXPECT_TRUE(fs::exists(nested / EffortStore::kFileName));
}

TEST(StoreTest, UnusablePathRunsInMemory) {
  TempDir dir;
  const fs::path file = dir.path() / "not_a_dir";
  std::ofstream(file) << "x";
  StoreOpenResult opened = EffortStore::open(file);
  ASSERT_EQ(opened.warnings.size(), 1u);
  EXPECT_THAT(opened.warnings[0], HasSubstr("is not a directory"));
  EXPECT_THAT(opened.warnings[0], HasSubstr("running without persistence"));
  EXPECT_FALSE(opened.store->persistent());
  std::mt19937_64 rng(1);
  EXPECT_TRUE(opened.store->appendRecord(synthetic::featureRecords(ActionKind::kPick, 1, rng)[0]).ok());

  StoreOpenResult below_file = EffortStore::open(file / "sub");
  ASSERT_EQ(below_file.warnings.size(), 1u);
  EXPECT_THAT(below_file.warnings[0], HasSubstr("cannot be created"));
  EXPECT_FALSE(below_file.store->persistent());
}

TEST(StoreTest, InvalidRowsAreSkippedWithTheirReason) {
  TempDir dir;
  std::mt19937_64 rng(9);
  {
    StoreOpenResult opened = EffortStore::open(dir.path());
    for (const auto& r : synthetic::featureRecords(ActionKind::kPlace, 3, rng)) ASSERT_TRUE(opened.store->appendRecord(r).ok());
  }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir.path() / EffortStore::kFileName).c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db,
                         "UPDATE records SET duration_s = -2 WHERE id = 2;"
                         "INSERT INTO records(kind, duration_s, timestamp_s, source, features) "
                         "VALUES('fly', 1, 0, 'x', '{}');"
                         "INSERT INTO records(kind, duration_s, timestamp_s, source, features) "
                         "VALUES('pick', 1, 0, 'x', 'not json');"
                         "INSERT INTO models(kind, model) VALUES('move_base', '{\"values\": [1]}');",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  StoreOpenResult opened = EffortStore::open(dir.path());
  EXPECT_EQ(opened.records.size(), 2u);
  EXPECT_EQ(opened.rows_skipped, 4u);
  const std::string all = joined(opened.warnings);
  EXPECT_THAT(all, HasSubstr("skipped record row 2: field 'duration_s': duration must be positive"));
  EXPECT_THAT(all, HasSubstr("unknown action kind 'fly'"));
  EXPECT_THAT(all, HasSubstr("skipped record row 5"));
  EXPECT_THAT(all, HasSubstr("ignored the stored 'move_base' model"));
}

}  // namespace
}  // namespace tamp::effort_estimator
