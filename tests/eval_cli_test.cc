// End-to-end tests of `pkslam eval`: the published evo numbers through the real binary, and one
// clear error line with a non-zero exit for each kind of bad input.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

std::string ReadFile(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

// The number after `"key": ` following the first occurrence of `section` in a JSON text.
double JsonNumber(const std::string& json, const std::string& section, const std::string& key) {
  const std::size_t start = json.find(section);
  if (start == std::string::npos) return -1.0;
  const std::size_t at = json.find("\"" + key + "\": ", start);
  if (at == std::string::npos) return -1.0;
  return std::stod(json.substr(at + key.size() + 4));
}

testing::CommandResult Eval(const std::string& arguments) {
  return testing::RunCommand(
      fmt::format("'{}' eval {}", testing::PkslamExecutable().string(), arguments));
}

class EvalCliTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::MakeTempDir("eval_cli_test"); }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& content) {
    const fs::path file = dir_ / name;
    std::ofstream(file) << content;
    return file.string();
  }

  // Runs eval expecting failure: non-zero exit and a single line "pkslam: error: ...".
  std::string ExpectOneLineError(const std::string& arguments) {
    const testing::CommandResult r = Eval(arguments);
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.rfind("pkslam: error: ", 0), 0u) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    return r.output;
  }

  fs::path dir_;
};

const char* const kGood =
    "1.00 0 0 0 0 0 0 1\n1.05 1 0 0 0 0 0 1\n1.10 2 0 0 0 0 0 1\n1.15 3 1 0 0 0 0 1\n";

TEST_F(EvalCliTest, ReproducesEvoOnFr2Desk) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path json = dir_ / "fr2.json";
  const testing::CommandResult r =
      Eval(fmt::format("--gt '{}' --est '{}' --align se3 --json '{}'",
                       (shared / "evo" / "fr2_desk_groundtruth.txt").string(),
                       (shared / "evo" / "fr2_desk_ORB.txt").string(), json.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("ATE [m]"), std::string::npos) << r.output;
  const std::string text = ReadFile(json);
  EXPECT_NE(text.find("\"alignment\": \"se3\""), std::string::npos) << text;
  EXPECT_NEAR(JsonNumber(text, "\"ate\"", "rmse"), 0.008119, 5e-7);
  EXPECT_NEAR(JsonNumber(text, "\"ate\"", "mean"), 0.007492, 5e-7);
  EXPECT_NEAR(JsonNumber(text, "\"ate\"", "max"), 0.024300, 5e-7);
  EXPECT_NEAR(JsonNumber(text, "\"ate\"", "sse"), 0.143305, 5e-7);
  EXPECT_EQ(JsonNumber(text, "{", "scale"), 1.0);
  EXPECT_GT(JsonNumber(text, "\"ate_rot_deg\"", "rmse"), 0.0);
  EXPECT_GT(JsonNumber(text, "\"rpe\"", "rmse"), 0.0);
}

