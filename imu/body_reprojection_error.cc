#include "imu/body_reprojection_error.h"

#include <limits>

#include "imu/imu_manifolds.h"

namespace pkslam {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Shared kernel: obs has kRes entries (u, v[, u_right]); jac_pose is kRes x 7 and jac_point
// kRes x 3 (row-major), either may be null.
template <int kRes>
bool EvaluateBodyReprojection(const BodyCamera& cam, const double* obs, double sqrt_info,
                              const double* pose_block, const double* p_world_ptr,
                              double* residuals, double* jac_pose, double* jac_point) {
  const SE3d world_from_body = BodyPoseFromBlock(pose_block);
  const Eigen::Map<const Vec3> p_world(p_world_ptr);
  const Mat3 r_bw = world_from_body.RotationMatrix().transpose();
  const Vec3 p_body = r_bw * (p_world - world_from_body.translation());
  const Mat3 r_cb = cam.camera_from_body.RotationMatrix();
  const Vec3 p_camera = r_cb * p_body + cam.camera_from_body.translation();
  if (!(p_camera.z() > kMinBodyReprojectionDepth)) return false;  // also rejects NaN
  const double inv_z = 1.0 / p_camera.z();
  const double u = cam.fx * p_camera.x() * inv_z + cam.cx;
  const double v = cam.fy * p_camera.y() * inv_z + cam.cy;
  residuals[0] = sqrt_info * (u - obs[0]);
  residuals[1] = sqrt_info * (v - obs[1]);
  if constexpr (kRes == 3) residuals[2] = sqrt_info * (u - cam.bf * inv_z - obs[2]);
  if (jac_pose == nullptr && jac_point == nullptr) return true;

  // Whitened d r / d p_camera.
  const double inv_z2 = inv_z * inv_z;
  Eigen::Matrix<double, kRes, 3> d_camera;
  d_camera(0, 0) = cam.fx * inv_z;
  d_camera(0, 1) = 0.0;
  d_camera(0, 2) = -cam.fx * p_camera.x() * inv_z2;
  d_camera(1, 0) = 0.0;
  d_camera(1, 1) = cam.fy * inv_z;
  d_camera(1, 2) = -cam.fy * p_camera.y() * inv_z2;
  if constexpr (kRes == 3) {
    d_camera(2, 0) = d_camera(0, 0);
    d_camera(2, 1) = 0.0;
    d_camera(2, 2) = d_camera(0, 2) + cam.bf * inv_z2;
  }
  d_camera *= sqrt_info;
  const Eigen::Matrix<double, kRes, 3> d_body = d_camera * r_cb;

  if (jac_pose != nullptr) {
    // world_from_body * Exp(delta): body_from_world <- Exp(-delta) body_from_world, so
    // p_body <- p_body - rho - phi x p_body: d p_body / d delta = [-I3, hat(p_body)].
    Eigen::Map<Eigen::Matrix<double, kRes, 7, Eigen::RowMajor>> j(jac_pose);
    j.template leftCols<3>() = -d_body;
    j.template middleCols<3>(3) = d_body * SO3d::Hat(p_body);
    j.col(6).setZero();
  }
  if (jac_point != nullptr) {
    Eigen::Map<Eigen::Matrix<double, kRes, 3, Eigen::RowMajor>> j(jac_point);
    j = d_body * r_bw;
  }
  return true;
}

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

double BodyMonoChi2(const BodyCamera& camera, const SE3d& world_from_body, const Vec3& p_world,
                    const Eigen::Vector2d& uv, double inv_sigma2) {
  const Vec3 p = camera.camera_from_body * (world_from_body.Inverse() * p_world);
  if (!(p.z() > kMinBodyReprojectionDepth)) return kInfinity;
  const Eigen::Vector2d e(camera.fx * p.x() / p.z() + camera.cx - uv.x(),
                          camera.fy * p.y() / p.z() + camera.cy - uv.y());
  return inv_sigma2 * e.squaredNorm();
}

double BodyStereoChi2(const BodyCamera& camera, const SE3d& world_from_body, const Vec3& p_world,
                      const Vec3& uv_right, double inv_sigma2) {
  const Vec3 p = camera.camera_from_body * (world_from_body.Inverse() * p_world);
  if (!(p.z() > kMinBodyReprojectionDepth)) return kInfinity;
  const double u = camera.fx * p.x() / p.z() + camera.cx;
  const Vec3 e(u - uv_right.x(), camera.fy * p.y() / p.z() + camera.cy - uv_right.y(),
               u - camera.bf / p.z() - uv_right.z());
  return inv_sigma2 * e.squaredNorm();
}

bool BodyMonoReprojectionError::Evaluate(double const* const* parameters, double* residuals,
                                         double** jacobians) const {
  return EvaluateBodyReprojection<2>(camera_, obs_.data(), sqrt_info_, parameters[0], parameters[1],
                                     residuals, jacobians != nullptr ? jacobians[0] : nullptr,
                                     jacobians != nullptr ? jacobians[1] : nullptr);
}

bool BodyStereoReprojectionError::Evaluate(double const* const* parameters, double* residuals,
                                           double** jacobians) const {
  return EvaluateBodyReprojection<3>(camera_, obs_.data(), sqrt_info_, parameters[0], parameters[1],
                                     residuals, jacobians != nullptr ? jacobians[0] : nullptr,
                                     jacobians != nullptr ? jacobians[1] : nullptr);
}

bool BodyMonoPoseOnlyError::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  return EvaluateBodyReprojection<2>(camera_, obs_.data(), sqrt_info_, parameters[0],
                                     p_world_.data(), residuals,
                                     jacobians != nullptr ? jacobians[0] : nullptr, nullptr);
}

bool BodyStereoPoseOnlyError::Evaluate(double const* const* parameters, double* residuals,
                                       double** jacobians) const {
  return EvaluateBodyReprojection<3>(camera_, obs_.data(), sqrt_info_, parameters[0],
                                     p_world_.data(), residuals,
                                     jacobians != nullptr ? jacobians[0] : nullptr, nullptr);
}

}  // namespace pkslam
