// Sim(3) similarity transform: p_target = s * R * p_source + t (monocular loops, Umeyama).
//
// Tangent ordering is [rho (3); phi (3, rotation); sigma (1, log-scale)].
// Exp builds R = Exp(phi), s = e^sigma, t = W(phi, sigma) * rho with
// W = integral_0^1 e^(sigma u) R(u phi) du, evaluated in closed form or by series.
#pragma once

#include <cmath>

#include "core/geometry/lie_series.h"
#include "core/geometry/se3.h"

namespace pkslam {

template <typename Scalar_>
class Sim3 {
 public:
  using Scalar = Scalar_;
  using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
  using Mat3 = Eigen::Matrix<Scalar, 3, 3>;
  using Mat4 = Eigen::Matrix<Scalar, 4, 4>;
  using Tangent = Eigen::Matrix<Scalar, 7, 1>;
  using Mat7 = Eigen::Matrix<Scalar, 7, 7>;
  static constexpr int kDof = 7;

  Sim3() : scale_(Scalar(1)), translation_(Vec3::Zero()) {}
  Sim3(Scalar scale, const SO3<Scalar>& rotation, const Vec3& translation)
      : scale_(scale), rotation_(rotation), translation_(translation) {}
  explicit Sim3(const SE3<Scalar>& rigid, Scalar scale = Scalar(1))
      : scale_(scale), rotation_(rigid.so3()), translation_(rigid.translation()) {}

  static Sim3 Exp(const Tangent& xi) {
    using std::exp;
    const Vec3 rho = xi.template head<3>();
    const Vec3 phi = xi.template segment<3>(3);
    const Scalar sigma = xi(6);
    return Sim3(exp(sigma), SO3<Scalar>::Exp(phi), W(phi, sigma) * rho);
  }

  Tangent Log() const {
    using std::log;
    const Vec3 phi = rotation_.Log();
    const Scalar sigma = log(scale_);
    Tangent xi;
    xi.template head<3>() = W(phi, sigma).inverse() * translation_;
    xi.template segment<3>(3) = phi;
    xi(6) = sigma;
    return xi;
  }

  static Mat4 Hat(const Tangent& xi) {
    Mat4 m = Mat4::Zero();
    m.template block<3, 3>(0, 0) =
        SO3<Scalar>::Hat(xi.template segment<3>(3)) + xi(6) * Mat3::Identity();
    m.template block<3, 1>(0, 3) = xi.template head<3>();
    return m;
  }

  static Mat7 ad(const Tangent& xi) {
    const Vec3 rho = xi.template head<3>();
    const Mat3 phi_hat = SO3<Scalar>::Hat(xi.template segment<3>(3));
    Mat7 m = Mat7::Zero();
    m.template block<3, 3>(0, 0) = phi_hat + xi(6) * Mat3::Identity();
    m.template block<3, 3>(0, 3) = SO3<Scalar>::Hat(rho);
    m.template block<3, 1>(0, 6) = -rho;
    m.template block<3, 3>(3, 3) = phi_hat;
    return m;
  }

  // T * Exp(x) * T^-1 = Exp(Adj(T) x).
  Mat7 Adj() const {
    const Mat3 r = rotation_.Matrix();
    Mat7 m = Mat7::Zero();
    m.template block<3, 3>(0, 0) = scale_ * r;
    m.template block<3, 3>(0, 3) = SO3<Scalar>::Hat(translation_) * r;
    m.template block<3, 1>(0, 6) = -translation_;
    m.template block<3, 3>(3, 3) = r;
    m(6, 6) = Scalar(1);
    return m;
  }

  static Mat7 RightJacobian(const Tangent& xi) { return lie_series::RightJacobian(Mat7(ad(xi))); }
  static Mat7 RightJacobianInverse(const Tangent& xi) {
    return lie_series::RightJacobian(Mat7(ad(xi))).inverse();
  }

  static Sim3 Interpolate(const Sim3& a, const Sim3& b, Scalar t) {
    return a * Exp(t * (a.Inverse() * b).Log());
  }

