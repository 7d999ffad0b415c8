#include "rgbd/test_scene.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>

namespace pkslam::rgbd::testing {
namespace fs = std::filesystem;

CameraModel TestCamera() { return CameraModel::Pinhole(320, 240, 260, 260, 159.5, 119.5); }

namespace {

// Room bounds and an inner box (table-like obstacle).
constexpr double kRoomMin[3] = {-1.6, -1.5, -2.5};
constexpr double kRoomMax[3] = {1.6, 1.2, 2.0};
// Boxes standing on the floor: a low one in front and a pillar to the right, so every
// direction of motion is constrained by some surface (ICP needs that).
constexpr int kBoxes = 2;
constexpr double kBoxMin[kBoxes][3] = {{-0.6, 0.5, 0.9}, {0.7, -1.5, 1.2}};
constexpr double kBoxMax[kBoxes][3] = {{0.1, 1.2, 1.4}, {1.0, 1.2, 1.5}};

std::uint32_t Hash(std::int64_t a, std::int64_t b, std::int64_t c) {
  std::uint64_t h = static_cast<std::uint64_t>(a) * 0x9E3779B97F4A7C15ull ^
                    static_cast<std::uint64_t>(b) * 0xC2B2AE3D27D4EB4Full ^
                    static_cast<std::uint64_t>(c) * 0x165667B19E3779F9ull;
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 32;
  return static_cast<std::uint32_t>(h);
}

// Blocks of 12 cm with one of a few strong colours, on each face (face id separates them).
cv::Vec3b FaceColour(int face, double a, double b) {
  const auto ia = static_cast<std::int64_t>(std::floor(a / 0.12));
  const auto ib = static_cast<std::int64_t>(std::floor(b / 0.12));
  const std::uint32_t h = Hash(face, ia, ib);
  static constexpr unsigned char kPalette[6][3] = {{40, 40, 200},   {200, 60, 40}, {40, 180, 60},
                                                   {220, 220, 220}, {30, 30, 30},  {60, 200, 220}};
  const auto& c = kPalette[h % 6];
  return {c[0], c[1], c[2]};
}

// Nearest hit of the ray o + t d (t > 0) with the room's inside or the box's outside.
bool CastRay(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double* t_hit, cv::Vec3b* colour) {
  double best = std::numeric_limits<double>::infinity();
  cv::Vec3b best_colour;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(d[axis]) < 1e-12) continue;
    const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      // Room walls.
      const double plane = side == 0 ? kRoomMin[axis] : kRoomMax[axis];
      double t = (plane - o[axis]) / d[axis];
      if (t > 1e-6 && t < best) {
        const Eigen::Vector3d p = o + t * d;
        best = t;
        best_colour = FaceColour(axis * 2 + side, p[a1], p[a2]);
      }
      // Box faces.
      for (int box = 0; box < kBoxes; ++box) {
        const double box_plane = side == 0 ? kBoxMin[box][axis] : kBoxMax[box][axis];
        t = (box_plane - o[axis]) / d[axis];
        if (t > 1e-6 && t < best) {
          const Eigen::Vector3d p = o + t * d;
          if (p[a1] >= kBoxMin[box][a1] && p[a1] <= kBoxMax[box][a1] && p[a2] >= kBoxMin[box][a2] &&
              p[a2] <= kBoxMax[box][a2]) {
            best = t;
            best_colour = FaceColour(10 + 6 * box + axis * 2 + side, p[a1], p[a2]);
          }
        }
      }
    }
  }
  if (!std::isfinite(best)) return false;
  *t_hit = best;
  *colour = best_colour;
  return true;
}

}  // namespace

RenderedView RenderRoom(const CameraModel& camera, const SE3d& world_from_camera,
                        double depth_noise_m, unsigned seed) {
  RenderedView view;
  view.colour_bgr = cv::Mat(camera.height(), camera.width(), CV_8UC3, cv::Scalar::all(0));
  view.depth_m = cv::Mat(camera.height(), camera.width(), CV_32FC1, cv::Scalar(0));
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, depth_noise_m > 0 ? depth_noise_m : 1.0);
  const Eigen::Matrix3d r = world_from_camera.RotationMatrix();
  const Eigen::Vector3d o = world_from_camera.translation();
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      const Eigen::Vector3d ray((u - camera.cx()) / camera.fx(), (v - camera.cy()) / camera.fy(),
                                1);
      double t = 0;
      cv::Vec3b colour;
      if (!CastRay(o, r * ray, &t, &colour)) continue;  // z of the hit in the camera is t
      view.colour_bgr.at<cv::Vec3b>(v, u) = colour;
      view.depth_m.at<float>(v, u) = static_cast<float>(t + (depth_noise_m > 0 ? noise(rng) : 0.0));
    }
  }
  return view;
}

SE3d PathPose(int k) {
  const double s = k / 30.0;
  const Eigen::Vector3d position(-0.3 + 0.25 * s, 0.05 * std::sin(2 * s), -0.8 + 0.1 * s);
  const Eigen::Vector3d omega(0.03 * std::sin(s), 0.15 * s, 0.02 * s);
  return SE3d(SO3d::Exp(omega), position);
}

std::vector<std::int64_t> WriteTumRoom(const fs::path& dir, int frames, double depth_noise_m) {
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  std::ofstream rgb(dir / "rgb.txt"), depth(dir / "depth.txt"), gt(dir / "groundtruth.txt");
  rgb << "# colour images\n";
  depth << "# depth images\n";
  gt << "# timestamp tx ty tz qx qy qz qw\n";
  const CameraModel camera = TestCamera();
  std::vector<std::int64_t> stamps;
  for (int k = 0; k < frames; ++k) {
    const std::int64_t t_ns = 1'000'000'000'000'000'000 / 1000 + k * 33'333'000LL;
    const std::string t =
        fmt::format("{}.{:06d}", t_ns / 1'000'000'000, (t_ns % 1'000'000'000) / 1000);
    const SE3d pose = PathPose(k);
    const RenderedView view = RenderRoom(camera, pose, depth_noise_m, 100 + k);
    cv::Mat depth16;
    view.depth_m.convertTo(depth16, CV_16U, 5000.0);
    cv::imwrite((dir / "rgb" / (t + ".png")).string(), view.colour_bgr);
    cv::imwrite((dir / "depth" / (t + ".png")).string(), depth16);
    rgb << t << " rgb/" << t << ".png\n";
    depth << t << " depth/" << t << ".png\n";
    const auto& q = pose.quaternion();
    const auto& p = pose.translation();
    gt << fmt::format("{} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n", t, p.x(), p.y(),
                      p.z(), q.x(), q.y(), q.z(), q.w());
    stamps.push_back(t_ns);
  }
  std::ofstream settings(dir / "settings.yaml");
  settings
      << "%YAML:1.0\nFile.version: \"1.0\"\nCamera.type: \"PinHole\"\n"
         "Camera1.fx: 260.0\nCamera1.fy: 260.0\nCamera1.cx: 159.5\nCamera1.cy: 119.5\n"
         "Camera.width: 320\nCamera.height: 240\nCamera.fps: 30\nRGBD.DepthMapFactor: 5000.0\n";
  return stamps;
}

}  // namespace pkslam::rgbd::testing
