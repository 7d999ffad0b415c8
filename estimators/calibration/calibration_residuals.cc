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

// world_from_body block * Exp(d) (BodyPoseManifold's right perturbation).
template <typename T>
SE3<T> PerturbedBodyPose(const double* block, const T* d) {
  const Eigen::Matrix<T, 6, 1> delta(d[0], d[1], d[2], d[3], d[4], d[5]);
  return BodyPoseFromBlock(block).cast<T>() * SE3<T>::Exp(delta);
}

// Exp(d) * block (SE3LeftManifold's left perturbation).
template <typename T>
SE3<T> PerturbedLeftPose(const double* block, const T* d) {
  const Eigen::Matrix<T, 6, 1> delta(d[0], d[1], d[2], d[3], d[4], d[5]);
  return SE3<T>::Exp(delta) * PoseFromBlock(block).cast<T>();
}

// The point in the body frame at the image's IMU time (calibration_bundle.h).
template <typename T>
Vec3T<T> PointInBodyAtImage(const SE3<T>& world_from_body, const Vec3T<T>& p_world,
                            const T& offset, const Vec3T<T>& velocity, const ImageTiming& timing) {
  const T delta = offset - T(timing.offset_applied);
  const Vec3T<T> turn = timing.angular_velocity.cast<T>() * delta;
  const SO3<T> rotation = world_from_body.so3() * SO3<T>::Exp(turn);
  const Vec3T<T> position = world_from_body.translation() + velocity * delta;
  return rotation.Inverse() * (p_world - position);
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

// Blocks of the left residual.
constexpr int kLeftJetSize = 6 + 3 + kCalibIntrinsicsSize + 6 + 1 + 3;
constexpr std::array<BlockLayout, 6> kLeftLayout = {{{0, 6, 7},
                                                     {6, 3, 3},
                                                     {9, kCalibIntrinsicsSize, 6},
                                                     {15, 6, 7},
                                                     {21, 1, 1},
                                                     {22, 3, 3}}};
constexpr int kRightJetSize = 6 + 3 + kCalibIntrinsicsSize + 6 + 6 + 1 + 3;
constexpr std::array<BlockLayout, 7> kRightLayout = {{{0, 6, 7},
                                                      {6, 3, 3},
                                                      {9, kCalibIntrinsicsSize, 6},
                                                      {15, 6, 7},
                                                      {21, 6, 7},
                                                      {27, 1, 1},
                                                      {28, 3, 3}}};

}  // namespace

CalibratedLeftError::CalibratedLeftError(const Eigen::Vector2d& raw,
                                         const Eigen::Matrix2d& whitening,
                                         const FixedDistortion& fixed, const ImageTiming& timing)
    : raw_(raw), whitening_(whitening), fixed_(fixed), timing_(timing) {
  set_num_residuals(2);
  for (const BlockLayout& l : kLeftLayout) mutable_parameter_block_sizes()->push_back(l.ambient);
}

bool CalibratedLeftError::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  using J = ceres::Jet<double, kLeftJetSize>;
  J d_pose[6], point[3], intrinsics[kCalibIntrinsicsSize], d_extrinsic[6], offset[1], velocity[3];
  SeedZero(6, kLeftLayout[0].offset, d_pose);
  Seed(parameters[1], 3, kLeftLayout[1].offset, point);
  Seed(parameters[2], kCalibIntrinsicsSize, kLeftLayout[2].offset, intrinsics);
  SeedZero(6, kLeftLayout[3].offset, d_extrinsic);
  Seed(parameters[4], 1, kLeftLayout[4].offset, offset);
  Seed(parameters[5], 3, kLeftLayout[5].offset, velocity);
  const SE3<J> world_from_body = PerturbedBodyPose(parameters[0], d_pose);
  const SE3<J> cam0_from_body = PerturbedLeftPose(parameters[3], d_extrinsic);
  const Vec3T<J> p_body =
      PointInBodyAtImage(world_from_body, Vec3T<J>(point[0], point[1], point[2]), offset[0],
                         Vec3T<J>(velocity[0], velocity[1], velocity[2]), timing_);
  J uv[2];
  if (!ProjectCalibrated(intrinsics, fixed_, Vec3T<J>(cam0_from_body * p_body), uv)) return false;
  const J e0 = uv[0] - raw_.x();
  const J e1 = uv[1] - raw_.y();
  const J r[2] = {whitening_(0, 0) * e0 + whitening_(0, 1) * e1,
                  whitening_(1, 0) * e0 + whitening_(1, 1) * e1};
  residuals[0] = r[0].a;
  residuals[1] = r[1].a;
  WriteJacobians(r, 2, kLeftLayout, jacobians);
  return true;
}

