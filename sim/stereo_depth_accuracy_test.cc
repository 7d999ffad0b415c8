// The project's stereo front end on rendered EuRoC pairs against the renderer's exact depth:
// the whole chain a real EuRoC run goes through (distorted cam0/cam1 with EuRoC's extrinsics,
// sensor noise and blur, rectification, ORB on both images, row-band matching with sub-pixel
// refinement) must give depths within 1% (median) of the truth up to 5 m (issue 4).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "core/camera/stereo_rectification.h"
#include "core/features/orb_extractor.h"
#include "core/features/stereo_matcher.h"
#include "sim/euroc_writer.h"
#include "sim/renderer.h"
#include "sim/scene_builder.h"
#include "sim/scene_description.h"
#include "sim/sensor_model.h"

namespace pkslam::sim {
namespace {

SE3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return SE3d(SO3d(r), eye);
}

cv::Mat Develop(const Renderer& renderer, const CameraRays& rays, const SE3d& world_from_camera,
                std::uint64_t seed) {
  RenderBuffers buffers;
  renderer.Render(rays, world_from_camera, &buffers);
  SensorModel sensor(SensorOptions(), rays, seed);
  return sensor.Develop(buffers.radiance, sensor.NextGain(buffers.radiance, 0.05), seed);
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST(StereoDepthAccuracy, RenderedEurocPairsGiveDepthWithinOnePercentUpToFiveMetres) {
  SceneBuildOptions build;
  build.texture_size = 512;
  build.seed = 3;
  const Scene scene = BuildScene(LoadSceneDescription("vicon_room"), build, {});
  const CameraRig left = EurocCam0();
  const CameraRig right = EurocCam1();
  const CameraRays left_rays(left.camera);
  const CameraRays right_rays(right.camera);
  const SE3d right_from_left = right.body_from_camera.Inverse() * left.body_from_camera;
  const StereoRectification rectification(left.camera, right.camera, right_from_left);
  const CameraRays rect_rays(rectification.rectified_camera());
  RenderOptions depth_options;
  depth_options.depth = true;
  const Renderer renderer(scene, RenderOptions());
  const Renderer depth_renderer(scene, depth_options);
  const OrbExtractor extractor;

  // Views from near the room centre towards walls and objects at several distances.
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> views = {
      {{0.0, 0.0, 1.4}, {3.0, 0.5, 1.0}},  {{0.5, -0.5, 1.6}, {-3.5, -1.0, 0.8}},
      {{-1.0, 1.0, 1.2}, {1.0, 4.0, 1.5}}, {{1.0, 1.0, 2.0}, {2.0, -4.0, 0.5}},
      {{0.0, -1.5, 1.0}, {0.0, 4.0, 2.0}}, {{-2.0, -2.0, 1.5}, {4.0, 4.0, 0.5}},
      // Near views: walls, floor and objects 1-2.5 m away.
      {{2.3, 0.0, 1.4}, {4.0, 0.3, 1.2}},  {{-2.5, 0.5, 1.5}, {-4.0, 1.0, 1.0}},
      {{0.5, 2.4, 1.2}, {0.0, 4.0, 1.6}},  {{0.0, -2.2, 1.8}, {0.3, -4.0, 0.8}},
      {{1.0, 1.0, 1.8}, {1.5, 1.5, 0.0}},  {{-1.0, -1.0, 1.6}, {-1.8, -1.5, 0.0}},
  };
  std::vector<double> rel_near, rel_far;  // up to 2.5 m, 2.5..5 m
  int matched = 0;
  int gross = 0;
  std::uint64_t seed = 10;
  for (const auto& [eye, target] : views) {
    const SE3d world_from_body = LookAt(eye, target) * left.body_from_camera.Inverse();
    const cv::Mat raw_l = Develop(renderer, left_rays, world_from_body * left.body_from_camera,
                                  ++seed);
    const cv::Mat raw_r = Develop(renderer, right_rays, world_from_body * right.body_from_camera,
                                  ++seed);
    const auto [rect_l, rect_r] = rectification.Rectify(raw_l, raw_r);
    // Truth: depth along the rectified left camera's optical axis, per pixel.
    RenderBuffers truth;
    depth_renderer.Render(rect_rays,
                          world_from_body * rectification.BodyFromRectLeft(left.body_from_camera),
                          &truth);
    OrbFeatures fl, fr;
    extractor.ExtractStereo(rect_l, rect_r, &fl, &fr);
    const StereoMatches m =
        MatchStereo(fl, fr, rectification.bf(), rectification.rectified_camera().fx());
    for (std::size_t i = 0; i < fl.keypoints.size(); ++i) {
      if (m.depth[i] <= 0.0f) continue;
      const cv::Point2f& p = fl.keypoints[i].pt;
      const int x = static_cast<int>(std::lround(p.x));
      const int y = static_cast<int>(std::lround(p.y));
      // Skip keypoints on depth discontinuities: the truth there is ill-defined.
      float lo = 1e9f, hi = 0.0f;
      for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
          const int xx = std::clamp(x + dx, 0, truth.depth.cols - 1);
          const int yy = std::clamp(y + dy, 0, truth.depth.rows - 1);
          lo = std::min(lo, truth.depth.at<float>(yy, xx));
          hi = std::max(hi, truth.depth.at<float>(yy, xx));
        }
      }
      if (lo <= 0.0f || hi - lo > 0.03f * lo) continue;
      // Bilinear truth at the sub-pixel keypoint.
      cv::Mat patch;
      cv::getRectSubPix(truth.depth, cv::Size(1, 1), p, patch);
      const double z = patch.at<float>(0, 0);
      if (z > 5.0) continue;
      ++matched;
      const double rel = std::abs(m.depth[i] - z) / z;
      if (rel > 0.1) ++gross;
      (z <= 2.5 ? rel_near : rel_far).push_back(rel);
    }
  }
  const double med_near = Median(rel_near);
  const double med_far = Median(rel_far);
  std::vector<double> all = rel_near;
  all.insert(all.end(), rel_far.begin(), rel_far.end());
  std::printf(
      "stereo depth vs renderer truth: %d matches <= 5 m, median relative error %.3f%% "
      "(<= 2.5 m: %.3f%% of %zu, 2.5-5 m: %.3f%% of %zu), gross (>10%%) %d\n",
      matched, 100 * Median(all), 100 * med_near, rel_near.size(), 100 * med_far, rel_far.size(),
      gross);
  ASSERT_GT(rel_near.size(), 200u);
  ASSERT_GT(rel_far.size(), 300u);
  EXPECT_LT(Median(all), 0.01);
  EXPECT_LT(med_near, 0.01);
  EXPECT_LT(med_far, 0.01);
  EXPECT_LT(gross, matched / 20);  // < 5% gross mismatches
}

}  // namespace
}  // namespace pkslam::sim
