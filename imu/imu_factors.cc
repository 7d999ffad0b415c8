#include "imu/imu_factors.h"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "core/util/error.h"
#include "imu/imu_manifolds.h"
#include "imu/preintegration.h"

namespace pkslam {
namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;
template <int C>
using RowMajorJacobian = Eigen::Matrix<double, 9, C, Eigen::RowMajor>;

// The deltas, Jacobians, bias and covariance of pim, without the (possibly long) step list.
PreintegratedImu WithoutSteps(const PreintegratedImu& pim) {
  PreintegratedImu p;
  p.dt = pim.dt;
  p.delta_R = pim.delta_R;
  p.delta_v = pim.delta_v;
  p.delta_p = pim.delta_p;
  p.J_R_bg = pim.J_R_bg;
  p.J_v_bg = pim.J_v_bg;
  p.J_v_ba = pim.J_v_ba;
  p.J_p_bg = pim.J_p_bg;
  p.J_p_ba = pim.J_p_ba;
  p.covariance = pim.covariance;
  p.bias = pim.bias;
  p.noise = pim.noise;
  p.average_accel = pim.average_accel;
  p.average_gyro = pim.average_gyro;
  return p;
}

// Rotation residual r_R = Log(dR(b)^T R_i^T R_j) and its derivative w.r.t. the gyro bias.
struct RotationResidual {
  Vec3 r;
  Mat3 jr_inv;  // Jr^-1(r)
  Mat3 d_bg;    // d r / d b_g
};

RotationResidual EvaluateRotation(const PreintegratedImu& pim, const Vec3& bias_gyro,
                                  const SO3d& r_i, const SO3d& r_j, bool jacobians) {
  const Vec3 dbg = bias_gyro - pim.bias.gyro;
  const Vec3 corr = pim.J_R_bg * dbg;
  const SO3d e = (pim.delta_R * SO3d::Exp(corr)).Inverse() * r_i.Inverse() * r_j;
  RotationResidual out;
  out.r = e.Log();
  if (jacobians) {
    out.jr_inv = SO3d::RightJacobianInverse(out.r);
    // dR(b + d) = dR(b) Exp(Jr(corr) J_R_bg d): the error rotation gains Exp(-x) on the left,
    // i.e. Exp(-e^T x) on the right.
    out.d_bg = -out.jr_inv * e.Matrix().transpose() * SO3d::RightJacobian(corr) * pim.J_R_bg;
  }
  return out;
}

// Stores a fixed-size expression into Ceres's row-major output array.
template <typename M, typename Expr>
void Write(double* out, const Expr& value) {
  Eigen::Map<M> m(out);
  m = value;
}

// W^T W = information (PSD; negative eigenvalues from round-off are clipped to zero).
template <int N>
Eigen::Matrix<double, N, N> SqrtOfInformation(const Eigen::Matrix<double, N, N>& information) {
  const Eigen::Matrix<double, N, N> sym = 0.5 * (information + information.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> es(sym);
  const Eigen::Matrix<double, N, 1> sqrt_eig = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return sqrt_eig.asDiagonal() * es.eigenvectors().transpose();
}

// The inertial edge's residual and Jacobians for a preintegration `pim` (InertialError and, with
// deltas shifted by the IMU's axis errors, ImuAxesInertialError).
bool EvaluateInertialEdge(const PreintegratedImu& pim_, const Vec3& gravity_world_,
                          const Mat9& sqrt_info_, double const* const* parameters,
                          double* residuals, double** jacobians) {
  const SE3d pose_i = BodyPoseFromBlock(parameters[0]);
  const Eigen::Map<const Vec3> v_i(parameters[1]);
  const Eigen::Map<const Vec3> bg(parameters[2]);
  const Eigen::Map<const Vec3> ba(parameters[3]);
  const SE3d pose_j = BodyPoseFromBlock(parameters[4]);
  const Eigen::Map<const Vec3> v_j(parameters[5]);
  const ImuBias bias(bg, ba);
  const double dt = pim_.dt;

  const Mat3 rt_i = pose_i.RotationMatrix().transpose();
  const Mat3 r_j = pose_j.RotationMatrix();
  const Vec3 u_v = v_j - v_i - gravity_world_ * dt;
  const Vec3 u_p =
      pose_j.translation() - pose_i.translation() - v_i * dt - 0.5 * gravity_world_ * dt * dt;
  const RotationResidual rot =
      EvaluateRotation(pim_, bg, pose_i.so3(), pose_j.so3(), jacobians != nullptr);
  Vec9 r;
  r.segment<3>(0) = rot.r;
  r.segment<3>(3) = rt_i * u_v - DeltaVelocity(pim_, bias);
  r.segment<3>(6) = rt_i * u_p - DeltaPosition(pim_, bias);
  Write<Vec9>(residuals, sqrt_info_ * r);
  if (jacobians == nullptr) return true;

  if (jacobians[0] != nullptr) {  // pose_i: [rho_i, phi_i, pad]
    RowMajorJacobian<7> j = RowMajorJacobian<7>::Zero();
    j.block<3, 3>(6, 0) = -Mat3::Identity();
    j.block<3, 3>(0, 3) = -rot.jr_inv * r_j.transpose() * rt_i.transpose();
    j.block<3, 3>(3, 3) = SO3d::Hat(rt_i * u_v);
    j.block<3, 3>(6, 3) = SO3d::Hat(rt_i * u_p);
    Write<RowMajorJacobian<7>>(jacobians[0], sqrt_info_ * j);
  }
  if (jacobians[1] != nullptr) {  // v_i
    RowMajorJacobian<3> j = RowMajorJacobian<3>::Zero();
    j.block<3, 3>(3, 0) = -rt_i;
    j.block<3, 3>(6, 0) = -rt_i * dt;
    Write<RowMajorJacobian<3>>(jacobians[1], sqrt_info_ * j);
  }
  if (jacobians[2] != nullptr) {  // bias_gyro_i
    RowMajorJacobian<3> j;
    j.block<3, 3>(0, 0) = rot.d_bg;
    j.block<3, 3>(3, 0) = -pim_.J_v_bg;
    j.block<3, 3>(6, 0) = -pim_.J_p_bg;
    Write<RowMajorJacobian<3>>(jacobians[2], sqrt_info_ * j);
  }
  if (jacobians[3] != nullptr) {  // bias_accel_i
    RowMajorJacobian<3> j = RowMajorJacobian<3>::Zero();
    j.block<3, 3>(3, 0) = -pim_.J_v_ba;
    j.block<3, 3>(6, 0) = -pim_.J_p_ba;
    Write<RowMajorJacobian<3>>(jacobians[3], sqrt_info_ * j);
  }
  if (jacobians[4] != nullptr) {  // pose_j: [rho_j, phi_j, pad]
    RowMajorJacobian<7> j = RowMajorJacobian<7>::Zero();
    j.block<3, 3>(6, 0) = rt_i * r_j;
    j.block<3, 3>(0, 3) = rot.jr_inv;
    Write<RowMajorJacobian<7>>(jacobians[4], sqrt_info_ * j);
  }
  if (jacobians[5] != nullptr) {  // v_j
    RowMajorJacobian<3> j = RowMajorJacobian<3>::Zero();
    j.block<3, 3>(3, 0) = rt_i;
    Write<RowMajorJacobian<3>>(jacobians[5], sqrt_info_ * j);
  }
  return true;
}

}  // namespace

Eigen::Matrix<double, 9, 1> InertialResidual(const PreintegratedImu& pim, const Vec3& gravity_world,
                                             const NavState& state_i, const ImuBias& bias_i,
                                             const NavState& state_j) {
  const SO3d& r_i = state_i.world_from_body.so3();
  const double dt = pim.dt;
  const Vec3 u_v = state_j.velocity_world - state_i.velocity_world - gravity_world * dt;
  const Vec3 u_p = state_j.world_from_body.translation() - state_i.world_from_body.translation() -
                   state_i.velocity_world * dt - 0.5 * gravity_world * dt * dt;
  Vec9 r;
  r.segment<3>(0) = EvaluateRotation(pim, bias_i.gyro, r_i, state_j.world_from_body.so3(), false).r;
  r.segment<3>(3) = r_i.Inverse() * u_v - DeltaVelocity(pim, bias_i);
  r.segment<3>(6) = r_i.Inverse() * u_p - DeltaPosition(pim, bias_i);
  return r;
}

InertialError::InertialError(const PreintegratedImu& pim, const Vec3& gravity_world)
    : pim_(WithoutSteps(pim)),
      gravity_world_(gravity_world),
      sqrt_info_(PreintegrationSqrtInformation(pim)) {
  PKSLAM_CHECK(pim.dt > 0, "inertial edge over an empty preintegration");
}

bool InertialError::Evaluate(double const* const* parameters, double* residuals,
                             double** jacobians) const {
  return EvaluateInertialEdge(pim_, gravity_world_, sqrt_info_, parameters, residuals, jacobians);
}

ImuAxesInertialError::ImuAxesInertialError(const PreintegratedImu& pim, const Vec3& gravity_world,
                                           const GyroScaleJacobians& gyro,
                                           const AccelAxesJacobians& accel,
                                           const Vec3& integrated_gyro_scale,
                                           const Mat3& integrated_accel_axes)
    : pim_(WithoutSteps(pim)),
      gravity_world_(gravity_world),
      sqrt_info_(PreintegrationSqrtInformation(pim)),
      gyro_(gyro),
      accel_(accel),
      inv_integrated_(Vec3::Ones().cwiseQuotient(Vec3::Ones() + integrated_gyro_scale)),
      integrated_scale_(integrated_gyro_scale),
      integrated_axes_(Eigen::Map<const Eigen::Matrix<double, 9, 1>>(
          Eigen::Matrix<double, 3, 3, Eigen::RowMajor>(integrated_accel_axes).data())) {
  PKSLAM_CHECK(pim.dt > 0, "inertial edge over an empty preintegration");
  PKSLAM_CHECK(
      integrated_gyro_scale.allFinite() && integrated_gyro_scale.cwiseAbs().maxCoeff() < 0.5,
      "gyro scale error ({}, {}, {}) out of range", integrated_gyro_scale.x(),
      integrated_gyro_scale.y(), integrated_gyro_scale.z());
  PKSLAM_CHECK(
      integrated_accel_axes.allFinite() && integrated_accel_axes.cwiseAbs().maxCoeff() < 0.5,
      "accelerometer axis errors out of range (largest {})",
      integrated_accel_axes.cwiseAbs().maxCoeff());
  const Mat3 inv = (Mat3::Identity() + integrated_accel_axes).inverse();
  axes_to_corrected_.setZero();
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) {
      axes_to_corrected_.block<3, 3>(3 * r, 3 * k) = inv(r, k) * Mat3::Identity();
    }
  }
}

