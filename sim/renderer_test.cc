#include "sim/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/camera/stereo_rectification.h"
#include "sim/euroc_writer.h"
#include "sim/scene_builder.h"
#include "sim/sensor_model.h"

namespace pkslam::sim {
namespace {

// A plain room with one 9 x 7 checkerboard (8 x 6 inner corners) facing -y at 1.5 m height.
constexpr double kSquare = 0.06;  // metres
constexpr int kCols = 9;
constexpr int kRows = 7;

Scene MarkerScene() {
  const std::string yaml = R"(
name: marker_test
ambient: 0.7
room: {size: [8, 8, 4], materials: {walls: plain, floor: plain, ceiling: plain}}
lights: [{position: [0, 0, 3.5], intensity: 0.3, range: 6}]
materials:
  plain: {texture: {kind: noise, base_cells: 8, contrast: 0.1}, tile: 2.0, albedo: 0.6}
  marker: {texture: {kind: checker, cols: 9, rows: 7, square_px: 64}, stretch: true, albedo: 0.95, macro: 0}
objects:
  - {type: quad, name: board, position: [0, 0, 1.5], size: [0.66, 0.54], normal: [0, -1, 0], material: marker}
)";
  SceneBuildOptions o;
  o.texture_size = 256;
  return BuildScene(ParseSceneYaml(yaml, "marker_test"), o, {});
}

// World positions of the inner corners, row-major from the top-left (as seen from the front).
std::vector<Eigen::Vector3d> InnerCorners(const Scene& scene) {
  const Shape* board = nullptr;
  for (const Shape& s : scene.shapes) {
    if (s.name == "board") board = &s;
  }
  EXPECT_NE(board, nullptr);
  std::vector<Eigen::Vector3d> corners;
  for (int r = 1; r < kRows; ++r) {
    for (int c = 1; c < kCols; ++c) {
      const Eigen::Vector3f local(-board->half.x() + (c + 1) * kSquare,
                                  board->half.y() - (r + 1) * kSquare, 0.0f);
      corners.push_back((board->center + board->world_from_local * local).cast<double>());
    }
  }
  return corners;
}

// Camera at `eye` looking at `target` (x right, y down, z forward; world z up).
SE3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target, double roll_deg) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return SE3d(SO3d(r) * SO3d::Exp(Eigen::Vector3d(0, 0, roll_deg * M_PI / 180)), eye);
}

cv::Mat Image(const Scene& scene, const CameraRays& rays, const SE3d& world_from_camera,
              std::uint64_t seed) {
  const Renderer renderer(scene, RenderOptions());
  RenderBuffers buffers;
  renderer.Render(rays, world_from_camera, &buffers);
  SensorModel sensor(SensorOptions(), rays, seed);
  return sensor.Develop(buffers.radiance, sensor.NextGain(buffers.radiance, 0.05), 0);
}

std::vector<cv::Point2f> Detect(const cv::Mat& image) {
  std::vector<cv::Point2f> corners;
  const bool found = cv::findChessboardCorners(image, cv::Size(kCols - 1, kRows - 1), corners,
                                               cv::CALIB_CB_ADAPTIVE_THRESH);
  if (!found) return {};
  cv::cornerSubPix(image, corners, cv::Size(5, 5), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
  return corners;
}

// For each detected corner the offset to the nearest projected corner.
std::vector<Eigen::Vector2d> Residuals(const std::vector<cv::Point2f>& detected,
                                       const std::vector<Eigen::Vector2d>& projected) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& d : detected) {
    Eigen::Vector2d best(1e9, 1e9);
    for (const auto& p : projected) {
      const Eigen::Vector2d r(d.x - p.x(), d.y - p.y());
      if (r.norm() < best.norm()) best = r;
    }
    out.push_back(best);
  }
  return out;
}

