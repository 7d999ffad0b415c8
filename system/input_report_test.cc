#include "system/input_report.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/util/error.h"

namespace pkslam {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

TEST(FindTimestampJumps, FlagsLongAndNonIncreasingIntervals) {
  // 50 ms frames; a 1000 s jump after frame 3 and a stamp going back at frame 6.
  const std::vector<std::int64_t> t = {0, 50, 100, 150, 1'000'150, 1'000'200, 1'000'190, 1'000'240};
  const auto jumps = FindTimestampJumps(t, 5.0);
  ASSERT_EQ(jumps.size(), 2u);
  EXPECT_EQ(jumps[0].frame, 4u);
  EXPECT_EQ(jumps[0].dt_ns, 1'000'000);
  EXPECT_EQ(jumps[1].frame, 6u);
  EXPECT_EQ(jumps[1].dt_ns, -10);
  EXPECT_TRUE(FindTimestampJumps({0, 50, 100, 340}, 5.0).empty());  // 4.8 periods: no jump
}

TEST(FramesWithoutImu, FindsFramesOutsideTheImuSpanAndInItsGaps) {
  const std::vector<std::int64_t> frames = {0, 100, 200, 300, 400, 500};
  // IMU from 90 to 195 and again from 420: frame 3 (200, 300] has no sample in its interval
  // (the lookahead 20 reaches 320), frame 4 (300, 420] is covered by the sample at 420 =
  // 400 + 20; frame 0 integrates nothing.
  const std::vector<std::int64_t> imu = {90, 110, 150, 190, 195, 420, 460, 500, 520};
  EXPECT_THAT(FramesWithoutImu(frames, imu, 20), ElementsAre(3u));
  // Starting late and ending early.
  EXPECT_THAT(FramesWithoutImu(frames, {250, 310, 330}, 20), ElementsAre(1u, 2u, 5u));
  EXPECT_THAT(FramesWithoutImu(frames, {}, 20), ElementsAre(1u, 2u, 3u, 4u, 5u));
}

TEST(FormatIndexRanges, CollapsesRunsAndCutsLongLists) {
  EXPECT_EQ(FormatIndexRanges({0, 1, 2, 5, 7, 8}), "0-2, 5, 7-8");
  EXPECT_EQ(FormatIndexRanges({1, 3, 5, 7}, 2), "1, 3, ...");
  EXPECT_EQ(FormatIndexRanges({}), "");
}

std::vector<ImuSample> Samples(const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel) {
  std::vector<ImuSample> samples(10);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    samples[i].t_ns = static_cast<std::int64_t>(i) * 5'000'000;
    samples[i].gyro = gyro;
    samples[i].accel = accel;
  }
  return samples;
}

TEST(CheckImuUnits, AcceptsSiUnitsAndNamesTheFileForGAndDegreesPerSecond) {
  EXPECT_NO_THROW(CheckImuUnits(Samples({0.1, 0.2, 0.0}, {0.3, 9.7, 0.5}), "imu.csv"));
  try {
    CheckImuUnits(Samples({0.1, 0.2, 0.0}, {0.03, 0.99, 0.05}), "imu.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("imu.csv"));
    EXPECT_THAT(e.what(), HasSubstr("look like g"));
  }
  try {
    CheckImuUnits(Samples({5.7, 11.5, 0.0}, {0.3, 9.7, 0.5}), "imu.csv");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("deg/s"));
  }
}

}  // namespace
}  // namespace pkslam
