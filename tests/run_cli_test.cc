// End-to-end: `pkslam run` on inputs whose timestamps are wrong (issue 20): a jump is reported
// and --realtime does not sleep through it.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

using ::testing::HasSubstr;

using testing::RunPkslam;

// A 3 s simulated flight (EuRoC layout, fast rendering) with `seed` into `seq`; gtest failure
// with the simulator's output when it fails.
::testing::AssertionResult Simulate(const std::filesystem::path& seq, int seed,
                                    double duration_s = 3) {
  const auto sim = RunPkslam(fmt::format(
      "--log-level warn simulate --out '{}' --motion medium --duration {} --quality fast "
      "--quiet --no-cloud --seed {}",
      seq.string(), duration_s, seed));
  if (sim.exit_code == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << sim.output;
}

// Rewrites cam0's data.csv so that the last `rows` frames come `jump_s` later (file names keep
// their old stamps: only the listed times change).
void ShiftLastFrames(const std::filesystem::path& dataset, int rows, double jump_s) {
  const auto csv = dataset / "mav0/cam0/data.csv";
  std::ifstream in(csv);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  in.close();
  const std::size_t first = lines.size() - static_cast<std::size_t>(rows);
  for (std::size_t i = first; i < lines.size(); ++i) {
    const std::size_t comma = lines[i].find(',');
    const long long t = std::stoll(lines[i].substr(0, comma));
    lines[i] =
        fmt::format("{}{}", t + static_cast<long long>(jump_s * 1e9), lines[i].substr(comma));
  }
  std::ofstream out(csv, std::ios::trunc);
  for (const std::string& line : lines) out << line << '\n';
}

// A 1000 s jump in cam0's stamps: run warns naming the dataset, and --realtime paces on after
// it instead of sleeping 1000 s (ctest's timeout would catch a hang).
TEST(RunCli, TimestampJumpIsReportedAndNotSleptThrough) {
  const auto dir = testing::MakeTempDir("run_cli_jump");
  const auto seq = dir / "seq";
  ASSERT_TRUE(Simulate(seq, 3));
  ShiftLastFrames(seq, 3, 1000.0);
  const auto run =
      RunPkslam(fmt::format("run --dataset '{}' --sensor mono --realtime --quiet --out '{}'",
                            seq.string(), (dir / "out").string()));
  // 0, or 5 when the monocular map did not initialise on this short, slow flight: either way
  // the run went to the end and wrote stats.json.
  EXPECT_TRUE(run.exit_code == 0 || run.exit_code == 5) << run.output;
  EXPECT_THAT(run.output, HasSubstr("1 timestamp jump(s) beyond 5 frame periods: 1000.050 s "
                                    "after frame 57"));
  EXPECT_THAT(run.output, HasSubstr("--realtime pacing restarts after the timestamp jump at "
                                    "frame 58"));
  EXPECT_THAT(run.output, HasSubstr(seq.filename().string()));
  EXPECT_THAT(testing::ReadFileBytes(dir / "out/stats.json"), HasSubstr("\"timestamp_jumps\": 1"));
}

// A vocabulary path that is a directory is a one-line error naming it (it was
// "basic_filebuf::underflow error").
TEST(RunCli, VocabularyDirectoryIsNamed) {
  const auto dir = testing::MakeTempDir("run_cli_vocab");
  const auto seq = dir / "seq";
  ASSERT_TRUE(Simulate(seq, 1));
  const auto run = RunPkslam(fmt::format("run --dataset '{}' --vocabulary '{}' --quiet --out '{}'",
                                         seq.string(), dir.string(), (dir / "out").string()));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_THAT(run.output, HasSubstr("vocabulary is not a file"));
  EXPECT_THAT(run.output, HasSubstr(dir.filename().string()));
}

// Keeps the header and the first `rows` samples of imu0/data.csv.
void TruncateImu(const std::filesystem::path& dataset, int rows) {
  const auto csv = dataset / "mav0/imu0/data.csv";
  std::ifstream in(csv);
  std::string kept;
  std::string line;
  for (int n = 0; n <= rows && std::getline(in, line); ++n) kept += line + '\n';
  in.close();
  std::ofstream(csv, std::ios::trunc) << kept;
}

// IMU that ends early is reported (those frames are tracked without IMU); a single sample is
// an error naming the file.
TEST(RunCli, ImuCoverageIsChecked) {
  const auto dir = testing::MakeTempDir("run_cli_imu");
  const auto seq = dir / "seq";
  ASSERT_TRUE(Simulate(seq, 1));
  TruncateImu(seq, 200);  // the first second of 3
  const std::string run =
      fmt::format("run --dataset '{}' --sensor stereo-inertial --quiet --out '{}'", seq.string(),
                  (dir / "out").string());
  // An inertial run over frames without IMU is an error naming the IMU file and the frames...
  const auto early = RunPkslam(run);
  EXPECT_EQ(early.exit_code, 1) << early.output;
  EXPECT_THAT(early.output, HasSubstr("imu0/data.csv: 40 of 61 frames have no IMU sample"));
  EXPECT_THAT(early.output, HasSubstr("frames 21-60; the IMU covers 0.000..0.995 s of frames "
                                      "spanning 0..3.000 s"));
  // ... unless allowed: then a warning and a degraded run in stats.json.
  const auto allowed = RunPkslam(run + " --allow-imu-gaps");
  EXPECT_EQ(allowed.exit_code, 0) << allowed.output;
  EXPECT_THAT(allowed.output, HasSubstr("tracked without IMU"));
  EXPECT_THAT(allowed.output, HasSubstr("degraded input: 1 warning(s)"));
  const std::string stats = testing::ReadFileBytes(dir / "out/stats.json");
  EXPECT_THAT(stats, HasSubstr("\"degraded\": true"));
  EXPECT_THAT(stats, HasSubstr("\"frames_without_imu\": 40"));
  // Keyframes per creating rule: the map's first is the initialisation's.
  EXPECT_THAT(stats, HasSubstr("\"keyframe_reasons\": {"));
  EXPECT_THAT(stats, HasSubstr("\"selector_criteria\": {"));
  EXPECT_THAT(stats, HasSubstr("\"initialisation\": 1"));
  // A finished run keeps no crash copy of its trajectory.
  EXPECT_FALSE(std::filesystem::exists(dir / "out/trajectory.txt.partial"));
  EXPECT_EQ(RunPkslam(run + " --allow-imu-gaps --strict").exit_code, 3);
  TruncateImu(seq, 1);
  const auto single = RunPkslam(run);
  EXPECT_NE(single.exit_code, 0);
  EXPECT_THAT(single.output, HasSubstr("imu0/data.csv: a single IMU sample"));
}

// Overwrites frames [first, last) of cam0 and cam1 with a uniform grey image: nothing to track.
void BlankFrames(const std::filesystem::path& dataset, std::size_t first, std::size_t last) {
  for (const char* cam : {"cam0", "cam1"}) {
    std::vector<std::filesystem::path> images;
    for (const auto& e : std::filesystem::directory_iterator(dataset / "mav0" / cam / "data")) {
      images.push_back(e.path());
    }
    std::sort(images.begin(), images.end());
    for (std::size_t i = first; i < last && i < images.size(); ++i) {
      const cv::Mat image = cv::imread(images[i].string(), cv::IMREAD_UNCHANGED);
      cv::imwrite(images[i].string(), cv::Mat(image.size(), image.type(), cv::Scalar::all(128)));
    }
  }
}

// A run that loses tracking for good says its estimate is suspect (summary line, stats.json
// "estimate", --strict exit 4); the same flight without the blank stretch does not. A stereo
// map is kept through a short loss and relocalised into, so the stretch outlasts the 5 s a
// lost map is waited for.
TEST(RunCli, LossForGoodMakesTheEstimateSuspect) {
  const auto dir = testing::MakeTempDir("run_cli_suspect");
  const auto seq = dir / "seq";
  ASSERT_TRUE(Simulate(seq, 2, 12));
  const std::string run = fmt::format("run --dataset '{}' --sensor stereo --quiet --out '{}'",
                                      seq.string(), (dir / "out").string());
  const auto clean = RunPkslam(run);
  EXPECT_EQ(clean.exit_code, 0) << clean.output;
  EXPECT_THAT(clean.output, ::testing::Not(HasSubstr("suspect estimate")));
  EXPECT_THAT(testing::ReadFileBytes(dir / "out/stats.json"), HasSubstr("\"suspect\": false"));

  BlankFrames(seq, 45, 165);  // 6 s of grey in a 12 s flight
  const auto lost = RunPkslam(run);
  EXPECT_EQ(lost.exit_code, 0) << lost.output;
  EXPECT_THAT(lost.output, HasSubstr("suspect estimate: tracking lost for good at t = "));
  const std::string stats = testing::ReadFileBytes(dir / "out/stats.json");
  EXPECT_THAT(stats, HasSubstr("\"suspect\": true"));
  EXPECT_THAT(stats, HasSubstr("\"lost_for_good\": 1"));
  EXPECT_EQ(RunPkslam(run + " --strict").exit_code, 4);
}

// A frame of another size than the calibration is an error naming that image (mono tracked it
// with the wrong intrinsics; stereo failed inside the rectification, naming a source file).
TEST(RunCli, ImageSizeMustMatchTheCalibration) {
  const auto dir = testing::MakeTempDir("run_cli_size");
  const auto seq = dir / "seq";
  ASSERT_TRUE(Simulate(seq, 1));
  std::vector<std::filesystem::path> frames;
  for (const auto& e : std::filesystem::directory_iterator(seq / "mav0/cam1/data")) {
    frames.push_back(e.path());
  }
  std::sort(frames.begin(), frames.end());
  ASSERT_GT(frames.size(), 10u);
  const auto& bad = frames[5];
  const cv::Mat image = cv::imread(bad.string(), cv::IMREAD_GRAYSCALE);
  cv::Mat small;
  cv::resize(image, small, cv::Size(640, 480));
  ASSERT_TRUE(cv::imwrite(bad.string(), small));
  const auto run = RunPkslam(fmt::format("run --dataset '{}' --sensor stereo --quiet --out '{}'",
                                         seq.string(), (dir / "out").string()));
  EXPECT_NE(run.exit_code, 0);
  EXPECT_THAT(run.output, HasSubstr(bad.filename().string() + ": 640x480 image, but the "
                                                              "calibration is 752x480"));
}

// A re-run into the same --out leaves none of the earlier run's files: a stereo run's metric
// trajectory_body.txt beside a monocular run's outputs would be scored by mistake.
TEST(RunCli, RerunIntoTheSameFolderLeavesNoStaleFiles) {
  const auto dir = testing::MakeTempDir("run_cli_rerun");
  const auto seq = dir / "seq";
  ASSERT_TRUE(Simulate(seq, 1));
  const auto out = dir / "out";
  const auto stereo = RunPkslam(fmt::format(
      "run --dataset '{}' --sensor stereo --trace --quiet --out '{}'", seq.string(), out.string()));
  ASSERT_EQ(stereo.exit_code, 0) << stereo.output;
  ASSERT_TRUE(std::filesystem::exists(out / "trajectory_body.txt"));
  ASSERT_TRUE(std::filesystem::exists(out / "keyframe_trace.csv"));
  const auto mono = RunPkslam(fmt::format("run --dataset '{}' --sensor mono --quiet --out '{}'",
                                          seq.string(), out.string()));
  // A monocular map may not initialise on this short flight: exit 5 (no estimate) still writes
  // the run's outputs.
  ASSERT_TRUE(mono.exit_code == 0 || mono.exit_code == 5) << mono.output;
  EXPECT_FALSE(std::filesystem::exists(out / "trajectory_body.txt"));
  EXPECT_FALSE(std::filesystem::exists(out / "keyframe_trace.csv"));
  EXPECT_TRUE(std::filesystem::exists(out / "stats.json"));
}

}  // namespace
}  // namespace pkslam
