// Closed-form rigid alignment of corresponding 3-D points (Arun, Huang & Blostein 1987; the
// determinant fix of Umeyama 1991): the rotation R and translation t minimising
// sum_i |target_i - (R source_i + t)|^2.
//
// The cross-covariance H = sum (s_i - s_mean)(t_i - t_mean)^T is decomposed H = U S V^T and
// R = V diag(1, 1, det(V U^T)) U^T: when the plain solution V U^T would be a reflection
// (det = -1; coplanar or very noisy points) V's last column is flipped, so R is always a
// proper rotation.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>

#include "core/geometry/se3.h"

namespace pkslam::rgbd {

// Accumulates correspondence sums so the solution needs no copies of the points (ICP and
// RANSAC add pairs in their own loops). Value type; not thread-safe.
class RigidAlignmentAccumulator {
 public:
  void Add(const Eigen::Vector3d& source, const Eigen::Vector3d& target);
  std::size_t count() const { return count_; }
  // target_from_source; nullopt with fewer than 3 pairs or when the source points are
  // (nearly) collinear or coincident, where the rotation about their line is undetermined.
  std::optional<SE3d> Solve() const;
  // Sum over the pairs of |target - T source|^2 (from the moments; T = Solve() gives the least-
  // squares residual).
  double SumSquaredResiduals(const SE3d& target_from_source) const;

 private:
  std::size_t count_ = 0;
  Eigen::Vector3d sum_source_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_target_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_outer_ = Eigen::Matrix3d::Zero();  // sum source target^T
  double sum_source_sq_ = 0;                             // sum |source|^2
  double sum_target_sq_ = 0;                             // sum |target|^2
};

// target_from_source from equally long point lists (see RigidAlignmentAccumulator::Solve).
std::optional<SE3d> AlignRigid(std::span<const Eigen::Vector3d> source,
                               std::span<const Eigen::Vector3d> target);

// The same over the pairs named by `indices`.
std::optional<SE3d> AlignRigid(std::span<const Eigen::Vector3d> source,
                               std::span<const Eigen::Vector3d> target,
                               std::span<const int> indices);

// Rotation from a cross-covariance H (sum source target^T about the centroids) with the
// reflection fix; exposed for tests.
Eigen::Matrix3d RotationFromCrossCovariance(const Eigen::Matrix3d& h);

}  // namespace pkslam::rgbd