TEST_F(EvalCliTest, ReproducesEvoOnFr1XyzRgbdslam) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path json = dir_ / "fr1.json";
  const testing::CommandResult r =
      Eval(fmt::format("--gt '{}' --est '{}' --json '{}'",
                       (shared / "evo" / "freiburg1_xyz-groundtruth.txt").string(),
                       (shared / "evo" / "freiburg1_xyz-rgbdslam.txt").string(), json.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string text = ReadFile(json);
  EXPECT_EQ(JsonNumber(text, "{", "pairs"), 785.0);
  EXPECT_NEAR(JsonNumber(text, "\"ate\"", "rmse"), 0.013470, 5e-7);
}

TEST_F(EvalCliTest, SyntheticRunWithEveryAlignmentAndRpeUnit) {
  const std::string gt = Write("gt.txt", kGood);
  for (const char* align : {"se3", "sim3", "posyaw", "none"}) {
    const testing::CommandResult r =
        Eval(fmt::format("--gt {} --est {} --align {} --rpe-delta 1 --rpe-unit m", gt, gt, align));
    EXPECT_EQ(r.exit_code, 0) << align << "\n" << r.output;
    EXPECT_NE(r.output.find("pairs      4"), std::string::npos) << r.output;
  }
}

// --body-from-camera moves body-frame ground truth into the camera: a camera trajectory
// 0.5 m ahead of the body along its x axis matches it exactly, and does not without the option.
TEST_F(EvalCliTest, BodyFromCameraComparesCameraPoses) {
  const std::string gt = Write("gt.txt", kGood);
  // Body yaw 90 deg (qz = qw = sqrt(1/2)): the camera, 0.5 m along body x, sits at +0.5 m y.
  const std::string est = Write("est.txt",
                                "1.00 0 0.5 0 0 0 0.7071067811865476 0.7071067811865476\n"
                                "1.05 1 0.5 0 0 0 0.7071067811865476 0.7071067811865476\n"
                                "1.10 2 0.5 0 0 0 0.7071067811865476 0.7071067811865476\n"
                                "1.15 3 1.5 0 0 0 0.7071067811865476 0.7071067811865476\n");
  const std::string rotated_gt = Write("rotated_gt.txt",
                                       "1.00 0 0 0 0 0 0.7071067811865476 0.7071067811865476\n"
                                       "1.05 1 0 0 0 0 0.7071067811865476 0.7071067811865476\n"
                                       "1.10 2 0 0 0 0 0.7071067811865476 0.7071067811865476\n"
                                       "1.15 3 1 0 0 0 0.7071067811865476 0.7071067811865476\n");
  const std::string extrinsic =
      Write("body_from_camera.txt", "# body_from_camera\n1 0 0 0.5\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  testing::CommandResult r =
      Eval(fmt::format("--gt {} --est {} --align none --body-from-camera {} --json {}/r.json",
                       rotated_gt, est, extrinsic, dir_.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_LT(JsonNumber(ReadFile(dir_ / "r.json"), "\"ate\"", "rmse"), 1e-9) << r.output;
  r = Eval(fmt::format("--gt {} --est {} --align none --json {}/r.json", rotated_gt, est,
                       dir_.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NEAR(JsonNumber(ReadFile(dir_ / "r.json"), "\"ate\"", "rmse"), 0.5, 1e-9);
  const std::string bad = Write("bad.txt", "1 0 0\n");
  const std::string out =
      ExpectOneLineError(fmt::format("--gt {} --est {} --body-from-camera {}", gt, gt, bad));
  EXPECT_NE(out.find("bad.txt:1: expected 4 numbers"), std::string::npos) << out;
}

TEST_F(EvalCliTest, BadInputsGiveOneLineErrors) {
  const std::string good = Write("good.txt", kGood);
  const std::string empty = Write("empty.txt", "");
  std::string out = ExpectOneLineError(fmt::format("--gt {} --est {}", good, empty));
  EXPECT_NE(out.find("empty.txt: empty trajectory file"), std::string::npos) << out;

  const std::string garbage = Write("garbage.txt", "1.0 0 0 0 0 0 0 1\n1.1 0 0 oops 0 0 0 1\n");
  out = ExpectOneLineError(fmt::format("--gt {} --est {}", good, garbage));
  EXPECT_NE(out.find("garbage.txt:2: column 4: 'oops' is not a number"), std::string::npos) << out;

  const std::string unsorted =
      Write("unsorted.txt", "1.0 0 0 0 0 0 0 1\n1.1 0 0 0 0 0 0 1\n1.05 0 0 0 0 0 0 1\n");
  out = ExpectOneLineError(fmt::format("--gt {} --est {}", unsorted, good));
  EXPECT_NE(out.find("unsorted.txt:3: timestamp 1.050000000 s is before"), std::string::npos)
      << out;

  const std::string later = Write("later.txt",
                                  "100.00 0 0 0 0 0 0 1\n100.05 1 0 0 0 0 0 1\n"
                                  "100.10 2 0 0 0 0 0 1\n");
  out = ExpectOneLineError(fmt::format("--gt {} --est {}", good, later));
  EXPECT_NE(out.find("later.txt: no pose within 0.01 s"), std::string::npos) << out;
  EXPECT_NE(out.find("no time overlap"), std::string::npos) << out;

  const std::string five = Write("five.txt", "1 2 3 4 5\n");
  out = ExpectOneLineError(fmt::format("--gt {} --est {}", good, five));
  EXPECT_NE(out.find("five.txt:1: unknown trajectory format"), std::string::npos) << out;
  out = ExpectOneLineError(fmt::format("--gt {} --est {} --est-format kitti", good, good));
  EXPECT_NE(out.find("unknown trajectory format 'kitti'"), std::string::npos) << out;
  out = ExpectOneLineError(fmt::format("--gt {} --est {} --align affine", good, good));
  EXPECT_NE(out.find("unknown alignment 'affine'"), std::string::npos) << out;

  out = ExpectOneLineError(fmt::format("--gt {} --est {}", good, (dir_ / "missing.txt").string()));
  EXPECT_NE(out.find("missing.txt: trajectory file not found"), std::string::npos) << out;
  out = ExpectOneLineError(fmt::format("--gt {} --est {} --max-diff -1", good, good));
  EXPECT_NE(out.find("--max-diff"), std::string::npos) << out;  // the flag, not a field name
  out = ExpectOneLineError(fmt::format("--gt {} --est {} --rpe-delta 50", good, good));
  EXPECT_NE(out.find("RPE delta 50 frames selects no pose pair"), std::string::npos) << out;
}

// A circle of 200 poses (5 Hz) and estimates that drift from it differently.
std::string CircleTrajectory(double radius_gain, double height_drift_per_s) {
  std::string text;
  for (int k = 0; k < 200; ++k) {
    const double t = 0.2 * k;
    const double a = 2.0 * M_PI * t / 40.0;
    const double r = 3.0 * (1.0 + radius_gain * t / 40.0);
    // Heading along the circle: yaw a + 90 deg.
    const double half = 0.5 * (a + M_PI / 2);
    text += fmt::format("{:.3f} {:.9f} {:.9f} {:.9f} 0 0 {:.12f} {:.12f}\n", 100.0 + t,
                        r * std::cos(a), r * std::sin(a), height_drift_per_s * t, std::sin(half),
                        std::cos(half));
  }
  return text;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

// --plot with three estimates: one table, one JSON entry each, the eight figures listed and
// drawn, and the saved per-pose errors agree with the JSON's statistics.
TEST_F(EvalCliTest, PlotsAndSavesSeveralEstimatesAgainstOneTruth) {
  if (!fs::exists("/usr/bin/python3")) GTEST_SKIP() << "no /usr/bin/python3 for matplotlib";
  const std::string gt = Write("gt.txt", CircleTrajectory(0.0, 0.0));
  const std::string a = Write("grow.txt", CircleTrajectory(0.02, 0.0));
  const std::string b = Write("climb.txt", CircleTrajectory(0.0, 0.002));
  const std::string c = Write("both.txt", CircleTrajectory(0.02, 0.002));
  const fs::path plots = dir_ / "plots";
  const testing::CommandResult r = Eval(fmt::format(
      "--gt {} --est {} {} {} --label grow climb both --plot {} --save-aligned {} --save-errors {} "
      "--json {}",
      gt, a, b, c, plots.string(), (dir_ / "aligned").string(), (dir_ / "errors").string(),
      (dir_ / "all.json").string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const char* label : {"grow ", "climb ", "both "}) {
    EXPECT_NE(r.output.find(label), std::string::npos) << r.output;
  }
  EXPECT_NE(r.output.find("relative error over segment lengths"), std::string::npos) << r.output;

  const std::vector<std::string> figures = Lines(ReadFile(plots / "figures.tsv"));
  const std::vector<std::string> expected = {
      "trajectories_top.png", "trajectories_xyz.png", "trajectories_rpy.png", "ate_over_time.png",
      "ate_along_path.png",   "rpe_over_time.png",    "segment_errors.png",   "ate_box.png"};
  ASSERT_EQ(figures.size(), expected.size()) << ReadFile(plots / "figures.tsv");
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(figures[k].substr(0, figures[k].find('\t')), expected[k]);
    EXPECT_GT(fs::file_size(plots / expected[k]), 10000u) << expected[k];  // a drawn PNG
  }

  // One JSON entry per estimate, in order; the per-pose file reproduces its ATE rmse.
  const std::string json = ReadFile(dir_ / "all.json");
  const std::size_t grow = json.find("\"label\": \"grow\"");
  const std::size_t climb = json.find("\"label\": \"climb\"");
  const std::size_t both = json.find("\"label\": \"both\"");
  ASSERT_NE(both, std::string::npos) << json;
  EXPECT_LT(grow, climb);
  EXPECT_LT(climb, both);
  const std::vector<std::string> rows = Lines(ReadFile(dir_ / "errors" / "climb_poses.csv"));
  ASSERT_EQ(rows.size(), 201u);  // header + one per matched pose
  double sum_sq = 0.0;
  for (std::size_t k = 1; k < rows.size(); ++k) {
    std::vector<std::string> cells;
    std::stringstream line(rows[k]);
    for (std::string cell; std::getline(line, cell, ',');) cells.push_back(cell);
    ASSERT_EQ(cells.size(), 16u) << rows[k];
    sum_sq += std::stod(cells[13]) * std::stod(cells[13]);
  }
  EXPECT_NEAR(std::sqrt(sum_sq / 200.0), JsonNumber(json.substr(climb), "\"ate\"", "rmse"), 1e-7);
  EXPECT_GT(JsonNumber(json.substr(climb), "\"ate\"", "rmse"), 0.01);  // the climb is measured
  EXPECT_EQ(Lines(ReadFile(dir_ / "aligned" / "both_aligned.tum")).size(), 201u);  // + header
  EXPECT_TRUE(fs::exists(dir_ / "errors" / "grow_segments.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "errors" / "grow_rpe.csv"));
}

TEST_F(EvalCliTest, SeveralEstimatesBadOptionsGiveOneLineErrors) {
  const std::string good = Write("good.txt", kGood);
  std::string out =
      ExpectOneLineError(fmt::format("--gt {} --est {} {} --label only_one", good, good, good));
  EXPECT_NE(out.find("--label given 1 times for 2 --est files"), std::string::npos) << out;
  out = ExpectOneLineError(fmt::format("--gt {} --est {} --segments 10,abc", good, good));
  EXPECT_NE(out.find("'abc' is not a length"), std::string::npos) << out;
  out = ExpectOneLineError(
      fmt::format("--gt {} --est {} --rpe-all-pairs --rpe-consecutive", good, good));
  EXPECT_NE(out.find("exclude each other"), std::string::npos) << out;
}

TEST_F(EvalCliTest, MissingRequiredOptionFails) {
  const testing::CommandResult r = Eval("--gt x.txt");
  EXPECT_NE(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("--est"), std::string::npos) << r.output;
  const testing::CommandResult help = Eval("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("--rpe-unit"), std::string::npos) << help.output;
}

}  // namespace
}  // namespace pkslam