TEST(Renderer, CheckerboardCornersLandWhereTheCameraModelProjectsThem) {
  const Scene scene = MarkerScene();
  const CameraRig cam = EurocCam0();
  const CameraRays rays(cam.camera);
  const auto corners = InnerCorners(scene);
  const Eigen::Vector3d centre(0, 0, 1.5);
  // Frontal, oblique, and off-centre (strong distortion near the image corner).
  const SE3d poses[] = {LookAt(centre + Eigen::Vector3d(0.1, -1.2, 0.05), centre, 3),
                        LookAt(centre + Eigen::Vector3d(0.9, -1.0, 0.3), centre, -8),
                        LookAt(centre + Eigen::Vector3d(-0.3, -1.0, -0.2),
                               centre + Eigen::Vector3d(0.45, 0, -0.3), 10)};
  double worst = 0;
  for (int i = 0; i < 3; ++i) {
    const cv::Mat image = Image(scene, rays, poses[i], i);
    const auto detected = Detect(image);
    ASSERT_EQ(detected.size(), corners.size()) << "pose " << i;
    std::vector<Eigen::Vector2d> projected;
    for (const auto& c : corners) {
      const auto uv = cam.camera.Project(poses[i].Inverse() * c);
      ASSERT_TRUE(uv.has_value());
      projected.push_back(*uv);
    }
    const auto res = Residuals(detected, projected);
    double mean = 0, max = 0;
    Eigen::Vector2d bias = Eigen::Vector2d::Zero();
    for (const auto& r : res) {
      mean += r.norm() / res.size();
      max = std::max(max, r.norm());
      bias += r / res.size();
    }
    std::printf("pose %d: %zu corners, error mean %.3f px, max %.3f px, mean offset (%.3f, %.3f)\n",
                i, res.size(), mean, max, bias.x(), bias.y());
    EXPECT_LT(mean, 0.15);
    EXPECT_LT(max, 0.3);
    EXPECT_LT(bias.norm(), 0.05);  // no systematic offset between renderer and camera model
    worst = std::max(worst, max);
  }
}

TEST(Renderer, RectifiedStereoCorrespondencesShareRows) {
  const Scene scene = MarkerScene();
  const CameraRig left = EurocCam0();
  const CameraRig right = EurocCam1();
  const CameraRays left_rays(left.camera);
  const CameraRays right_rays(right.camera);
  const Eigen::Vector3d centre(0, 0, 1.5);
  const SE3d world_from_body =
      LookAt(centre + Eigen::Vector3d(0.2, -1.3, 0.1), centre, 0) * left.body_from_camera.Inverse();
  const cv::Mat img_l = Image(scene, left_rays, world_from_body * left.body_from_camera, 1);
  const cv::Mat img_r = Image(scene, right_rays, world_from_body * right.body_from_camera, 2);
  const auto corners_l = Detect(img_l);
  const auto corners_r = Detect(img_r);
  ASSERT_EQ(corners_l.size(), 48u);
  ASSERT_EQ(corners_r.size(), 48u);
  // Rectify the detected raw corners with the project's stereo rectification and compare rows.
  const SE3d right_from_left = right.body_from_camera.Inverse() * left.body_from_camera;
  const StereoRectification rectification(left.camera, right.camera, right_from_left);
  std::vector<Eigen::Vector2d> rect_l, rect_r;
  for (std::size_t i = 0; i < corners_l.size(); ++i) {
    const auto l = rectification.RectifyLeftPixel(Eigen::Vector2d(corners_l[i].x, corners_l[i].y));
    const auto r = rectification.RectifyRightPixel(Eigen::Vector2d(corners_r[i].x, corners_r[i].y));
    ASSERT_TRUE(l && r);
    rect_l.push_back(*l);
    rect_r.push_back(*r);
  }
  // Both detections start from the same board corner (same orientation in both views).
  double mean = 0, max = 0;
  for (std::size_t i = 0; i < rect_l.size(); ++i) {
    const double dy = std::abs(rect_l[i].y() - rect_r[i].y());
    mean += dy / rect_l.size();
    max = std::max(max, dy);
    // Positive disparity matching the board's depth (about 1.3 m): bf / z.
    const double disparity = rect_l[i].x() - rect_r[i].x();
    EXPECT_GT(disparity, rectification.bf() / 2.0);
    EXPECT_LT(disparity, rectification.bf() / 0.8);
  }
  std::printf("rectified stereo: row difference mean %.3f px, max %.3f px\n", mean, max);
  EXPECT_LT(mean, 0.2);
  EXPECT_LT(max, 0.4);
}

TEST(Renderer, DepthIsDistanceAlongTheOpticalAxis) {
  const Scene scene = MarkerScene();
  const CameraModel cam = CameraModel::Pinhole(64, 48, 50, 50, 31.5, 23.5);
  const CameraRays rays(cam);
  RenderOptions o;
  o.depth = true;
  const Renderer renderer(scene, o);
  RenderBuffers b;
  // Camera 2 m in front of the -y wall (at y = -4), looking straight at it.
  const SE3d pose = LookAt(Eigen::Vector3d(1.0, -2.0, 2.0), Eigen::Vector3d(1.0, -4.0, 2.0), 0);
  renderer.Render(rays, pose, &b);
  for (int y = 0; y < 48; y += 7) {
    for (int x = 0; x < 64; x += 9) EXPECT_NEAR(b.depth.at<float>(y, x), 2.0f, 1e-4f);
  }
}

