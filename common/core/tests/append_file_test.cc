// The file primitives of the run folder's journals (append_file.h) and writeFileAtomically
// (paths.h): appends land in order and whole, a closed file is a no-op, a move hands the
// descriptor over, a torn tail is cut, and every failure is kIo naming the file and what it is.
#include "tamp/core/append_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "tamp/core/paths.h"

namespace tamp {
namespace {

namespace fs = std::filesystem;

class AppendFileTest : public ::testing::Test {
 protected:
  AppendFileTest()
      : dir_(fs::temp_directory_path() /
             ("tamp_append_file_" + std::to_string(::getpid()) + "_" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  ~AppendFileTest() override { fs::remove_all(dir_); }
  static std::string text(const fs::path& f) {
    std::ifstream in(f, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  fs::path file() const { return dir_ / "journal"; }
  fs::path dir_;
};

TEST_F(AppendFileTest, AppendsGoAfterWhatIsThereInOrder) {
  std::ofstream(file()) << "old\n";
  auto f = AppendFile::open(file(), "the journal");
  ASSERT_TRUE(f) << f.error().toString();
  EXPECT_TRUE(f->isOpen());
  EXPECT_EQ(f->path(), file());
  ASSERT_TRUE(f->append("a\n", true));
  ASSERT_TRUE(f->append(std::string(100000, 'x') + "\n", false));  // more than one pipe buffer
  ASSERT_TRUE(f->append("b\n", true));
  EXPECT_EQ(text(file()), "old\na\n" + std::string(100000, 'x') + "\nb\n");
}

TEST_F(AppendFileTest, AMissingFileIsCreatedAndReadsAsEmpty) {
  auto before = readFileIfExists(file(), "the journal");
  ASSERT_TRUE(before) << before.error().toString();
  EXPECT_EQ(*before, "");
  EXPECT_FALSE(fs::exists(file())) << "reading does not create it";
  auto f = AppendFile::open(file(), "the journal");
  ASSERT_TRUE(f);
  EXPECT_TRUE(fs::exists(file()));
  ASSERT_TRUE(f->append("x\n", true));
  auto after = readFileIfExists(file(), "the journal");
  ASSERT_TRUE(after);
  EXPECT_EQ(*after, "x\n");
}

TEST_F(AppendFileTest, AClosedFileAppendsNothingAndSucceeds) {
  AppendFile f;
  EXPECT_FALSE(f.isOpen());
  EXPECT_TRUE(f.path().empty());
  EXPECT_TRUE(f.append("x\n", true));
}

TEST_F(AppendFileTest, AMoveHandsTheFileOver) {
  auto f = AppendFile::open(file(), "the journal");
  ASSERT_TRUE(f);
  AppendFile moved = std::move(*f);
  EXPECT_FALSE(f->isOpen());  // NOLINT(bugprone-use-after-move): the moved-from state is the point
  EXPECT_TRUE(f->append("lost\n", true)) << "a moved-from file is closed";
  ASSERT_TRUE(moved.append("kept\n", true));
  AppendFile assigned;
  assigned = std::move(moved);
  ASSERT_TRUE(assigned.append("too\n", true));
  EXPECT_EQ(text(file()), "kept\ntoo\n");
}

TEST_F(AppendFileTest, TruncateCutsATornTailAndTheNextAppendFollowsIt) {
  std::ofstream(file()) << "a\nto";
  auto f = AppendFile::open(file(), "the journal");
  ASSERT_TRUE(f);
  ASSERT_TRUE(f->truncate(2));
  ASSERT_TRUE(f->append("b\n", true));
  EXPECT_EQ(text(file()), "a\nb\n");
}

TEST_F(AppendFileTest, FailuresAreIoErrorsNamingTheFileAndWhatItIs) {
  const fs::path bad = dir_ / "missing_dir" / "journal";
  auto f = AppendFile::open(bad, "the test journal");
  ASSERT_FALSE(f);
  EXPECT_EQ(f.error().code, ErrorCode::kIo);
  EXPECT_NE(f.error().toString().find(bad.string()), std::string::npos) << f.error().toString();
  EXPECT_NE(f.error().toString().find("cannot open the test journal for appending"),
            std::string::npos)
      << f.error().toString();
  const Status s = syncDirectory(dir_ / "missing_dir", "the test journal");
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().toString().find("cannot open the folder of the test journal"),
            std::string::npos)
      << s.error().toString();
  EXPECT_TRUE(syncDirectory(dir_, "the test journal"));
}

TEST_F(AppendFileTest, WriteFileAtomicallyReplacesTheFileAndLeavesNoTemporary) {
  std::ofstream(file()) << "old content that is longer\n";
  ASSERT_TRUE(writeFileAtomically(file(), "new\n", "the checkpoint"));
  EXPECT_EQ(text(file()), "new\n");
  EXPECT_FALSE(fs::exists(file().string() + ".tmp"));
  const fs::path bad = dir_ / "missing_dir" / "checkpoint";
  const Status s = writeFileAtomically(bad, "x", "the checkpoint");
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code, ErrorCode::kIo);
  EXPECT_NE(s.error().toString().find("cannot write the checkpoint"), std::string::npos)
      << s.error().toString();
}

}  // namespace
}  // namespace tamp
