#include "dense/dense_cloud.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/util/error.h"
#include "io/settings_euroc.h"
#include "system/rig_factory.h"
#include "tests/support/test_data.h"

namespace pkslam::dense {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 160, kH = 120;

// A TUM RGB-D layout dataset of a wall z = 2 m (world) seen by cameras at x = 0.1 * i,
// looking along +z, so every depth pixel is 2 m. Frame i has timestamp 1 + 0.1 i s.
fs::path MakeRgbdDataset(const fs::path& dir, int frames) {
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  std::ofstream rgb(dir / "rgb.txt"), depth(dir / "depth.txt");
  for (int i = 0; i < frames; ++i) {
    const std::string t = fmt::format("{:.6f}", 1.0 + 0.1 * i);
    cv::Mat colour(kH, kW, CV_8UC3, cv::Scalar(10, 20, 200));  // BGR
    cv::Mat d(kH, kW, CV_16U, cv::Scalar(10000));              // 2 m * 5000
    cv::imwrite((dir / "rgb" / (t + ".png")).string(), colour);
    cv::imwrite((dir / "depth" / (t + ".png")).string(), d);
    rgb << t << " rgb/" << t << ".png\n";
    depth << t << " depth/" << t << ".png\n";
  }
  std::ofstream(dir / "settings.yaml")
      << "%YAML:1.0\nFile.version: \"1.0\"\nCamera.type: \"PinHole\"\n"
      << "Camera1.fx: 100.0\nCamera1.fy: 100.0\nCamera1.cx: 79.5\nCamera1.cy: 59.5\n"
      << "Camera.width: 160\nCamera.height: 120\nCamera.fps: 10\nCamera.RGB: 1\n"
      << "RGBD.DepthMapFactor: 5000.0\n";
  return dir;
}

Trajectory Keyframes(const std::vector<int>& frames) {
  Trajectory t;
  for (int i : frames) {
    t.poses.push_back(
        {1'000'000'000LL + 100'000'000LL * i, SE3d(SO3d(), Eigen::Vector3d(0.1 * i, 0, 0))});
  }
  return t;
}

class DenseCloudTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::MakeTempDir("dense_cloud_test"); }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(DenseCloudTest, RgbdKeyframesFuseOntoTheWall) {
  const auto source = KeyframeImageSource::Open(MakeRgbdDataset(dir_ / "ds", 3), std::nullopt);
  EXPECT_EQ(source.source(), DepthSource::kRgbd);
  DenseOptions o;
  o.voxel_m = 0.02;
  o.quiet = true;
  o.keep_unconfirmed = false;  // the strict filter: >= 2 keyframes for every point
  DenseStats stats;
  const PointCloud fused = BuildDenseCloud(Keyframes({0, 2}), source, o, &stats);
  EXPECT_EQ(stats.keyframes_used, 2);
  ASSERT_GT(fused.size(), 100u);
  for (const auto& p : fused.points) ASSERT_NEAR(p.z(), 2.0, 1e-4);
  // The views overlap where both see the wall: pixels 4..155 (4 px border) see
  // x = +-(75.5 / 100) * 2 = +-1.51 m around each camera, so x in [0.2 - 1.51, 1.51].
  float min_x = 1e9, max_x = -1e9;
  for (const auto& p : fused.points) {
    min_x = std::min(min_x, p.x());
    max_x = std::max(max_x, p.x());
  }
  EXPECT_NEAR(min_x, 0.2 - 1.51, 0.03);
  EXPECT_NEAR(max_x, 1.51, 0.03);
  EXPECT_EQ(fused.colours[0], (Rgb{200, 20, 10}));
  // Without the multi-view filter the single-view margins are kept too.
  o.min_views = 1;
  const PointCloud all = BuildDenseCloud(Keyframes({0, 2}), source, o, &stats);
  EXPECT_GT(all.size(), fused.size());
  EXPECT_EQ(stats.voxels, all.size());
  // The default keeps them as well: nothing contradicts a margin only one keyframe sees.
  // Their points carry views 1, the overlap's views 2.
  o.min_views = 2;
  o.keep_unconfirmed = true;
  const PointCloud kept = BuildDenseCloud(Keyframes({0, 2}), source, o, &stats);
  EXPECT_EQ(kept.size(), all.size());
  EXPECT_GT(stats.unconfirmed_points, 0u);
  std::size_t single = 0;
  for (std::size_t i = 0; i < kept.size(); ++i) single += kept.views[i] == 1;
  EXPECT_GT(single, 0u);
  EXPECT_EQ(kept.size() - single, fused.size());
}

TEST_F(DenseCloudTest, WindowAndBatchSizes) {
  const auto source = KeyframeImageSource::Open(MakeRgbdDataset(dir_ / "ds", 6), std::nullopt);
  DenseOptions o;
  o.voxel_m = 0.02;
  o.quiet = true;
  o.window = 1;
  o.keep_unconfirmed = false;
  o.batch = 1;  // depth maps released as soon as the window has passed them
  DenseStats stats;
  const Trajectory kfs = Keyframes({0, 1, 2, 3, 4, 5});
  const PointCloud one = BuildDenseCloud(kfs, source, o, &stats);
  o.batch = 4;
  const PointCloud four = BuildDenseCloud(kfs, source, o, &stats);
  ASSERT_GT(one.size(), 100u);
  EXPECT_EQ(one.points, four.points);
  // Three views: the first and last keyframes have one neighbour each, so nothing of theirs
  // survives; the confirmed points lie where a keyframe and both its neighbours see the wall.
  o.min_views = 3;
  const PointCloud three = BuildDenseCloud(kfs, source, o, &stats);
  EXPECT_LT(three.size(), one.size());
  EXPECT_LT(stats.consistent_points, stats.depth_points * 4 / 6 + 1);
  EXPECT_GT(stats.consistent_points, stats.depth_points / 2);
  // A window too small for min_views is an option error.
  o.window = 0;
  EXPECT_THROW(BuildDenseCloud(kfs, source, o, &stats), OptionError);
}

TEST_F(DenseCloudTest, KeyframesWithoutFramesAreSkippedOrRejected) {
  const auto source = KeyframeImageSource::Open(MakeRgbdDataset(dir_ / "ds", 2), std::nullopt);
  DenseOptions o;
  o.quiet = true;
  o.min_views = 1;
  Trajectory kfs = Keyframes({0, 7});  // frame 7 does not exist
  DenseStats stats;
  BuildDenseCloud(kfs, source, o, &stats);
  EXPECT_EQ(stats.keyframes_used, 1);
  ASSERT_EQ(stats.missing_t_ns.size(), 1u);
  EXPECT_EQ(stats.missing_t_ns[0], 1'700'000'000LL);
  EXPECT_THROW(BuildDenseCloud(Keyframes({5, 6}), source, o, &stats), InputError);
  o.max_depth_m = 1.5;  // the wall is beyond: nothing survives
  EXPECT_EQ(BuildDenseCloud(Keyframes({0, 1}), source, o, &stats).size(), 0u);
}

TEST_F(DenseCloudTest, RayTableInvertsADistortedCamera) {
  const CameraModel camera =
      CameraModel::Pinhole(752, 480, 458.654, 457.296, 367.215, 248.375,
                           {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05});
  const cv::Mat rays = RayTable(camera);
  for (const auto& [u, v] : {std::pair{0, 0}, {751, 479}, {367, 248}, {100, 400}}) {
    const cv::Vec2f r = rays.at<cv::Vec2f>(v, u);
    const auto uv = camera.Project(Eigen::Vector3d(r[0] * 2.0, r[1] * 2.0, 2.0));
    ASSERT_TRUE(uv.has_value());
    EXPECT_NEAR(uv->x(), u, 1e-3);
    EXPECT_NEAR(uv->y(), v, 1e-3);
  }
}

TEST(DenseStereoSourceTest, SameRectifiedCameraAsTheRun) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path dataset = shared / "euroc" / "V1_01_easy_static";
  const auto source = KeyframeImageSource::Open(dataset, std::nullopt);
  ASSERT_EQ(source.source(), DepthSource::kStereo);
  const RigSetup rig = MakeRig(SettingsFromEuroc(EurocDataset::Open(dataset)), Sensor::kStereo);
  EXPECT_EQ(source.camera().fx(), rig.rig->camera.fx());
  EXPECT_EQ(source.camera().cx(), rig.rig->camera.cx());
  EXPECT_EQ(source.camera().cy(), rig.rig->camera.cy());
  EXPECT_DOUBLE_EQ(source.bf(), rig.rig->bf);
  // The images load rectified and SGBM finds depth on most of the real scene.
  const auto frame = source.FindFrame(source.timestamps()[10]);
  ASSERT_TRUE(frame.has_value());
  const KeyframeImages images = source.Load(*frame);
  DenseOptions o;
  o.max_depth_m = 10;
  const cv::Mat depth = KeyframeDepth(images, source, o);
  const double valid = static_cast<double>(cv::countNonZero(depth)) / depth.total();
  EXPECT_GT(valid, 0.3);
}

TEST(DenseStereoSourceTest, FullViewKeepsTheRunsGeometryOnAWiderCanvas) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path dataset = shared / "euroc" / "V1_01_easy_static";
  const auto run_view = KeyframeImageSource::Open(dataset, std::nullopt);
  const auto full = KeyframeImageSource::Open(dataset, std::nullopt, true);
  const CameraModel& a = run_view.camera();
  const CameraModel& b = full.camera();
  // Same focal length and baseline (the run's poses and disparities stay valid), larger image.
  EXPECT_EQ(b.fx(), a.fx());
  EXPECT_EQ(b.fy(), a.fy());
  EXPECT_DOUBLE_EQ(full.bf(), run_view.bf());
  EXPECT_TRUE(run_view.valid_mask().empty());
  const int dx = static_cast<int>(std::lround(b.cx() - a.cx()));
  const int dy = static_cast<int>(std::lround(b.cy() - a.cy()));
  EXPECT_DOUBLE_EQ(b.cx() - a.cx(), dx);
  EXPECT_DOUBLE_EQ(b.cy() - a.cy(), dy);
  EXPECT_GT(dx, 20);  // EuRoC's barrel distortion: the raw images reach well beyond
  EXPECT_GT(b.width(), a.width() + 2 * 20);
  EXPECT_GE(b.height(), a.height());
  ASSERT_EQ(full.valid_mask().size(), cv::Size(b.width(), b.height()));
  EXPECT_EQ(full.valid_mask().at<std::uint8_t>(b.height() / 2, b.width() / 2), 255);
  EXPECT_EQ(full.valid_mask().at<std::uint8_t>(0, 0), 0);  // the canvas corner is no raw pixel
  // The run's rectified image is the full view's centre (the same rectifying rotation).
  const std::size_t frame = *full.FindFrame(full.timestamps()[10]);
  const KeyframeImages small = run_view.Load(frame);
  const KeyframeImages wide = full.Load(frame);
  ASSERT_EQ(wide.grey.size(), cv::Size(b.width(), b.height()));
  ASSERT_EQ(wide.right.size(), wide.grey.size());
  const cv::Rect inner(dx + 10, dy + 10, a.width() - 20, a.height() - 20);
  cv::Mat diff;
  cv::absdiff(small.grey(cv::Rect(10, 10, a.width() - 20, a.height() - 20)), wide.grey(inner),
              diff);
  EXPECT_LT(cv::mean(diff)[0], 1.0);
  cv::absdiff(small.right(cv::Rect(10, 10, a.width() - 20, a.height() - 20)), wide.right(inner),
              diff);
  EXPECT_LT(cv::mean(diff)[0], 1.0);
  // More depth pixels, none outside the raw footprint.
  DenseOptions o;
  o.max_depth_m = 10;
  const cv::Mat d_small = KeyframeDepth(small, run_view, o);
  const cv::Mat d_wide = KeyframeDepth(wide, full, o);
  EXPECT_GT(cv::countNonZero(d_wide), cv::countNonZero(d_small) * 11 / 10);
  cv::Mat outside;
  cv::bitwise_and(d_wide > 0, full.valid_mask() == 0, outside);
  EXPECT_EQ(cv::countNonZero(outside), 0);
}

}  // namespace
}  // namespace pkslam::dense
