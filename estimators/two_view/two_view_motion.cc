#include "estimators/two_view/two_view_motion.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

namespace pkslam::two_view {

Eigen::Matrix3d Pinhole::K() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

std::vector<Motion> DecomposeEssential(const Eigen::Matrix3d& e21) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(e21, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  Eigen::Matrix3d w;
  w << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  Eigen::Matrix3d r1 = u * w * v.transpose();
  Eigen::Matrix3d r2 = u * w.transpose() * v.transpose();
  // E is defined up to sign, so U W V^T may be a reflection; its negation is the rotation.
  if (r1.determinant() < 0) r1 = -r1;
  if (r2.determinant() < 0) r2 = -r2;
  const Eigen::Vector3d t = u.col(2).normalized();
  return {Motion{r1, t}, Motion{r2, t}, Motion{r1, -t}, Motion{r2, -t}};
}

std::vector<PlanarMotion> DecomposeHomography(const Eigen::Matrix3d& a21) {
  // a21 = U diag(d1, d2, d3) V^T. With s = det(U) det(V), R' = s U^T R V, t' = U^T t,
  // n' = V^T n and d' = s d, the diagonal satisfies diag(d1, d2, d3) = d' R' + t' n'^T,
  // whose solutions (Faugeras & Lustman 1988) have n' = (x1, 0, x3) and R' a rotation about
  // the y axis (d' = +d2) or a reflection-composed rotation (d' = -d2).
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(a21, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& u = svd.matrixU();
  const Eigen::Matrix3d& v = svd.matrixV();
  const Eigen::Vector3d d = svd.singularValues();
  const double d1 = d(0), d2 = d(1), d3 = d(2);
  // Distinct singular values are required; the ratio test mirrors ORB-SLAM's tolerance.
  constexpr double kMinRatio = 1.00001;
  if (!(d3 > 0) || d1 / d2 < kMinRatio || d2 / d3 < kMinRatio) return {};
  const double s = u.determinant() * v.determinant();

  const double d1s = d1 * d1, d2s = d2 * d2, d3s = d3 * d3;
  const double x1_abs = std::sqrt((d1s - d2s) / (d1s - d3s));
  const double x3_abs = std::sqrt((d2s - d3s) / (d1s - d3s));
  const std::array<double, 4> e1 = {1, 1, -1, -1};
  const std::array<double, 4> e3 = {1, -1, 1, -1};

  std::vector<PlanarMotion> out;
  out.reserve(8);
  const auto emit = [&](const Eigen::Matrix3d& r_prime, const Eigen::Vector3d& t_prime,
                        const Eigen::Vector3d& n_prime) {
    PlanarMotion pm;
    pm.motion.rotation = s * u * r_prime * v.transpose();
    pm.motion.translation = (u * t_prime).normalized();
    pm.normal = v * n_prime;
    if (pm.normal.z() < 0) pm.normal = -pm.normal;
    out.push_back(pm);
  };
  for (int k = 0; k < 4; ++k) {
    const double x1 = e1[k] * x1_abs, x3 = e3[k] * x3_abs;
    const Eigen::Vector3d n_prime(x1, 0, x3);
    {  // d' = +d2: R' rotates about y by theta.
      const double cos_t = (d2s + d1 * d3) / ((d1 + d3) * d2);
      const double sin_t = (d1 - d3) * x1 * x3 / d2;
      Eigen::Matrix3d r_prime;
      r_prime << cos_t, 0, -sin_t, 0, 1, 0, sin_t, 0, cos_t;
      emit(r_prime, (d1 - d3) * Eigen::Vector3d(x1, 0, -x3), n_prime);
    }
    {  // d' = -d2: R' = diag(1, -1, 1)-composed rotation by phi.
      const double cos_p = (d1 * d3 - d2s) / ((d1 - d3) * d2);
      const double sin_p = (d1 + d3) * x1 * x3 / d2;
      Eigen::Matrix3d r_prime;
      r_prime << cos_p, 0, sin_p, 0, -1, 0, sin_p, 0, -cos_p;
      emit(r_prime, (d1 + d3) * Eigen::Vector3d(x1, 0, x3), n_prime);
    }
  }
  return out;
}

Eigen::Vector3d TriangulateLinear(const Eigen::Vector2d& x1, const Eigen::Vector2d& x2,
                                  const Motion& motion) {
  // DLT rows x * P.row(2) - P.row(0) and y * P.row(2) - P.row(1) for P1 = [I|0] and
  // P2 = [R|t], solved with the homogeneous coordinate fixed to 1 (Hartley & Sturm's
  // linear-LS): a 3x3 normal system instead of a 4x4 SVD. Rays that are exactly parallel make
  // the system singular and give a non-finite point, as the SVD's w = 0 would.
  const Eigen::Matrix3d& r = motion.rotation;
  const Eigen::Vector3d& t = motion.translation;
  Eigen::Matrix<double, 4, 3> a;
  Eigen::Vector4d b;
  a.row(0) << -1, 0, x1.x();
  a.row(1) << 0, -1, x1.y();
  a.row(2) = x2.x() * r.row(2) - r.row(0);
  a.row(3) = x2.y() * r.row(2) - r.row(1);
  b << 0, 0, -(x2.x() * t(2) - t(0)), -(x2.y() * t(2) - t(1));
  const Eigen::Matrix3d ata = a.transpose() * a;
  const double det = ata.determinant();
  if (!(std::abs(det) > 1e-18)) {
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return ata.inverse() * (a.transpose() * b);
}

MotionCheck CheckMotion(const Motion& motion, const Correspondences& pixels,
                        const Correspondences& normalized, const std::vector<std::uint8_t>& inliers,
                        const Pinhole& camera1, const Pinhole& camera2,
                        double max_reprojection_error2) {
  const int n = pixels.size();
  MotionCheck out;
  out.points.assign(n, Eigen::Vector3d::Zero());
  out.triangulated.assign(n, 0);
  std::vector<double> cos_parallax;
  cos_parallax.reserve(n);
  const Eigen::Matrix3d& r = motion.rotation;
  const Eigen::Vector3d& t = motion.translation;
  // Centre of camera 2 in camera 1.
  const Eigen::Vector3d center2 = -r.transpose() * t;
  for (int i = 0; i < n; ++i) {
    if (!inliers[i]) continue;
    const Eigen::Vector3d p1 = TriangulateLinear(normalized.first[i], normalized.second[i], motion);
    if (!p1.allFinite()) continue;
    const Eigen::Vector3d ray1 = p1;
    const Eigen::Vector3d ray2 = p1 - center2;
    const double cos_par = ray1.dot(ray2) / (ray1.norm() * ray2.norm());
    const bool has_parallax = cos_par < kTriangulatedCosParallax;
    // Cheirality, only meaningful with parallax.
    if (p1.z() <= 0 && has_parallax) continue;
    const Eigen::Vector3d p2 = r * p1 + t;
    if (p2.z() <= 0 && has_parallax) continue;
    // Written so that a NaN error (zero depth) fails as well.
    const double e1 = (camera1.Project(p1) - pixels.first[i]).squaredNorm();
    if (!(e1 <= max_reprojection_error2)) continue;
    const double e2 = (camera2.Project(p2) - pixels.second[i]).squaredNorm();
    if (!(e2 <= max_reprojection_error2)) continue;
    cos_parallax.push_back(cos_par);
    out.points[i] = p1;
    ++out.num_good;
    if (has_parallax) out.triangulated[i] = 1;
  }
  if (out.num_good > 0) {
    // Ascending cosines = descending angles: rank kParallaxRank from the largest angle.
    const auto rank =
        static_cast<std::ptrdiff_t>(std::min<std::size_t>(kParallaxRank, cos_parallax.size() - 1));
    std::nth_element(cos_parallax.begin(), cos_parallax.begin() + rank, cos_parallax.end());
    const double c = std::clamp(cos_parallax[rank], -1.0, 1.0);
    out.parallax_deg = std::acos(c) * 180.0 / std::numbers::pi;
  }
  return out;
}

}  // namespace pkslam::two_view