bool ImuAxesInertialError::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  // The steps were corrected with integrated_scale_: the change to 1 / (1 + k) is, to first
  // order, a scale change dk = (k - k_integrated) / (1 + k_integrated) of the corrected rates.
  // Likewise the accelerometer's: dE' = (I + E_integrated)^-1 (E - E_integrated).
  const Eigen::Map<const Vec3> k(parameters[6]);
  const Eigen::Map<const Eigen::Matrix<double, 9, 1>> e(parameters[7]);
  const Vec3 dk = (k - integrated_scale_).cwiseProduct(inv_integrated_);
  const Eigen::Matrix<double, 9, 1> de = axes_to_corrected_ * (e - integrated_axes_);
  const Vec3 psi = gyro_.rotation * dk;
  PreintegratedImu shifted = pim_;
  shifted.delta_R = pim_.delta_R * SO3d::Exp(psi);
  shifted.delta_v = pim_.delta_v + gyro_.velocity * dk + accel_.velocity * de;
  shifted.delta_p = pim_.delta_p + gyro_.position * dk + accel_.position * de;
  if (!EvaluateInertialEdge(shifted, gravity_world_, sqrt_info_, parameters, residuals,
                            jacobians)) {
    return false;
  }
  if (jacobians == nullptr) return true;
  if (jacobians[6] != nullptr) {
    const Eigen::Map<const Vec3> bg(parameters[2]);
    const SO3d r_i = BodyPoseFromBlock(parameters[0]).so3();
    const SO3d r_j = BodyPoseFromBlock(parameters[4]).so3();
    const RotationResidual rot = EvaluateRotation(shifted, bg, r_i, r_j, true);
    // r_R = Log(B^T Exp(-psi) dR^T R_i^T R_j) with B the bias correction: a change of psi
    // enters as Exp(-B^T Jr(psi) d psi) on the left of the error rotation.
    const Mat3 b = SO3d::Exp(shifted.J_R_bg * (bg - shifted.bias.gyro)).Matrix();
    const Mat3 d_psi = -rot.jr_inv * SO3d::Exp(rot.r).Matrix().transpose() * b.transpose() *
                       SO3d::RightJacobian(psi);
    RowMajorJacobian<3> j;
    j.block<3, 3>(0, 0) = d_psi * gyro_.rotation;
    j.block<3, 3>(3, 0) = -gyro_.velocity;
    j.block<3, 3>(6, 0) = -gyro_.position;
    j = j * inv_integrated_.asDiagonal();
    Write<RowMajorJacobian<3>>(jacobians[6], sqrt_info_ * j);
  }
  if (jacobians[7] != nullptr) {
    RowMajorJacobian<9> j = RowMajorJacobian<9>::Zero();
    j.block<3, 9>(3, 0) = -accel_.velocity * axes_to_corrected_;
    j.block<3, 9>(6, 0) = -accel_.position * axes_to_corrected_;
    Write<RowMajorJacobian<9>>(jacobians[7], sqrt_info_ * j);
  }
  return true;
}

