#include "estimators/optim/reprojection_error.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/crs_matrix.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "core/geometry/lie_test_utils.h"
#include "estimators/optim/se3_manifold.h"

namespace pkslam {
namespace {

using testing::RandomTangent;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using RowMajorX = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

const PinholeIntrinsics kIntrinsics{435.0, 430.0, 367.0, 248.0, 435.0 * 0.11};

// The same residual written once more, generically, on a tangent perturbation of a fixed base
// pose: r(Exp(delta) * base, p). AutoDiff of this at delta = 0 is the reference Jacobian.
template <int kRes>
struct PerturbedResidual {
  SE3d base;
  Eigen::Matrix<double, kRes, 1> obs;
  double sqrt_info;
  double sqrt_info_disparity = 0.0;  // > 0: RGB-D disparity form of the third residual

  template <typename T>
  bool operator()(const T* delta, const T* point, T* residual) const {
    const Eigen::Map<const Eigen::Matrix<T, 6, 1>> d(delta);
    const SE3<T> pose = SE3<T>::Exp(d) * base.cast<T>();
    const Eigen::Matrix<T, 3, 1> p = pose * Eigen::Map<const Eigen::Matrix<T, 3, 1>>(point);
    const T u = T(kIntrinsics.fx) * p.x() / p.z() + T(kIntrinsics.cx);
    const T v = T(kIntrinsics.fy) * p.y() / p.z() + T(kIntrinsics.cy);
    residual[0] = T(sqrt_info) * (u - T(obs(0)));
    residual[1] = T(sqrt_info) * (v - T(obs(1)));
    if constexpr (kRes == 3) {
      residual[2] = sqrt_info_disparity > 0.0
                        ? T(sqrt_info_disparity) * (T(kIntrinsics.bf) / p.z() - T(obs(0) - obs(2)))
                        : T(sqrt_info) * (u - T(kIntrinsics.bf) / p.z() - T(obs(2)));
    }
    return true;
  }
};

struct Scenario {
  SE3d camera_from_world;
  Eigen::Vector3d p_world;
  Eigen::Vector3d obs;  // u, v, u_right (noisy)
  double inv_sigma2;
};

Scenario MakeScenario(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Scenario s;
  s.camera_from_world = SE3d::Exp(RandomTangent<6>(rng, 1.0));
  const Eigen::Vector3d p_camera(u(rng), u(rng), 3.0 + 2.0 * u(rng));
  s.p_world = s.camera_from_world.Inverse() * p_camera;
  const double uu = kIntrinsics.fx * p_camera.x() / p_camera.z() + kIntrinsics.cx;
  s.obs = Eigen::Vector3d(uu + 2.0 * u(rng),
                          kIntrinsics.fy * p_camera.y() / p_camera.z() + kIntrinsics.cy + u(rng),
                          uu - kIntrinsics.bf / p_camera.z() + u(rng));
  s.inv_sigma2 = 1.0 / std::pow(1.2, 2 * (static_cast<int>(rng() % 4)));
  return s;
}

// Checks an analytic cost function (pose block through the manifold [+ point]) against
// AutoDiff of PerturbedResidual and against central differences of r(Plus(x, delta)).
template <int kRes>
void CheckJacobians(const ceres::CostFunction& analytic, const Scenario& s, bool with_point,
                    double disparity_inv_sigma2 = 0.0) {
  double pose[7];
  PoseToBlock(s.camera_from_world, pose);
  double point[3] = {s.p_world.x(), s.p_world.y(), s.p_world.z()};
  const double* params[2] = {pose, point};

  Eigen::Matrix<double, kRes, 1> r;
  Eigen::Matrix<double, kRes, 7, Eigen::RowMajor> j_pose_ambient;
  Eigen::Matrix<double, kRes, 3, Eigen::RowMajor> j_point;
  double* jacobians[2] = {j_pose_ambient.data(), j_point.data()};
  ASSERT_TRUE(analytic.Evaluate(params, r.data(), jacobians));
  EXPECT_EQ(j_pose_ambient.col(6).norm(), 0.0);

  const SE3LeftManifold manifold;
  Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus_jacobian;
  manifold.PlusJacobian(pose, plus_jacobian.data());
  const Eigen::Matrix<double, kRes, 6> j_tangent = j_pose_ambient * plus_jacobian;

  // Reference 1: AutoDiff of the generic residual.
  PerturbedResidual<kRes> functor{s.camera_from_world, s.obs.head<kRes>(), std::sqrt(s.inv_sigma2),
                                  std::sqrt(disparity_inv_sigma2)};
  ceres::AutoDiffCostFunction<PerturbedResidual<kRes>, kRes, 6, 3> autodiff(
      new PerturbedResidual<kRes>(functor));
  const Vec6 zero = Vec6::Zero();
  const double* ad_params[2] = {zero.data(), point};
  Eigen::Matrix<double, kRes, 1> r_ad;
  Eigen::Matrix<double, kRes, 6, Eigen::RowMajor> j_delta_ad;
  Eigen::Matrix<double, kRes, 3, Eigen::RowMajor> j_point_ad;
  double* ad_jacobians[2] = {j_delta_ad.data(), j_point_ad.data()};
  ASSERT_TRUE(autodiff.Evaluate(ad_params, r_ad.data(), ad_jacobians));
  EXPECT_LT((r - r_ad).norm(), 1e-9);
  const double scale = j_delta_ad.norm();
  EXPECT_LT((j_tangent - j_delta_ad).norm(), 1e-9 * scale) << j_tangent << "\n\n" << j_delta_ad;
  if (with_point) {
    EXPECT_LT((j_point - j_point_ad).norm(), 1e-9 * j_point_ad.norm());
  }

  // Reference 2: central differences of delta -> r(Plus(x, delta)) through the manifold.
  constexpr double h = 1e-6;
  for (int c = 0; c < 6; ++c) {
    Vec6 d = Vec6::Zero();
    double plus_x[7], minus_x[7];
    d(c) = h;
    manifold.Plus(pose, d.data(), plus_x);
    d(c) = -h;
    manifold.Plus(pose, d.data(), minus_x);
    Eigen::Matrix<double, kRes, 1> r_plus, r_minus;
    const double* pp[2] = {plus_x, point};
    const double* pm[2] = {minus_x, point};
    ASSERT_TRUE(analytic.Evaluate(pp, r_plus.data(), nullptr));
    ASSERT_TRUE(analytic.Evaluate(pm, r_minus.data(), nullptr));
    const Eigen::Matrix<double, kRes, 1> numeric = (r_plus - r_minus) / (2 * h);
    EXPECT_LT((numeric - j_tangent.col(c)).norm(), 1e-5 * std::max(1.0, scale)) << c;
  }
}

TEST(ReprojectionError, MonoJacobians) {
  std::mt19937 rng(11);
  for (int i = 0; i < 30; ++i) {
    const Scenario s = MakeScenario(rng);
    const MonoReprojectionError cost(kIntrinsics, s.obs.head<2>(), s.inv_sigma2);
    CheckJacobians<2>(cost, s, true);
  }
}

TEST(ReprojectionError, StereoJacobians) {
  std::mt19937 rng(12);
  for (int i = 0; i < 30; ++i) {
    const Scenario s = MakeScenario(rng);
    const StereoReprojectionError cost(kIntrinsics, s.obs, s.inv_sigma2);
    CheckJacobians<3>(cost, s, true);
  }
}

TEST(ReprojectionError, PoseOnlyJacobians) {
  std::mt19937 rng(13);
  for (int i = 0; i < 30; ++i) {
    const Scenario s = MakeScenario(rng);
    const MonoPoseOnlyError mono(kIntrinsics, s.p_world, s.obs.head<2>(), s.inv_sigma2);
    CheckJacobians<2>(mono, s, false);
    const StereoPoseOnlyError stereo(kIntrinsics, s.p_world, s.obs, s.inv_sigma2);
    CheckJacobians<3>(stereo, s, false);
  }
}

TEST(ReprojectionError, SquaredResidualIsChi2) {
  std::mt19937 rng(14);
  for (int i = 0; i < 20; ++i) {
    const Scenario s = MakeScenario(rng);
    double pose[7];
    PoseToBlock(s.camera_from_world, pose);
    const double* params[1] = {pose};
    Eigen::Vector2d r2;
    Eigen::Vector3d r3;
    ASSERT_TRUE(MonoPoseOnlyError(kIntrinsics, s.p_world, s.obs.head<2>(), s.inv_sigma2)
                    .Evaluate(params, r2.data(), nullptr));
    ASSERT_TRUE(StereoPoseOnlyError(kIntrinsics, s.p_world, s.obs, s.inv_sigma2)
                    .Evaluate(params, r3.data(), nullptr));
    EXPECT_NEAR(
        r2.squaredNorm(),
        MonoChi2(kIntrinsics, s.camera_from_world, s.p_world, s.obs.head<2>(), s.inv_sigma2), 1e-9);
    EXPECT_NEAR(r3.squaredNorm(),
                StereoChi2(kIntrinsics, s.camera_from_world, s.p_world, s.obs, s.inv_sigma2), 1e-9);
    EXPECT_GT(r2.squaredNorm(), 0.0);
  }
}

// RGB-D: the third residual is on the depth reading's disparity, with its own information.
TEST(ReprojectionError, RgbdDisparityJacobians) {
  std::mt19937 rng(16);
  for (int i = 0; i < 30; ++i) {
    const Scenario s = MakeScenario(rng);
    const double info = 1.0 / std::pow(0.05 + 0.1 * static_cast<double>(i % 3), 2);
    CheckJacobians<3>(StereoReprojectionError(kIntrinsics, s.obs, s.inv_sigma2, info), s, true,
                      info);
    CheckJacobians<3>(StereoPoseOnlyError(kIntrinsics, s.p_world, s.obs, s.inv_sigma2, info), s,
                      false, info);
  }
}

TEST(ReprojectionError, RgbdDisparityResidualIgnoresTheKeypointError) {
  // A depth reading gives d = bf / z whatever the keypoint's u error: moving u (and the
  // virtual right coordinate derived from it) changes the first residual only, and the chi2
  // weighs the disparity error with the depth's information.
  const SE3d identity;
  const Eigen::Vector3d p(0.3, -0.2, 2.5);
  const double u = kIntrinsics.fx * p.x() / p.z() + kIntrinsics.cx;
  const double v = kIntrinsics.fy * p.y() / p.z() + kIntrinsics.cy;
  const double d = kIntrinsics.bf / p.z() + 0.1;  // depth reading 0.1 px of disparity off
  const double info = 1.0 / (0.05 * 0.05);
  double pose[7];
  PoseToBlock(identity, pose);
  const double* params[1] = {pose};
  for (const double du : {0.0, 1.5}) {
    const Eigen::Vector3d obs(u + du, v, u + du - d);
    Eigen::Vector3d r;
    ASSERT_TRUE(
        StereoPoseOnlyError(kIntrinsics, p, obs, 1.0, info).Evaluate(params, r.data(), nullptr));
    EXPECT_NEAR(r(0), -du, 1e-9);
    EXPECT_NEAR(r(2), -0.1 / 0.05, 1e-9);
    EXPECT_NEAR(StereoChi2(kIntrinsics, identity, p, obs, 1.0, info), r.squaredNorm(), 1e-9);
    // The stereo form would charge the keypoint's u error to the right coordinate too.
    Eigen::Vector3d r_stereo;
    ASSERT_TRUE(
        StereoPoseOnlyError(kIntrinsics, p, obs, 1.0).Evaluate(params, r_stereo.data(), nullptr));
    EXPECT_NEAR(r_stereo(2), 0.1 - du, 1e-9);
  }
}

TEST(ReprojectionError, PointBehindCameraIsRejected) {
  const SE3d identity;
  const Eigen::Vector3d behind(0.1, 0.2, -2.0);
  double pose[7];
  PoseToBlock(identity, pose);
  const double* params[1] = {pose};
  Eigen::Vector2d r;
  EXPECT_FALSE(MonoPoseOnlyError(kIntrinsics, behind, Eigen::Vector2d(300, 200), 1.0)
                   .Evaluate(params, r.data(), nullptr));
  EXPECT_TRUE(std::isinf(MonoChi2(kIntrinsics, identity, behind, Eigen::Vector2d(300, 200), 1)));
  EXPECT_TRUE(
      std::isinf(StereoChi2(kIntrinsics, identity, behind, Eigen::Vector3d(300, 200, 290), 1)));
}

// Through Ceres's own machinery: Problem::Evaluate multiplies by PlusJacobian and reports the
// Jacobian in tangent coordinates; it must equal the AutoDiff tangent Jacobian.
TEST(ReprojectionError, CeresSeesTheTangentJacobian) {
  std::mt19937 rng(15);
  const Scenario s = MakeScenario(rng);
  double pose[7];
  PoseToBlock(s.camera_from_world, pose);
  double point[3] = {s.p_world.x(), s.p_world.y(), s.p_world.z()};
  SE3LeftManifold manifold;
  ceres::Problem::Options options;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(options);
  problem.AddResidualBlock(new StereoReprojectionError(kIntrinsics, s.obs, s.inv_sigma2), nullptr,
                           pose, point);
  problem.SetManifold(pose, &manifold);
  ceres::CRSMatrix crs;
  ceres::Problem::EvaluateOptions eval;
  eval.parameter_blocks = {pose, point};
  ASSERT_TRUE(problem.Evaluate(eval, nullptr, nullptr, nullptr, &crs));
  ASSERT_EQ(crs.num_rows, 3);
  ASSERT_EQ(crs.num_cols, 9);
  RowMajorX j = RowMajorX::Zero(3, 9);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) j(row, crs.cols[k]) = crs.values[k];
  }
  PerturbedResidual<3> functor{s.camera_from_world, s.obs, std::sqrt(s.inv_sigma2)};
  ceres::AutoDiffCostFunction<PerturbedResidual<3>, 3, 6, 3> autodiff(
      new PerturbedResidual<3>(functor));
  const Vec6 zero = Vec6::Zero();
  const double* ad_params[2] = {zero.data(), point};
  Eigen::Vector3d r_ad;
  Eigen::Matrix<double, 3, 6, Eigen::RowMajor> j_delta;
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> j_point;
  double* ad_jacobians[2] = {j_delta.data(), j_point.data()};
  ASSERT_TRUE(autodiff.Evaluate(ad_params, r_ad.data(), ad_jacobians));
  EXPECT_LT((j.leftCols(6) - RowMajorX(j_delta)).norm(), 1e-9 * j_delta.norm());
  EXPECT_LT((j.rightCols(3) - RowMajorX(j_point)).norm(), 1e-9 * j_point.norm());
}

}  // namespace
}  // namespace pkslam
