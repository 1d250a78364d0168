// The execution monitor's journal of commands sent to the robot: ids survive a reopen (a restart),
// a torn last line is cut off, a repeated id is written once, and a journal that
// cannot be opened is an error naming the file.
#include "tamp/execution_monitor/sent_journal.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

namespace tamp::execution_monitor {
namespace {

namespace fs = std::filesystem;

class SentJournalTest : public ::testing::Test {
 protected:
  SentJournalTest()
      : dir_(fs::temp_directory_path() / ("tamp_sent_journal_" + std::to_string(::getpid()) + "_" +
                                          ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~SentJournalTest() override { fs::remove_all(dir_); }
  std::string text() const {
    std::ifstream in(file());
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  fs::path file() const { return dir_ / "execution_monitor.sent"; }
  fs::path dir_;
};

TEST_F(SentJournalTest, IdsSurviveAReopenAndARepeatIsWrittenOnce) {
  {
    auto j = SentJournal::open(file());
    ASSERT_TRUE(j) << j.error().toString();
    EXPECT_TRUE(j->previous().empty());
    ASSERT_TRUE(j->append("a"));
    ASSERT_TRUE(j->append("b"));
    ASSERT_TRUE(j->append("a"));
  }
  EXPECT_EQ(text(), "a\nb\n");
  auto j = SentJournal::open(file());
  ASSERT_TRUE(j);
  EXPECT_EQ(j->previous(), (std::vector<std::string>{"a", "b"}));
  ASSERT_TRUE(j->append("b"));
  ASSERT_TRUE(j->append("c"));
  EXPECT_EQ(text(), "a\nb\nc\n");
}

TEST_F(SentJournalTest, ATornLastLineIsDroppedAndTheNextIdStartsOnItsOwnLine) {
  std::ofstream(file()) << "a\nm3-e1";  // "m3-e12" torn by a crash
  auto j = SentJournal::open(file());
  ASSERT_TRUE(j);
  EXPECT_EQ(j->previous(), (std::vector<std::string>{"a"}));
  ASSERT_TRUE(j->append("b"));
  auto again = SentJournal::open(file());
  ASSERT_TRUE(again);
  // The fragment never becomes an id: a later command "m3-e1" is not taken for one sent before.
  EXPECT_EQ(again->previous(), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(text(), "a\nb\n");
  std::ofstream(file(), std::ios::trunc) << "torn";  // a first line torn
  auto first = SentJournal::open(file());
  ASSERT_TRUE(first);
  EXPECT_TRUE(first->previous().empty());
  EXPECT_EQ(text(), "");
}

TEST_F(SentJournalTest, AnUnwritableJournalIsAnErrorNamingTheFile) {
  const fs::path bad = dir_ / "missing_dir" / "execution_monitor.sent";
  auto j = SentJournal::open(bad);
  ASSERT_FALSE(j);
  EXPECT_EQ(j.error().code, ErrorCode::kIo);
  EXPECT_NE(j.error().toString().find(bad.string()), std::string::npos);
}

TEST_F(SentJournalTest, AnIdOverSeveralLinesIsMisuse) {
  auto j = SentJournal::open(file());
  ASSERT_TRUE(j);
  EXPECT_THROW((void)j->append("a\nb"), std::invalid_argument);
  EXPECT_THROW((void)j->append(""), std::invalid_argument);
}

}  // namespace
}  // namespace tamp::execution_monitor
