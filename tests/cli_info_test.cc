// End-to-end: `pkslam info` on the real EuRoC slice and on broken datasets.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

using testing::RunPkslam;

void WriteText(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary | std::ios::trunc) << text;
}

std::string ReadText(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A bad input must give exactly one line "pkslam: error: ..." and a non-zero exit.
void ExpectOneLineError(const testing::CommandResult& r, const std::string& expected) {
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, StartsWith("pkslam: error: "));
  EXPECT_THAT(r.output, HasSubstr(expected));
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

TEST(CliInfo, SharedEurocSlice) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path out = testing::MakeTempDir("cli_info");
  const auto r = RunPkslam(fmt::format("info '{}' --json '{}'",
                                       (shared / "euroc" / "V1_01_easy_static").string(),
                                       (out / "info.json").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("layout       EuRoC ASL"));
  EXPECT_THAT(r.output, HasSubstr("stereo pairs 95 "));
  EXPECT_THAT(r.output, HasSubstr("95 frames (99 listed, 4 missing)"));
  EXPECT_THAT(r.output, HasSubstr("29,120 samples, rate nominal 200 Hz, measured 200.000 Hz"));
  EXPECT_THAT(r.output, HasSubstr("missing      4 files"));
  for (const char* name : {"1403715278012143104", "1403715278062142976", "1403715278112143104",
                           "1403715278162142976"}) {
    EXPECT_THAT(r.output, HasSubstr(fmt::format("mav0/cam1/data/{}.png", name)));
  }
  EXPECT_THAT(r.output, HasSubstr("gaps imu0    0 intervals"));
  std::string json = ReadText(out / "info.json");
  std::erase_if(json, [](char c) { return c == ' ' || c == '\n'; });
  EXPECT_THAT(json, HasSubstr("\"stereo_pairs\":95,"));
  EXPECT_THAT(json, HasSubstr("\"name\":\"imu0\",\"description\":"));
  EXPECT_THAT(json, HasSubstr("\"listed\":29120,\"count\":29120,\"missing\":0,"
                              "\"nominal_rate_hz\":200,"));
  EXPECT_THAT(json, HasSubstr("\"listed\":99,\"count\":95,\"missing\":4,"));
  fs::remove_all(out);
}

class CliInfoBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("cli_bad");
    WriteText(dir_ / "mav0" / "cam0" / "sensor.yaml",
              "%YAML:1.0\nT_BS:\n  cols: 4\n  rows: 4\n"
              "  data: [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0]\n"
              "rate_hz: 20\nresolution: [752, 480]\ncamera_model: pinhole\n"
              "intrinsics: [458.654, 457.296, 367.215, 248.375]\n"
              "distortion_model: radial-tangential\n"
              "distortion_coefficients: [-0.28, 0.07, 0.0002, 0.00002]\n");
    csv_ = dir_ / "mav0" / "cam0" / "data.csv";
  }
  void TearDown() override { fs::remove_all(dir_); }
  testing::CommandResult Info() const { return RunPkslam(fmt::format("info '{}'", dir_.string())); }

  fs::path dir_;
  fs::path csv_;
};

TEST_F(CliInfoBadInput, NonexistentDirectory) {
  ExpectOneLineError(RunPkslam(fmt::format("info '{}'", (dir_ / "nope").string())),
                     (dir_ / "nope").string() + ": dataset directory not found");
}

TEST_F(CliInfoBadInput, UnknownLayout) {
  fs::remove_all(dir_ / "mav0");
  ExpectOneLineError(Info(), "unknown dataset layout");
}

TEST_F(CliInfoBadInput, EmptyDataCsv) {
  WriteText(csv_, "");
  ExpectOneLineError(Info(), csv_.string() + ": no data rows (empty file)");
}

TEST_F(CliInfoBadInput, GarbageLine) {
  WriteText(csv_, "#timestamp [ns],filename\n100,100.png\n\x01garbage here\n200,200.png\n");
  ExpectOneLineError(Info(), csv_.string() + ":3: expected 2 fields");
}

TEST_F(CliInfoBadInput, UnsortedTimestamps) {
  WriteText(csv_, "#timestamp [ns],filename\n200,200.png\n100,100.png\n");
  ExpectOneLineError(Info(), csv_.string() + ":3: timestamp 100 is before the previous row's 200");
}

TEST_F(CliInfoBadInput, UnsortedTumRgb) {
  fs::remove_all(dir_ / "mav0");
  WriteText(dir_ / "rgb.txt", "# color images\n1305031102.2 rgb/a.png\n1305031102.1 rgb/b.png\n");
  WriteText(dir_ / "depth.txt", "1305031102.2 depth/a.png\n");
  ExpectOneLineError(Info(), (dir_ / "rgb.txt").string() + ":3: timestamp");
}

TEST_F(CliInfoBadInput, MalformedSensorYaml) {
  WriteText(csv_, "#timestamp [ns],filename\n100,100.png\n");
  WriteText(dir_ / "mav0" / "cam0" / "sensor.yaml", "%YAML:1.0\nrate_hz: fast\n");
  ExpectOneLineError(Info(), "sensor.yaml: key 'T_BS': missing (required)");
}

TEST(CliInfo, HelpDescribesTheCommand) {
  const auto r = RunPkslam("info --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_THAT(r.output, HasSubstr("--json"));
  EXPECT_THAT(r.output, HasSubstr("EuRoC ASL or TUM RGB-D"));
}

}  // namespace
}  // namespace pkslam
