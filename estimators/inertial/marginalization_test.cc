// Marginalisation prior of the local inertial BA (values): the Schur complement against a dense
// solve, the clamp to PSD, the prior factor's quadratic, and the options' checks.
#include "estimators/inertial/marginalization.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <random>

#include "core/util/error.h"
#include "estimators/inertial/inertial_bundle.h"
#include "imu/imu_factors.h"
#include "imu/imu_manifolds.h"

namespace pkslam {
namespace {

// A linear-Gaussian chain x0 - x1 - x2 (3 blocks of `dim`): a prior on x0, relative factors
// between neighbours, a measurement of x2; J and r of the stacked whitened residuals.
void MakeChain(int dim, std::mt19937* rng, Eigen::MatrixXd* j, Eigen::VectorXd* r) {
  std::normal_distribution<double> n01(0.0, 1.0);
  auto random = [&](int rows, int cols) {
    Eigen::MatrixXd m(rows, cols);
    for (int a = 0; a < rows; ++a) {
      for (int b = 0; b < cols; ++b) m(a, b) = n01(*rng);
    }
    return m;
  };
  const int n = 3 * dim;
  *j = Eigen::MatrixXd::Zero(4 * dim, n);
  j->block(0, 0, dim, dim) = random(dim, dim) + 3 * Eigen::MatrixXd::Identity(dim, dim);
  for (int e = 0; e < 2; ++e) {
    j->block((1 + e) * dim, e * dim, dim, dim) = random(dim, dim);
    j->block((1 + e) * dim, (e + 1) * dim, dim, dim) = random(dim, dim);
  }
  j->block(3 * dim, 2 * dim, dim, dim) = random(dim, dim);
  *r = random(4 * dim, 1);
}

TEST(Marginalization, SchurComplementIsTheExactMarginal) {
  std::mt19937 rng(11);
  for (int dim : {1, 3, 15}) {
    Eigen::MatrixXd j;
    Eigen::VectorXd r;
    MakeChain(dim, &rng, &j, &r);
    const Eigen::MatrixXd h = j.transpose() * j;
    const Eigen::VectorXd b = j.transpose() * r;
    Eigen::MatrixXd h_kept;
    Eigen::VectorXd b_kept;
    MarginalizeLeading(h, b, dim, &h_kept, &b_kept);
    // Dense: the joint covariance's kept block is the inverse of the marginal information, and
    // the joint minimum -H^-1 b restricted to the kept variables is the marginal's minimum.
    const Eigen::MatrixXd covariance = h.inverse();
    const Eigen::MatrixXd marginal = covariance.bottomRightCorner(2 * dim, 2 * dim).inverse();
    EXPECT_LT((h_kept - marginal).norm(), 1e-8 * marginal.norm()) << "dim " << dim;
    const Eigen::VectorXd joint_min = -h.ldlt().solve(b);
    const Eigen::VectorXd kept_min = -h_kept.ldlt().solve(b_kept);
    EXPECT_LT((kept_min - joint_min.tail(2 * dim)).norm(), 1e-8 * (1 + joint_min.norm()));
  }
}

TEST(Marginalization, UnobservableDirectionsCarryNothing) {
  // x0 is seen only together with x1 (x0 - x1 measured); marginalising x0 leaves nothing on x1.
  Eigen::MatrixXd j(1, 2);
  j << 1, -1;
  Eigen::VectorXd r(1);
  r << 0.5;
  Eigen::MatrixXd h_kept;
  Eigen::VectorXd b_kept;
  MarginalizeLeading(j.transpose() * j, j.transpose() * r, 1, &h_kept, &b_kept);
  EXPECT_NEAR(h_kept(0, 0), 0.0, 1e-12);
  EXPECT_NEAR(b_kept(0), 0.0, 1e-12);
}

TEST(Marginalization, ProjectToPsdClampsNegativeEigenvalues) {
  Eigen::Matrix2d m;
  m << 1, 2, 2.1, 1;  // eigenvalues ~3.05 and ~-1.05, slightly asymmetric
  const Eigen::MatrixXd p = ProjectToPsd(m);
  EXPECT_LT((p - p.transpose()).norm(), 1e-15);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(p);
  EXPECT_GE(es.eigenvalues().minCoeff(), -1e-12);
  EXPECT_NEAR(es.eigenvalues().maxCoeff(), 3.05, 1e-12);
}

TEST(Marginalization, PriorFactorReproducesTheQuadratic) {
  // At the linearisation point the prior factor's J^T J and J^T r are H and b.
  std::mt19937 rng(5);
  std::normal_distribution<double> n01(0.0, 1.0);
  Eigen::Matrix<double, 15, 15> a;
  Eigen::Matrix<double, 15, 1> b;
  for (int i = 0; i < 15; ++i) {
    b[i] = 1e-3 * n01(rng);
    for (int k = 0; k < 15; ++k) a(i, k) = n01(rng);
  }
  const Eigen::Matrix<double, 15, 15> h =
      a.transpose() * a + Eigen::Matrix<double, 15, 15>::Identity();
  NavState lin;
  lin.world_from_body = SE3d(SO3d::Exp(Eigen::Vector3d(0.3, -0.2, 1.0)), Eigen::Vector3d(1, 2, 3));
  lin.velocity_world = Eigen::Vector3d(0.5, -0.1, 0.2);
  const ImuBias bias(Eigen::Vector3d(0.01, 0, -0.02), Eigen::Vector3d(0.1, 0.2, -0.1));
  const InertialStatePrior prior = MakeInertialStatePrior(lin, bias, h, b);
  const InertialStatePriorError cost(prior.mean, prior.bias_mean, prior.information);
  double pose[kBodyPoseBlockSize];
  BodyPoseToBlock(lin.world_from_body, pose);
  const double* params[] = {pose, lin.velocity_world.data(), bias.gyro.data(), bias.accel.data()};
  Eigen::Matrix<double, 15, 1> r;
  Eigen::Matrix<double, 15, 7, Eigen::RowMajor> j_pose;
  Eigen::Matrix<double, 15, 3, Eigen::RowMajor> j_v, j_bg, j_ba;
  double* jacobians[] = {j_pose.data(), j_v.data(), j_bg.data(), j_ba.data()};
  ASSERT_TRUE(cost.Evaluate(params, r.data(), jacobians));
  Eigen::Matrix<double, 15, 15> j;
  j << j_pose.leftCols<6>(), j_v, j_bg, j_ba;
  // First order in the mean shift (|H^-1 b| is small here).
  EXPECT_LT((j.transpose() * j - h).norm(), 1e-2 * h.norm());
  EXPECT_LT((j.transpose() * r - b).norm(), 1e-2 * b.norm());
}

TEST(Marginalization, OptionsAreChecked) {
  InertialBundleOptions options;
  EXPECT_NO_THROW(options.Check());
  options.marginalization_visual_weight = 0;
  EXPECT_THROW(options.Check(), OptionError);
  options.marginalization_visual_weight = 1.5;
  EXPECT_THROW(options.Check(), OptionError);
  options.marginalization_visual_weight = 1;
  options.marginalization_threshold = -1;
  EXPECT_THROW(options.Check(), OptionError);
}

}  // namespace
}  // namespace pkslam
