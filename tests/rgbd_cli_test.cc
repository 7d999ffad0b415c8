// pkslam rgbd-odometry / planar end to end: bad inputs give one line and a non-zero exit.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {
namespace fs = std::filesystem;

int Lines(const std::string& text) {
  int n = 0;
  for (const char c : text) n += c == '\n';
  return n;
}

// A two-frame TUM folder whose second depth image is listed but missing.
fs::path FolderWithMissingDepth() {
  const fs::path dir = testing::MakeTempDir("rgbd_cli_missing");
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  std::ofstream(dir / "rgb.txt") << "1.000000 rgb/1.png\n1.033333 rgb/2.png\n";
  std::ofstream(dir / "depth.txt") << "1.000000 depth/1.png\n1.033333 depth/2.png\n";
  // Only the listed rgb files exist (their content is never read: the check comes first).
  std::ofstream(dir / "rgb" / "1.png") << "x";
  std::ofstream(dir / "rgb" / "2.png") << "x";
  std::ofstream(dir / "depth" / "1.png") << "x";
  return dir;
}

TEST(RgbdCli, MissingFolderIsOneLineError) {
  for (const char* command : {"rgbd-odometry", "planar"}) {
    const auto r =
        testing::RunCommand(fmt::format("{} {} --dataset /nonexistent/tum_folder --quiet 2>&1",
                                        testing::PkslamExecutable().string(), command));
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(Lines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find("pkslam: error: /nonexistent/tum_folder"), std::string::npos)
        << r.output;
  }
}

TEST(RgbdCli, MissingDepthFileIsOneLineError) {
  const fs::path dir = FolderWithMissingDepth();
  for (const char* command : {"rgbd-odometry", "planar"}) {
    const auto r = testing::RunCommand(fmt::format("{} {} --dataset {} --out {} --quiet 2>&1",
                                                   testing::PkslamExecutable().string(), command,
                                                   dir.string(), (dir / "out").string()));
    EXPECT_EQ(r.exit_code, 1) << r.output;
    // The reader's own warning about the missing file may precede the error line.
    const auto error = r.output.find("pkslam: error:");
    ASSERT_NE(error, std::string::npos) << r.output;
    EXPECT_EQ(Lines(r.output.substr(error)), 1) << r.output;
    EXPECT_NE(r.output.find("2.png", error), std::string::npos) << r.output;
  }
}

// A two-frame TUM folder with a settings.yaml and placeholder images; `edit` breaks it.
fs::path TumFolder(const std::string& name) {
  const fs::path dir = testing::MakeTempDir(name);
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  std::ofstream(dir / "rgb.txt") << "# colour\n1.000000 rgb/1.png\n1.033333 rgb/2.png\n";
  std::ofstream(dir / "depth.txt") << "# depth\n1.000000 depth/1.png\n1.033333 depth/2.png\n";
  for (const char* f : {"rgb/1.png", "rgb/2.png", "depth/1.png", "depth/2.png"}) {
    std::ofstream(dir / f) << "not a png";
  }
  std::ofstream(dir / "settings.yaml")
      << "%YAML:1.0\nFile.version: \"1.0\"\nCamera.type: \"PinHole\"\nCamera1.fx: 525.0\n"
         "Camera1.fy: 525.0\nCamera1.cx: 319.5\nCamera1.cy: 239.5\nCamera.width: 640\n"
         "Camera.height: 480\nCamera.fps: 30\nRGBD.DepthMapFactor: 5000.0\n";
  return dir;
}

// Runs both commands on `dir`; each must fail with exactly one line "pkslam: error: ..."
// (after any warnings) containing every string of `expected`.
void ExpectOneLineError(const fs::path& dir, const std::vector<std::string>& expected) {
  for (const char* command : {"rgbd-odometry", "planar"}) {
    const auto r = testing::RunCommand(fmt::format(
        "{} --log-level warn {} --dataset {} --out {} --quiet 2>&1",
        testing::PkslamExecutable().string(), command, dir.string(), (dir / "out").string()));
    EXPECT_EQ(r.exit_code, 1) << command << ": " << r.output;
    const auto error = r.output.find("pkslam: error: ");
    ASSERT_NE(error, std::string::npos) << command << ": " << r.output;
    EXPECT_EQ(Lines(r.output.substr(error)), 1) << command << ": " << r.output;
    for (const std::string& e : expected) {
      EXPECT_NE(r.output.find(e, error), std::string::npos)
          << command << ": " << e << " in " << r.output;
    }
  }
}

TEST(RgbdCli, MalformedListLineNamesFileAndLine) {
  const fs::path dir = TumFolder("rgbd_cli_list");
  std::ofstream(dir / "rgb.txt") << "# colour\n1.000000 rgb/1.png\nabc rgb/2.png\n";
  ExpectOneLineError(dir, {(dir / "rgb.txt").string() + ":3", "abc"});
}

TEST(RgbdCli, DecreasingTimestampsNameFileAndLine) {
  const fs::path dir = TumFolder("rgbd_cli_order");
  std::ofstream(dir / "depth.txt") << "1.033333 depth/2.png\n1.000000 depth/1.png\n";
  ExpectOneLineError(dir, {(dir / "depth.txt").string() + ":2", "increasing"});
}

