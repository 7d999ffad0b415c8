#include "imu/imu_factors.h"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "core/geometry/lie_test_utils.h"
#include "imu/imu_manifolds.h"
#include "imu/imu_test_utils.h"
#include "imu/preintegration.h"

namespace pkslam {
namespace {

using testing::CompareJacobians;
using testing::HelixMotion;
using testing::JacobianPair;
using testing::kTestGravity;
using testing::RandomTangent;
using testing::SampleImu;
using testing::Seconds;
using Vec3 = Eigen::Vector3d;
using Block = std::vector<double>;

constexpr std::int64_t kT0 = 1'000'000'000, kT1 = 1'300'000'000;

Block PoseBlock(const SE3d& world_from_body) {
  Block b(7);
  BodyPoseToBlock(world_from_body, b.data());
  return b;
}
Block VecBlock(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

void ExpectJacobiansMatch(const std::vector<JacobianPair>& pairs, std::size_t expected_blocks,
                          double rel_tol = 1e-6) {
  ASSERT_EQ(pairs.size(), expected_blocks) << "Evaluate failed";
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const double scale = 1.0 + pairs[i].analytic.cwiseAbs().maxCoeff();
    EXPECT_LT((pairs[i].analytic - pairs[i].numeric).cwiseAbs().maxCoeff(), rel_tol * scale)
        << "block " << i << "\nanalytic\n"
        << pairs[i].analytic << "\nnumeric\n"
        << pairs[i].numeric;
  }
}

// A preintegration of the helix over [kT0, kT1] with a true bias, linearised at another bias.
struct Scenario {
  HelixMotion motion;
  ImuBias true_bias{Vec3(0.01, -0.02, 0.005), Vec3(0.1, -0.05, 0.08)};
  PreintegratedImu pim;
  Scenario() {
    pim = StartPreintegration(ImuBias(Vec3(0.005, -0.01, 0), Vec3(0.05, 0, 0.05)), ImuNoise{});
    IntegrateSamples(
        SampleImu(motion, kT0 - 5'000'000, kT1 + 5'000'000, 2'500'000, true_bias, {}, nullptr), kT0,
        kT1, &pim);
  }
};

TEST(InertialError, ResidualVanishesAtTruth) {
  const Scenario s;
  const Eigen::Matrix<double, 9, 1> r = InertialResidual(
      s.pim, kTestGravity, s.motion.State(Seconds(kT0)), s.true_bias, s.motion.State(Seconds(kT1)));
  EXPECT_LT(r.head<3>().norm(), 2e-5);
  EXPECT_LT(r.segment<3>(3).norm(), 1e-3);
  EXPECT_LT(r.tail<3>().norm(), 2e-4);
  // Whitened, at the truth the chi2 is small; a 5 cm position error is not.
  const InertialError cost(s.pim, kTestGravity);
  NavState moved = s.motion.State(Seconds(kT1));
  moved.world_from_body.translation().x() += 0.05;
  const Eigen::Matrix<double, 9, 1> r_bad =
      InertialResidual(s.pim, kTestGravity, s.motion.State(Seconds(kT0)), s.true_bias, moved);
  EXPECT_GT((cost.sqrt_information() * r_bad).squaredNorm(), 100.0);
}

TEST(InertialError, JacobiansMatchNumeric) {
  const Scenario s;
  const InertialError cost(s.pim, kTestGravity);
  const BodyPoseManifold pose_manifold;
  std::mt19937 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    const NavState a = s.motion.State(Seconds(kT0));
    const NavState b = s.motion.State(Seconds(kT1));
    const std::vector<Block> blocks = {
        PoseBlock(a.world_from_body * SE3d::Exp(RandomTangent<6>(rng, 0.1))),
        VecBlock(a.velocity_world + RandomTangent<3>(rng, 0.2)),
        VecBlock(s.true_bias.gyro + RandomTangent<3>(rng, 0.02)),
        VecBlock(s.true_bias.accel + RandomTangent<3>(rng, 0.2)),
        PoseBlock(b.world_from_body * SE3d::Exp(RandomTangent<6>(rng, 0.1))),
        VecBlock(b.velocity_world + RandomTangent<3>(rng, 0.2))};
    ExpectJacobiansMatch(
        CompareJacobians(cost, blocks,
                         {&pose_manifold, nullptr, nullptr, nullptr, &pose_manifold, nullptr}),
        6);
  }
}

TEST(InertialError, SolvesForTheSecondStateInCeres) {
  // States i and the bias fixed at the truth; state j starts 20 cm / 5 deg / 0.3 m/s off.
  const Scenario s;
  const NavState a = s.motion.State(Seconds(kT0));
  const NavState b = s.motion.State(Seconds(kT1));
  std::mt19937 rng(5);
  Block pose_i = PoseBlock(a.world_from_body);
  Block v_i = VecBlock(a.velocity_world);
  Block bg = VecBlock(s.true_bias.gyro);
  Block ba = VecBlock(s.true_bias.accel);
  Block pose_j = PoseBlock(b.world_from_body * SE3d::Exp(RandomTangent<6>(rng, 0.15)));
  Block v_j = VecBlock(b.velocity_world + Vec3(0.3, -0.2, 0.1));
  InertialError cost(s.pim, kTestGravity);
  BodyPoseManifold manifold;
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  problem.AddResidualBlock(&cost, nullptr, pose_i.data(), v_i.data(), bg.data(), ba.data(),
                           pose_j.data(), v_j.data());
  problem.SetManifold(pose_i.data(), &manifold);
  problem.SetManifold(pose_j.data(), &manifold);
  for (double* fixed : {pose_i.data(), v_i.data(), bg.data(), ba.data()}) {
    problem.SetParameterBlockConstant(fixed);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  EXPECT_EQ(summary.termination_type, ceres::CONVERGENCE);
  const SE3d solved = BodyPoseFromBlock(pose_j.data());
  EXPECT_LT((solved.translation() - b.world_from_body.translation()).norm(), 2e-4);
  EXPECT_LT((solved.so3().Inverse() * b.world_from_body.so3()).Angle(), 2e-5);
  EXPECT_LT((Eigen::Map<const Vec3>(v_j.data()) - b.velocity_world).norm(), 1e-3);
}

// Row-major 9-vector of a 3x3 matrix (the accelerometer axes' parameter block).
Block AxesBlock(const Eigen::Matrix3d& m) {
  Block b(9);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) b[3 * r + c] = m(r, c);
  }
  return b;
}

