#include "tamp/core/error.h"

#include <gtest/gtest.h>

namespace tamp {
namespace {

TEST(ErrorTest, ToStringNamesEveryKnownPartOfTheLocation) {
  Error e(ErrorCode::kParseError, "expected ')'", SourceLocation{"d.pddl", 12, 7, ""});
  EXPECT_EQ(e.toString(), "d.pddl:12:7: expected ')'");
  Error f(ErrorCode::kInvalidArgument, "must be positive", SourceLocation{"s.yaml", 3, 0, "robot.mass"});
  EXPECT_EQ(f.toString(), "s.yaml:3: field 'robot.mass': must be positive");
  EXPECT_EQ(Error(ErrorCode::kTimeout, "late").toString(), "late");
}

TEST(ResultTest, HoldsValueOrError) {
  Result<int> ok = 4;
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(*ok, 4);
  EXPECT_THROW((void)ok.error(), std::logic_error);

  Result<int> bad = Error(ErrorCode::kNotFound, "nope");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, ErrorCode::kNotFound);
  EXPECT_EQ(bad.valueOr(7), 7);
  EXPECT_THROW((void)bad.value(), std::logic_error);
}

TEST(StatusTest, OkAndError) {
  EXPECT_TRUE(Status::Ok().ok());
  Status s = Error(ErrorCode::kIo, "disk");
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.error().message, "disk");
}

TEST(RequireTest, ThrowsWithMessage) {
  EXPECT_NO_THROW(require(true, "x"));
  try {
    require(false, "timeout must be positive, got -1");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "timeout must be positive, got -1");
  }
}

}  // namespace
}  // namespace tamp
