#include "evaluation/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/util/error.h"

namespace pkslam {
namespace {

TEST(ComputeErrorStatistics, MatchesNumpyDefinitions) {
  // numpy: rmse sqrt(mean(e^2)) = sqrt(7.5), mean 2.5, median 2.5, std (ddof=0) sqrt(1.25).
  const std::vector<double> e = {4.0, 1.0, 3.0, 2.0};
  const ErrorStatistics s = ComputeErrorStatistics(e);
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_EQ(s.min, 1.0);
  EXPECT_EQ(s.max, 4.0);
}

TEST(ComputeErrorStatistics, OddCountMedianAndSingleValue) {
  EXPECT_EQ(ComputeErrorStatistics(std::vector<double>{5.0, 1.0, 9.0, 7.0, 2.0}).median, 5.0);
  const ErrorStatistics one = ComputeErrorStatistics(std::vector<double>{0.25});
  EXPECT_EQ(one.median, 0.25);
  EXPECT_EQ(one.std, 0.0);
  EXPECT_EQ(one.rmse, 0.25);
  EXPECT_THROW(ComputeErrorStatistics(std::vector<double>{}), Error);
}

}  // namespace
}  // namespace pkslam