bool CalibratedLeftError::PixelError(double const* const* parameters,
                                     Eigen::Vector2d* error) const {
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  const SE3d world_from_body = PerturbedBodyPose(parameters[0], zero);
  const SE3d cam0_from_body = PerturbedLeftPose(parameters[3], zero);
  const Eigen::Vector3d p_body = PointInBodyAtImage(
      world_from_body, Eigen::Vector3d(Eigen::Map<const Eigen::Vector3d>(parameters[1])),
      parameters[4][0], Eigen::Vector3d(Eigen::Map<const Eigen::Vector3d>(parameters[5])),
      timing_);
  double uv[2];
  if (!ProjectCalibrated(parameters[2], fixed_, Eigen::Vector3d(cam0_from_body * p_body), uv)) {
    return false;
  }
  *error = Eigen::Vector2d(uv[0], uv[1]) - raw_;
  return true;
}

CalibratedRightError::CalibratedRightError(const Eigen::Vector2d& raw,
                                           const Eigen::RowVector2d& whitening,
                                           const FixedDistortion& fixed,
                                           const ImageTiming& timing)
    : raw_(raw), whitening_(whitening), fixed_(fixed), timing_(timing) {
  set_num_residuals(1);
  for (const BlockLayout& l : kRightLayout) mutable_parameter_block_sizes()->push_back(l.ambient);
}

bool CalibratedRightError::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  using J = ceres::Jet<double, kRightJetSize>;
  J d_pose[6], point[3], intrinsics[kCalibIntrinsicsSize], d_imu[6], d_stereo[6], offset[1],
      velocity[3];
  SeedZero(6, kRightLayout[0].offset, d_pose);
  Seed(parameters[1], 3, kRightLayout[1].offset, point);
  Seed(parameters[2], kCalibIntrinsicsSize, kRightLayout[2].offset, intrinsics);
  SeedZero(6, kRightLayout[3].offset, d_imu);
  SeedZero(6, kRightLayout[4].offset, d_stereo);
  Seed(parameters[5], 1, kRightLayout[5].offset, offset);
  Seed(parameters[6], 3, kRightLayout[6].offset, velocity);
  const SE3<J> world_from_body = PerturbedBodyPose(parameters[0], d_pose);
  const SE3<J> cam0_from_body = PerturbedLeftPose(parameters[3], d_imu);
  const SE3<J> cam1_from_cam0 = PerturbedLeftPose(parameters[4], d_stereo);
  const Vec3T<J> p_body =
      PointInBodyAtImage(world_from_body, Vec3T<J>(point[0], point[1], point[2]), offset[0],
                         Vec3T<J>(velocity[0], velocity[1], velocity[2]), timing_);
  J uv[2];
  if (!ProjectCalibrated(intrinsics, fixed_, Vec3T<J>(cam1_from_cam0 * (cam0_from_body * p_body)),
                         uv)) {
    return false;
  }
  const J r[1] = {whitening_(0) * (uv[0] - raw_.x()) + whitening_(1) * (uv[1] - raw_.y())};
  residuals[0] = r[0].a;
  WriteJacobians(r, 1, kRightLayout, jacobians);
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

ExtrinsicPriorError::ExtrinsicPriorError(const SE3d& mean, double sigma_translation,
                                         double sigma_rotation)
    : mean_inverse_(mean.Inverse()),
      inv_sigma_translation_(1.0 / sigma_translation),
      inv_sigma_rotation_(1.0 / sigma_rotation) {
  set_num_residuals(6);
  mutable_parameter_block_sizes()->push_back(kCalibExtrinsicSize);
}

bool ExtrinsicPriorError::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  using J = ceres::Jet<double, 6>;
  J d[6];
  SeedZero(6, 0, d);
  const Eigen::Matrix<J, 6, 1> log =
      (PerturbedLeftPose(parameters[0], d) * mean_inverse_.cast<J>()).Log();
  J r[6];
  for (int i = 0; i < 6; ++i) {
    r[i] = log[i] * (i < 3 ? inv_sigma_translation_ : inv_sigma_rotation_);
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
