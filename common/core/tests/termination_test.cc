#include "tamp/core/termination.h"

#include <cmath>
#include <thread>

#include <gtest/gtest.h>

namespace tamp {
namespace {

TEST(DeadlineTest, NeverDoesNotExpire) {
  EXPECT_FALSE(Deadline::never().expired());
  EXPECT_TRUE(std::isinf(Deadline::never().secondsLeft()));
  EXPECT_TRUE(Deadline::in(std::numeric_limits<double>::infinity()).isNever());
}

TEST(DeadlineTest, PastDeadlineIsExpired) {
  EXPECT_TRUE(Deadline::in(0.0).expired());
  EXPECT_TRUE(Deadline::in(-1.0).expired());
  EXPECT_FALSE(Deadline::in(60.0).expired());
  EXPECT_GT(Deadline::in(60.0).secondsLeft(), 59.0);
}

TEST(DeadlineTest, MinPicksEarlier) {
  auto a = Deadline::in(1.0), b = Deadline::in(100.0);
  EXPECT_EQ(a.min(b).time(), a.time());
  EXPECT_EQ(b.min(a).time(), a.time());
  EXPECT_EQ(Deadline::never().min(a).time(), a.time());
}

TEST(TerminationTest, StopsOnDeadlineOrStopRequest) {
  Termination none;
  EXPECT_FALSE(none());
  EXPECT_EQ(Termination::after(-1).reason(), StopReason::kDeadline);

  std::stop_source src;
  Termination t(Deadline::never(), src.get_token());
  EXPECT_FALSE(t());
  src.request_stop();
  EXPECT_TRUE(t());
  EXPECT_EQ(t.reason(), StopReason::kStopRequested);
}

TEST(TerminationTest, TightenedKeepsTokenAndEarlierDeadline) {
  std::stop_source src;
  Termination t(Deadline::in(100.0), src.get_token());
  Termination sub = t.tightened(Deadline::in(-1.0));
  EXPECT_EQ(sub.reason(), StopReason::kDeadline);
  Termination sub2 = t.tightened(Deadline::in(1000.0));
  EXPECT_EQ(sub2.deadline().time(), t.deadline().time());
  src.request_stop();
  EXPECT_EQ(sub2.reason(), StopReason::kStopRequested);
}

}  // namespace
}  // namespace tamp
