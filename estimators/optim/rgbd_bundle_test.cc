// Bundle adjustment with RGB-D observations: the depth reading's disparity weighted by the
// depth noise (reprojection_error.h) pins points along their rays, which a pixel-sigma
// residual on the virtual right coordinate (ORB-SLAM's form) leaves to the keyframes'
// small baselines.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "estimators/optim/bundle_adjustment.h"

namespace pkslam {
namespace {

constexpr double kF = 525.0, kCx = 319.5, kCy = 239.5, kBf = 525.0 * 0.07;
constexpr double kKinectK = 1.425e-3;

struct Outcome {
  double point_rms = 0.0;     // m
  double position_rms = 0.0;  // m, free keyframes
};

// Four keyframes 5 cm apart (a dense RGB-D keyframe rate), the first fixed; 200 points
// 1.5-4 m away seen by all, with 1 px keypoint noise and Kinect depth noise. Points start at
// the first keyframe's depth reading, free keyframes 1 cm / 0.3 degrees off.
Outcome Solve(std::uint64_t seed, bool weight_depth) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  BundleProblem problem;
  problem.fx = problem.fy = kF;
  problem.cx = kCx;
  problem.cy = kCy;
  problem.bf = kBf;
  std::vector<SE3d> truth;
  for (int k = 0; k < 4; ++k) {
    const SE3d pose = SE3d::Exp(
        (Eigen::Matrix<double, 6, 1>() << -0.05 * k, 0.01 * k, 0, 0, 0.01 * k, 0).finished());
    truth.push_back(pose);
    const Eigen::Matrix<double, 6, 1> noise =
        (Eigen::Matrix<double, 6, 1>() << 0.01 * uni(rng), 0.01 * uni(rng), 0.01 * uni(rng),
         0.005 * uni(rng), 0.005 * uni(rng), 0.005 * uni(rng))
            .finished();
    problem.keyframes.push_back({k, k == 0 ? pose : SE3d::Exp(noise) * pose, k == 0});
  }
  std::vector<Eigen::Vector3d> points;
  for (int j = 0; j < 200; ++j) {
    const double z = 2.75 + 1.25 * uni(rng);
    const Eigen::Vector3d p(0.5 * z * uni(rng), 0.35 * z * uni(rng), z);
    points.push_back(p);
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d pc = truth[k] * p;
      const double u = kF * pc.x() / pc.z() + kCx + gauss(rng);
      const double v = kF * pc.y() / pc.z() + kCy + gauss(rng);
      const double sigma_z = kKinectK * pc.z() * pc.z();
      const double depth = pc.z() + sigma_z * gauss(rng);
      const double info = weight_depth ? std::pow(kBf * sigma_z / (depth * depth), -2) : 0.0;
      problem.observations.push_back({k, j, j, Eigen::Vector2d(u, v), u - kBf / depth, 1.0, info});
      if (k == 0) {
        // The point a keyframe creates from its own depth reading.
        const Eigen::Vector3d start((u - kCx) / kF * depth, (v - kCy) / kF * depth, depth);
        problem.points.push_back({j, start});
      }
    }
  }
  BundleAdjustmentOptions options;
  options.iterations_first = 10;
  options.iterations_second = 20;
  const BundleResult r = SolveBundle(problem, options);
  Outcome o;
  for (int j = 0; j < 200; ++j) o.point_rms += (r.points_world[j] - points[j]).squaredNorm();
  o.point_rms = std::sqrt(o.point_rms / 200);
  for (int k = 1; k < 4; ++k) {
    o.position_rms +=
        (r.camera_from_world[k].Inverse().translation() - truth[k].Inverse().translation())
            .squaredNorm();
  }
  o.position_rms = std::sqrt(o.position_rms / 3);
  return o;
}

TEST(RgbdBundle, DepthNoiseWeightingPinsPointsAndKeyframes) {
  double points_weighted = 0, points_pixel = 0, poses_weighted = 0, poses_pixel = 0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Outcome w = Solve(seed, true);
    const Outcome p = Solve(seed, false);
    points_weighted += w.point_rms;
    points_pixel += p.point_rms;
    poses_weighted += w.position_rms;
    poses_pixel += p.position_rms;
  }
  // Kinect noise at 1.5-4 m is 3-23 mm per reading, four readings per point.
  EXPECT_LT(points_weighted / 5, 0.012);
  EXPECT_LT(points_weighted, 0.2 * points_pixel) << points_weighted << " " << points_pixel;
  EXPECT_LT(poses_weighted, 0.8 * poses_pixel) << poses_weighted << " " << poses_pixel;
}

}  // namespace
}  // namespace pkslam
