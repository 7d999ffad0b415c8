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
using ::testing::Not;
using ::testing::StartsWith;

using testing::RunPkslam;

TEST(SimulateCli, ReplayThenInfo) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const auto out = testing::MakeTempDir("cli_simulate");
  const auto sim = RunPkslam(
      fmt::format("--log-level warn simulate --out '{}' --trajectory '{}' --start 30 --duration 1 "
                  "--quality fast --quiet --no-cloud --realism ideal",
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

// Replays of ground truth default to the euroc realism preset; sources switch off alone.
TEST(SimulateCli, ReplaysAreRealisticByDefault) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const auto dir = testing::MakeTempDir("cli_simulate_realism");
  const std::string replay = fmt::format(
      "--log-level warn simulate --trajectory '{}' --start 30 --duration 0.3 "
      "--quality fast --quiet --no-cloud",
      (shared / "euroc/groundtruth/V1_02_medium.txt").string());
  const auto euroc = RunPkslam(replay + fmt::format(" --out '{}'", (dir / "euroc").string()));
  ASSERT_EQ(euroc.exit_code, 0) << euroc.output;
  EXPECT_THAT(euroc.output, HasSubstr("realism euroc: appearance on calibration on timing on"));
  EXPECT_THAT(euroc.output, HasSubstr("scene euroc_vicon_room"));
  EXPECT_TRUE(std::filesystem::exists(dir / "euroc/truth/cam0_sensor.yaml"));
  const auto info = RunPkslam(fmt::format("info '{}'", (dir / "euroc").string()));
  EXPECT_THAT(info.output, Not(HasSubstr("baseline 0.110078 m")));  // miscalibrated

  const auto off = RunPkslam(
      replay + fmt::format(" --out '{}' --realism-off calibration,appearance --device-seed 4",
                           (dir / "off").string()));
  ASSERT_EQ(off.exit_code, 0) << off.output;
  EXPECT_THAT(off.output, HasSubstr("appearance off calibration off timing on"));
  EXPECT_THAT(off.output, HasSubstr("scene vicon_room"));
  const auto info_off = RunPkslam(fmt::format("info '{}'", (dir / "off").string()));
  EXPECT_THAT(info_off.output, HasSubstr("baseline 0.110078 m"));

  const auto report = RunPkslam(
      "simulate --realism euroc --realism-report "
      "--realism-param calibration.focal_px=2.5");
  ASSERT_EQ(report.exit_code, 0) << report.output;
  EXPECT_THAT(report.output, HasSubstr("calibration.focal_px"));
  EXPECT_THAT(report.output, HasSubstr("2.5"));
  EXPECT_THAT(report.output, HasSubstr("Kalibr"));
}

// --camera kitti: KITTI odometry's grey pair (1241x376, 0.537 m, 10 Hz) and its ORB-SLAM3
// feature count in settings.yaml, which `run --settings` then uses.
TEST(SimulateCli, KittiCameraSizeRateBaselineAndFeatures) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const auto out = testing::MakeTempDir("cli_simulate_kitti");
  const auto sim = RunPkslam(
      fmt::format("--log-level warn simulate --out '{}' --trajectory '{}' --start 30 --duration 1 "
                  "--quality fast --quiet --no-cloud --realism ideal --camera kitti",
                  out.string(), (shared / "euroc/groundtruth/V1_02_medium.txt").string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  EXPECT_THAT(sim.output, HasSubstr("11 frames, 201 IMU samples"));  // 10 Hz
  const auto info = RunPkslam(fmt::format("info '{}'", out.string()));
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_THAT(info.output, HasSubstr("1241x376"));
  EXPECT_THAT(info.output, HasSubstr("baseline 0.537000 m"));
  const std::string settings = testing::ReadFileBytes(out / "settings.yaml");
  EXPECT_THAT(settings, HasSubstr("ORBextractor.nFeatures: 2000"));
  EXPECT_THAT(settings, HasSubstr("Camera.width: 1241"));
  const auto bad = RunPkslam(
      fmt::format("simulate --out '{}' --camera fisheye --quiet", (out / "bad").string()));
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_THAT(bad.output, HasSubstr("--camera"));
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
  EXPECT_THAT(r.output, HasSubstr("euroc_vicon_room"));
  for (const char* bad : {"--realism real", "--realism-off lighting",
                          "--realism-param calibration.focal_px=x", "--realism-param no.such=1",
                          "--realism euroc --rgbd", "--realism ideal --realism-off timing"}) {
    r = RunPkslam(
        fmt::format("simulate --out '{}' --quiet {} --realism-report", out.string(), bad));
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_THAT(r.output, StartsWith("pkslam: error: ")) << bad;
  }
}

}  // namespace
}  // namespace pkslam
