#include "estimators/calibration/calibration_residuals.h"

#include <ceres/jet.h>

#include <utility>

#include "core/camera/projection.h"
#include "estimators/optim/se3_manifold.h"
#include "imu/imu_manifolds.h"

namespace pkslam {
namespace {

// A parameter block's place among the Jet's derivatives: `tangent` columns from `offset`, and
// the block's `ambient` size (a manifold block's extra ambient columns get zeros).
struct BlockLayout {
  int offset;
  int tangent;
  int ambient;
};

// Seeds the derivative part of `n` Jets: jet[i] = value[i] + e_{offset + i}.
template <typename J>
void Seed(const double* value, int n, int offset, J* jet) {
  for (int i = 0; i < n; ++i) jet[i] = J(value[i], offset + i);
}

template <typename J>
void SeedZero(int n, int offset, J* jet) {
  for (int i = 0; i < n; ++i) jet[i] = J(0.0, offset + i);
}

// Row-major Jacobians of residual Jets into Ceres' buffers (skipping constant blocks).
template <typename J, std::size_t K>
void WriteJacobians(const J* residuals, int num_residuals,
                    const std::array<BlockLayout, K>& layout, double** jacobians) {
  if (jacobians == nullptr) return;
  for (std::size_t b = 0; b < K; ++b) {
    if (jacobians[b] == nullptr) continue;
    const BlockLayout& l = layout[b];
    for (int r = 0; r < num_residuals; ++r) {
      double* row = jacobians[b] + static_cast<std::size_t>(r) * l.ambient;
      for (int c = 0; c < l.ambient; ++c) row[c] = c < l.tangent ? residuals[r].v[l.offset + c] : 0;
    }
  }
}

template <typename T>
using Vec3T = Eigen::Matrix<T, 3, 1>;

// Exp(d) * block (SE3LeftManifold's left perturbation).
template <typename T>
SE3<T> PerturbedLeftPose(const double* block, const T* d) {
  const Eigen::Matrix<T, 6, 1> delta(d[0], d[1], d[2], d[3], d[4], d[5]);
  return SE3<T>::Exp(delta) * PoseFromBlock(block).cast<T>();
}

// Full radial-tangential parameters (fx fy cx cy k1 k2 p1 p2 k3) from the estimated six and the
// fixed three.
template <typename T>
std::array<T, 9> RadTanParams(const T* intrinsics, const FixedDistortion& fixed) {
  return {intrinsics[0], intrinsics[1], intrinsics[2], intrinsics[3], intrinsics[4],
          intrinsics[5], T(fixed[0]),   T(fixed[1]),   T(fixed[2])};
}

template <typename T>
bool ProjectCalibrated(const T* intrinsics, const FixedDistortion& fixed, const Vec3T<T>& p_cam,
                       T* uv) {
  const std::array<T, 9> params = RadTanParams(intrinsics, fixed);
  return projection::ProjectRadTan(params.data(), p_cam.data(), uv);
}

// A point in cam0 at the image of a keyframe, and its derivatives with respect to every block's
// tangent (calibration_bundle.h for the model):
//   R_d = Exp(omega * d), d = offset - applied;  q = R^T (X - p - v d);  p_b = R_d^T q;
//   p_c0 = R_cb p_b + t_cb.
// Right perturbations of the body pose (R Exp(phi), p + R rho) give dq = -rho + [q]x phi; the
// left perturbation of cam0_from_body gives dp_c0 = rho_e - [p_c0]x phi_e.
struct CameraPoint {
  Eigen::Vector3d p_c0;
  Eigen::Matrix<double, 3, 6> d_pose;
  Eigen::Matrix3d d_point;
  Eigen::Matrix<double, 3, 6> d_extrinsic;
  Eigen::Vector3d d_offset;
  Eigen::Matrix3d d_velocity;
};

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

void ComputeCameraPoint(double const* const* parameters, int extrinsic_index, int offset_index,
                        int velocity_index, const ImageTiming& timing, bool jacobians,
                        CameraPoint* out) {
  const SE3d world_from_body = BodyPoseFromBlock(parameters[0]);
  const Eigen::Map<const Eigen::Vector3d> x(parameters[1]);
  const SE3d cam0_from_body = PoseFromBlock(parameters[extrinsic_index]);
  const Eigen::Map<const Eigen::Vector3d> v(parameters[velocity_index]);
  const double d = parameters[offset_index][0] - timing.offset_applied;
  const Eigen::Matrix3d r_wb = world_from_body.RotationMatrix();
  const Eigen::Matrix3d r_d = SO3d::Exp(timing.angular_velocity * d).Matrix();
  const Eigen::Vector3d q = r_wb.transpose() * (x - world_from_body.translation() - v * d);
  const Eigen::Vector3d p_b = r_d.transpose() * q;
  const Eigen::Matrix3d r_cb = cam0_from_body.RotationMatrix();
  out->p_c0 = r_cb * p_b + cam0_from_body.translation();
  if (!jacobians) return;
  const Eigen::Matrix3d a = r_cb * r_d.transpose();  // d p_c0 / d q
  out->d_pose.leftCols<3>() = -a;
  out->d_pose.rightCols<3>() = a * Skew(q);
  out->d_point = a * r_wb.transpose();
  out->d_extrinsic.leftCols<3>().setIdentity();
  out->d_extrinsic.rightCols<3>() = -Skew(out->p_c0);
  out->d_offset = r_cb * (-timing.angular_velocity.cross(p_b) - r_d.transpose() * r_wb.transpose() * v);
  out->d_velocity = -d * out->d_point;
}

// Radial-tangential projection of p_cam with the estimated intrinsics, and its derivatives
// (forward-mode Jets: 3 for the point, 6 for the intrinsics).
bool Project(const double* intrinsics, const FixedDistortion& fixed, const Eigen::Vector3d& p_cam,
             bool jacobians, Eigen::Vector2d* uv, Eigen::Matrix<double, 2, 3>* d_point,
             Eigen::Matrix<double, 2, kCalibIntrinsicsSize>* d_intrinsics) {
  if (!jacobians) {
    double out[2];
    if (!ProjectCalibrated(intrinsics, fixed, p_cam, out)) return false;
    *uv = Eigen::Vector2d(out[0], out[1]);
    return true;
  }
  using J = ceres::Jet<double, 3 + kCalibIntrinsicsSize>;
  J k[kCalibIntrinsicsSize];
  Seed(intrinsics, kCalibIntrinsicsSize, 3, k);
  J p[3];
  Seed(p_cam.data(), 3, 0, p);
  J out[2];
  if (!ProjectCalibrated(k, fixed, Vec3T<J>(p[0], p[1], p[2]), out)) return false;
  for (int r = 0; r < 2; ++r) {
    (*uv)[r] = out[r].a;
    for (int c = 0; c < 3; ++c) (*d_point)(r, c) = out[r].v[c];
    for (int c = 0; c < kCalibIntrinsicsSize; ++c) (*d_intrinsics)(r, c) = out[r].v[3 + c];
  }
  return true;
}

// Row-major writes of a residual Jacobian block (tangent columns, zeros in the rest).
template <int R, int C>
void Put(const Eigen::Matrix<double, R, C>& m, int ambient, double* out) {
  if (out == nullptr) return;
  for (int r = 0; r < R; ++r) {
    for (int c = 0; c < ambient; ++c) out[r * ambient + c] = c < C ? m(r, c) : 0.0;
  }
}

constexpr int kLeftBlocks[6] = {7, 3, kCalibIntrinsicsSize, 7, 1, 3};
constexpr int kRightBlocks[8] = {7, 3, kCalibIntrinsicsSize, kCalibIntrinsicsSize, 7, 7, 1, 3};

}  // namespace

CalibratedLeftError::CalibratedLeftError(const Eigen::Vector2d& raw,
                                         const Eigen::Matrix2d& whitening,
                                         const FixedDistortion& fixed, const ImageTiming& timing)
    : raw_(raw), whitening_(whitening), fixed_(fixed), timing_(timing) {
  set_num_residuals(2);
  for (int size : kLeftBlocks) mutable_parameter_block_sizes()->push_back(size);
}

bool CalibratedLeftError::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const bool want = jacobians != nullptr;
  CameraPoint cp;
  ComputeCameraPoint(parameters, 3, 4, 5, timing_, want, &cp);
  Eigen::Vector2d uv;
  Eigen::Matrix<double, 2, 3> d_uv_d_p;
  Eigen::Matrix<double, 2, kCalibIntrinsicsSize> d_uv_d_k;
  if (!Project(parameters[2], fixed_, cp.p_c0, want, &uv, &d_uv_d_p, &d_uv_d_k)) return false;
  Eigen::Map<Eigen::Vector2d> r(residuals);
  r = whitening_ * (uv - raw_);
  if (!want) return true;
  const Eigen::Matrix<double, 2, 3> a = whitening_ * d_uv_d_p;
  Put<2, 6>(a * cp.d_pose, 7, jacobians[0]);
  Put<2, 3>(a * cp.d_point, 3, jacobians[1]);
  Put<2, kCalibIntrinsicsSize>(whitening_ * d_uv_d_k, kCalibIntrinsicsSize, jacobians[2]);
  Put<2, 6>(a * cp.d_extrinsic, 7, jacobians[3]);
  Put<2, 1>(a * cp.d_offset, 1, jacobians[4]);
  Put<2, 3>(a * cp.d_velocity, 3, jacobians[5]);
  return true;
}

