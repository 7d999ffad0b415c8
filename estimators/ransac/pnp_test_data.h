// Test/benchmark data for PnP: a synthetic view (synthetic_views.h) whose keypoints are
// paired with their scene points, a share of them with a wrong point.
#pragma once

#include <random>
#include <vector>

#include "estimators/ransac/pnp.h"
#include "estimators/ransac/synthetic_views.h"

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
  const ViewRig rig;
  const ScenePoints scene = MakeScenePoints(600, seed);
  PnpProblem p;
  p.camera = rig.intrinsics;
  p.camera_from_world =
      SE3d(SO3d::Exp(Eigen::Vector3d(0.05, -0.1, 0.02)), Eigen::Vector3d(0.3, -0.2, 0.5)).Inverse();
  const std::vector<ViewKeypoint> view =
      ProjectView(scene, rig, p.camera_from_world, 0, pixel_noise, seed);
  std::mt19937_64 rng(seed + 5);
  std::uniform_real_distribution<double> unit(0, 1);
  std::uniform_int_distribution<int> any(0, static_cast<int>(view.size()) - 1);
  for (std::size_t i = 0; i < view.size(); ++i) {
    PnpCorrespondence c;
    c.uv = view[i].uv;
    c.sigma2 = rig.pyramid.sigma2[static_cast<std::size_t>(view[i].octave)];
    c.index = static_cast<int>(i);
    int point = view[i].point;
    const bool inlier = unit(rng) >= outlier_fraction;
    if (!inlier) point = view[static_cast<std::size_t>(any(rng))].point;  // a wrong match
    c.point_world = scene.points_world[static_cast<std::size_t>(point)];
    p.correspondences.push_back(c);
    p.is_inlier.push_back(inlier || point == view[i].point);
  }
  return p;
}

}  // namespace pkslam::testing
