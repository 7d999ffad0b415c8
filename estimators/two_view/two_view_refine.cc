#include "estimators/two_view/two_view_refine.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "core/geometry/so3.h"

namespace pkslam::two_view {

namespace {

// Orthonormal basis of the plane orthogonal to t.
Eigen::Matrix<double, 3, 2> TangentBasis(const Eigen::Vector3d& t) {
  const Eigen::Vector3d helper =
      std::abs(t.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d b1 = t.cross(helper).normalized();
  const Eigen::Vector3d b2 = t.cross(b1).normalized();
  Eigen::Matrix<double, 3, 2> basis;
  basis << b1, b2;
  return basis;
}

Motion Apply(const Motion& m, const Eigen::Matrix<double, 5, 1>& delta) {
  const Eigen::Matrix<double, 3, 2> basis = TangentBasis(m.translation);
  Motion out;
  out.rotation = SO3d::Exp(delta.head<3>()).Matrix() * m.rotation;
  out.translation = (m.translation + basis * delta.tail<2>()).normalized();
  return out;
}

double Cost(const Motion& m, const Correspondences& c, const std::vector<std::uint8_t>& mask) {
  const Eigen::Matrix3d e = SO3d::Hat(m.translation) * m.rotation;
  double cost = 0;
  for (int i = 0; i < c.size(); ++i) {
    if (!mask[i]) continue;
    const double r = SampsonError(e, c.first[i], c.second[i]);
    cost += r * r;
  }
  return cost;
}

}  // namespace

double SampsonError(const Eigen::Matrix3d& e21, const Eigen::Vector2d& x1,
                    const Eigen::Vector2d& x2) {
  const Eigen::Vector3d q1 = x1.homogeneous(), q2 = x2.homogeneous();
  const Eigen::Vector3d l2 = e21 * q1, l1 = e21.transpose() * q2;
  return q2.dot(l2) / std::sqrt(l2.head<2>().squaredNorm() + l1.head<2>().squaredNorm() + 1e-30);
}

std::vector<std::uint8_t> SampsonInliers(const Motion& motion, const Correspondences& normalized,
                                         double max_error) {
  const Eigen::Matrix3d e = SO3d::Hat(motion.translation) * motion.rotation;
  std::vector<std::uint8_t> mask(normalized.size(), 0);
  for (int i = 0; i < normalized.size(); ++i) {
    mask[i] = std::abs(SampsonError(e, normalized.first[i], normalized.second[i])) <= max_error;
  }
  return mask;
}

MotionRefinement RefineMotion(const Motion& initial, const Correspondences& normalized,
                              const std::vector<std::uint8_t>& mask, int max_iterations) {
  MotionRefinement out;
  out.motion = initial;
  int count = 0;
  for (std::uint8_t m : mask) count += m;
  double cost = Cost(initial, normalized, mask);
  out.initial_rms = out.final_rms = count > 0 ? std::sqrt(cost / count) : 0;
  if (count < 5) return out;

  double lambda = 1e-4;
  for (int it = 0; it < max_iterations; ++it) {
    // Gauss-Newton normal equations at the current motion for the perturbation
    // [rotation (left increment); translation direction (tangent basis)]. The residual's
    // numerator x2^T [t]x R x1 is differentiated exactly; its Sampson normaliser is held at
    // the current value (it varies slowly), while the step is accepted on the exact cost.
    const Eigen::Matrix<double, 3, 2> basis = TangentBasis(out.motion.translation);
    const Eigen::Matrix3d e = SO3d::Hat(out.motion.translation) * out.motion.rotation;
    Eigen::Matrix<double, 5, 5> jtj = Eigen::Matrix<double, 5, 5>::Zero();
    Eigen::Matrix<double, 5, 1> jtr = Eigen::Matrix<double, 5, 1>::Zero();
    Eigen::Matrix<double, 5, 1> jac;
    for (int i = 0; i < normalized.size(); ++i) {
      if (!mask[i]) continue;
      const Eigen::Vector3d q1 = normalized.first[i].homogeneous();
      const Eigen::Vector3d q2 = normalized.second[i].homogeneous();
      const Eigen::Vector3d l2 = e * q1, l1 = e.transpose() * q2;
      const double norm2 = l2.head<2>().squaredNorm() + l1.head<2>().squaredNorm();
      if (!(norm2 > 1e-30)) continue;
      const double inv_norm = 1.0 / std::sqrt(norm2);
      const double r = q2.dot(l2) * inv_norm;
      const Eigen::Vector3d rq1 = out.motion.rotation * q1;
      // d/dw x2^T [t]x Exp(w) R x1 = (R x1) x (x2 x t); d/dt along B a: B^T ((R x1) x x2).
      jac.head<3>() = rq1.cross(q2.cross(out.motion.translation)) * inv_norm;
      jac.tail<2>() = basis.transpose() * rq1.cross(q2) * inv_norm;
      jtj.noalias() += jac * jac.transpose();
      jtr.noalias() += r * jac;
    }
    // Levenberg-Marquardt: raise the damping until a step lowers the cost.
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::Matrix<double, 5, 5> a = jtj;
      a.diagonal() *= 1.0 + lambda;
      const Eigen::Matrix<double, 5, 1> step = a.ldlt().solve(-jtr);
      if (!step.allFinite()) break;
      const Motion candidate = Apply(out.motion, step);
      const double candidate_cost = Cost(candidate, normalized, mask);
      if (candidate_cost < cost) {
        improved = true;
        const double decrease = (cost - candidate_cost) / cost;
        out.motion = candidate;
        cost = candidate_cost;
        lambda = std::max(lambda * 0.1, 1e-10);
        ++out.iterations;
        if (decrease < 1e-10) it = max_iterations;  // converged
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  out.final_rms = std::sqrt(cost / count);
  return out;
}

}  // namespace pkslam::two_view
