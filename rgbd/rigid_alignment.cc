#include "rgbd/rigid_alignment.h"

#include <Eigen/SVD>
#include <algorithm>

#include "core/util/error.h"

namespace pkslam::rgbd {

void RigidAlignmentAccumulator::Add(const Eigen::Vector3d& source, const Eigen::Vector3d& target) {
  ++count_;
  sum_source_ += source;
  sum_target_ += target;
  sum_outer_.noalias() += source * target.transpose();
  sum_source_sq_ += source.squaredNorm();
  sum_target_sq_ += target.squaredNorm();
}

double RigidAlignmentAccumulator::SumSquaredResiduals(const SE3d& target_from_source) const {
  // sum |t_i - R s_i - c|^2 expanded: with u_i = R s_i + c,
  // sum |t|^2 + sum |u|^2 - 2 sum t.u, where sum |u|^2 = sum |s|^2 + 2 c.R sum s + n |c|^2 and
  // sum t.u = trace(R sum s t^T) + c . sum t.
  const Eigen::Matrix3d r = target_from_source.RotationMatrix();
  const Eigen::Vector3d& c = target_from_source.translation();
  const double n = static_cast<double>(count_);
  const double sum_u2 = sum_source_sq_ + 2 * c.dot(r * sum_source_) + n * c.squaredNorm();
  const double sum_tu = (r * sum_outer_).trace() + c.dot(sum_target_);
  return std::max(0.0, sum_target_sq_ + sum_u2 - 2 * sum_tu);
}

Eigen::Matrix3d RotationFromCrossCovariance(const Eigen::Matrix3d& h) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d v = svd.matrixV();
  const Eigen::Matrix3d& u = svd.matrixU();
  // A reflection: flip the axis of the smallest singular value (Arun's fix).
  if ((v * u.transpose()).determinant() < 0) v.col(2) = -v.col(2);
  return v * u.transpose();
}

std::optional<SE3d> RigidAlignmentAccumulator::Solve() const {
  if (count_ < 3) return std::nullopt;
  const double n = static_cast<double>(count_);
  const Eigen::Vector3d mean_source = sum_source_ / n;
  const Eigen::Vector3d mean_target = sum_target_ / n;
  const Eigen::Matrix3d h = sum_outer_ - n * mean_source * mean_target.transpose();
  // Collinear or coincident sources leave a rotation undetermined: the second singular value
  // of the source scatter vanishes. H's singular values bound it from below only when the
  // targets are spread too, so test H directly (both clouds must be spread).
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h);
  const Eigen::Vector3d s = svd.singularValues();
  if (!(s(0) > 0) || s(1) <= 1e-9 * s(0)) return std::nullopt;
  const Eigen::Matrix3d r = RotationFromCrossCovariance(h);
  if (!r.allFinite()) return std::nullopt;
  return SE3d(r, mean_target - r * mean_source);
}

std::optional<SE3d> AlignRigid(std::span<const Eigen::Vector3d> source,
                               std::span<const Eigen::Vector3d> target) {
  PKSLAM_CHECK(source.size() == target.size(), "{} source vs {} target points", source.size(),
               target.size());
  RigidAlignmentAccumulator acc;
  for (std::size_t i = 0; i < source.size(); ++i) acc.Add(source[i], target[i]);
  return acc.Solve();
}

std::optional<SE3d> AlignRigid(std::span<const Eigen::Vector3d> source,
                               std::span<const Eigen::Vector3d> target,
                               std::span<const int> indices) {
  PKSLAM_CHECK(source.size() == target.size(), "{} source vs {} target points", source.size(),
               target.size());
  RigidAlignmentAccumulator acc;
  for (const int i : indices) {
    PKSLAM_CHECK(i >= 0 && static_cast<std::size_t>(i) < source.size(), "index {} of {}", i,
                 source.size());
    acc.Add(source[i], target[i]);
  }
  return acc.Solve();
}

}  // namespace pkslam::rgbd
