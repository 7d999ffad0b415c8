// End-to-end: `pkslam simulate` replays real EuRoC ground truth into a sequence that
// `pkslam info` reads; bad input gives one error line.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

testing::CommandResult RunPkslam(const std::string& args) {
  return testing::RunCommand(fmt::format("'{}' {}", testing::PkslamExecutable().string(), args));
}

TEST(SimulateCli, ReplayThenInfo) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const auto out = testing::MakeTempDir("cli_simulate");
  const auto sim = RunPkslam(
      fmt::format("--log-level warn simulate --out '{}' --trajectory '{}' --start 30 --duration 1 "
                  "--quality fast --quiet --no-cloud",
                  out.string(), (shared / "euroc/groundtruth/V1_02_medium.txt").string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  EXPECT_THAT(sim.output, HasSubstr("21 frames, 201 IMU samples, 1.000 s"));
  const auto info = RunPkslam(fmt::format("info '{}'", out.string()));
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_THAT(info.output, HasSubstr("EuRoC ASL"));
  EXPECT_THAT(info.output, HasSubstr("stereo pairs 21"));
  EXPECT_THAT(info.output, HasSubstr("baseline 0.110078 m"));
  EXPECT_THAT(info.output, HasSubstr("missing      0 files"));
}

TEST(SimulateCli, BadInputIsOneErrorLine) {
  const auto out = testing::MakeTempDir("cli_simulate_bad");
  auto r =
      RunPkslam(fmt::format("simulate --out '{}' --scene no_such_scene --quiet", out.string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, StartsWith("pkslam: error: "));
  EXPECT_THAT(r.output, HasSubstr("vicon_room"));  // lists the built-in scenes
  r = RunPkslam(fmt::format("simulate --out '{}' --motion sideways --quiet", out.string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("easy, medium or difficult"));
  r = RunPkslam("simulate --list-scenes");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("machine_hall"));
}

}  // namespace
}  // namespace pkslam