bool CalibratedLeftError::PixelError(double const* const* parameters,
                                     Eigen::Vector2d* error) const {
  CameraPoint cp;
  ComputeCameraPoint(parameters, 3, 4, 5, timing_, false, &cp);
  Eigen::Vector2d uv;
  if (!Project(parameters[2], fixed_, cp.p_c0, false, &uv, nullptr, nullptr)) return false;
  *error = uv - raw_;
  return true;
}

CalibratedRightError::CalibratedRightError(const Eigen::Vector2d& raw,
                                           const Eigen::RowVector2d& whitening,
                                           const FixedDistortion& fixed,
                                           const ImageTiming& timing,
                                           const Eigen::Vector2d& vertical_offset)
    : raw_(raw),
      whitening_(whitening),
      fixed_(fixed),
      timing_(timing),
      vertical_offset_(vertical_offset) {
  set_num_residuals(1);
  for (int size : kRightBlocks) mutable_parameter_block_sizes()->push_back(size);
}

bool CalibratedRightError::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  const bool want = jacobians != nullptr;
  CameraPoint cp;
  ComputeCameraPoint(parameters, 4, 6, 7, timing_, want, &cp);
  const SE3d cam1_from_cam0 = PoseFromBlock(parameters[5]);
  const Eigen::Vector3d p_c1 = cam1_from_cam0 * cp.p_c0;
  // cam1's fy and cy follow cam0's (calibration_residuals.h).
  const double intrinsics[kCalibIntrinsicsSize] = {
      parameters[2][0], parameters[3][1] + vertical_offset_[0],
      parameters[2][2], parameters[3][3] + vertical_offset_[1],
      parameters[2][4], parameters[2][5]};
  Eigen::Vector2d uv;
  Eigen::Matrix<double, 2, 3> d_uv_d_p;
  Eigen::Matrix<double, 2, kCalibIntrinsicsSize> d_uv_d_k;
  if (!Project(intrinsics, fixed_, p_c1, want, &uv, &d_uv_d_p, &d_uv_d_k)) return false;
  residuals[0] = whitening_ * (uv - raw_);
  if (!want) return true;
  const Eigen::Matrix<double, 1, 3> a = whitening_ * d_uv_d_p;
  const Eigen::Matrix<double, 1, 3> b = a * cam1_from_cam0.RotationMatrix();  // through p_c0
  const Eigen::Matrix<double, 1, kCalibIntrinsicsSize> k = whitening_ * d_uv_d_k;
  Eigen::Matrix<double, 1, kCalibIntrinsicsSize> k1 = k;
  Eigen::Matrix<double, 1, kCalibIntrinsicsSize> k0 = Eigen::Matrix<double, 1, 6>::Zero();
  for (int c : {1, 3}) {
    k0(c) = k(c);
    k1(c) = 0.0;
  }
  Put<1, 6>(b * cp.d_pose, 7, jacobians[0]);
  Put<1, 3>(b * cp.d_point, 3, jacobians[1]);
  Put<1, kCalibIntrinsicsSize>(k1, kCalibIntrinsicsSize, jacobians[2]);
  Put<1, kCalibIntrinsicsSize>(k0, kCalibIntrinsicsSize, jacobians[3]);
  Put<1, 6>(b * cp.d_extrinsic, 7, jacobians[4]);
  Eigen::Matrix<double, 3, 6> d_stereo;
  d_stereo.leftCols<3>().setIdentity();
  d_stereo.rightCols<3>() = -Skew(p_c1);
  Put<1, 6>(a * d_stereo, 7, jacobians[5]);
  Put<1, 1>(b * cp.d_offset, 1, jacobians[6]);
  Put<1, 3>(b * cp.d_velocity, 3, jacobians[7]);
  return true;
}