TEST(ImuAxesInertialError, EqualsInertialErrorAtTheIntegratedAxesAndJacobiansMatch) {
  const Scenario s;
  const Vec3 integrated(0.002, -0.004, 0.001);
  Eigen::Matrix3d axes;
  axes << 0.003, 0.0005, -0.0004, 0.0002, -0.002, 0.0007, -0.0006, 0.0003, 0.001;
  const ImuAxesInertialError scaled(s.pim, kTestGravity, GyroScaleJacobiansOf(s.pim),
                                    AccelAxesJacobiansOf(s.pim), integrated, axes);
  const InertialError plain(s.pim, kTestGravity);
  const BodyPoseManifold pose_manifold;
  std::mt19937 rng(7);
  const NavState a = s.motion.State(Seconds(kT0));
  const NavState b = s.motion.State(Seconds(kT1));
  std::vector<Block> blocks = {
      PoseBlock(a.world_from_body * SE3d::Exp(RandomTangent<6>(rng, 0.05))),
      VecBlock(a.velocity_world + RandomTangent<3>(rng, 0.1)),
      VecBlock(s.true_bias.gyro + RandomTangent<3>(rng, 0.01)),
      VecBlock(s.true_bias.accel + RandomTangent<3>(rng, 0.1)),
      PoseBlock(b.world_from_body * SE3d::Exp(RandomTangent<6>(rng, 0.05))),
      VecBlock(b.velocity_world + RandomTangent<3>(rng, 0.1)),
      VecBlock(integrated),
      AxesBlock(axes)};
  std::vector<const double*> p;
  for (const Block& block : blocks) p.push_back(block.data());
  Eigen::Matrix<double, 9, 1> r_scaled, r_plain;
  ASSERT_TRUE(scaled.Evaluate(p.data(), r_scaled.data(), nullptr));
  ASSERT_TRUE(plain.Evaluate(p.data(), r_plain.data(), nullptr));
  EXPECT_LT((r_scaled - r_plain).norm(), 1e-12);
  for (int trial = 0; trial < 3; ++trial) {
    blocks[6] = VecBlock(integrated + RandomTangent<3>(rng, 0.01));
    blocks[7] = AxesBlock(axes + Eigen::Matrix3d::Random() * 0.01);
    ExpectJacobiansMatch(CompareJacobians(scaled, blocks,
                                          {&pose_manifold, nullptr, nullptr, nullptr,
                                           &pose_manifold, nullptr, nullptr, nullptr}),
                         8, 1e-5);
  }
}