  Sim3 Inverse() const {
    const SO3<Scalar> r_inv = rotation_.Inverse();
    const Scalar s_inv = Scalar(1) / scale_;
    return Sim3(s_inv, r_inv, -(s_inv * (r_inv * translation_)));
  }
  Sim3 operator*(const Sim3& o) const {
    return Sim3(scale_ * o.scale_, rotation_ * o.rotation_,
                scale_ * (rotation_ * o.translation_) + translation_);
  }
  Sim3& operator*=(const Sim3& o) { return *this = *this * o; }
  Vec3 operator*(const Vec3& p) const { return scale_ * (rotation_ * p) + translation_; }

  Mat4 Matrix() const {
    Mat4 m = Mat4::Identity();
    m.template block<3, 3>(0, 0) = scale_ * rotation_.Matrix();
    m.template block<3, 1>(0, 3) = translation_;
    return m;
  }

  Scalar scale() const { return scale_; }
  void set_scale(Scalar s) { scale_ = s; }
  const SO3<Scalar>& so3() const { return rotation_; }
  Mat3 RotationMatrix() const { return rotation_.Matrix(); }
  const Vec3& translation() const { return translation_; }
  Vec3& translation() { return translation_; }
  // The rigid part with translation divided by scale: the camera pose a Sim3 correction
  // implies (as ORB-SLAM does when it maps corrected Sim3 poses back to SE3).
  SE3<Scalar> ToSE3ScaledTranslation() const {
    return SE3<Scalar>(rotation_, translation_ / scale_);
  }
  void Normalize() { rotation_.Normalize(); }

  template <typename Other>
  Sim3<Other> cast() const {
    return Sim3<Other>(Other(scale_), rotation_.template cast<Other>(),
                       translation_.template cast<Other>());
  }

  // W(phi, sigma) = integral_0^1 e^(sigma u) Exp(u phi) du (the V-matrix of Sim3).
  static Mat3 W(const Vec3& phi, Scalar sigma) {
    using std::cos;
    using std::exp;
    using std::sin;
    using std::sqrt;
    const Scalar theta_sq = phi.squaredNorm();
    const Mat3 phi_hat = SO3<Scalar>::Hat(phi);
    const Scalar a = Moment(0, sigma);
    Scalar b;  // coefficient of phi_hat
    Scalar c;  // coefficient of phi_hat^2
    if (theta_sq < Scalar(1)) {
      // sin(u t)/t and (1 - cos(u t))/t^2 expanded in t^2; converges fast for t < 1.
      b = Scalar(0);
      c = Scalar(0);
      Scalar t_pow = Scalar(1);
      Scalar fact_odd = Scalar(1);   // (2j+1)!
      Scalar fact_even = Scalar(2);  // (2j+2)!
      for (int j = 0; j < 10; ++j) {
        const Scalar sign = (j % 2 == 0) ? Scalar(1) : Scalar(-1);
        b += sign * t_pow / fact_odd * Moment(2 * j + 1, sigma);
        c += sign * t_pow / fact_even * Moment(2 * j + 2, sigma);
        t_pow *= theta_sq;
        fact_odd *= Scalar((2 * j + 2) * (2 * j + 3));
        fact_even *= Scalar((2 * j + 3) * (2 * j + 4));
      }
    } else {
      const Scalar theta = sqrt(theta_sq);
      const Scalar denom = sigma * sigma + theta_sq;
      const Scalar es = exp(sigma);
      const Scalar int_sin = (es * (sigma * sin(theta) - theta * cos(theta)) + theta) / denom;
      const Scalar int_cos = (es * (sigma * cos(theta) + theta * sin(theta)) - sigma) / denom;
      b = int_sin / theta;
      c = (a - int_cos) / theta_sq;
    }
    return a * Mat3::Identity() + b * phi_hat + c * phi_hat * phi_hat;
  }

 private:
  // m_k(sigma) = integral_0^1 u^k e^(sigma u) du = sum_j sigma^j / (j! (k + j + 1)).
  static Scalar Moment(int k, Scalar sigma) {
    using std::abs;
    Scalar sum = Scalar(0);
    Scalar term = Scalar(1);  // sigma^j / j!
    for (int j = 0; j < 200; ++j) {
      const Scalar contribution = term / Scalar(k + j + 1);
      sum += contribution;
      if (j > 2 && abs(contribution) < Scalar(1e-18) * abs(sum)) break;
      term *= sigma / Scalar(j + 1);
    }
    return sum;
  }

  Scalar scale_;
  SO3<Scalar> rotation_;
  Vec3 translation_;
};

using Sim3d = Sim3<double>;

}  // namespace pkslam
