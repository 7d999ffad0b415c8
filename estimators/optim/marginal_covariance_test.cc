#include "estimators/optim/marginal_covariance.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/covariance.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/rotation.h>
#include <ceres/solver.h>
#include <gtest/gtest.h>

#include <array>
#include <random>
#include <vector>

#include "core/util/error.h"

namespace pkslam {
namespace {

// A pinhole projection with shared intrinsics [f, cx, cy] and an angle-axis pose per view.
struct Projection {
  Eigen::Vector2d uv;
  template <typename T>
  bool operator()(const T* intrinsics, const T* rotation, const T* translation, const T* point,
                  T* r) const {
    T p[3];
    ceres::AngleAxisRotatePoint(rotation, point, p);
    for (int i = 0; i < 3; ++i) p[i] += translation[i];
    r[0] = intrinsics[0] * p[0] / p[2] + intrinsics[1] - uv.x();
    r[1] = intrinsics[0] * p[1] / p[2] + intrinsics[2] - uv.y();
    return true;
  }
};

// A small bundle adjustment with the properties of the calibration adjustment: shared
// intrinsics with a frozen coordinate (a subset manifold), two views held constant (no gauge
// freedom), a robust loss that is active on a few gross outliers, and noisy observations, so
// that J^T J is a generic positive definite matrix.
struct SmallBundle {
  std::array<double, 3> intrinsics = {410.0, 321.0, 239.0};
  std::vector<std::array<double, 3>> rotations, translations, points;
  ceres::Problem problem;

  SmallBundle() {
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 0.7);
    std::uniform_real_distribution<double> spread(-1.5, 1.5);
    for (int v = 0; v < 4; ++v) {
      rotations.push_back({0.02 * v, -0.03 * v, 0.01 * v});
      translations.push_back({-0.3 * v, 0.05 * v, 0.1 * v});
    }
    for (int p = 0; p < 30; ++p) points.push_back({spread(rng), spread(rng), 4.0 + spread(rng)});
    problem.AddParameterBlock(intrinsics.data(), 3, new ceres::SubsetManifold(3, {2}));
    for (std::size_t v = 0; v < rotations.size(); ++v) {
      for (std::size_t p = 0; p < points.size(); ++p) {
        Projection truth{Eigen::Vector2d::Zero()};
        double r[2];
        truth(intrinsics.data(), rotations[v].data(), translations[v].data(), points[p].data(),
              r);
        const bool outlier = (v * points.size() + p) % 23 == 0;
        const Eigen::Vector2d uv(r[0] + noise(rng) + (outlier ? 25.0 : 0.0), r[1] + noise(rng));
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<Projection, 2, 3, 3, 3, 3>(new Projection{uv}),
            new ceres::HuberLoss(1.5), intrinsics.data(), rotations[v].data(),
            translations[v].data(), points[p].data());
      }
    }
    for (int v = 0; v < 2; ++v) {
      problem.SetParameterBlockConstant(rotations[static_cast<std::size_t>(v)].data());
      problem.SetParameterBlockConstant(translations[static_cast<std::size_t>(v)].data());
    }
    ceres::Solver::Options options;
    options.max_num_iterations = 50;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
  }
};

Eigen::MatrixXd CeresBlock(ceres::Covariance* covariance, const double* block, int n,
                           bool ambient) {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(n, n);
  const bool ok = ambient ? covariance->GetCovarianceMatrix({block}, m.data())
                          : covariance->GetCovarianceMatrixInTangentSpace({block}, m.data());
  EXPECT_TRUE(ok);
  return m;
}

TEST(MarginalCovariance, MatchesCeresCovarianceInTangentAndAmbientCoordinates) {
  SmallBundle b;
  const double* intrinsics = b.intrinsics.data();
  const double* rotation = b.rotations[3].data();
  const double* point = b.points[5].data();
  const auto ours = ComputeMarginalCovariance(&b.problem, {intrinsics, rotation, point});
  ASSERT_TRUE(ours.has_value());
  ASSERT_EQ(ours->joint.rows(), 2 + 3 + 3);  // the intrinsics' tangent has 2 coordinates

  ceres::Covariance::Options options;
  options.algorithm_type = ceres::SPARSE_QR;
  options.apply_loss_function = true;
  ceres::Covariance covariance(options);
  ASSERT_TRUE(covariance.Compute(
      std::vector<std::pair<const double*, const double*>>{
          {intrinsics, intrinsics}, {rotation, rotation}, {point, point}, {intrinsics, point}},
      &b.problem));
  const auto expect_close = [](const Eigen::MatrixXd& a, const Eigen::MatrixXd& e) {
    ASSERT_EQ(a.rows(), e.rows());
    ASSERT_EQ(a.cols(), e.cols());
    EXPECT_LT((a - e).norm(), 1e-6 * e.norm()) << "ours\n" << a << "\nceres\n" << e;
  };
  expect_close(ours->Block(intrinsics), CeresBlock(&covariance, intrinsics, 2, false));
  expect_close(ours->Block(rotation), CeresBlock(&covariance, rotation, 3, false));
  expect_close(ours->Block(point), CeresBlock(&covariance, point, 3, false));
  // The cross block between the intrinsics and the point.
  Eigen::Matrix<double, 2, 3, Eigen::RowMajor> cross;
  ASSERT_TRUE(covariance.GetCovarianceBlockInTangentSpace(intrinsics, point, cross.data()));
  expect_close(ours->joint.block(0, 5, 2, 3), cross);
  // Ambient coordinates: the frozen cy has no variance, as in Ceres.
  const Eigen::MatrixXd ambient =
      AmbientCovariance(b.problem, intrinsics, ours->Block(intrinsics));
  expect_close(ambient, CeresBlock(&covariance, intrinsics, 3, true));
  EXPECT_EQ(ambient(2, 2), 0.0);
  EXPECT_GT(ambient(0, 0), 0.0);
}

