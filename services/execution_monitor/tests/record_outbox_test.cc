// Execution records kept until the effort estimator acknowledges them: unacknowledged records
// survive a reopen (a restarted monitor) and are due at once, acknowledged ones never come back,
// resends follow the period, a torn last line is dropped, and a corrupt file names its line.
#include "tamp/execution_monitor/record_outbox.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace tamp::execution_monitor {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> ids(const std::vector<RecordOutbox::Entry>& entries) {
  std::vector<std::string> out;
  for (const auto& e : entries) out.push_back(e.record_id);
  return out;
}

class RecordOutboxTest : public ::testing::Test {
 protected:
  RecordOutboxTest()
      : dir_(fs::temp_directory_path() / ("tamp_record_outbox_" + std::to_string(::getpid()) + "_" +
                                          ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~RecordOutboxTest() override { fs::remove_all(dir_); }
  fs::path file() const { return dir_ / "execution_monitor.records"; }
  fs::path dir_;
};

TEST_F(RecordOutboxTest, UnacknowledgedRecordsSurviveAReopenWithTheirPayload) {
  const std::string binary("\x00\x01\xff rec\n", 8);
  {
    auto box = RecordOutbox::open(file());
    ASSERT_TRUE(box) << box.error().toString();
    ASSERT_TRUE(box->add("m1-e1", binary).value());
    ASSERT_TRUE(box->add("m1-e2", "two").value());
    ASSERT_TRUE(box->add("m1-e3", "three").value());
    EXPECT_FALSE(box->add("m1-e2", "again").value()) << "an id kept already";
    EXPECT_EQ(ids(box->due(0.0, 1.0)), (std::vector<std::string>{"m1-e1", "m1-e2", "m1-e3"}));
    EXPECT_TRUE(box->acknowledge("m1-e2"));
    EXPECT_FALSE(box->acknowledge("m1-e2"));
    EXPECT_FALSE(box->acknowledge("unknown"));
    EXPECT_EQ(box->pending(), 2u);
  }
  auto box = RecordOutbox::open(file());
  ASSERT_TRUE(box) << box.error().toString();
  EXPECT_EQ(box->pending(), 2u);
  EXPECT_FALSE(box->isPending("m1-e2"));
  EXPECT_FALSE(box->add("m1-e2", "two").value()) << "acknowledged before the restart: never sent again";
  const auto due = box->due(100.0, 1.0);  // read back: due at once
  ASSERT_EQ(ids(due), (std::vector<std::string>{"m1-e1", "m1-e3"}));
  EXPECT_EQ(due[0].payload, binary);
  EXPECT_EQ(due[1].payload, "three");
}

TEST_F(RecordOutboxTest, AWaitingRecordIsResentEveryPeriodUntilAcknowledged) {
  RecordOutbox box;  // in memory
  ASSERT_TRUE(box.add("r1", "x").value());
  EXPECT_EQ(box.due(10.0, 2.0).size(), 1u);
  EXPECT_EQ(box.due(11.0, 2.0).size(), 0u);
  ASSERT_TRUE(box.add("r2", "y").value());
  EXPECT_EQ(ids(box.due(11.5, 2.0)), (std::vector<std::string>{"r2"}));
  EXPECT_EQ(ids(box.due(12.0, 2.0)), (std::vector<std::string>{"r1"}));
  EXPECT_TRUE(box.acknowledge("r1"));
  EXPECT_EQ(ids(box.due(20.0, 2.0)), (std::vector<std::string>{"r2"}));
  const auto again = box.due(22.0, 2.0);
  ASSERT_EQ(again.size(), 1u);
  EXPECT_EQ(again[0].sends, 3);
  EXPECT_TRUE(box.acknowledge("r2"));
  EXPECT_TRUE(box.due(100.0, 2.0).empty());
  EXPECT_EQ(box.pending(), 0u);
}

TEST_F(RecordOutboxTest, ATornLastLineIsDroppedAndTheNextEventStartsOnItsOwnLine) {
  std::ofstream(file()) << "r a 61\nr b 6";  // b torn mid-write: it had not been sent
  {
    auto box = RecordOutbox::open(file());
    ASSERT_TRUE(box) << box.error().toString();
    EXPECT_EQ(ids(box->due(0.0, 1.0)), (std::vector<std::string>{"a"}));
    ASSERT_TRUE(box->add("c", "c").value());
  }
  auto box = RecordOutbox::open(file());
  ASSERT_TRUE(box) << box.error().toString();
  EXPECT_EQ(ids(box->due(0.0, 1.0)), (std::vector<std::string>{"a", "c"}));
}

TEST_F(RecordOutboxTest, ACorruptLineIsAnErrorNamingTheFileAndLine) {
  std::ofstream(file()) << "r a 61\nx what\n";
  auto box = RecordOutbox::open(file());
  ASSERT_FALSE(box);
  EXPECT_EQ(box.error().code, ErrorCode::kParseError);
  EXPECT_NE(box.error().toString().find(file().string()), std::string::npos) << box.error().toString();
  EXPECT_NE(box.error().toString().find("2"), std::string::npos) << box.error().toString();
  std::ofstream(file()) << "r a 6z\n";  // not hex
  EXPECT_FALSE(RecordOutbox::open(file()));
}

TEST_F(RecordOutboxTest, AnIdWithWhitespaceIsMisuse) {
  RecordOutbox box;
  EXPECT_THROW((void)box.add("", "x"), std::invalid_argument);
  EXPECT_THROW((void)box.add("a b", "x"), std::invalid_argument);
}

TEST_F(RecordOutboxTest, AnOutboxThatCannotBeOpenedIsAnErrorNamingTheFile) {
  const fs::path bad = dir_ / "missing" / "execution_monitor.records";
  auto box = RecordOutbox::open(bad);
  ASSERT_FALSE(box);
  EXPECT_EQ(box.error().code, ErrorCode::kIo);
  EXPECT_NE(box.error().toString().find(bad.string()), std::string::npos);
}

}  // namespace
}  // namespace tamp::execution_monitor
