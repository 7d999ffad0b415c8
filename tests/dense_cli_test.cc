// End-to-end tests of `pkslam dense`, `pkslam cloud-compare` and `pkslam export-colmap`: bad
// input gives one error line and a non-zero exit; a short real stereo run exports a COLMAP
// model that COLMAP reads (when colmap is installed) and a dense cloud.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

testing::CommandResult Pkslam(const std::string& arguments) {
  return testing::RunCommand(
      fmt::format("'{}' {}", testing::PkslamExecutable().string(), arguments));
}

class DenseCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::MakeTempDir("dense_cli_test");
    fs::create_directories(dir_ / "data");  // not a dataset; outputs go beside it
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& content) {
    const fs::path file = dir_ / name;
    fs::create_directories(file.parent_path());
    std::ofstream(file) << content;
    return file.string();
  }

  std::string ExpectOneLineError(const std::string& arguments) {
    const testing::CommandResult r = Pkslam(arguments);
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.rfind("pkslam: error: ", 0), 0u) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    return r.output;
  }

  fs::path dir_;
};

constexpr const char* kTinyPly =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";

TEST_F(DenseCliTest, DenseBadInputIsOneLine) {
  const std::string out = (dir_ / "c.ply").string();
  EXPECT_NE(ExpectOneLineError(fmt::format("dense --run {}/nope --dataset {} --out {}",
                                           dir_.string(), (dir_ / "data").string(), out))
                .find("run directory does not exist"),
            std::string::npos);
  fs::create_directories(dir_ / "run");
  EXPECT_NE(ExpectOneLineError(fmt::format("dense --run {}/run --dataset {} --out {}",
                                           dir_.string(), (dir_ / "data").string(), out))
                .find("keyframes.txt"),
            std::string::npos);
  Write("run/keyframes.txt", "1.0 0 0 0 0 0 0 1\n1.5 0 0 zero 0 0 0 1\n");
  EXPECT_NE(ExpectOneLineError(fmt::format("dense --run {}/run --dataset {} --out {}",
                                           dir_.string(), (dir_ / "data").string(), out))
                .find("keyframes.txt:2:"),
            std::string::npos);
  Write("run/keyframes.txt", "1.0 0 0 0 0 0 0 1\n");
  EXPECT_NE(ExpectOneLineError(fmt::format("dense --run {}/run --dataset {} --out {}",
                                           dir_.string(), (dir_ / "data").string(), out))
                .find("not a EuRoC"),
            std::string::npos);
  ExpectOneLineError(fmt::format("dense --run {}/run --dataset {} --out {} --voxel 0",
                                 dir_.string(), (dir_ / "data").string(), out));
}

TEST_F(DenseCliTest, CloudCompareBadInputIsOneLine) {
  const std::string good = Write("good.ply", kTinyPly);
  const std::string bad = Write("bad.ply",
                                "ply\nformat ascii 1.0\nelement vertex 2\n"
                                "property float x\nproperty float y\n"
                                "property float z\nend_header\n0 0 0\n");
  EXPECT_NE(ExpectOneLineError(fmt::format("cloud-compare --cloud {} --ref {}", bad, good))
                .find("bad.ply:9:"),
            std::string::npos);
  EXPECT_NE(ExpectOneLineError(
                fmt::format("cloud-compare --cloud {} --ref {}/none.ply", good, dir_.string()))
                .find("cannot open"),
            std::string::npos);
  EXPECT_NE(ExpectOneLineError(fmt::format("cloud-compare --cloud {} --ref {} --align-run {}", good,
                                           good, dir_.string()))
                .find("--gt"),
            std::string::npos);
  // Identical clouds: perfect scores, JSON written.
  const auto r = Pkslam(
      fmt::format("cloud-compare --cloud {} --ref {} --json {}/r.json", good, good, dir_.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("completeness  100.0%"), std::string::npos) << r.output;
  std::ifstream json(dir_ / "r.json");
  std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"completeness\": 1"), std::string::npos) << text;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
  // The same cloud 3 m away and unaligned: the numbers come with a warning naming the fix.
  const std::string far = Write("far.ply",
                                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                "property float y\nproperty float z\nend_header\n3 0 0\n4 0 0\n"
                                "3 1 0\n");
  const auto w = Pkslam(fmt::format("cloud-compare --cloud {} --ref {}", far, good));
  ASSERT_EQ(w.exit_code, 0) << w.output;
  EXPECT_NE(w.output.find("warning: the median distance to the reference is"), std::string::npos)
      << w.output;
  EXPECT_NE(w.output.find("--align-run"), std::string::npos) << w.output;
}

