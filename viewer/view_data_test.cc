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
