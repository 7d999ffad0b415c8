#include "estimators/optim/reprojection_error.h"

#include <Eigen/Geometry>
#include <limits>

namespace pkslam {
namespace {

// Shared kernel of the four cost functions. obs has kRes entries (u, v[, u_right]);
// jac_pose is kRes x 7 and jac_point kRes x 3 (row-major, Ceres layout), either may be null.
// sqrt_info_disparity > 0: the third residual is on the disparity (RGB-D, see the header).
template <int kRes>
bool EvaluateReprojection(const PinholeIntrinsics& k, const double* obs, double sqrt_info,
                          double sqrt_info_disparity, const double* pose, const double* p_world_ptr,
                          double* residuals, double* jac_pose, double* jac_point) {
  // The block stores (qx, qy, qz, qw), Eigen's coefficient order.
  const Eigen::Map<const Eigen::Quaterniond> q(pose);
  const Eigen::Map<const Eigen::Vector3d> t(pose + 4);
  const Eigen::Map<const Eigen::Vector3d> p_world(p_world_ptr);
  const Eigen::Matrix3d r = q.toRotationMatrix();
  const Eigen::Vector3d p_camera = r * p_world + t;
  // Also rejects NaN.
  if (!(p_camera.z() > kMinReprojectionDepth)) return false;
  const double inv_z = 1.0 / p_camera.z();
  const double u = k.fx * p_camera.x() * inv_z + k.cx;
  const double v = k.fy * p_camera.y() * inv_z + k.cy;
  residuals[0] = sqrt_info * (u - obs[0]);
  residuals[1] = sqrt_info * (v - obs[1]);
  const bool disparity = kRes == 3 && sqrt_info_disparity > 0.0;
  if constexpr (kRes == 3) {
    residuals[2] = disparity ? sqrt_info_disparity * (k.bf * inv_z - (obs[0] - obs[2]))
                             : sqrt_info * (u - k.bf * inv_z - obs[2]);
  }
  if (jac_pose == nullptr && jac_point == nullptr) return true;

  // Whitened d r / d p_camera.
  const double inv_z2 = inv_z * inv_z;
  Eigen::Matrix<double, kRes, 3> d_camera;
  d_camera(0, 0) = k.fx * inv_z;
  d_camera(0, 1) = 0.0;
  d_camera(0, 2) = -k.fx * p_camera.x() * inv_z2;
  d_camera(1, 0) = 0.0;
  d_camera(1, 1) = k.fy * inv_z;
  d_camera(1, 2) = -k.fy * p_camera.y() * inv_z2;
  if constexpr (kRes == 3) {
    d_camera(2, 0) = disparity ? 0.0 : d_camera(0, 0);
    d_camera(2, 1) = 0.0;
    d_camera(2, 2) = disparity ? -k.bf * inv_z2 : d_camera(0, 2) + k.bf * inv_z2;
  }
  d_camera.template topRows<2>() *= sqrt_info;
  if constexpr (kRes == 3) d_camera.row(2) *= disparity ? sqrt_info_disparity : sqrt_info;

  if (jac_pose != nullptr) {
    // Exp(delta) * p_camera ~= p_camera + rho + phi x p_camera, so
    // d p_camera / d delta = [I3, -hat(p_camera)]; column 6 is the [I6; 0] padding.
    Eigen::Map<Eigen::Matrix<double, kRes, 7, Eigen::RowMajor>> j(jac_pose);
    j.template leftCols<3>() = d_camera;
    j.template middleCols<3>(3) = -d_camera * SO3d::Hat(p_camera);
    j.col(6).setZero();
  }
  if (jac_point != nullptr) {
    Eigen::Map<Eigen::Matrix<double, kRes, 3, Eigen::RowMajor>> j(jac_point);
    j = d_camera * r;
  }
  return true;
}

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

double MonoChi2(const PinholeIntrinsics& k, const SE3d& camera_from_world,
                const Eigen::Vector3d& p_world, const Eigen::Vector2d& uv, double inv_sigma2) {
  const Eigen::Vector3d p = camera_from_world * p_world;
  if (!(p.z() > kMinReprojectionDepth)) return kInfinity;
  const double inv_z = 1.0 / p.z();
  const Eigen::Vector2d e(k.fx * p.x() * inv_z + k.cx - uv.x(),
                          k.fy * p.y() * inv_z + k.cy - uv.y());
  return inv_sigma2 * e.squaredNorm();
}

double StereoChi2(const PinholeIntrinsics& k, const SE3d& camera_from_world,
                  const Eigen::Vector3d& p_world, const Eigen::Vector3d& uv_right,
                  double inv_sigma2, double disparity_inv_sigma2) {
  const Eigen::Vector3d p = camera_from_world * p_world;
  if (!(p.z() > kMinReprojectionDepth)) return kInfinity;
  const double inv_z = 1.0 / p.z();
  const double u = k.fx * p.x() * inv_z + k.cx;
  const Eigen::Vector3d e(u - uv_right.x(), k.fy * p.y() * inv_z + k.cy - uv_right.y(),
                          u - k.bf * inv_z - uv_right.z());
  if (disparity_inv_sigma2 > 0.0) {
    const double ed = k.bf * inv_z - (uv_right.x() - uv_right.z());
    return inv_sigma2 * e.head<2>().squaredNorm() + disparity_inv_sigma2 * ed * ed;
  }
  return inv_sigma2 * e.squaredNorm();
}

bool MonoReprojectionError::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  return EvaluateReprojection<2>(k_, obs_.data(), sqrt_info_, 0.0, parameters[0], parameters[1],
                                 residuals, jacobians ? jacobians[0] : nullptr,
                                 jacobians ? jacobians[1] : nullptr);
}

bool StereoReprojectionError::Evaluate(double const* const* parameters, double* residuals,
                                       double** jacobians) const {
  return EvaluateReprojection<3>(k_, obs_.data(), sqrt_info_, sqrt_info_disparity_, parameters[0],
                                 parameters[1], residuals, jacobians ? jacobians[0] : nullptr,
                                 jacobians ? jacobians[1] : nullptr);
}

bool MonoPoseOnlyError::Evaluate(double const* const* parameters, double* residuals,
                                 double** jacobians) const {
  return EvaluateReprojection<2>(k_, obs_.data(), sqrt_info_, 0.0, parameters[0], p_world_.data(),
                                 residuals, jacobians ? jacobians[0] : nullptr, nullptr);
}

bool StereoPoseOnlyError::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  return EvaluateReprojection<3>(k_, obs_.data(), sqrt_info_, sqrt_info_disparity_, parameters[0],
                                 p_world_.data(), residuals, jacobians ? jacobians[0] : nullptr,
                                 nullptr);
}

}  // namespace pkslam
