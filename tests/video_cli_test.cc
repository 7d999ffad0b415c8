// End-to-end: `pkslam run --video` and `--images --timestamps` (issue 23) on a simulated
// sequence written as a lossless video (FFV1) with OpenCV's VideoWriter: under --deterministic
// both give the same poses (only the clocks differ: the video's starts at 0); and their input
// errors. (A lossy MJPG clip of this smooth fast-quality render, 3.4 grey levels off per pixel,
// does not initialise monocular tracking at all: docs/maps.md, video input.)
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <set>
#include <string>
#include <vector>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using ::testing::HasSubstr;

using testing::RunPkslam;

using testing::JsonIntField;

// A TUM trajectory's lines without their time column.
std::vector<std::string> PosesOf(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    out.push_back(line.substr(line.find(' ')));
  }
  return out;
}

TEST(VideoCli, VideoAndImageFolderRunMonocularSlam) {
  const auto dir = testing::MakeTempDir("video_cli");
  const auto seq = dir / "seq";
  const auto sim = RunPkslam(fmt::format(
      "--log-level warn simulate --out '{}' --motion medium --duration 5 --quality fast --quiet "
      "--no-cloud --seed 4",
      seq.string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  std::set<std::string> names;  // sorted: EuRoC names are equal-length ns stamps
  for (const auto& e : std::filesystem::directory_iterator(seq / "mav0/cam0/data")) {
    names.insert(e.path().filename().string());
  }
  ASSERT_GT(names.size(), 50u);
  const auto video = dir / "clip.avi";
  {
    cv::VideoWriter writer(video.string(), cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 20.0,
                           cv::Size(752, 480), /*isColor=*/false);
    ASSERT_TRUE(writer.isOpened());
    for (const auto& n : names) {
      writer.write(cv::imread((seq / "mav0/cam0/data" / n).string(), cv::IMREAD_GRAYSCALE));
    }
  }
  const auto settings = seq / "settings.yaml";
  const auto run = RunPkslam(fmt::format(
      "run --video '{}' --settings '{}' --sensor mono --deterministic --quiet --out '{}'",
      video.string(), settings.string(), (dir / "video").string()));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const long long frames = JsonIntField(dir / "video/stats.json", "frames");
  EXPECT_EQ(frames, static_cast<long long>(names.size()));

  // The same frames as an image folder with a timestamps file (ns per line).
  {
    std::ofstream times(dir / "times.txt");
    for (const auto& n : names) times << n.substr(0, n.size() - 4) << '\n';
  }
  const auto folder = RunPkslam(fmt::format(
      "run --images '{}' --timestamps '{}' --settings '{}' --sensor mono --deterministic "
      "--quiet --out '{}'",
      (seq / "mav0/cam0/data").string(), (dir / "times.txt").string(), settings.string(),
      (dir / "folder").string()));
  ASSERT_EQ(folder.exit_code, 0) << folder.output;
  EXPECT_EQ(JsonIntField(dir / "folder/stats.json", "frames"), frames);
  const long long posed = JsonIntField(dir / "folder/stats.json", "frames_in_trajectory");
  EXPECT_GT(posed, 0);
  EXPECT_EQ(JsonIntField(dir / "video/stats.json", "frames_in_trajectory"), posed);
  EXPECT_EQ(PosesOf(dir / "video/trajectory.txt"), PosesOf(dir / "folder/trajectory.txt"));

  // Input errors: one line, non-zero exit.
  const auto stereo =
      RunPkslam(fmt::format("run --video '{}' --settings '{}' --sensor stereo "
                            "--out '{}'",
                            video.string(), settings.string(), (dir / "x").string()));
  EXPECT_NE(stereo.exit_code, 0);
  EXPECT_THAT(stereo.output, HasSubstr("--sensor mono"));
  const auto no_settings = RunPkslam(fmt::format("run --video '{}' --sensor mono --out '{}'",
                                                 video.string(), (dir / "x").string()));
  EXPECT_NE(no_settings.exit_code, 0);
  EXPECT_THAT(no_settings.output, HasSubstr("--settings"));
  const auto missing =
      RunPkslam(fmt::format("run --video '{}' --settings '{}' --sensor mono "
                            "--out '{}'",
                            (dir / "none.mp4").string(), settings.string(), (dir / "x").string()));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_THAT(missing.output, HasSubstr("none.mp4"));
  const auto two = RunPkslam(fmt::format("run --video '{}' --dataset '{}' --out '{}'",
                                         video.string(), seq.string(), (dir / "x").string()));
  EXPECT_NE(two.exit_code, 0);
  EXPECT_THAT(two.output, HasSubstr("exactly one input"));
}

}  // namespace
}  // namespace pkslam