EuclideanPriorError::EuclideanPriorError(Eigen::VectorXd mean, Eigen::VectorXd sigma)
    : mean_(std::move(mean)), inv_sigma_(sigma.cwiseInverse()) {
  set_num_residuals(static_cast<int>(mean_.size()));
  mutable_parameter_block_sizes()->push_back(static_cast<int>(mean_.size()));
}

bool EuclideanPriorError::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const int n = static_cast<int>(mean_.size());
  for (int i = 0; i < n; ++i) residuals[i] = (parameters[0][i] - mean_[i]) * inv_sigma_[i];
  if (jacobians != nullptr && jacobians[0] != nullptr) {
    for (int r = 0; r < n; ++r) {
      for (int c = 0; c < n; ++c) jacobians[0][r * n + c] = r == c ? inv_sigma_[r] : 0.0;
    }
  }
  return true;
}

ExtrinsicPriorError::ExtrinsicPriorError(const SE3d& mean, const Eigen::Matrix<double, 6, 1>& sigma)
    : mean_inverse_(mean.Inverse()), inv_sigma_(sigma.cwiseInverse()) {
  set_num_residuals(6);
  mutable_parameter_block_sizes()->push_back(kCalibExtrinsicSize);
}

ExtrinsicPriorError::ExtrinsicPriorError(const SE3d& mean, double sigma_translation,
                                         double sigma_rotation)
    : ExtrinsicPriorError(mean, (Eigen::Matrix<double, 6, 1>() << sigma_translation,
                                 sigma_translation, sigma_translation, sigma_rotation,
                                 sigma_rotation, sigma_rotation)
                                    .finished()) {}