// Three consecutive seconds of the helix, sampled by an IMU with axis errors and integrated as
// if exact; with both states and the biases held at the truth, the edges are explained by the
// true errors, and the plain edges are not.
struct AxisErrorCase {
  Vec3 gyro_scale = Vec3::Zero();
  Eigen::Matrix3d accel_axes = Eigen::Matrix3d::Zero();
  bool free_gyro = true;
  bool free_accel = true;
};

struct AxisErrorFit {
  Vec3 gyro_scale;
  Eigen::Matrix3d accel_axes;
  double plain_cost = 0;
  double final_cost = 0;
};

AxisErrorFit FitAxisErrors(const AxisErrorCase& c) {
  const HelixMotion motion;
  constexpr std::int64_t kSecondNs = 1'000'000'000;
  std::vector<ImuMeasurement> samples =
      SampleImu(motion, 0, 3 * kSecondNs + 5'000'000, 2'500'000, ImuBias(), {}, nullptr);
  for (ImuMeasurement& m : samples) {
    m.gyro = m.gyro.cwiseProduct(Vec3::Ones() + c.gyro_scale);
    m.accel = (Eigen::Matrix3d::Identity() + c.accel_axes) * m.accel;
  }
  std::vector<PreintegratedImu> pims;
  for (int i = 0; i < 3; ++i) {
    pims.push_back(StartPreintegration(ImuBias(), ImuNoise{}));
    IntegrateSamples(samples, i * kSecondNs, (i + 1) * kSecondNs, &pims.back());
  }
  std::vector<Block> poses, velocities;
  for (int i = 0; i <= 3; ++i) {
    const NavState x = motion.State(static_cast<double>(i));
    poses.push_back(PoseBlock(x.world_from_body));
    velocities.push_back(VecBlock(x.velocity_world));
  }
  Block bg = VecBlock(Vec3::Zero()), ba = VecBlock(Vec3::Zero()), k = VecBlock(Vec3::Zero());
  Block e = AxesBlock(Eigen::Matrix3d::Zero());
  ceres::Problem problem;
  AxisErrorFit fit;
  for (int i = 0; i < 3; ++i) {
    problem.AddResidualBlock(
        new ImuAxesInertialError(pims[i], kTestGravity, GyroScaleJacobiansOf(pims[i]),
                                 AccelAxesJacobiansOf(pims[i]), Vec3::Zero(),
                                 Eigen::Matrix3d::Zero()),
        nullptr,
        {poses[i].data(), velocities[i].data(), bg.data(), ba.data(), poses[i + 1].data(),
         velocities[i + 1].data(), k.data(), e.data()});
    const InertialError plain(pims[i], kTestGravity);
    const std::vector<const double*> p = {poses[i].data(), velocities[i].data(), bg.data(),
                                          ba.data(), poses[i + 1].data(), velocities[i + 1].data()};
    Eigen::Matrix<double, 9, 1> r;
    plain.Evaluate(p.data(), r.data(), nullptr);
    fit.plain_cost += r.squaredNorm();
  }
  for (int i = 0; i <= 3; ++i) {
    problem.SetParameterBlockConstant(poses[i].data());
    problem.SetParameterBlockConstant(velocities[i].data());
  }
  problem.SetParameterBlockConstant(bg.data());
  problem.SetParameterBlockConstant(ba.data());
  if (!c.free_gyro) problem.SetParameterBlockConstant(k.data());
  if (!c.free_accel) problem.SetParameterBlockConstant(e.data());
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  fit.final_cost = summary.final_cost;
  fit.gyro_scale = Vec3(k[0], k[1], k[2]);
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col < 3; ++col) fit.accel_axes(r, col) = e[3 * r + col];
  }
  return fit;
}

