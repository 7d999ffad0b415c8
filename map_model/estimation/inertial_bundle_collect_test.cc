// SolveInertialBundle on a synthetic problem: a body on an analytic path observed by a stereo
// camera, exact IMU with constant biases. From perturbed poses, zero velocities and zero biases
// the solver must recover the states and the biases.
#include "map_model/estimation/inertial_bundle_collect.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "estimators/inertial/gravity_gauge.h"
#include "imu/imu_test_utils.h"
#include "imu/preintegration.h"

namespace pkslam {
namespace {

using testing::HelixMotion;
using testing::kTestGravity;

constexpr double kFx = 450, kFy = 450, kCx = 376, kCy = 240, kBf = 450 * 0.11;

struct Scene {
  InertialBundleProblem problem;
  std::vector<NavState> truth;
  ImuBias bias;
};

// Keyframes every 0.25 s over [0, 3] s; the camera is the body (identity extrinsics) looking
// along its z axis; points scattered around the path, seen when in front and in the image.
Scene MakeScene(bool shared_bias) {
  Scene s;
  const HelixMotion motion;
  s.bias = ImuBias(Eigen::Vector3d(0.01, -0.02, 0.015), Eigen::Vector3d(0.1, -0.05, 0.08));
  ImuNoise noise;
  const std::int64_t period = 5'000'000;
  const std::int64_t kf_period = 250'000'000;
  const int num_kf = 13;
  const auto samples = SampleImu(motion, 0, kf_period * num_kf, period, s.bias, noise, nullptr);
  std::mt19937 rng(3);
  std::normal_distribution<double> n01(0.0, 1.0);
  InertialBundleProblem& p = s.problem;
  p.visual.fx = kFx;
  p.visual.fy = kFy;
  p.visual.cx = kCx;
  p.visual.cy = kCy;
  p.visual.bf = kBf;
  p.gravity_world = kTestGravity;
  p.shared_bias = shared_bias;
  for (int k = 0; k < num_kf; ++k) {
    const double t = 0.25 * k;
    const NavState truth = motion.State(t);
    s.truth.push_back(truth);
    SE3d start = truth.world_from_body;
    if (k > 0) {
      start = start * SE3d::Exp((Eigen::Matrix<double, 6, 1>() << 0.03 * n01(rng), 0.03 * n01(rng),
                                 0.03 * n01(rng), 0.01 * n01(rng), 0.01 * n01(rng), 0.01 * n01(rng))
                                    .finished());
    }
    p.visual.keyframes.push_back({k, start.Inverse(), k == 0});
    p.inertial.push_back(1);
    p.velocities.push_back(Eigen::Vector3d::Zero());
    p.biases.emplace_back();
    if (k > 0) {
      PreintegratedImu pim = StartPreintegration(ImuBias(), noise);
      IntegrateSamples(samples, kf_period * (k - 1), kf_period * k, &pim);
      p.edges.push_back({k - 1, k, pim});
    }
  }
  std::uniform_real_distribution<double> u(-6, 6);
  for (int i = 0; i < 600; ++i) {
    const Eigen::Vector3d x(u(rng), u(rng), u(rng) * 0.5 + 1.0);
    const int index = static_cast<int>(p.visual.points.size());
    bool seen = false;
    for (int k = 0; k < num_kf; ++k) {
      const Eigen::Vector3d pc = s.truth[k].world_from_body.Inverse() * x;
      if (pc.z() < 0.5) continue;
      const double uu = kFx * pc.x() / pc.z() + kCx;
      const double vv = kFy * pc.y() / pc.z() + kCy;
      if (uu < 0 || uu > 752 || vv < 0 || vv > 480) continue;
      p.visual.observations.push_back(
          {k, index, 0, Eigen::Vector2d(uu, vv), uu - kBf / pc.z(), 1.0});
      seen = true;
    }
    if (seen)
      p.visual.points.push_back({i, x + 0.05 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng))});
  }
  return s;
}