bool ExtrinsicPriorError::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  using J = ceres::Jet<double, 6>;
  J d[6];
  SeedZero(6, 0, d);
  const Eigen::Matrix<J, 6, 1> log =
      (PerturbedLeftPose(parameters[0], d) * mean_inverse_.cast<J>()).Log();
  J r[6];
  for (int i = 0; i < 6; ++i) {
    r[i] = log[i] * inv_sigma_[i];
    residuals[i] = r[i].a;
  }
  WriteJacobians(r, 6, std::array<BlockLayout, 1>{{{0, 6, 7}}}, jacobians);
  return true;
}

std::array<double, kCalibIntrinsicsSize> IntrinsicsBlock(const CameraModel& camera) {
  const std::vector<double>& d = camera.distortion();
  return {camera.fx(), camera.fy(), camera.cx(),
          camera.cy(), d.empty() ? 0.0 : d[0], d.size() < 2 ? 0.0 : d[1]};
}

FixedDistortion FixedDistortionOf(const CameraModel& camera) {
  const std::vector<double>& d = camera.distortion();
  return {d.size() > 2 ? d[2] : 0.0, d.size() > 3 ? d[3] : 0.0, d.size() > 4 ? d[4] : 0.0};
}

CameraModel CameraFromIntrinsicsBlock(const CameraModel& like, const double* block) {
  std::vector<double> distortion = like.distortion();
  if (distortion.empty() && (block[4] != 0.0 || block[5] != 0.0)) distortion.assign(4, 0.0);
  if (!distortion.empty()) {
    distortion[0] = block[4];
    distortion[1] = block[5];
  }
  return CameraModel::Pinhole(like.width(), like.height(), block[0], block[1], block[2], block[3],
                              distortion);
}

}  // namespace pkslam
