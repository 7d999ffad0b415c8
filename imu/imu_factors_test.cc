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

TEST(GyroScaledInertialError, EqualsInertialErrorAtTheIntegratedScaleAndJacobiansMatch) {
  const Scenario s;
  const Vec3 integrated(0.002, -0.004, 0.001);
  const GyroScaledInertialError scaled(s.pim, kTestGravity, GyroScaleJacobiansOf(s.pim),
                                       integrated);
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
      VecBlock(integrated)};
  std::vector<const double*> p;
  for (const Block& block : blocks) p.push_back(block.data());
  Eigen::Matrix<double, 9, 1> r_scaled, r_plain;
  ASSERT_TRUE(scaled.Evaluate(p.data(), r_scaled.data(), nullptr));
  ASSERT_TRUE(plain.Evaluate(p.data(), r_plain.data(), nullptr));
  EXPECT_LT((r_scaled - r_plain).norm(), 1e-12);
  for (int trial = 0; trial < 3; ++trial) {
    blocks[6] = VecBlock(integrated + RandomTangent<3>(rng, 0.01));
    ExpectJacobiansMatch(CompareJacobians(scaled, blocks,
                                          {&pose_manifold, nullptr, nullptr, nullptr,
                                           &pose_manifold, nullptr, nullptr}),
                         7, 1e-5);
  }
}

TEST(GyroScaledInertialError, RecoversAScaleErrorOfTheGyro) {
  // The samples come from a gyro reading 0.8% fast about x and 0.5% slow about z, integrated
  // as if exact; with both states and the bias held at the truth, the edges of three
  // consecutive seconds are explained by k = (0.008, 0, -0.005), and the plain edge is not.
  const HelixMotion motion;
  const Vec3 k_true(0.008, 0.0, -0.005);
  constexpr std::int64_t kSecondNs = 1'000'000'000;
  std::vector<ImuMeasurement> samples =
      SampleImu(motion, 0, 3 * kSecondNs + 5'000'000, 2'500'000, ImuBias(), {}, nullptr);
  for (ImuMeasurement& m : samples) m.gyro = m.gyro.cwiseProduct(Vec3::Ones() + k_true);
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
  ceres::Problem problem;
  double plain_cost = 0;
  for (int i = 0; i < 3; ++i) {
    problem.AddResidualBlock(new GyroScaledInertialError(pims[i], kTestGravity,
                                                         GyroScaleJacobiansOf(pims[i]), Vec3::Zero()),
                             nullptr, poses[i].data(), velocities[i].data(), bg.data(), ba.data(),
                             poses[i + 1].data(), velocities[i + 1].data(), k.data());
    const InertialError plain(pims[i], kTestGravity);
    const std::vector<const double*> p = {poses[i].data(), velocities[i].data(), bg.data(),
                                          ba.data(), poses[i + 1].data(), velocities[i + 1].data()};
    Eigen::Matrix<double, 9, 1> r;
    plain.Evaluate(p.data(), r.data(), nullptr);
    plain_cost += r.squaredNorm();
  }
  for (int i = 0; i <= 3; ++i) {
    problem.SetParameterBlockConstant(poses[i].data());
    problem.SetParameterBlockConstant(velocities[i].data());
  }
  problem.SetParameterBlockConstant(bg.data());
  problem.SetParameterBlockConstant(ba.data());
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  const Vec3 solved(k[0], k[1], k[2]);
  EXPECT_LT((solved - k_true).cwiseAbs().maxCoeff(), 2e-4) << solved.transpose();
  EXPECT_GT(plain_cost, 1e3 * summary.final_cost);
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