BiasRandomWalkError::BiasRandomWalkError(const Mat3& covariance)
    : sqrt_info_(SqrtInformation<3>(covariance)) {}

std::unique_ptr<BiasRandomWalkError> BiasRandomWalkError::Gyro(const PreintegratedImu& pim) {
  return std::make_unique<BiasRandomWalkError>(pim.covariance.block<3, 3>(9, 9));
}

std::unique_ptr<BiasRandomWalkError> BiasRandomWalkError::Accel(const PreintegratedImu& pim) {
  return std::make_unique<BiasRandomWalkError>(pim.covariance.block<3, 3>(12, 12));
}

bool BiasRandomWalkError::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const Eigen::Map<const Vec3> b_i(parameters[0]);
  const Eigen::Map<const Vec3> b_j(parameters[1]);
  Write<Vec3>(residuals, sqrt_info_ * (b_j - b_i));
  using J = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  if (jacobians != nullptr && jacobians[0] != nullptr) Write<J>(jacobians[0], -sqrt_info_);
  if (jacobians != nullptr && jacobians[1] != nullptr) Write<J>(jacobians[1], sqrt_info_);
  return true;
}

InertialGravityScaleError::InertialGravityScaleError(const PreintegratedImu& pim,
                                                     const SE3d& world_from_body_i,
                                                     const SE3d& world_from_body_j,
                                                     double gravity_magnitude)
    : pim_(WithoutSteps(pim)),
      world_from_body_i_(world_from_body_i),
      world_from_body_j_(world_from_body_j),
      gravity_magnitude_(gravity_magnitude),
      sqrt_info_(PreintegrationSqrtInformation(pim)) {
  PKSLAM_CHECK(pim.dt > 0, "inertial edge over an empty preintegration");
}

