// Series forms shared by SE3 and Sim3 (whose closed-form Jacobians are long and easy to get
// wrong): Jr(x) = sum_n (-ad_x)^n / (n+1)!. The series is entire; for the magnitudes met in
// SLAM (rotation angle <= pi, bounded log-scale) ~30 terms reach double precision. Not used
// in per-feature hot paths.
#pragma once

#include <cmath>

#include <Eigen/Core>

namespace pkslam::lie_series {

template <typename Derived>
typename Derived::PlainObject RightJacobian(const Eigen::MatrixBase<Derived>& ad) {
  using Mat = typename Derived::PlainObject;
  using Scalar = typename Derived::Scalar;
  using std::abs;
  Mat sum = Mat::Identity();
  Mat term = Mat::Identity();
  const Mat minus_ad = -ad;
  for (int n = 1; n < 80; ++n) {
    term = (term * minus_ad) / Scalar(n + 1);
    sum += term;
    if (term.cwiseAbs().maxCoeff() < Scalar(1e-18)) break;
  }
  return sum;
}

}  // namespace pkslam::lie_series
