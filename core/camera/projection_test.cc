#include "core/camera/projection.h"

#include <ceres/jet.h>
#include <gtest/gtest.h>

#include "core/camera/camera_model.h"
#include "core/camera/test_cameras.h"

namespace pkslam {
namespace {

using Jet3 = ceres::Jet<double, 3>;
using Matrix23d = Eigen::Matrix<double, 2, 3>;

// Projects p with Jets seeded on x, y, z: value and d(uv)/d(p).
template <typename ProjectFn>
bool JetProject(ProjectFn project, const Eigen::Vector3d& p, Eigen::Vector2d* uv, Matrix23d* jac) {
  const Jet3 p_jet[3] = {Jet3(p.x(), 0), Jet3(p.y(), 1), Jet3(p.z(), 2)};
  Jet3 uv_jet[2];
  if (!project(p_jet, uv_jet)) return false;
  for (int r = 0; r < 2; ++r) {
    (*uv)[r] = uv_jet[r].a;
    jac->row(r) = uv_jet[r].v.transpose();
  }
  return true;
}

std::vector<Eigen::Vector3d> TestPoints() {
  return {{0.3, -0.2, 2.0}, {-1.1, 0.7, 1.5}, {0.0, 0.0, 3.0}, {2.0, 1.0, 4.0}, {1e-10, 0.0, 1.0}};
}

void ExpectSame(const CameraModel& cam, const Eigen::Vector3d& p, const Eigen::Vector2d& uv,
                const Matrix23d& jac) {
  Matrix23d analytic;
  const auto expected = cam.Project(p, &analytic);
  ASSERT_TRUE(expected.has_value());
  EXPECT_LT((uv - *expected).norm(), 1e-9) << p.transpose();
  EXPECT_LT((jac - analytic).norm(), 1e-9 * analytic.norm()) << p.transpose() << "\njet\n"
                                                             << jac << "\nanalytic\n"
                                                             << analytic;
}

TEST(ProjectionTest, IdealPinholeJetsEqualAnalyticJacobian) {
  const CameraModel euroc = testing::EurocCam0();
  const CameraModel ideal = CameraModel::Pinhole(euroc.width(), euroc.height(), euroc.fx(),
                                                 euroc.fy(), euroc.cx(), euroc.cy());
  // ProjectT ignores the distortion of a pinhole model: BA runs on undistorted keypoints.
  const std::array<double, 9> params = euroc.Params();
  for (const Eigen::Vector3d& p : TestPoints()) {
    Eigen::Vector2d uv;
    Matrix23d jac;
    ASSERT_TRUE(JetProject(
        [&](const Jet3* pc, Jet3* out) {
          return CameraModel::ProjectT(CameraType::kPinhole, params.data(), pc, out);
        },
        p, &uv, &jac));
    ExpectSame(ideal, p, uv, jac);
  }
}

TEST(ProjectionTest, RadTanJetsEqualAnalyticJacobian) {
  const CameraModel k3_cam =
      CameraModel::Pinhole(640, 480, 400, 410, 330, 236, {-0.3, 0.1, 0.002, -0.003, -0.01});
  for (const CameraModel& cam : {testing::EurocCam0(), k3_cam}) {
    const std::array<double, 9> params = cam.Params();
    for (const Eigen::Vector3d& p : TestPoints()) {
      Eigen::Vector2d uv;
      Matrix23d jac;
      ASSERT_TRUE(
          JetProject([&](const Jet3* pc,
                         Jet3* out) { return projection::ProjectRadTan(params.data(), pc, out); },
                     p, &uv, &jac));
      ExpectSame(cam, p, uv, jac);
    }
  }
}

TEST(ProjectionTest, Kb8JetsEqualAnalyticJacobian) {
  const CameraModel cam = testing::TumViKb8();
  const std::array<double, 9> params = cam.Params();
  std::vector<Eigen::Vector3d> points = TestPoints();
  points.emplace_back(1.0, 0.4, -0.3);  // beyond 90 degrees
  for (const Eigen::Vector3d& p : points) {
    Eigen::Vector2d uv;
    Matrix23d jac;
    ASSERT_TRUE(JetProject(
        [&](const Jet3* pc, Jet3* out) {
          return CameraModel::ProjectT(CameraType::kKannalaBrandt8, params.data(), pc, out);
        },
        p, &uv, &jac));
    ExpectSame(cam, p, uv, jac);
    // The double instantiation gives the same pixel.
    double uv_d[2];
    ASSERT_TRUE(projection::ProjectKannalaBrandt8(params.data(), p.data(), uv_d));
    EXPECT_NEAR(uv_d[0], uv.x(), 1e-12);
  }
}

TEST(ProjectionTest, RejectsUnprojectablePoints) {
  const std::array<double, 9> params = testing::EurocCam0().Params();
  const double behind[3] = {0.1, 0.2, -1.0};
  const double on_plane[3] = {0.1, 0.2, 1e-7};
  double uv[2] = {-1, -1};
  EXPECT_FALSE(projection::ProjectIdealPinhole(params.data(), behind, uv));
  EXPECT_FALSE(projection::ProjectIdealPinhole(params.data(), on_plane, uv));
  EXPECT_FALSE(projection::ProjectRadTan(params.data(), behind, uv));
  EXPECT_EQ(uv[0], -1.0);  // untouched
  const std::array<double, 9> kb = testing::TumViKb8().Params();
  const double straight_back[3] = {0.0, 0.0, -1.0};
  const double origin[3] = {0.0, 0.0, 0.0};
  EXPECT_FALSE(projection::ProjectKannalaBrandt8(kb.data(), straight_back, uv));
  EXPECT_FALSE(projection::ProjectKannalaBrandt8(kb.data(), origin, uv));
  EXPECT_TRUE(projection::ProjectKannalaBrandt8(kb.data(), behind, uv));
}

}  // namespace
}  // namespace pkslam
