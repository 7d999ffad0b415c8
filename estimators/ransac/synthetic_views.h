// Test/benchmark data for the estimators, made of values only (no Frame, no map): random scene
// points and their noisy projections into a pinhole view. The random streams are those of the
// map_model synthetic-map fixture (MakeScene, MakeFrame), so a scene and a view here are the
// fixture's, seen without the map model.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/geometry/pinhole_intrinsics.h"
#include "core/geometry/se3.h"
#include "core/sensor/scale_pyramid.h"

namespace pkslam::testing {

// The fixture's EuRoC-like rectified camera: 752x480, fx = fy = 435, 8 levels of scale 1.2.
struct ViewRig {
  CameraModel camera = CameraModel::Pinhole(752, 480, 435.0, 435.0, 367.0, 248.0);
  ScalePyramid pyramid{8, 1.2};
  PinholeIntrinsics intrinsics{435.0, 435.0, 367.0, 248.0};
};

struct ScenePoints {
  std::vector<Eigen::Vector3d> points_world;
  std::vector<int> octaves;  // a fixed pyramid level per point
};

// n points uniform in [-w, w] x [-h, h] x [z0, z1] with levels 0..3.
inline ScenePoints MakeScenePoints(int n, std::uint64_t seed, double w = 4.0, double h = 2.5,
                                   double z0 = 3.0, double z1 = 8.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(-w, w), uy(-h, h), uz(z0, z1);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_int_distribution<int> level(0, 3);
  ScenePoints scene;
  for (int i = 0; i < n; ++i) {
    scene.points_world.emplace_back(ux(rng), uy(rng), uz(rng));
    for (int b = 0; b < 32; ++b) byte(rng);  // the fixture's descriptor bytes (same stream)
    scene.octaves.push_back(level(rng));
  }
  return scene;
}

struct ViewKeypoint {
  Eigen::Vector2d uv;  // observed pixel (noisy, float precision as a keypoint)
  int octave = 0;
  int point = -1;  // index into the scene
};

// The scene points in front of the camera and inside the image (20 px border), observed with
// Gaussian pixel noise; `view_id` and `seed` pick the noise stream.
inline std::vector<ViewKeypoint> ProjectView(const ScenePoints& scene, const ViewRig& rig,
                                             const SE3d& camera_from_world, std::int64_t view_id,
                                             double pixel_noise, std::uint64_t seed) {
  std::mt19937_64 rng(seed ^ static_cast<std::uint64_t>(view_id * 7919 + 17));
  std::normal_distribution<double> noise(0.0, pixel_noise);
  std::vector<ViewKeypoint> view;
  for (std::size_t i = 0; i < scene.points_world.size(); ++i) {
    const Eigen::Vector3d pc = camera_from_world * scene.points_world[i];
    if (pc.z() < 0.2) continue;
    const auto uv = rig.camera.Project(pc);
    if (!uv || !rig.camera.InImage(*uv, 20.0)) continue;
    Eigen::Vector2d obs = *uv;
    if (pixel_noise > 0) obs += Eigen::Vector2d(noise(rng), noise(rng));
    view.push_back({obs.cast<float>().cast<double>(), scene.octaves[i], static_cast<int>(i)});
  }
  return view;
}

}  // namespace pkslam::testing