TEST(ImuAxesInertialError, RecoversAScaleErrorOfTheGyro) {
  // A gyro reading 0.8% fast about x and 0.5% slow about z; the accelerometer's block held.
  AxisErrorCase c;
  c.gyro_scale = Vec3(0.008, 0.0, -0.005);
  c.free_accel = false;
  const AxisErrorFit fit = FitAxisErrors(c);
  EXPECT_LT((fit.gyro_scale - c.gyro_scale).cwiseAbs().maxCoeff(), 2e-4)
      << fit.gyro_scale.transpose();
  EXPECT_EQ(fit.accel_axes, Eigen::Matrix3d::Zero());
  EXPECT_GT(fit.plain_cost, 1e3 * fit.final_cost);
}

TEST(ImuAxesInertialError, RecoversTheAccelerometersScaleAndMisalignment) {
  // An accelerometer 0.4% long on x, 0.3% short on z, with 0.05-0.1 deg cross-axis terms, and
  // the gyro's 0.5% on y: over the helix's turning and gravity both are seen.
  AxisErrorCase c;
  c.gyro_scale = Vec3(0.0, 0.005, 0.0);
  c.accel_axes << 0.004, 0.0012, -0.0009, 0.0015, 0.0, 0.0017, -0.0010, 0.0009, -0.003;
  const AxisErrorFit fit = FitAxisErrors(c);
  EXPECT_LT((fit.accel_axes - c.accel_axes).cwiseAbs().maxCoeff(), 2e-4) << fit.accel_axes;
  EXPECT_LT((fit.gyro_scale - c.gyro_scale).cwiseAbs().maxCoeff(), 2e-4)
      << fit.gyro_scale.transpose();
  EXPECT_GT(fit.plain_cost, 1e3 * fit.final_cost);
}

TEST(InertialGravityScaleError, ResidualVanishesAtTruthAndJacobiansMatch) {
  const Scenario s;
  // The visual world: rotated by R_vw (with tilt) and scaled by 1 / scale from the true world.
  const double scale = 2.5;
  const SO3d r_vw = SO3d::Exp(Vec3(0.3, -0.2, 1.0));
  const auto to_visual = [&](const NavState& x) {
    return SE3d(r_vw * x.world_from_body.so3(), r_vw * x.world_from_body.translation() / scale);
  };
  const NavState a = s.motion.State(Seconds(kT0));
  const NavState b = s.motion.State(Seconds(kT1));
  const InertialGravityScaleError cost(s.pim, to_visual(a), to_visual(b), 9.81);
  // Gravity in the visual world: r_vw * (0, 0, -1) direction; any yaw of R_wg works.
  Block gravity(4);
  GravityRotationToBlock(r_vw * SO3d::Exp(Vec3(0, 0, 0.7)), gravity.data());
  std::vector<Block> blocks = {VecBlock(r_vw * a.velocity_world / scale),
                               VecBlock(r_vw * b.velocity_world / scale),
                               VecBlock(s.true_bias.gyro),
                               VecBlock(s.true_bias.accel),
                               gravity,
                               {std::log(scale)}};
  std::vector<const double*> params;
  params.reserve(blocks.size());
  for (const Block& blk : blocks) params.push_back(blk.data());
  Eigen::Matrix<double, 9, 1> r;
  ASSERT_TRUE(cost.Evaluate(params.data(), r.data(), nullptr));
  // Whitened: consistent with the sensor noise at the truth (exact data -> well below 1).
  EXPECT_LT(r.squaredNorm(), 1.0);

  const GravityDirectionManifold gravity_manifold;
  std::mt19937 rng(9);
  for (int trial = 0; trial < 5; ++trial) {
    std::vector<Block> moved = blocks;
    for (int k = 0; k < 4; ++k) {
      for (double& x : moved[k]) x += 0.05 * std::normal_distribution<double>()(rng);
    }
    const Eigen::Vector2d d = RandomTangent<2>(rng, 0.1);
    gravity_manifold.Plus(blocks[4].data(), d.data(), moved[4].data());
    moved[5][0] += 0.1;
    ExpectJacobiansMatch(
        CompareJacobians(cost, moved,
                         {nullptr, nullptr, nullptr, nullptr, &gravity_manifold, nullptr}),
        6);
  }
}