TEST(Renderer, RangeLimitedVisibilityMarksOnlyHitsWithinItsDepth) {
  const Scene scene = MarkerScene();
  const CameraModel cam = CameraModel::Pinhole(64, 48, 50, 50, 31.5, 23.5);
  const CameraRays rays(cam);
  const Renderer renderer(scene, RenderOptions{});
  // The room is shape 0; find the -y wall face and the cell straight ahead of the camera.
  SurfaceVisibility any(scene, 0.1f);
  SurfaceVisibility near(scene, 0.1f, 2.5f);
  SurfaceVisibility nearer(scene, 0.1f, 1.5f);
  SurfaceVisibility* marks[] = {&any, &near, &nearer, nullptr};
  RenderBuffers b;
  // The wall is 2 m ahead along the optical axis.
  const SE3d pose = LookAt(Eigen::Vector3d(1.0, -2.0, 2.0), Eigen::Vector3d(1.0, -4.0, 2.0), 0);
  renderer.Render(rays, pose, &b, marks);
  int seen_any = 0, seen_near = 0, seen_nearer = 0;
  for (int s = 0; s < static_cast<int>(scene.shapes.size()); ++s) {
    for (int f = 0; f < scene.shapes[s].num_faces(); ++f) {
      const Scene::FaceFrame frame = Scene::Face(scene.shapes[s], f);
      for (float u = 0.05f; u < frame.size.x(); u += 0.1f) {
        for (float v = 0.05f; v < frame.size.y(); v += 0.1f) {
          const Eigen::Vector2f uv(u, v);
          seen_any += any.Seen(s, f, uv);
          seen_near += near.Seen(s, f, uv);
          seen_nearer += nearer.Seen(s, f, uv);
          if (near.Seen(s, f, uv)) {
            EXPECT_TRUE(any.Seen(s, f, uv));
          }
        }
      }
    }
  }
  // Every hit is at depth 2 m: the 2.5 m layer sees what the unlimited one sees, the 1.5 m
  // layer nothing (a 64 x 48 view of a wall 2 m away: about 2.6 x 1.9 m, ~500 cells).
  EXPECT_GT(seen_any, 300);
  EXPECT_EQ(seen_near, seen_any);
  EXPECT_EQ(seen_nearer, 0);
}

TEST(Renderer, DistantSurfacesAreFilteredNotAliased) {
  // A fine texture 7 m away: a pixel covers ~0.14 m = hundreds of texels. Moving the camera by
  // 1/30 of a pixel footprint must barely change a mip-mapped image; point sampling (a large
  // negative LOD bias) flickers.
  const std::string yaml = R"(
room: {size: [8, 8, 4], materials: {walls: fine, floor: fine, ceiling: fine}}
materials:
  fine: {texture: {kind: noise, base_cells: 16, contrast: 0.2}, tile: 0.25, albedo: 0.6, macro: 0}
)";
  SceneBuildOptions so;
  so.texture_size = 512;
  const Scene scene = BuildScene(ParseSceneYaml(yaml, "fine"), so, {});
  const CameraRays rays(CameraModel::Pinhole(64, 48, 50, 50, 31.5, 23.5));
  RenderOptions sharp;
  sharp.lod_bias = -9.0f;
  const Renderer filtered(scene, RenderOptions());
  const Renderer point(scene, sharp);
  double flicker_filtered = 0;
  double flicker_point = 0;
  RenderBuffers prev_f, prev_p, f, p;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d eye(0.005 * i, -3.0, 2.0);
    const SE3d pose = LookAt(eye, eye + Eigen::Vector3d(0, 1, 0), 0);
    filtered.Render(rays, pose, &f);
    point.Render(rays, pose, &p);
    if (i > 0) {
      flicker_filtered += cv::mean(cv::abs(f.radiance - prev_f.radiance))[0] / 7;
      flicker_point += cv::mean(cv::abs(p.radiance - prev_p.radiance))[0] / 7;
    }
    prev_f.radiance = f.radiance.clone();
    prev_p.radiance = p.radiance.clone();
  }
  std::printf("frame-to-frame change: mip-mapped %.4f, point-sampled %.4f\n", flicker_filtered,
              flicker_point);
  EXPECT_LT(flicker_filtered, 0.005);
  EXPECT_GT(flicker_point, 5 * flicker_filtered);
}

}  // namespace
}  // namespace pkslam::sim