void ExpectRecovered(const Scene& s, const InertialBundleResult& r) {
  for (std::size_t k = 0; k < s.truth.size(); ++k) {
    const SE3d world_from_body = r.visual.camera_from_world[k].Inverse();
    EXPECT_LT((world_from_body.translation() - s.truth[k].world_from_body.translation()).norm(),
              2e-3)
        << "keyframe " << k;
    EXPECT_LT((r.velocities[k] - s.truth[k].velocity_world).norm(), 1e-2) << "keyframe " << k;
  }
  const ImuBias& b = r.biases.back();
  EXPECT_LT((b.gyro - s.bias.gyro).norm(), 2e-3) << b.gyro.transpose();
  EXPECT_LT((b.accel - s.bias.accel).norm(), 2e-2) << b.accel.transpose();
}

TEST(InertialBundle, RecoversStatesAndSharedBiases) {
  const Scene s = MakeScene(true);
  InertialBundleOptions options;
  options.iterations_first = 30;
  options.iterations_second = 10;
  const InertialBundleResult r = SolveInertialBundle(s.problem, options);
  EXPECT_LT(r.visual.final_cost, r.visual.initial_cost);
  ExpectRecovered(s, r);
  EXPECT_TRUE(r.visual.outlier_observations.empty());
}

TEST(InertialBundle, RecoversStatesWithPerKeyframeBiases) {
  const Scene s = MakeScene(false);
  InertialBundleOptions options;
  options.iterations_first = 30;
  options.iterations_second = 10;
  const InertialBundleResult r = SolveInertialBundle(s.problem, options);
  ExpectRecovered(s, r);
}

TEST(InertialBundle, FixedAnchorStateIsUntouched) {
  Scene s = MakeScene(false);
  s.problem.inertial[0] = 2;  // the local window's anchor: velocity and biases fixed
  s.problem.velocities[0] = s.truth[0].velocity_world;
  s.problem.biases[0] = s.bias;
  InertialBundleOptions options;
  options.iterations_first = 30;
  const InertialBundleResult r = SolveInertialBundle(s.problem, options);
  EXPECT_EQ(r.velocities[0], s.truth[0].velocity_world);
  EXPECT_EQ(r.biases[0].gyro, s.bias.gyro);
  EXPECT_TRUE(r.visual.camera_from_world[0].translation() ==
              s.problem.visual.keyframes[0].camera_from_world.translation());
  ExpectRecovered(s, r);
}

TEST(InertialBundle, SinglePassClassifiesOutliersAndStillRecovers) {
  Scene s = MakeScene(false);
  // Two gross outliers on a middle keyframe.
  int corrupted = 0;
  std::vector<int> bad;
  for (int i = 0; i < static_cast<int>(s.problem.visual.observations.size()) && corrupted < 2;
       ++i) {
    auto& o = s.problem.visual.observations[i];
    if (o.keyframe_index != 6) continue;
    o.uv += Eigen::Vector2d(40, -30);
    o.u_right += 40;
    bad.push_back(i);
    ++corrupted;
  }
  ASSERT_EQ(corrupted, 2);
  InertialBundleOptions options;  // the local BA defaults: one robust pass
  ASSERT_EQ(options.iterations_second, 0);
  options.iterations_first = 30;
  const InertialBundleResult r = SolveInertialBundle(s.problem, options);
  ExpectRecovered(s, r);
  for (int i : bad) {
    EXPECT_NE(
        std::find(r.visual.outlier_observations.begin(), r.visual.outlier_observations.end(), i),
        r.visual.outlier_observations.end())
        << "observation " << i;
  }
}

// How far keyframe 0 moved (translation plus rotation angle) from its start.
double AnchorMotion(const Scene& s, const InertialBundleResult& r) {
  const SE3d start = s.problem.visual.keyframes[0].camera_from_world.Inverse();
  const SE3d end = r.visual.camera_from_world[0].Inverse();
  return (end.translation() - start.translation()).norm() +
         (start.so3().Inverse() * end.so3()).Log().norm() +
         (r.velocities[0] - s.problem.velocities[0]).norm() +
         (r.biases[0].accel - s.problem.biases[0].accel).norm();
}