TEST(BiasRandomWalkError, WhitensTheDifferenceAndJacobiansMatch) {
  const Scenario s;
  const std::unique_ptr<BiasRandomWalkError> gyro = BiasRandomWalkError::Gyro(s.pim);
  const std::unique_ptr<BiasRandomWalkError> accel = BiasRandomWalkError::Accel(s.pim);
  const std::vector<Block> blocks = {VecBlock(Vec3(0.01, 0.02, 0.03)), VecBlock(Vec3(0.02, 0, 0))};
  std::vector<const double*> params = {blocks[0].data(), blocks[1].data()};
  Vec3 r;
  ASSERT_TRUE(gyro->Evaluate(params.data(), r.data(), nullptr));
  const double sigma = s.pim.noise.gyro_random_walk * std::sqrt(s.pim.dt);
  EXPECT_NEAR(r.x(), 0.01 / sigma, 1e-6 * std::abs(r.x()));
  EXPECT_NEAR(r.z(), -0.03 / sigma, 1e-6 * std::abs(r.z()));
  ASSERT_TRUE(accel->Evaluate(params.data(), r.data(), nullptr));
  EXPECT_NEAR(r.y(), -0.02 / (s.pim.noise.accel_random_walk * std::sqrt(s.pim.dt)), 1e-9);
  ExpectJacobiansMatch(CompareJacobians(*gyro, blocks, {nullptr, nullptr}), 2);
}

TEST(BiasPriorError, IsotropicInformation) {
  const BiasPriorError prior(Vec3(0.1, 0, 0), 1e4);
  const Block b = VecBlock(Vec3(0.1, 0.01, -0.02));
  const double* p = b.data();
  Vec3 r;
  ASSERT_TRUE(prior.Evaluate(&p, r.data(), nullptr));
  EXPECT_NEAR(r.x(), 0.0, 1e-14);
  EXPECT_NEAR(r.y(), 1.0, 1e-12);
  EXPECT_NEAR(r.z(), -2.0, 1e-12);
  ExpectJacobiansMatch(CompareJacobians(prior, {b}, {nullptr}), 1);
}

TEST(InertialStatePriorError, ZeroAtPriorAndJacobiansMatch) {
  std::mt19937 rng(4);
  const NavState prior{SE3d::Exp(RandomTangent<6>(rng, 1.0)), Vec3(0.5, -0.3, 0.1)};
  const ImuBias prior_bias(Vec3(0.01, 0, 0.02), Vec3(0.1, 0.2, -0.1));
  // A full-rank information with correlations.
  Eigen::Matrix<double, 15, 15> a = Eigen::Matrix<double, 15, 15>::Random();
  const Eigen::Matrix<double, 15, 15> info =
      a * a.transpose() + 10 * Eigen::Matrix<double, 15, 15>::Identity();
  const InertialStatePriorError cost(prior, prior_bias, info);
  std::vector<Block> blocks = {PoseBlock(prior.world_from_body), VecBlock(prior.velocity_world),
                               VecBlock(prior_bias.gyro), VecBlock(prior_bias.accel)};
  std::vector<const double*> params;
  params.reserve(blocks.size());
  for (const Block& b : blocks) params.push_back(b.data());
  Eigen::Matrix<double, 15, 1> r;
  ASSERT_TRUE(cost.Evaluate(params.data(), r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-12);

  // A tangent displacement d gives chi2 ~ d^T info d (the information is in tangent coordinates).
  const BodyPoseManifold pose_manifold;
  Eigen::Matrix<double, 15, 1> d = 1e-4 * Eigen::Matrix<double, 15, 1>::Random();
  std::vector<Block> moved = blocks;
  pose_manifold.Plus(blocks[0].data(), d.data(), moved[0].data());
  for (int k = 1; k < 4; ++k) {
    for (int i = 0; i < 3; ++i) moved[k][i] += d(3 + 3 * k + i);
  }
  for (std::size_t k = 0; k < 4; ++k) params[k] = moved[k].data();
  ASSERT_TRUE(cost.Evaluate(params.data(), r.data(), nullptr));
  EXPECT_NEAR(r.squaredNorm(), d.dot(info * d), 1e-4 * d.dot(info * d));

  for (Block& b : moved) {
    for (double& x : b) x += 0.05;
  }
  BodyPoseToBlock(BodyPoseFromBlock(moved[0].data()), moved[0].data());  // renormalise
  ExpectJacobiansMatch(CompareJacobians(cost, moved, {&pose_manifold, nullptr, nullptr, nullptr}),
                       4);
}

}  // namespace
}  // namespace pkslam
