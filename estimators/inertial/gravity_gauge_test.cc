#include "estimators/inertial/gravity_gauge.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>

#include "imu/imu_factors.h"
#include "imu/imu_manifolds.h"

namespace pkslam {
namespace {

// A body mounted with the EuRoC-like tilt (x axis 20 deg off up), turned to `heading` about
// gravity.
SO3d Mounted(double heading) {
  return SO3d::Exp(Eigen::Vector3d(0, 0, heading)) * SO3d::Exp(Eigen::Vector3d(0, -1.22, 0));
}

TEST(TiltObservability, ZeroAtAFixedHeading) {
  EXPECT_EQ(TiltObservability({}), 0.0);
  EXPECT_EQ(TiltObservability({Mounted(0.3)}), 0.0);
  EXPECT_LT(TiltObservability(std::vector<SO3d>(20, Mounted(0.3))), 1e-12);
}

TEST(TiltObservability, IsOneMinusMeanResultantSquaredForHeadings) {
  for (const double span : {0.5, 1.1, 2.1, 6.0}) {
    std::vector<SO3d> orientations;
    std::complex<double> resultant = 0;
    const int n = 50;
    for (int i = 0; i < n; ++i) {
      const double heading = 0.7 + span * (i / (n - 1.0) - 0.5);
      orientations.push_back(Mounted(heading));
      resultant += std::polar(1.0, heading) / static_cast<double>(n);
    }
    EXPECT_NEAR(TiltObservability(orientations), 1.0 - std::norm(resultant), 1e-9) << span;
  }
  // Uniform over 65 deg: about the default threshold of the refinement.
  std::vector<SO3d> spread;
  for (int i = 0; i <= 64; ++i) spread.push_back(Mounted((i - 32) * M_PI / 180));
  EXPECT_NEAR(TiltObservability(spread), 0.10, 0.01);
}

TEST(TiltObservability, RollAndPitchAloneSeparateLittle) {
  // Rocking about a fixed heading (+-5 deg) changes G_i only to first order in the angle.
  std::vector<SO3d> rocking;
  for (int i = 0; i < 40; ++i) {
    rocking.push_back(
        SO3d::Exp(Eigen::Vector3d(0.087 * std::sin(0.3 * i), 0.087 * std::cos(0.5 * i), 0)) *
        Mounted(0.2));
  }
  const double value = TiltObservability(rocking);
  EXPECT_GT(value, 0.0);
  EXPECT_LT(value, 0.01);
}

TEST(PositionYawPrior, HoldsPositionAndYawButNotTilt) {
  const NavState state{SE3d(Mounted(0.4), Eigen::Vector3d(1, 2, 3)), Eigen::Vector3d(0.1, 0, 0)};
  const InertialStatePrior prior = PositionYawPrior(state, ImuBias(), 1e4);
  ASSERT_TRUE(prior.sqrt_information.has_value());
  EXPECT_LT(
      (prior.sqrt_information->transpose() * *prior.sqrt_information - prior.information).norm(),
      1e-9);
  const InertialStatePriorError error(prior.mean, prior.bias_mean, *prior.sqrt_information,
                                      InertialStatePriorError::SqrtInformation{});
  auto cost = [&](const SE3d& pose, const Eigen::Vector3d& v) {
    double block[kBodyPoseBlockSize];
    BodyPoseToBlock(pose, block);
    const Eigen::Vector3d bg(0.01, 0, 0);
    const Eigen::Vector3d ba(0, 0.2, 0);
    const double* parameters[] = {block, v.data(), bg.data(), ba.data()};
    Eigen::Matrix<double, 15, 1> r;
    EXPECT_TRUE(error.Evaluate(parameters, r.data(), nullptr));
    return r.squaredNorm();
  };
  const Eigen::Vector3d v(0.5, -0.2, 0.3);  // velocity and biases are free
  // A tilt of the world about the body position (roll / pitch): free.
  const SE3d about(SO3d(), state.world_from_body.translation());
  const SE3d tilted = about *
                      SE3d(SO3d::Exp(Eigen::Vector3d(0.01, -0.02, 0)), Eigen::Vector3d::Zero()) *
                      about.Inverse() * state.world_from_body;
  EXPECT_LT(cost(tilted, v), 1e-12);
  // Yaw and position are held.
  const SE3d yawed = about * SE3d(SO3d::Exp(Eigen::Vector3d(0, 0, 0.01)), Eigen::Vector3d::Zero()) *
                     about.Inverse() * state.world_from_body;
  EXPECT_NEAR(cost(yawed, v), 1e4 * 1e-4, 1e-3);
  const SE3d moved(state.world_from_body.so3(),
                   state.world_from_body.translation() + Eigen::Vector3d(0, 0.01, 0));
  EXPECT_NEAR(cost(moved, v), 1e4 * 1e-4, 1e-6);
}

}  // namespace
}  // namespace pkslam