TEST_F(DenseCliTest, ExportColmapBadInputIsOneLine) {
  fs::create_directories(dir_ / "run");
  EXPECT_NE(ExpectOneLineError(fmt::format("export-colmap --run {}/run --dataset {} --out {}/o",
                                           dir_.string(), dir_.string(), dir_.string()))
                .find("sparse_model.txt"),
            std::string::npos);
  Write("run/sparse_model.txt", "pkslam_sparse_model 1\ncamera 10 10 5 5 5 5 0\nkeyframes 2\n");
  EXPECT_NE(ExpectOneLineError(fmt::format("export-colmap --run {}/run --dataset {} --out {}/o",
                                           dir_.string(), dir_.string(), dir_.string()))
                .find("truncated"),
            std::string::npos);
}

// A short real stereo run (the static V1_01 start: 95 pairs) -> sparse model -> COLMAP model
// that COLMAP's model_analyzer reads, and a dense cloud.
TEST_F(DenseCliTest, RealRunExportsAColmapModelAndADenseCloud) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path dataset = shared / "euroc" / "V1_01_easy_static";
  const fs::path run = dir_ / "run";
  const auto r =
      Pkslam(fmt::format("run --dataset '{}' --sensor stereo --out '{}' --quiet "
                         "--max-frames 40 --deterministic",
                         dataset.string(), run.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(fs::exists(run / "sparse_model.txt"));
  const auto e = Pkslam(fmt::format("export-colmap --run '{}' --dataset '{}' --out '{}' --quiet",
                                    run.string(), dataset.string(), (dir_ / "colmap").string()));
  ASSERT_EQ(e.exit_code, 0) << e.output;
  EXPECT_TRUE(fs::exists(dir_ / "colmap" / "sparse" / "points3D.txt"));
  EXPECT_FALSE(fs::is_empty(dir_ / "colmap" / "images"));
  if (fs::exists("/usr/bin/colmap")) {
    const auto a = testing::RunCommand(
        fmt::format("QT_QPA_PLATFORM=offscreen /usr/bin/colmap model_analyzer --path '{}'",
                    (dir_ / "colmap" / "sparse").string()));
    EXPECT_EQ(a.exit_code, 0) << a.output;
    EXPECT_NE(a.output.find("Cameras: 1"), std::string::npos) << a.output;
    EXPECT_NE(a.output.find("Mean reprojection error"), std::string::npos) << a.output;
  }
  const auto d =
      Pkslam(fmt::format("dense --run '{}' --dataset '{}' --out '{}' --quiet "
                         "--max-depth 8 --min-views 1",
                         run.string(), dataset.string(), (dir_ / "d.ply").string()));
  ASSERT_EQ(d.exit_code, 0) << d.output;
  EXPECT_GT(fs::file_size(dir_ / "d.ply"), 100000u);
  // The TSDF mesh of the same keyframes: a PLY with faces whose surface lies on the cloud (a
  // mesh fused at the wrong poses or with the wrong intrinsics would not).
  const auto m =
      Pkslam(fmt::format("dense --run '{}' --dataset '{}' --mesh '{}' --quiet "
                         "--max-depth 8",
                         run.string(), dataset.string(), (dir_ / "m.ply").string()));
  ASSERT_EQ(m.exit_code, 0) << m.output;
  EXPECT_NE(m.output.find("triangles"), std::string::npos) << m.output;
  const auto c = Pkslam(fmt::format("cloud-compare --cloud '{}' --ref '{}' --json '{}'",
                                    (dir_ / "m.ply").string(), (dir_ / "d.ply").string(),
                                    (dir_ / "c.json").string()));
  ASSERT_EQ(c.exit_code, 0) << c.output;
  EXPECT_NE(c.output.find("sampled on its triangles"), std::string::npos) << c.output;
  std::ifstream json(dir_ / "c.json");
  const std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  const auto at = text.find("\"median\": ", text.find("\"accuracy\""));
  ASSERT_NE(at, std::string::npos) << text;
  EXPECT_LT(std::stod(text.substr(at + 10)), 0.05) << text.substr(0, 400);
}

}  // namespace
}  // namespace pkslam
