// End-to-end: ROS 1 bags (issue 40). A short simulated stereo sequence is written as a bag
// (`pkslam convert --folder`) in each chunk compression and converted back (`convert --bag`):
// the images decode to the same pixels, the IMU rows hold the same values and times. `pkslam
// run --bag` gives the trajectory of the run on the folder byte for byte under --deterministic.
// Bad bags (truncated, wrong topic, unknown compression, garbage) end with exit != 0 and one
// error line naming the file.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::ReadFileBytes;
using testing::RunPkslam;

// Lines of a text file without the header comments, split at commas.
std::vector<std::vector<std::string>> CsvRows(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream fields_in(line);
    for (std::string f; std::getline(fields_in, f, ',');) fields.push_back(f);
    rows.push_back(fields);
  }
  return rows;
}

// The non-empty lines of a command's output.
std::vector<std::string> Lines(const std::string& output) {
  std::vector<std::string> lines;
  std::stringstream in(output);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

class RosbagCli : public ::testing::Test {
 protected:
  // One simulated 3 s stereo-inertial sequence and its lz4 bag for the whole suite. The
  // "difficult" random flight turns by about 45 degrees in these 3 s (the stereo run makes 4
  // keyframes); the medium one barely moves yet.
  static void SetUpTestSuite() {
    dir_ = new fs::path(testing::MakeTempDir("rosbag_cli"));
    const auto sim = RunPkslam(fmt::format(
        "--log-level warn simulate --out '{}' --duration 3 --quality fast --no-cloud --quiet "
        "--motion difficult --seed 5",
        (*dir_ / "seq").string()));
    ASSERT_EQ(sim.exit_code, 0) << sim.output;
    const auto bag = RunPkslam(
        fmt::format("--log-level warn convert --folder '{}' --out '{}' --compression lz4 --quiet",
                    (*dir_ / "seq").string(), (*dir_ / "seq.bag").string()));
    ASSERT_EQ(bag.exit_code, 0) << bag.output;
  }
  static void TearDownTestSuite() { delete dir_; }

  static const fs::path& dir() { return *dir_; }

 private:
  static fs::path* dir_;
};

fs::path* RosbagCli::dir_ = nullptr;

TEST_F(RosbagCli, FolderToBagToFolderIsExactForEveryCompression) {
  const fs::path seq = dir() / "seq" / "mav0";
  for (const char* compression : {"none", "bz2", "lz4"}) {
    const fs::path bag = dir() / fmt::format("rt_{}.bag", compression);
    const auto to_bag = RunPkslam(
        fmt::format("--log-level warn convert --folder '{}' --out '{}' --compression {} --quiet",
                    (dir() / "seq").string(), bag.string(), compression));
    ASSERT_EQ(to_bag.exit_code, 0) << to_bag.output;
    EXPECT_THAT(to_bag.output, HasSubstr(fmt::format("({} chunks", compression)));
    const fs::path back = dir() / fmt::format("back_{}", compression);
    const auto to_folder = RunPkslam(
        fmt::format("--log-level warn convert --bag '{}' --out '{}' --settings '{}' --quiet",
                    bag.string(), back.string(), (dir() / "seq" / "settings.yaml").string()));
    ASSERT_EQ(to_folder.exit_code, 0) << to_folder.output;
    for (const char* cam : {"cam0", "cam1"}) {
      const auto rows = CsvRows(seq / cam / "data.csv");
      const auto rows_back = CsvRows(back / "mav0" / cam / "data.csv");
      ASSERT_EQ(rows.size(), rows_back.size()) << cam;
      ASSERT_GT(rows.size(), 50u);
      for (std::size_t i = 0; i < rows.size(); ++i) {
        ASSERT_EQ(rows[i][0], rows_back[i][0]) << cam << " row " << i;
        const cv::Mat a =
            cv::imread((seq / cam / "data" / rows[i][1]).string(), cv::IMREAD_GRAYSCALE);
        const cv::Mat b = cv::imread((back / "mav0" / cam / "data" / rows_back[i][1]).string(),
                                     cv::IMREAD_UNCHANGED);
        ASSERT_EQ(b.type(), CV_8UC1);
        ASSERT_EQ(a.size(), b.size());
        ASSERT_EQ(cv::countNonZero(a != b), 0) << cam << " row " << i;
      }
    }
    const auto imu = CsvRows(seq / "imu0" / "data.csv");
    const auto imu_back = CsvRows(back / "mav0" / "imu0" / "data.csv");
    ASSERT_EQ(imu.size(), imu_back.size());
    for (std::size_t i = 0; i < imu.size(); ++i) {
      ASSERT_EQ(imu[i].size(), 7u);
      ASSERT_EQ(imu[i][0], imu_back[i][0]) << "imu row " << i;
      for (int k = 1; k < 7; ++k) {
        ASSERT_EQ(std::stod(imu[i][k]), std::stod(imu_back[i][k])) << "imu row " << i;
      }
    }
    // With --settings, the folder is a complete dataset.
    EXPECT_TRUE(fs::exists(back / "mav0" / "cam1" / "sensor.yaml"));
    EXPECT_EQ(RunPkslam(fmt::format("--log-level warn info '{}'", back.string())).exit_code, 0);
  }
}

TEST_F(RosbagCli, RunOnTheBagIsTheRunOnTheFolderByteForByte) {
  const std::string settings = (dir() / "seq" / "settings.yaml").string();
  const auto folder = RunPkslam(fmt::format(
      "--log-level warn run --dataset '{}' --settings '{}' --sensor stereo --deterministic "
      "--quiet --out '{}'",
      (dir() / "seq").string(), settings, (dir() / "run_folder").string()));
  ASSERT_EQ(folder.exit_code, 0) << folder.output;
  const auto bag = RunPkslam(fmt::format(
      "--log-level warn run --bag '{}' --settings '{}' --sensor stereo --deterministic --quiet "
      "--out '{}'",
      (dir() / "seq.bag").string(), settings, (dir() / "run_bag").string()));
  ASSERT_EQ(bag.exit_code, 0) << bag.output;
  const std::string trajectory = ReadFileBytes(dir() / "run_folder" / "trajectory.txt");
  EXPECT_GT(std::count(trajectory.begin(), trajectory.end(), '\n'), 50);
  EXPECT_EQ(ReadFileBytes(dir() / "run_bag" / "trajectory.txt"), trajectory);
  EXPECT_EQ(ReadFileBytes(dir() / "run_bag" / "keyframes.txt"),
            ReadFileBytes(dir() / "run_folder" / "keyframes.txt"));
  EXPECT_GE(testing::JsonIntField(dir() / "run_bag" / "stats.json", "keyframes"), 3);
  EXPECT_FALSE(fs::exists(dir() / "run_bag" / "seq.euroc.tmp"));
  // A bag holds no calibration.
  const auto no_settings =
      RunPkslam(fmt::format("--log-level warn run --bag '{}' --sensor stereo --out '{}'",
                            (dir() / "seq.bag").string(), (dir() / "x").string()));
  EXPECT_NE(no_settings.exit_code, 0);
  EXPECT_THAT(no_settings.output, HasSubstr("--settings"));
}

TEST_F(RosbagCli, BadBagsAreOneErrorLineNamingTheFile) {
  const std::string good = ReadFileBytes(dir() / "seq.bag");
  ASSERT_GT(good.size(), 100000u);
  const auto write = [&](const std::string& name, const std::string& bytes) {
    const fs::path file = dir() / name;
    std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes;
    return file;
  };
  std::string unknown = good;
  const std::size_t at = unknown.find("compression=lz4");
  ASSERT_NE(at, std::string::npos);
  unknown.replace(at, 15, "compression=xz4");
  std::string garbage(20000, '\0');
  for (std::size_t i = 0; i < garbage.size(); ++i) garbage[i] = static_cast<char>(i * 7919 % 251);
  struct Case {
    fs::path bag;
    std::string options;
    std::string says;
  };
  const std::vector<Case> cases = {
      {write("truncated.bag", good.substr(0, good.size() / 2)), "", "(truncated)"},
      {dir() / "seq.bag", "--topics cam0=/nope", "no sensor_msgs/Image messages on topic /nope"},
      {write("unknown.bag", unknown), "", "unknown chunk compression 'xz4'"},
      {write("garbage.bag", garbage), "", "not a ROS bag"},
      {dir() / "missing.bag", "", "file not found"},
  };
  const std::string settings = (dir() / "seq" / "settings.yaml").string();
  for (const Case& c : cases) {
    const std::string input = fmt::format("--bag '{}' {}", c.bag.string(), c.options);
    for (const std::string& command :
         {fmt::format("convert {} --out '{}' --quiet", input, (dir() / "bad_folder").string()),
          fmt::format("run {} --settings '{}' --sensor stereo --quiet --out '{}'", input, settings,
                      (dir() / "bad_run").string())}) {
      const auto r = RunPkslam("--log-level warn " + command);
      EXPECT_NE(r.exit_code, 0) << command;
      const std::vector<std::string> lines = Lines(r.output);
      ASSERT_EQ(lines.size(), 1u) << command << "\n" << r.output;
      EXPECT_THAT(lines[0], HasSubstr("error"));
      EXPECT_THAT(lines[0], HasSubstr(c.bag.string()));
      EXPECT_THAT(lines[0], HasSubstr(c.says)) << command;
    }
  }
  // The input is never changed.
  EXPECT_EQ(ReadFileBytes(dir() / "seq.bag"), good);
}

}  // namespace
}  // namespace pkslam
