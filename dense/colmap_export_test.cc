#include "dense/colmap_export.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam::dense {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> Lines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(in, line)) lines.push_back(line);
  return lines;
}

// Three keyframes 0.2 m apart along x looking along +z at a 6 x 5 grid of points 3 m away;
// every point is a keypoint (exact projection) in every keyframe, except point 29 which only
// keyframe 10 sees (a track of one).
SparseModel GeometricModel() {
  SparseModel m;
  m.camera = {640, 480, 400, 410, 320, 240, 40};
  for (int k = 0; k < 3; ++k) {
    SparseKeyframe kf;
    kf.id = 10 + 2 * k;
    kf.t_ns = 1'000'000'000 + 50'000'000LL * k;
    kf.camera_from_world = SE3d(SO3d(), Eigen::Vector3d(-0.2 * k, 0, 0));
    m.keyframes.push_back(kf);
  }
  for (int i = 0; i < 30; ++i) {
    SparsePoint p;
    p.id = 100 + i;
    p.position_world = Eigen::Vector3d(-0.5 + 0.2 * (i % 6), -0.4 + 0.2 * (i / 6), 3.0);
    for (auto& kf : m.keyframes) {
      if (i == 29 && kf.id != 10) continue;
      const Eigen::Vector3d pc = kf.camera_from_world * p.position_world;
      SparseKeypoint kp;
      kp.u = static_cast<float>(400 * pc.x() / pc.z() + 320);
      kp.v = static_cast<float>(410 * pc.y() / pc.z() + 240);
      kp.point_id = p.id;
      p.observations.emplace_back(kf.id, static_cast<int>(kf.keypoints.size()));
      kf.keypoints.push_back(kp);
    }
    m.points.push_back(p);
  }
  // A keypoint without a point.
  m.keyframes[1].keypoints.push_back({5.0f, 6.0f, 0, -1});
  m.CheckConsistency();
  return m;
}

class ColmapExportTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::MakeTempDir("colmap_export_test"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(ColmapExportTest, TextFilesHaveCheckedLines) {
  const SparseModel m = GeometricModel();
  const std::vector<std::string> names = {"a.png", "b.png", "c.png"};
  std::vector<Rgb> colours(m.points.size(), Rgb{1, 2, 3});
  const ColmapExportStats s = WriteColmapText(m, names, colours, ColmapExportOptions{}, dir_);
  EXPECT_EQ(s.images, 3);
  EXPECT_EQ(s.points, 29);
  EXPECT_EQ(s.points_dropped, 1);
  EXPECT_EQ(s.observations, 29u * 3u);
  EXPECT_NEAR(s.mean_reprojection_error_px, 0.0, 1e-3);

  const auto cameras = Lines(dir_ / "cameras.txt");
  ASSERT_EQ(cameras.size(), 4u);
  // COLMAP's principal point is shifted by half a pixel.
  EXPECT_EQ(cameras[3], "1 PINHOLE 640 480 400 410 320.5 240.5");

  const auto images = Lines(dir_ / "images.txt");
  ASSERT_EQ(images.size(), 4u + 2u * 3u);
  EXPECT_EQ(images[3], "# Number of images: 3, mean observations per image: 29");
  // Keyframe 12: identity rotation, cam_from_world translation (-0.2, 0, 0).
  EXPECT_EQ(images[6],
            "2 1.000000000000 0.000000000000 0.000000000000 0.000000000000 -0.200000000 "
            "0.000000000 0.000000000 1 b.png");
  // Its first keypoint: point 100 at (-0.5, -0.4, 3) seen from x = 0.2: u = 400 * -0.7 / 3 +
  // 320 = 226.6667 (+0.5), v = 410 * -0.4 / 3 + 240 = 185.3333 (+0.5); POINT3D_ID = 101.
  std::istringstream kps(images[7]);
  double x, y;
  long long id;
  kps >> x >> y >> id;
  EXPECT_NEAR(x, 227.1667, 1e-3);
  EXPECT_NEAR(y, 185.8333, 1e-3);
  EXPECT_EQ(id, 101);
  // The last keypoint of keyframe 12 has no point.
  EXPECT_NE(images[7].find(" 5.5000 6.5000 -1"), std::string::npos);
  // Keyframe 10 keeps point 129's keypoint but with -1 (its track of one is left out).
  EXPECT_NE(images[5].find(" -1"), std::string::npos);

  const auto points = Lines(dir_ / "points3D.txt");
  ASSERT_EQ(points.size(), 3u + 29u);
  EXPECT_EQ(points[2], "# Number of points: 29, mean track length: 3");
  // id + 1, xyz, colour, error (~0: float keypoints), track (image id, keypoint index).
  const std::string head = "101 -0.500000000 -0.400000000 3.000000000 1 2 3 0.0000";
  EXPECT_EQ(points[3].substr(0, head.size()), head) << points[3];
  const std::string track = " 1 0 2 0 3 0";
  EXPECT_EQ(points[3].substr(points[3].size() - track.size()), track) << points[3];
}

TEST_F(ColmapExportTest, ModelAnalyzerReadsTheModel) {
  const fs::path colmap = "/usr/bin/colmap";
  if (!fs::exists(colmap)) GTEST_SKIP() << "colmap is not installed (apt-get install colmap)";
  const SparseModel m = GeometricModel();
  WriteColmapText(m, {"a.png", "b.png", "c.png"}, {}, ColmapExportOptions{}, dir_);
  const auto r = testing::RunCommand(fmt::format(
      "QT_QPA_PLATFORM=offscreen {} model_analyzer --path '{}'", colmap.string(), dir_.string()));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("Cameras: 1"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Images: 3"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Points: 29"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Observations: 87"), std::string::npos) << r.output;
}

TEST_F(ColmapExportTest, InconsistentInputsThrow) {
  const SparseModel m = GeometricModel();
  EXPECT_THROW(WriteColmapText(m, {"a.png"}, {}, ColmapExportOptions{}, dir_), Error);
  ColmapExportOptions bad;
  bad.min_track_length = 0;
  EXPECT_THROW(WriteColmapText(m, {"a", "b", "c"}, {}, bad, dir_), OptionError);
}

}  // namespace
}  // namespace pkslam::dense