TEST(RgbdCli, MalformedGroundTruthNamesFileAndLine) {
  const fs::path dir = TumFolder("rgbd_cli_gt");
  std::ofstream(dir / "groundtruth.txt") << "1.0 0 0 0 0 0 0 1\n1.03 0 0 x 0 0 0 1\n";
  ExpectOneLineError(dir, {(dir / "groundtruth.txt").string() + ":2", "'x'"});
}

TEST(RgbdCli, CorruptImageNamesTheFile) {
  const fs::path dir = TumFolder("rgbd_cli_png");
  // The depth images are looked at first (an all-zero depth folder is refused up front).
  ExpectOneLineError(dir, {(dir / "depth" / "1.png").string(), "cannot decode"});
}

TEST(RgbdCli, BadSettingsNameTheFile) {
  const fs::path dir = TumFolder("rgbd_cli_yaml");
  std::ofstream(dir / "settings.yaml") << "%YAML:1.0\nCamera.type: \"PinHole\"\nCamera1.fx: [\n";
  ExpectOneLineError(dir, {"settings.yaml"});
}

int FileLines(const fs::path& file) {
  std::ifstream in(file);
  int n = 0;
  for (std::string line; std::getline(in, line);) n += !line.empty() && line[0] != '#';
  return n;
}

// The rmse column of a `pkslam eval` line starting with `row` ("ATE [m]"), or -1.
double EvalRmse(const std::string& output, const std::string& row) {
  const auto at = output.find(row);
  if (at == std::string::npos) return -1;
  return std::stod(output.substr(at + row.size()));
}

// simulate --rgbd (replaying 0.5 s of real EuRoC ground truth) -> rgbd-odometry, planar and
// eval: the documented outputs exist, every frame is tracked and the trajectories are accurate.
TEST(RgbdCli, SimulatedSequenceEndToEnd) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path dir = testing::MakeTempDir("rgbd_cli_e2e");
  const std::string exe = testing::PkslamExecutable().string();
  auto r = testing::RunCommand(fmt::format(
      "{} --log-level warn simulate --rgbd --out {} --trajectory {} --start 40 --duration 0.5 "
      "--quality fast --no-cloud --quiet 2>&1",
      exe, (dir / "seq").string(), (shared / "euroc/groundtruth/V2_01_easy.txt").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path gt = dir / "seq" / "groundtruth.txt";

  r =
      testing::RunCommand(fmt::format("{} --log-level warn rgbd-odometry --dataset {} --out {} "
                                      "--quiet 2>&1",
                                      exe, (dir / "seq").string(), (dir / "odo").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("frames 16 poses 16 tracked 15"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("preprocessing"), std::string::npos) << r.output;
  for (const char* f : {"trajectory.txt", "map.ply", "frames.csv", "stats.json"}) {
    EXPECT_TRUE(fs::exists(dir / "odo" / f)) << f;
  }
  EXPECT_EQ(FileLines(dir / "odo" / "trajectory.txt"), 16);
  r = testing::RunCommand(fmt::format("{} eval --gt {} --est {} 2>&1", exe, gt.string(),
                                      (dir / "odo" / "trajectory.txt").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const double odometry_ate = EvalRmse(r.output, "ATE [m]");
  EXPECT_GT(odometry_ate, 0) << r.output;
  EXPECT_LT(odometry_ate, 0.03) << r.output;  // 0.16 m path, 0.5 s

  r = testing::RunCommand(
      fmt::format("{} --log-level warn planar --dataset {} --out {} --max-frames 5 --gaps 1 2 "
                  "--reference full-icp --full-stride 4 --min-plane-points 50 --quiet 2>&1",
                  exe, (dir / "seq").string(), (dir / "planar").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("speedup%"), std::string::npos) << r.output;
  for (const char* f : {"trajectory.txt", "trajectory_gap1.txt", "trajectory_gap2.txt",
                        "trajectory_full_icp_gap1.txt", "map.ply", "pairs.csv", "stats.json"}) {
    EXPECT_TRUE(fs::exists(dir / "planar" / f)) << f;
  }
  EXPECT_EQ(FileLines(dir / "planar" / "trajectory_gap1.txt"), 5);
  EXPECT_EQ(FileLines(dir / "planar" / "trajectory_gap2.txt"), 3);  // frames 0, 2, 4
  EXPECT_EQ(FileLines(dir / "planar" / "pairs.csv"), 1 + 4 + 2);    // header + pairs
  r = testing::RunCommand(fmt::format("{} eval --gt {} --est {} 2>&1", exe, gt.string(),
                                      (dir / "planar" / "trajectory.txt").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const double planar_ate = EvalRmse(r.output, "ATE [m]");
  EXPECT_GT(planar_ate, 0) << r.output;
  EXPECT_LT(planar_ate, 0.02) << r.output;
}

TEST(RgbdCli, BadOptionValuesAreOneLineErrors) {
  const auto r =
      testing::RunCommand(fmt::format("{} planar --dataset /tmp --plane-fit svd --quiet 2>&1",
                                      testing::PkslamExecutable().string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(Lines(r.output), 1) << r.output;
}

}  // namespace
}  // namespace pkslam
