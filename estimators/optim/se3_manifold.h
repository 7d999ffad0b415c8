// SE(3) pose parameter blocks for Ceres: 7 doubles (qx, qy, qz, qw, tx, ty, tz) holding a
// camera_from_world transform, and a ceres::Manifold that updates them by a LEFT perturbation
//   Plus(T, delta) = Exp(delta) * T,   delta = [rho; phi]  (core/geometry/se3.h tangent order).
//
// The "[I6; 0] Jacobian trick" (read this before writing a cost function on a pose block):
// Ceres never uses a cost function's 7-column ambient Jacobian J_ambient on its own; it only
// ever forms the tangent Jacobian J_tangent = J_ambient * PlusJacobian(x) (a k x 6 matrix), and
// PlusJacobian is used for nothing else. Instead of the true d Plus(x, delta) / d delta at
// delta = 0 (a 7 x 6 matrix through the quaternion), SE3LeftManifold::PlusJacobian returns the
// constant [I6; 0]. Cost functions on a pose block (estimators/optim/reprojection_error.h) then put
// the analytic derivative of the residual w.r.t. delta in the first 6 columns of their ambient
// Jacobian and zeros in the 7th, so that J_ambient * [I6; 0] is exactly d r(Exp(delta) T) /
// d delta at delta = 0: no quaternion chain rule, no 7x4 matrices, cheap analytic Jacobians.
// The price: a pose block with this manifold only works with cost functions that follow the
// convention (an AutoDiffCostFunction on the raw 7 numbers would be silently wrong), and
// ceres's own manifold invariant checks (manifold_test_utils.h) do not apply because
// PlusJacobian is not the derivative of Plus in ambient coordinates. MinusJacobian is [I6 0]
// for the same reason, so MinusJacobian * PlusJacobian = I as Ceres expects.
#pragma once

#include <ceres/manifold.h>

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/geometry/se3.h"

namespace pkslam {

inline constexpr int kPoseBlockSize = 7;

// Fills / reads a 7-double pose block (qx, qy, qz, qw, tx, ty, tz).
void PoseToBlock(const SE3d& camera_from_world, double* block);
SE3d PoseFromBlock(const double* block);

class SE3LeftManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseBlockSize; }
  int TangentSize() const override { return 6; }
  // x_plus_delta = Exp(delta) * x.
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  // The constant [I6; 0] (7 x 6, row-major): see the file comment.
  bool PlusJacobian(const double* x, double* jacobian) const override;
  // tangent_matrix = the first 6 columns of ambient_matrix (num_rows x 7 -> num_rows x 6).
  bool RightMultiplyByPlusJacobian(const double* x, int num_rows, const double* ambient_matrix,
                                   double* tangent_matrix) const override;
  // y_minus_x = Log(y * x^-1), so that Minus(Plus(x, d), x) = d.
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  // The constant [I6 0] (6 x 7, row-major).
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

// SE3LeftManifold with some tangent axes held: Plus(T, d) = Exp(E d) * T, where E (6 x k) picks
// the free axes of [rho; phi]. Holding a block's axes exactly this way, rather than by a prior
// a thousand times tighter, keeps the Jacobian's columns of one scale: Ceres' covariance (sparse
// QR, whose rank tolerance grows with the largest column) found the calibration adjustment's
// Jacobian rank-deficient on every machine-hall replay with such a prior in it. With rho held, a
// block X = parent_from_child only turns (Exp(phi) X), and the translation of its inverse, the
// parent's origin in the child frame (for cam0_from_body, the camera's position in the body),
// stays exactly where it is. The same [I6; 0] convention as SE3LeftManifold.
class SE3LeftSubsetManifold final : public ceres::Manifold {
 public:
  // held[i]: tangent axis i of [rho; phi] does not move. At least one axis must stay free.
  explicit SE3LeftSubsetManifold(const std::array<bool, 6>& held);

  int AmbientSize() const override { return kPoseBlockSize; }
  int TangentSize() const override { return static_cast<int>(free_.size()); }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool RightMultiplyByPlusJacobian(const double* x, int num_rows, const double* ambient_matrix,
                                   double* tangent_matrix) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

  // The 6 x k matrix E mapping the free tangent to the full [rho; phi].
  Eigen::MatrixXd Expansion() const;

 private:
  std::vector<int> free_;  // indices of the free axes, ascending
};

}  // namespace pkslam
