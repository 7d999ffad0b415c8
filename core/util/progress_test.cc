#include "core/util/progress.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

namespace pkslam {
namespace {

using progress_detail::FormatRate;
using progress_detail::PlainLineDue;

TEST(Progress, PlainLinesComeAtEachFivePercentStep) {
  EXPECT_TRUE(PlainLineDue(5, 4, 0.0));
  EXPECT_TRUE(PlainLineDue(10, 5, 0.0));
  EXPECT_FALSE(PlainLineDue(9, 5, 0.0));
  EXPECT_FALSE(PlainLineDue(3, -1, 0.0));  // nothing before the first step
}

TEST(Progress, SlowWorkGetsALinePerItemAfterAQuietMinute) {
  // A study of 385 runs of 2-3 minutes each: 5% is 19 runs, most of an hour without a line.
  EXPECT_FALSE(PlainLineDue(12, 10, 59.0));
  EXPECT_TRUE(PlainLineDue(12, 10, 60.0));
  // An unknown total prints only forced lines, however long it has been.
  EXPECT_FALSE(PlainLineDue(-1, -1, 600.0));
}

TEST(Progress, RateOfSlowItemsIsShownAsTimePerItem) {
  EXPECT_EQ(FormatRate(12.34), "12.3/s");
  EXPECT_EQ(FormatRate(0.5), "0.5/s");
  EXPECT_EQ(FormatRate(1.0 / 125.0), "2:05 each");
  EXPECT_EQ(FormatRate(0.0), "0.0/s");  // nothing finished yet
}

TEST(Progress, PlainOutputHasOneLinePerStepAndAFinalLine) {
  testing::internal::CaptureStderr();
  {
    Progress progress("work", 40);
    for (int i = 0; i < 40; ++i) progress.Add();
  }
  const std::string out = testing::internal::GetCapturedStderr();  // a file, not a terminal
  // 40 items: every 2 items is a 5% step (20 lines), then the destructor's final line.
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 21) << out;
  EXPECT_NE(out.find("work [##############################] 100% 40/40"), std::string::npos) << out;
}

TEST(Progress, QuietPrintsNothing) {
  testing::internal::CaptureStderr();
  {
    Progress progress("work", 10, /*quiet=*/true);
    for (int i = 0; i < 10; ++i) progress.Add();
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

}  // namespace
}  // namespace pkslam
