// pkslam rgbd-odometry / planar end to end: bad inputs give one line and a non-zero exit.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <fmt/format.h>

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
    const auto r = testing::RunCommand(fmt::format("{} {} --dataset /nonexistent/tum_folder --quiet 2>&1",
                                                   testing::PkslamExecutable().string(), command));
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(Lines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find("pkslam: error: /nonexistent/tum_folder"), std::string::npos) << r.output;
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

TEST(RgbdCli, BadOptionValuesAreOneLineErrors) {
  const auto r = testing::RunCommand(fmt::format(
      "{} planar --dataset /tmp --plane-fit svd --quiet 2>&1", testing::PkslamExecutable().string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(Lines(r.output), 1) << r.output;
}

}  // namespace
}  // namespace pkslam