bool InertialGravityScaleError::Evaluate(double const* const* parameters, double* residuals,
                                         double** jacobians) const {
  const Eigen::Map<const Vec3> v_i(parameters[0]);
  const Eigen::Map<const Vec3> v_j(parameters[1]);
  const Eigen::Map<const Vec3> bg(parameters[2]);
  const Eigen::Map<const Vec3> ba(parameters[3]);
  const SO3d world_from_gravity = GravityRotationFromBlock(parameters[4]);
  const double s = std::exp(parameters[5][0]);
  const ImuBias bias(bg, ba);
  const double dt = pim_.dt;

  const Vec3 g_gravity(0, 0, -gravity_magnitude_);
  const Vec3 g = world_from_gravity * g_gravity;
  const Mat3 rt_i = world_from_body_i_.RotationMatrix().transpose();
  const Vec3 dv_world = v_j - v_i;
  const Vec3 dp_world =
      world_from_body_j_.translation() - world_from_body_i_.translation() - v_i * dt;
  const RotationResidual rot = EvaluateRotation(pim_, bg, world_from_body_i_.so3(),
                                                world_from_body_j_.so3(), jacobians != nullptr);
  Vec9 r;
  r.segment<3>(0) = rot.r;
  r.segment<3>(3) = rt_i * (s * dv_world - g * dt) - DeltaVelocity(pim_, bias);
  r.segment<3>(6) = rt_i * (s * dp_world - 0.5 * g * dt * dt) - DeltaPosition(pim_, bias);
  Write<Vec9>(residuals, sqrt_info_ * r);
  if (jacobians == nullptr) return true;

  if (jacobians[0] != nullptr) {  // v_i
    RowMajorJacobian<3> j = RowMajorJacobian<3>::Zero();
    j.block<3, 3>(3, 0) = -s * rt_i;
    j.block<3, 3>(6, 0) = -s * dt * rt_i;
    Write<RowMajorJacobian<3>>(jacobians[0], sqrt_info_ * j);
  }
  if (jacobians[1] != nullptr) {  // v_j
    RowMajorJacobian<3> j = RowMajorJacobian<3>::Zero();
    j.block<3, 3>(3, 0) = s * rt_i;
    Write<RowMajorJacobian<3>>(jacobians[1], sqrt_info_ * j);
  }
  if (jacobians[2] != nullptr) {  // bias_gyro
    RowMajorJacobian<3> j;
    j.block<3, 3>(0, 0) = rot.d_bg;
    j.block<3, 3>(3, 0) = -pim_.J_v_bg;
    j.block<3, 3>(6, 0) = -pim_.J_p_bg;
    Write<RowMajorJacobian<3>>(jacobians[2], sqrt_info_ * j);
  }
  if (jacobians[3] != nullptr) {  // bias_accel
    RowMajorJacobian<3> j = RowMajorJacobian<3>::Zero();
    j.block<3, 3>(3, 0) = -pim_.J_v_ba;
    j.block<3, 3>(6, 0) = -pim_.J_p_ba;
    Write<RowMajorJacobian<3>>(jacobians[3], sqrt_info_ * j);
  }
  if (jacobians[4] != nullptr) {  // R_wg: g(delta) ~= g - R_wg hat(g_gravity) delta
    const Eigen::Matrix<double, 3, 2> dg_ddelta =
        -(world_from_gravity.Matrix() * SO3d::Hat(g_gravity)).leftCols<2>();
    RowMajorJacobian<4> j = RowMajorJacobian<4>::Zero();
    j.block<3, 2>(3, 0) = -rt_i * dg_ddelta * dt;
    j.block<3, 2>(6, 0) = -0.5 * rt_i * dg_ddelta * dt * dt;
    Write<RowMajorJacobian<4>>(jacobians[4], sqrt_info_ * j);
  }
  if (jacobians[5] != nullptr) {  // log_scale: d s / d log_scale = s
    Vec9 j = Vec9::Zero();
    j.segment<3>(3) = s * rt_i * dv_world;
    j.segment<3>(6) = s * rt_i * dp_world;
    Write<Vec9>(jacobians[5], sqrt_info_ * j);
  }
  return true;
}