TEST(MarginalCovariance, TheLossFunctionIsApplied) {
  // Without the loss the outliers would count fully and the focal length's variance would grow.
  SmallBundle b;
  const double* intrinsics = b.intrinsics.data();
  const auto robust = ComputeMarginalCovariance(&b.problem, {intrinsics});
  ASSERT_TRUE(robust.has_value());
  ceres::Covariance::Options options;
  options.apply_loss_function = false;
  ceres::Covariance plain(options);
  ASSERT_TRUE(plain.Compute(
      std::vector<std::pair<const double*, const double*>>{{intrinsics, intrinsics}},
      &b.problem));
  const Eigen::MatrixXd without_loss = CeresBlock(&plain, intrinsics, 2, false);
  EXPECT_GT(std::abs(robust->Block(intrinsics)(0, 0) - without_loss(0, 0)),
            1e-3 * without_loss(0, 0));
}

struct SumOnly {
  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    r[0] = a[0] + b[0] - T(1.0);
    return true;
  }
};

TEST(MarginalCovariance, RankDeficientProblemHasNoCovariance) {
  // Only a + b is observed: J^T J is singular, as it is for ceres::Covariance.
  double a = 0.3, b = 0.7;
  ceres::Problem problem;
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<SumOnly, 1, 1, 1>(new SumOnly),
                           nullptr, &a, &b);
  EXPECT_FALSE(ComputeMarginalCovariance(&problem, {&a}).has_value());
  ceres::Covariance covariance({});
  EXPECT_FALSE(covariance.Compute(std::vector<const double*>{&a}, &problem));
  // Holding b makes a observable: variance 1 (unit residual weight).
  problem.SetParameterBlockConstant(&b);
  const auto held = ComputeMarginalCovariance(&problem, {&a});
  ASSERT_TRUE(held.has_value());
  EXPECT_NEAR(held->Block(&a)(0, 0), 1.0, 1e-12);
}

// Two independent scalars observed at very different scales: r0 = 1e7 a, r1 = 1e-4 b.
struct Scaled {
  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    r[0] = 1e7 * (a[0] - T(2.0));
    r[1] = 1e-4 * (b[0] - T(3.0));
    return true;
  }
};

TEST(MarginalCovariance, UnitsAloneDoNotMakeAProblemIllConditioned) {
  // J^T J = diag(1e14, 1e-8): its condition number (1e22) is only the units'. Both scalars are
  // observed; their variances are 1e-14 and 1e8.
  double a = 2.0, b = 3.0;
  ceres::Problem problem;
  problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Scaled, 2, 1, 1>(new Scaled),
                           nullptr, &a, &b);
  const auto covariance = ComputeMarginalCovariance(&problem, {&a, &b});
  ASSERT_TRUE(covariance.has_value());
  EXPECT_NEAR(covariance->Block(&a)(0, 0) / 1e-14, 1.0, 1e-9);
  EXPECT_NEAR(covariance->Block(&b)(0, 0) / 1e8, 1.0, 1e-9);
}

TEST(MarginalCovariance, RejectsBlocksThatAreConstantOrForeign) {
  SmallBundle b;
  EXPECT_THROW(ComputeMarginalCovariance(&b.problem, {b.rotations[0].data()}), Error);
  const double foreign[3] = {0, 0, 0};
  EXPECT_THROW(ComputeMarginalCovariance(&b.problem, {foreign}), Error);
  MarginalCovarianceOptions bad;
  bad.num_threads = 0;
  EXPECT_THROW(ComputeMarginalCovariance(&b.problem, {b.intrinsics.data()}, bad), Error);
}

}  // namespace
}  // namespace pkslam
