// Test/benchmark data for PnP: a synthetic frame (shared synthetic-map fixture) whose
// keypoints are paired with their scene points, a share of them with a wrong point.
#pragma once

#include <random>
#include <vector>

#include "core/geometry/pnp.h"
#include "core/testing/synthetic_map.h"

namespace pkslam::testing {

struct PnpProblem {
  std::vector<PnpCorrespondence> correspondences;
  std::vector<bool> is_inlier;
  SE3d camera_from_world;
  PinholeIntrinsics camera;
};

// A synthetic frame of a scene; `outlier_fraction` of its keypoints get the 3-D point of
// another keypoint (a wrong match).
inline PnpProblem MakePnpProblem(double outlier_fraction, double pixel_noise, std::uint64_t seed) {
  const auto rig = MakeStereoRig();
  const auto scene = MakeScene(600, seed);
  PnpProblem p;
  p.camera = {rig->fx, rig->fy, rig->cx, rig->cy};
  p.camera_from_world =
      SE3d(SO3d::Exp(Eigen::Vector3d(0.05, -0.1, 0.02)), Eigen::Vector3d(0.3, -0.2, 0.5)).Inverse();
  FrameOptions fo;
  fo.pixel_noise = pixel_noise;
  fo.seed = seed;
  std::vector<int> scene_of;
  const Frame f = MakeFrame(scene, rig, p.camera_from_world, 0, 0, fo, &scene_of);
  std::mt19937_64 rng(seed + 5);
  std::uniform_real_distribution<double> unit(0, 1);
  std::uniform_int_distribution<int> any(0, static_cast<int>(scene_of.size()) - 1);
  for (std::size_t i = 0; i < scene_of.size(); ++i) {
    const auto& kp = f.keypoints_undistorted()[i];
    PnpCorrespondence c;
    c.uv = Eigen::Vector2d(kp.pt.x, kp.pt.y);
    c.sigma2 = rig->pyramid.sigma2[static_cast<std::size_t>(kp.octave)];
    c.index = static_cast<int>(i);
    int point = scene_of[i];
    const bool inlier = unit(rng) >= outlier_fraction;
    if (!inlier) point = scene_of[static_cast<std::size_t>(any(rng))];  // a wrong match
    c.point_world = scene.points_world[static_cast<std::size_t>(point)];
    p.correspondences.push_back(c);
    p.is_inlier.push_back(inlier || point == scene_of[i]);
  }
  return p;
}

}  // namespace pkslam::testing