BiasPriorError::BiasPriorError(const Vec3& prior, double information)
    : prior_(prior), sqrt_info_(Mat3::Identity() * std::sqrt(information)) {
  PKSLAM_CHECK(information >= 0, "negative prior information {}", information);
}

bool BiasPriorError::Evaluate(double const* const* parameters, double* residuals,
                              double** jacobians) const {
  const Eigen::Map<const Vec3> b(parameters[0]);
  Write<Vec3>(residuals, sqrt_info_ * (b - prior_));
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    Write<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(jacobians[0], sqrt_info_);
  }
  return true;
}

InertialStatePriorError::InertialStatePriorError(const NavState& prior_state,
                                                 const ImuBias& prior_bias,
                                                 const Eigen::Matrix<double, 15, 15>& information)
    : prior_state_(prior_state),
      prior_bias_(prior_bias),
      sqrt_info_(SqrtOfInformation<15>(information)) {}

InertialStatePriorError::InertialStatePriorError(
    const NavState& prior_state, const ImuBias& prior_bias,
    const Eigen::Matrix<double, 15, 15>& sqrt_information, SqrtInformation)
    : prior_state_(prior_state), prior_bias_(prior_bias), sqrt_info_(sqrt_information) {}

bool InertialStatePriorError::Evaluate(double const* const* parameters, double* residuals,
                                       double** jacobians) const {
  const SE3d pose = BodyPoseFromBlock(parameters[0]);
  const Eigen::Map<const Vec3> v(parameters[1]);
  const Eigen::Map<const Vec3> bg(parameters[2]);
  const Eigen::Map<const Vec3> ba(parameters[3]);
  const SE3d& pose0 = prior_state_.world_from_body;
  const Mat3 r0t = pose0.RotationMatrix().transpose();
  const Vec3 r_rot = (pose0.so3().Inverse() * pose.so3()).Log();
  Eigen::Matrix<double, 15, 1> r;
  r.segment<3>(0) = r0t * (pose.translation() - pose0.translation());
  r.segment<3>(3) = r_rot;
  r.segment<3>(6) = v - prior_state_.velocity_world;
  r.segment<3>(9) = bg - prior_bias_.gyro;
  r.segment<3>(12) = ba - prior_bias_.accel;
  Write<Eigen::Matrix<double, 15, 1>>(residuals, sqrt_info_ * r);
  if (jacobians == nullptr) return true;
  using J15x7 = Eigen::Matrix<double, 15, 7, Eigen::RowMajor>;
  using J15x3 = Eigen::Matrix<double, 15, 3, Eigen::RowMajor>;
  if (jacobians[0] != nullptr) {  // p <- p + R rho, R <- R Exp(phi)
    J15x7 j = J15x7::Zero();
    j.block<3, 3>(0, 0) = r0t * pose.RotationMatrix();
    j.block<3, 3>(3, 3) = SO3d::RightJacobianInverse(r_rot);
    Write<J15x7>(jacobians[0], sqrt_info_ * j);
  }
  for (int k = 1; k <= 3; ++k) {
    if (jacobians[k] == nullptr) continue;
    // Column block k of the identity rows 3 + 3k .. 5 + 3k.
    Write<J15x3>(jacobians[k], sqrt_info_.middleCols<3>(3 + 3 * k));
  }
  return true;
}

}  // namespace pkslam
