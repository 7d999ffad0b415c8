#include "evaluation/alignment.h"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <cmath>

#include "core/util/error.h"

namespace pkslam {
namespace {

Eigen::Vector3d Mean(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) sum += p;
  return sum / static_cast<double>(points.size());
}

void CheckInputs(const std::vector<Eigen::Vector3d>& est, const std::vector<Eigen::Vector3d>& ref,
                 AlignmentMethod method) {
  PKSLAM_CHECK(est.size() == ref.size(), "alignment needs equally many points ({} vs {})",
               est.size(), ref.size());
  PKSLAM_CHECK(est.size() >= MinimumAlignmentPairs(method),
               "{} alignment needs at least {} point pairs, got {}", AlignmentMethodName(method),
               MinimumAlignmentPairs(method), est.size());
}

}  // namespace

AlignmentMethod ParseAlignmentMethod(std::string_view name) {
  if (name == "none") return AlignmentMethod::kNone;
  if (name == "se3") return AlignmentMethod::kSE3;
  if (name == "sim3") return AlignmentMethod::kSim3;
  if (name == "posyaw") return AlignmentMethod::kPosYaw;
  throw OptionError(fmt::format("unknown alignment '{}' (expected se3|sim3|posyaw|none)", name));
}

std::string_view AlignmentMethodName(AlignmentMethod method) {
  switch (method) {
    case AlignmentMethod::kNone:
      return "none";
    case AlignmentMethod::kSE3:
      return "se3";
    case AlignmentMethod::kSim3:
      return "sim3";
    case AlignmentMethod::kPosYaw:
      return "posyaw";
  }
  return "?";
}

std::size_t MinimumAlignmentPairs(AlignmentMethod method) {
  switch (method) {
    case AlignmentMethod::kNone:
      return 0;
    case AlignmentMethod::kPosYaw:
      return 2;
    case AlignmentMethod::kSE3:
    case AlignmentMethod::kSim3:
      return 3;
  }
  return 3;
}

Sim3d UmeyamaAlignment(const std::vector<Eigen::Vector3d>& est,
                       const std::vector<Eigen::Vector3d>& ref, bool with_scale) {
  CheckInputs(est, ref, with_scale ? AlignmentMethod::kSim3 : AlignmentMethod::kSE3);
  const double n = static_cast<double>(est.size());
  const Eigen::Vector3d mean_est = Mean(est);
  const Eigen::Vector3d mean_ref = Mean(ref);
  // Cross-covariance of the centred point sets and the estimate's variance (Umeyama eq. 36, 38).
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double variance_est = 0.0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    const Eigen::Vector3d e = est[i] - mean_est;
    covariance += (ref[i] - mean_ref) * e.transpose();
    variance_est += e.squaredNorm();
  }
  covariance /= n;
  variance_est /= n;

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance,
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  // The sign fix: when U V^T would be a reflection, flip the weakest singular direction.
  Eigen::Vector3d s_diag = Eigen::Vector3d::Ones();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) s_diag(2) = -1.0;
  const Eigen::Matrix3d rotation = svd.matrixU() * s_diag.asDiagonal() * svd.matrixV().transpose();

  double scale = 1.0;
  if (with_scale) {
    PKSLAM_CHECK(variance_est > 0.0,
                 "sim3 alignment: all estimated positions coincide, the scale is undefined");
    scale = svd.singularValues().dot(s_diag) / variance_est;
  }
  const Eigen::Vector3d translation = mean_ref - scale * rotation * mean_est;
  return Sim3d(scale, SO3d(rotation), translation);
}

Sim3d PositionYawAlignment(const std::vector<Eigen::Vector3d>& est,
                           const std::vector<Eigen::Vector3d>& ref) {
  CheckInputs(est, ref, AlignmentMethod::kPosYaw);
  const Eigen::Vector3d mean_est = Mean(est);
  const Eigen::Vector3d mean_ref = Mean(ref);
  // With centred points, sum_i q_i . Rz(yaw) p_i = cos(yaw) * a + sin(yaw) * b + const, where
  // a = sum (qx px + qy py) and b = sum (qy px - qx py); its maximum is at yaw = atan2(b, a).
  double a = 0.0;
  double b = 0.0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    const Eigen::Vector3d p = est[i] - mean_est;
    const Eigen::Vector3d q = ref[i] - mean_ref;
    a += q.x() * p.x() + q.y() * p.y();
    b += q.y() * p.x() - q.x() * p.y();
  }
  const double yaw = std::atan2(b, a);
  const SO3d rotation = SO3d::Exp(Eigen::Vector3d(0.0, 0.0, yaw));
  return Sim3d(1.0, rotation, mean_ref - rotation * mean_est);
}

Sim3d AlignPositions(const std::vector<Eigen::Vector3d>& est,
                     const std::vector<Eigen::Vector3d>& ref, AlignmentMethod method) {
  CheckInputs(est, ref, method);
  switch (method) {
    case AlignmentMethod::kNone:
      return Sim3d();
    case AlignmentMethod::kSE3:
      return UmeyamaAlignment(est, ref, /*with_scale=*/false);
    case AlignmentMethod::kSim3:
      return UmeyamaAlignment(est, ref, /*with_scale=*/true);
    case AlignmentMethod::kPosYaw:
      return PositionYawAlignment(est, ref);
  }
  throw Error("unknown alignment method");
}

}  // namespace pkslam
