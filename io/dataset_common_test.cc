#include "io/dataset_common.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/util/error.h"

namespace pkslam {
namespace {

using ::testing::HasSubstr;

std::vector<std::int64_t> Stamps(std::int64_t period, int n, std::int64_t first = 1000) {
  std::vector<std::int64_t> t;
  for (int i = 0; i < n; ++i) t.push_back(first + i * period);
  return t;
}

std::string TimeBaseError(const std::vector<std::int64_t>& t, double rate_hz) {
  try {
    CheckTimeBase(t, rate_hz, "cam0/sensor.yaml", "cam0/data.csv", "images are");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CheckTimeBase, AcceptsTheNominalRateWithDropsAndJitter) {
  auto t = Stamps(50'000'000, 100);
  t.erase(t.begin() + 10, t.begin() + 20);  // dropped frames do not move the median
  EXPECT_EQ(TimeBaseError(t, 20), "");
  EXPECT_EQ(TimeBaseError(Stamps(33'333'333, 50), 30), "");
  EXPECT_EQ(TimeBaseError(Stamps(5, 2), 20), "");  // too short to tell
  EXPECT_EQ(TimeBaseError(Stamps(5, 50), 0), "");  // no nominal rate
}

TEST(CheckTimeBase, NamesTheUnitTheStampsLookLike) {
  const std::string us = TimeBaseError(Stamps(50'000, 100), 20);
  EXPECT_THAT(us, HasSubstr("cam0/data.csv"));
  EXPECT_THAT(us, HasSubstr("50000 ns apart"));
  EXPECT_THAT(us, HasSubstr("cam0/sensor.yaml says 20 Hz"));
  EXPECT_THAT(us, HasSubstr("look like microseconds"));
  EXPECT_THAT(TimeBaseError(Stamps(50, 100), 20), HasSubstr("look like milliseconds"));
  EXPECT_THAT(TimeBaseError(Stamps(5'000, 100), 200), HasSubstr("look like microseconds"));
  EXPECT_THAT(TimeBaseError(Stamps(50'000'000'000, 100), 20), HasSubstr("1000x too large"));
  EXPECT_NE(TimeBaseError(Stamps(1, 100), 20), "");  // whole seconds read as nanoseconds
}

}  // namespace
}  // namespace pkslam
