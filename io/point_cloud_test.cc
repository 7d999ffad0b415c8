#include "io/point_cloud.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

class PointCloudTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::MakeTempDir("point_cloud_test"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path Write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  std::string ErrorOf(const fs::path& file) {
    try {
      ReadPly(file);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  }
  fs::path dir_;
};

PointCloud ThreePoints() {
  PointCloud c;
  c.points = {{0.5f, -1.25f, 3.0f}, {1e3f, 2e-3f, -7.5f}, {0, 0, 0}};
  c.colours = {{255, 0, 10}, {30, 60, 90}, {7, 7, 7}};
  c.views = {2, 9, 255};
  return c;
}

TEST_F(PointCloudTest, BinaryRoundTripWithRgbAndViews) {
  const PointCloud c = ThreePoints();
  WritePly(c, dir_ / "c.ply", PlyColour::kRgb, "test cloud");
  const PointCloud r = ReadPly(dir_ / "c.ply");
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r.points, c.points);
  EXPECT_EQ(r.colours, c.colours);
  EXPECT_EQ(r.views, c.views);
}

TEST_F(PointCloudTest, GreyIsTheMeanAndReadsBackReplicated) {
  WritePly(ThreePoints(), dir_ / "g.ply", PlyColour::kGrey);
  const PointCloud r = ReadPly(dir_ / "g.ply");
  ASSERT_EQ(r.colours.size(), 3u);
  EXPECT_EQ(r.colours[0], (Rgb{88, 88, 88}));  // (255 + 0 + 10 + 1) / 3
  EXPECT_EQ(r.colours[1], (Rgb{60, 60, 60}));
  PointCloud plain;
  plain.points = {{1, 2, 3}};
  WritePly(plain, dir_ / "p.ply", PlyColour::kNone);
  EXPECT_FALSE(ReadPly(dir_ / "p.ply").has_colour());
  EXPECT_THROW(WritePly(plain, dir_ / "x.ply", PlyColour::kRgb), Error);  // no colours
}

TEST_F(PointCloudTest, ReadsAsciiWithOtherPropertiesAndTrailingFaces) {
  const fs::path f = Write("a.ply",
                           "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 2\n"
                           "property double x\nproperty double y\nproperty double z\n"
                           "property float nx\nproperty uchar red\nproperty uchar green\n"
                           "property uchar blue\nelement face 1\n"
                           "property list uchar int vertex_indices\nend_header\n"
                           "1 2 3 0.5 10 20 30\n-1.5 0 2.25 0 1 2 3\n3 0 1 1\n");
  const PointCloud r = ReadPly(f);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r.points[1], Eigen::Vector3f(-1.5f, 0.0f, 2.25f));
  EXPECT_EQ(r.colours[0], (Rgb{10, 20, 30}));
}

TEST_F(PointCloudTest, ReadsNormalizedNormalsAndRejectsZeroOnes) {
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n";
  const PointCloud r = ReadPly(Write("n.ply", header + "0 0 0 0 0 1\n1 1 1 0 1.1 0\n"));
  ASSERT_TRUE(r.has_normals());
  EXPECT_EQ(r.normals[0], Eigen::Vector3f(0, 0, 1));
  EXPECT_NEAR((r.normals[1] - Eigen::Vector3f(0, 1, 0)).norm(), 0.0f, 1e-6f);
  EXPECT_NE(ErrorOf(Write("z.ply", header + "0 0 0 0 0 1\n1 1 1 0 0 0\n")).find("z.ply:12:"),
            std::string::npos);
  EXPECT_FALSE(ReadPly(Write("p.ply",
                             "ply\nformat ascii 1.0\nelement vertex 1\n"
                             "property float x\nproperty float y\nproperty float z\n"
                             "property float nx\nend_header\n1 2 3 0.5\n"))
                   .has_normals());
}

TEST_F(PointCloudTest, MalformedFilesNameFileAndLine) {
  EXPECT_NE(ErrorOf(Write("n.ply", "PLY\n")).find("n.ply:1:"), std::string::npos);
  EXPECT_NE(ErrorOf(Write("f.ply", "ply\nformat binary_big_endian 1.0\nend_header\n"))
                .find("f.ply:2: unsupported PLY format"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Write("x.ply",
                          "ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\n"
                          "property float z\nend_header\n1 2\n"))
                .find("no x, y, z"),
            std::string::npos);
  EXPECT_NE(ErrorOf(Write("a.ply",
                          "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n1 2 3\n1 2\n"))
                .find("a.ply:9:"),
            std::string::npos);
  // Binary file cut short.
  WritePly(ThreePoints(), dir_ / "t.ply", PlyColour::kRgb);
  const auto size = fs::file_size(dir_ / "t.ply");
  fs::resize_file(dir_ / "t.ply", size - 5);
  EXPECT_NE(ErrorOf(dir_ / "t.ply").find("file ends at vertex 2 of 3"), std::string::npos);
  EXPECT_NE(ErrorOf(dir_ / "missing.ply").find("cannot open"), std::string::npos);
}

}  // namespace
}  // namespace pkslam
