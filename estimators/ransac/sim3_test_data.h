// Test/benchmark data for the Sim3 solver and the Sim3 optimiser: two synthetic views
// (synthetic_views.h) of one scene, matched through their known correspondences, with view 2's
// map scaled by a drift factor and wrong matches mixed in.
#pragma once

#include <cstdint>
#include <random>
#include <unordered_map>
#include <vector>

#include "estimators/ransac/sim3_solver.h"
#include "estimators/ransac/synthetic_views.h"

namespace pkslam::testing {

struct Sim3ProblemOptions {
  double scale = 1.2;             // map 2 is the true geometry divided by this (drift)
  double outlier_fraction = 0.3;  // share of matches replaced by a wrong keypoint of frame 2
  double pixel_noise = 1.0;       // keypoint noise (pixels)
  double depth_noise = 0.01;      // relative map-point error along the viewing ray
  int num_points = 600;
  std::uint64_t seed = 1;
};

struct Sim3Problem {
  std::vector<Sim3Match> matches;
  std::vector<bool> is_inlier;
  Sim3d camera1_from_camera2;  // the truth
  PinholeIntrinsics camera;
};

inline Sim3Problem MakeSim3Problem(const Sim3ProblemOptions& o) {
  const ViewRig rig;
  const ScenePoints scene = MakeScenePoints(o.num_points, o.seed);
  const SE3d camera1_from_world;
  const SE3d camera2_from_world =
      SE3d(SO3d::Exp(Eigen::Vector3d(0.02, -0.08, 0.03)), Eigen::Vector3d(0.6, 0.1, 0.3)).Inverse();
  const std::vector<ViewKeypoint> view1 =
      ProjectView(scene, rig, camera1_from_world, 0, o.pixel_noise, o.seed);
  const std::vector<ViewKeypoint> view2 =
      ProjectView(scene, rig, camera2_from_world, 1, o.pixel_noise, o.seed);
  std::unordered_map<int, int> keypoint_of2;
  for (std::size_t i = 0; i < view2.size(); ++i) keypoint_of2[view2[i].point] = static_cast<int>(i);

  std::mt19937_64 rng(o.seed * 31 + 7);
  std::normal_distribution<double> ray(0.0, o.depth_noise);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> any2(0, static_cast<int>(view2.size()) - 1);
  Sim3Problem p;
  p.camera = rig.intrinsics;
  p.camera1_from_camera2 = Sim3d(camera1_from_world * camera2_from_world.Inverse()) *
                           Sim3d(o.scale, SO3d(), Eigen::Vector3d::Zero());
  for (std::size_t i1 = 0; i1 < view1.size(); ++i1) {
    auto it = keypoint_of2.find(view1[i1].point);
    if (it == keypoint_of2.end()) continue;
    int i2 = it->second;
    const bool inlier = unit(rng) >= o.outlier_fraction;
    if (!inlier) {
      do {
        i2 = any2(rng);
      } while (i2 == it->second);
    }
    const ViewKeypoint& k1 = view1[i1];
    const ViewKeypoint& k2 = view2[static_cast<std::size_t>(i2)];
    const auto& x1 = scene.points_world[static_cast<std::size_t>(k1.point)];
    const auto& x2 = scene.points_world[static_cast<std::size_t>(k2.point)];
    Sim3Match m;
    m.point1 = (camera1_from_world * x1) * (1.0 + ray(rng));
    m.point2 = (camera2_from_world * x2) * ((1.0 + ray(rng)) / o.scale);
    m.uv1 = k1.uv;
    m.uv2 = k2.uv;
    m.sigma2_1 = rig.pyramid.sigma2[static_cast<std::size_t>(k1.octave)];
    m.sigma2_2 = rig.pyramid.sigma2[static_cast<std::size_t>(k2.octave)];
    m.index1 = static_cast<int>(i1);
    m.index2 = i2;
    p.matches.push_back(m);
    p.is_inlier.push_back(inlier);
  }
  return p;
}

}  // namespace pkslam::testing
