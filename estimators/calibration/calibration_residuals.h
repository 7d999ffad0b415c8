// Residuals of the calibration bundle adjustment (calibration_bundle.h): a keypoint's physical
// pixel against its projection through the estimated intrinsics, extrinsics and time offset,
// and the calibration file's priors.
//
// Parameter blocks:
//   body pose        7  world_from_body (imu/imu_manifolds.h BodyPoseManifold: T * Exp(d))
//   point            3  p_world
//   intrinsics       6  fx, fy, cx, cy, k1, k2 (p1, p2, k3 are constants of the residual)
//   cam0_from_body   7  SE3LeftManifold (estimators/optim/se3_manifold.h: Exp(d) * T)
//   cam1_from_cam0   7  SE3LeftManifold
//   time offset      1  seconds (t_imu = t_cam + offset)
//   velocity         3  v_world of the keyframe's body
// The pose and extrinsic blocks follow the "[I6; 0] Jacobian trick" of those manifolds: the
// derivatives with respect to the tangent perturbation go into the first 6 columns, 0 into the
// 7th. The derivatives come from Ceres Jets evaluated at a zero perturbation of every block
// (forward-mode automatic differentiation on the tangent), so no projection Jacobian is written
// by hand.
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <array>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"

namespace pkslam {

inline constexpr int kCalibIntrinsicsSize = 6;
inline constexpr int kCalibExtrinsicSize = 7;

// The radial-tangential parameters not estimated: p1, p2, k3.
using FixedDistortion = std::array<double, 3>;

// The body's motion at an image for the time-offset correction: the image was taken `delta` =
// offset - offset_applied after the keyframe's state time, where the body turned at
// `angular_velocity` (body frame) and moved at the velocity block.
struct ImageTiming {
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  double offset_applied = 0.0;
};

// Left keypoint. Parameters {pose[7], point[3], intrinsics0[6], cam0_from_body[7], offset[1],
// velocity[3]}; residual 2: whitening * (projection - raw).
class CalibratedLeftError final : public ceres::CostFunction {
 public:
  CalibratedLeftError(const Eigen::Vector2d& raw, const Eigen::Matrix2d& whitening,
                      const FixedDistortion& fixed, const ImageTiming& timing);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  // The unwhitened pixel error at `parameters` (false: the point is not in front).
  bool PixelError(double const* const* parameters, Eigen::Vector2d* error) const;

 private:
  Eigen::Vector2d raw_;
  Eigen::Matrix2d whitening_;
  FixedDistortion fixed_;
  ImageTiming timing_;
};

// Right coordinate of a stereo match. Parameters {pose[7], point[3], intrinsics1[6],
// intrinsics0[6], cam0_from_body[7], cam1_from_cam0[7], offset[1], velocity[3]}; residual 1:
// whitening * (projection - raw). Only the right image's column is measured, so cam1's fy and
// cy are not parameters of their own: they follow cam0's, fy1 = fy0 + vertical_offset[0],
// cy1 = cy0 + vertical_offset[1] (the file's differences), which keeps the pair's rows as
// aligned as the file had them while cam0's vertical parameters move (intrinsics1's fy and cy
// entries are not read).
class CalibratedRightError final : public ceres::CostFunction {
 public:
  CalibratedRightError(const Eigen::Vector2d& raw, const Eigen::RowVector2d& whitening,
                       const FixedDistortion& fixed, const ImageTiming& timing,
                       const Eigen::Vector2d& vertical_offset);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::Vector2d raw_;
  Eigen::RowVector2d whitening_;
  FixedDistortion fixed_;
  ImageTiming timing_;
  Eigen::Vector2d vertical_offset_;
};

// (x - mean) / sigma per component. Parameters {block[n]}; residual n.
class EuclideanPriorError final : public ceres::CostFunction {
 public:
  EuclideanPriorError(Eigen::VectorXd mean, Eigen::VectorXd sigma);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  Eigen::VectorXd mean_;
  Eigen::VectorXd inv_sigma_;
};

// Log(T * mean^-1) (translation part, rotation part) divided by per-component sigmas, on an
// SE3LeftManifold block. Parameters {T[7]}; residual 6.
class ExtrinsicPriorError final : public ceres::CostFunction {
 public:
  ExtrinsicPriorError(const SE3d& mean, const Eigen::Matrix<double, 6, 1>& sigma);
  ExtrinsicPriorError(const SE3d& mean, double sigma_translation, double sigma_rotation);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  SE3d mean_inverse_;
  Eigen::Matrix<double, 6, 1> inv_sigma_;
};

// Fills / reads the 6-double intrinsics block of a radial-tangential camera.
std::array<double, kCalibIntrinsicsSize> IntrinsicsBlock(const CameraModel& camera);
FixedDistortion FixedDistortionOf(const CameraModel& camera);
CameraModel CameraFromIntrinsicsBlock(const CameraModel& like, const double* block);

}  // namespace pkslam
