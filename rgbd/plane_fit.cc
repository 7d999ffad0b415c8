#include "rgbd/plane_fit.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>

#include "core/util/error.h"

namespace pkslam::rgbd {

PlaneFitMethod ParsePlaneFitMethod(const std::string& name) {
  if (name == "ls") return PlaneFitMethod::kLeastSquares;
  if (name == "pca") return PlaneFitMethod::kPca;
  throw OptionError(fmt::format("unknown plane fit '{}' (ls | pca)", name));
}

const char* PlaneFitMethodName(PlaneFitMethod method) {
  return method == PlaneFitMethod::kLeastSquares ? "ls" : "pca";
}

void PointMoments::Add(const Eigen::Vector3d& p) {
  ++count_;
  sum_ += p;
  sum_outer_.noalias() += p * p.transpose();
}

void PointMoments::Add(const PointMoments& other) {
  count_ += other.count_;
  sum_ += other.sum_;
  sum_outer_ += other.sum_outer_;
}

Eigen::Vector3d PointMoments::Mean() const {
  return count_ > 0 ? Eigen::Vector3d(sum_ / static_cast<double>(count_)) : Eigen::Vector3d::Zero();
}

Eigen::Matrix3d PointMoments::Covariance() const {
  if (count_ == 0) return Eigen::Matrix3d::Zero();
  const double n = static_cast<double>(count_);
  const Eigen::Vector3d mean = sum_ / n;
  return sum_outer_ / n - mean * mean.transpose();
}

std::optional<Plane> PointMoments::Fit(PlaneFitMethod method) const {
  if (count_ < 3) return std::nullopt;
  const Eigen::Vector3d mean = Mean();
  const Eigen::Matrix3d cov = Covariance();
  const double scale = cov.trace();
  if (!(scale > 0)) return std::nullopt;  // all points equal (or zero depth everywhere)
  Eigen::Vector3d normal;
  if (method == PlaneFitMethod::kLeastSquares) {
    // Normal equations of z = A x + B y + C on centred sums: [Sxx Sxy; Sxy Syy] [A B]^T =
    // [Sxz Syz]^T, C = mean_z - A mean_x - B mean_y (identical to Eq. 6's solution).
    const double sxx = cov(0, 0), sxy = cov(0, 1), syy = cov(1, 1);
    const double det = sxx * syy - sxy * sxy;
    if (!(det > 1e-12 * scale * scale)) return std::nullopt;
    const double a = (cov(0, 2) * syy - cov(1, 2) * sxy) / det;
    const double b = (sxx * cov(1, 2) - sxy * cov(0, 2)) / det;
    normal = Eigen::Vector3d(a, b, -1.0).normalized();
  } else {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    const Eigen::Vector3d values = eig.eigenvalues();       // ascending
    if (!(values(1) > 1e-12 * scale)) return std::nullopt;  // collinear
    normal = eig.eigenvectors().col(0);
  }
  if (!normal.allFinite()) return std::nullopt;
  if (normal.dot(mean) > 0) normal = -normal;  // face the camera
  return Plane{normal, normal.dot(mean)};
}

double PointMoments::RmsDistance(const Plane& plane) const {
  if (count_ == 0) return 0;
  // sum (n.p - d)^2 = n^T S n - 2 d n.sum + N d^2, S = sum p p^T.
  const double n = static_cast<double>(count_);
  const double sum_sq = plane.normal.dot(sum_outer_ * plane.normal) -
                        2 * plane.d * plane.normal.dot(sum_) + n * plane.d * plane.d;
  return std::sqrt(std::max(0.0, sum_sq) / n);
}

double NormalAngleDeg(const Plane& a, const Plane& b) {
  const double c = std::min(1.0, std::abs(a.normal.dot(b.normal)));
  return std::acos(c) * 180.0 / M_PI;
}

}  // namespace pkslam::rgbd
