#include "estimators/inertial/marginalization.h"

#include <Eigen/Eigenvalues>

#include "core/util/error.h"

namespace pkslam {
namespace {

// Pseudo-inverse of a symmetric PSD matrix (eigenvalues <= threshold * largest dropped).
Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& m, double relative_threshold) {
  const Eigen::MatrixXd sym = 0.5 * (m + m.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(sym);
  const Eigen::VectorXd& eig = es.eigenvalues();
  const double largest = eig.size() > 0 ? eig.cwiseAbs().maxCoeff() : 0.0;
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(eig.size());
  for (Eigen::Index i = 0; i < eig.size(); ++i) {
    if (eig[i] > relative_threshold * largest && eig[i] > 0) inv[i] = 1.0 / eig[i];
  }
  return es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
}

}  // namespace

void MarginalizeLeading(const Eigen::MatrixXd& information, const Eigen::VectorXd& gradient,
                        int marginalized, Eigen::MatrixXd* kept_information,
                        Eigen::VectorXd* kept_gradient, double relative_threshold) {
  const auto n = information.rows();
  PKSLAM_CHECK(
      information.cols() == n && gradient.size() == n && marginalized >= 0 && marginalized <= n,
      "MarginalizeLeading: sizes {} x {}, gradient {}, marginalised {}", n, information.cols(),
      gradient.size(), marginalized);
  const int m = marginalized;
  const auto k = n - m;
  const Eigen::MatrixXd hmm_inv =
      PseudoInverse(information.topLeftCorner(m, m), relative_threshold);
  const Eigen::MatrixXd hkm_hmm_inv = information.bottomLeftCorner(k, m) * hmm_inv;
  *kept_information =
      information.bottomRightCorner(k, k) - hkm_hmm_inv * information.topRightCorner(m, k);
  *kept_gradient = gradient.tail(k) - hkm_hmm_inv * gradient.head(m);
}

Eigen::MatrixXd ProjectToPsd(const Eigen::MatrixXd& matrix) {
  const Eigen::MatrixXd sym = 0.5 * (matrix + matrix.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(sym);
  return es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() *
         es.eigenvectors().transpose();
}

InertialStatePrior MakeInertialStatePrior(const NavState& state, const ImuBias& bias,
                                          const Eigen::Matrix<double, 15, 15>& information,
                                          const Eigen::Matrix<double, 15, 1>& gradient) {
  InertialStatePrior prior;
  const Eigen::Matrix<double, 15, 15> h = ProjectToPsd(information);
  const Eigen::Matrix<double, 15, 1> delta = -PseudoInverse(h, 1e-12) * gradient;
  const SE3d& pose = state.world_from_body;
  prior.mean.world_from_body =
      SE3d(pose.so3() * SO3d::Exp(delta.segment<3>(3)),
           pose.translation() + pose.so3() * Eigen::Vector3d(delta.segment<3>(0)));
  prior.mean.velocity_world = state.velocity_world + delta.segment<3>(6);
  prior.bias_mean = ImuBias(bias.gyro + delta.segment<3>(9), bias.accel + delta.segment<3>(12));
  prior.information = h;
  return prior;
}

}  // namespace pkslam
