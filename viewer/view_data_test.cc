#include "viewer/view_data.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

std::filesystem::path RunFolder(const std::string& name, const std::string& stats) {
  const auto run = testing::MakeTempDir(name);
  std::ofstream(run / "trajectory.txt") << "0.0 0 0 0 0 0 0 1\n0.1 0.1 0 0 0 0 0 1\n";
  if (!stats.empty()) std::ofstream(run / "stats.json") << stats;
  return run;
}

// The page leads with the run's own warnings: degraded input and a suspect estimate.
TEST(LoadViewData, CarriesTheRunsWarnings) {
  ViewOptions options;
  options.run = RunFolder("view_warnings", R"({"degraded": true,
      "input": {"frames_skipped": 2, "warnings": ["2 frames skipped"]},
      "estimate": {"suspect": true, "warnings": ["tracking lost for good at t = 14.000 s"]}})");
  const ViewData data = LoadViewData(options);
  EXPECT_EQ(data.estimate.size(), 2u);
  EXPECT_THAT(data.warnings, ElementsAre("input: 2 frames skipped",
                                         "estimate: tracking lost for good at t = 14.000 s"));
  EXPECT_THAT(ViewDataJson(data), HasSubstr(R"("warnings":["input: 2 frames skipped",)"));
}

// Online calibration: its warning leads the page, its applied adjustments reach the timeline.
TEST(LoadViewData, CarriesTheOnlineCalibration) {
  ViewOptions options;
  options.run = RunFolder("view_calibration", R"({"calibration": {"mode": "online",
      "parameters": [{"name": "time_offset", "file": 0.0, "estimate": 1.01}],
      "warnings": ["time_offset in seq/mav0/cam0/sensor.yaml is -1.01 ms off the estimate"],
      "history": [{"t_s": 8.0, "applied": true, "estimate": {"time_offset": 0.7}},
                  {"t_s": 12.0, "applied": false, "estimate": {"time_offset": 0.7}},
                  {"t_s": 18.0, "applied": true, "estimate": {"time_offset": 1.0}}]}})");
  const ViewData data = LoadViewData(options);
  EXPECT_THAT(data.warnings, ElementsAre("calibration: time_offset in seq/mav0/cam0/sensor.yaml "
                                         "is -1.01 ms off the estimate"));
  ASSERT_EQ(data.calibration.size(), 2u);  // the applied ones
  EXPECT_DOUBLE_EQ(data.calibration[1].t_s, 18.0);
  EXPECT_DOUBLE_EQ(data.calibration[1].estimate.at("time_offset"), 1.0);
  EXPECT_DOUBLE_EQ(data.calibration_file.at("time_offset"), 0.0);
  EXPECT_THAT(ViewDataJson(data), HasSubstr(R"("calibration":[{"t":8,"e":{"time_offset":0.7}})"));
}

TEST(LoadViewData, NoStatsNoWarningsAndBadStatsNamed) {
  ViewOptions options;
  options.run = RunFolder("view_no_stats", "");
  EXPECT_TRUE(LoadViewData(options).warnings.empty());
  options.run = RunFolder("view_bad_stats", "{\"estimate\": [");
  try {
    LoadViewData(options);
    FAIL() << "a broken stats.json must be an error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("stats.json"));
  }
}

}  // namespace
}  // namespace pkslam