TEST(InertialBundle, AnchorPriorHoldsTheFreeAnchor) {
  // The local window's anchor, free, starting at the true state, the rest perturbed.
  Scene s = MakeScene(false);
  s.problem.velocities[0] = s.truth[0].velocity_world;
  s.problem.biases[0] = s.bias;
  s.problem.visual.keyframes[0].fixed = false;
  s.problem.marginalize_from = 0;
  s.problem.marginalize_to = 1;
  InertialBundleOptions options;
  options.iterations_first = 30;
  auto solve_with = [&](double information) {
    Scene with = s;
    if (information > 0) {
      InertialStatePrior prior;
      prior.mean = s.truth[0];
      prior.bias_mean = s.bias;
      prior.information = information * Eigen::Matrix<double, 15, 15>::Identity();
      with.problem.anchor_prior = prior;
    }
    return AnchorMotion(with, SolveInertialBundle(with.problem, options));
  };
  const double free_motion = solve_with(0);
  const double weak_motion = solve_with(1e2);
  const double strong_motion = solve_with(1e14);
  EXPECT_GT(free_motion, 1e-4);
  EXPECT_LT(weak_motion, free_motion);
  EXPECT_LT(strong_motion, 1e-6);
  EXPECT_LT(strong_motion, weak_motion);
}

// Largest angle between the true and the estimated gravity direction seen from the body.
double MaxGravityError(const Scene& s, const InertialBundleResult& r) {
  double worst = 0;
  for (std::size_t k = 0; k < s.truth.size(); ++k) {
    const Eigen::Vector3d truth =
        s.truth[k].world_from_body.so3().Inverse() * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d estimate = r.visual.camera_from_world[k].so3() * Eigen::Vector3d::UnitZ();
    worst = std::max(worst, std::atan2(truth.cross(estimate).norm(), truth.dot(estimate)));
  }
  return worst;
}

TEST(InertialBundle, PositionYawGaugeLetsTheBundleCorrectATiltedWorld) {
  // The whole start (poses and points) tilted by 5 mrad about the first keyframe, as an
  // initialisation that got gravity wrong leaves a map.
  Scene s = MakeScene(false);
  const SE3d pivot(SO3d(), s.truth[0].world_from_body.translation());
  const SE3d tilt = pivot *
                    SE3d(SO3d::Exp(Eigen::Vector3d(0.004, -0.003, 0)), Eigen::Vector3d::Zero()) *
                    pivot.Inverse();
  for (auto& k : s.problem.visual.keyframes)
    k.camera_from_world = k.camera_from_world * tilt.Inverse();
  for (auto& p : s.problem.visual.points) p.position_world = tilt * p.position_world;
  InertialBundleOptions options;
  options.iterations_first = 40;
  options.iterations_second = 10;
  // First pose fixed: the world's tilt stays.
  const InertialBundleResult fixed = SolveInertialBundle(s.problem, options);
  EXPECT_GT(MaxGravityError(s, fixed), 4e-3);
  // Position and yaw held by the gauge prior: gravity comes back.
  Scene free = s;
  free.problem.visual.keyframes[0].fixed = false;
  const SE3d first = free.problem.visual.keyframes[0].camera_from_world.Inverse();
  free.problem.anchor_prior = PositionYawPrior({first, Eigen::Vector3d::Zero()}, ImuBias(), 1e8);
  free.problem.marginalize_from = 0;
  const InertialBundleResult refined = SolveInertialBundle(free.problem, options);
  EXPECT_LT(MaxGravityError(s, refined), 5e-4);
  const SE3d first_after = refined.visual.camera_from_world[0].Inverse();
  EXPECT_LT((first_after.translation() - first.translation()).norm(), 1e-3);
  EXPECT_LT((refined.biases.back().accel - s.bias.accel).norm(), 2e-2);
}

}  // namespace
}  // namespace pkslam
