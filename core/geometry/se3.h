// SE(3) rigid transform as a value type: p_target = R * p_source + t.
//
// Tangent ordering is [rho (translation part); phi (rotation part)], as in Sophus.
// Right Jacobian: Exp(x + d) ~= Exp(x) * Exp(Jr(x) d). Name variables by the frames they
// map: SE3d world_from_body; world_from_body * p_body = p_world.
#pragma once

#include "core/geometry/lie_series.h"
#include "core/geometry/so3.h"

namespace pkslam {

template <typename Scalar_>
class SE3 {
 public:
  using Scalar = Scalar_;
  using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
  using Mat3 = Eigen::Matrix<Scalar, 3, 3>;
  using Mat4 = Eigen::Matrix<Scalar, 4, 4>;
  using Mat34 = Eigen::Matrix<Scalar, 3, 4>;
  using Tangent = Eigen::Matrix<Scalar, 6, 1>;
  using Mat6 = Eigen::Matrix<Scalar, 6, 6>;
  using Quat = Eigen::Quaternion<Scalar>;
  static constexpr int kDof = 6;

  SE3() : translation_(Vec3::Zero()) {}
  SE3(const SO3<Scalar>& rotation, const Vec3& translation)
      : rotation_(rotation), translation_(translation) {}
  SE3(const Quat& q, const Vec3& translation) : rotation_(q), translation_(translation) {}
  SE3(const Mat3& r, const Vec3& translation) : rotation_(r), translation_(translation) {}
  // From a homogeneous 4x4 (or its top 3x4) matrix; the rotation block is re-orthonormalised.
  explicit SE3(const Mat4& m) : rotation_(Mat3(m.template block<3, 3>(0, 0))),
                                translation_(m.template block<3, 1>(0, 3)) {}

  static SE3 Exp(const Tangent& xi) {
    const Vec3 rho = xi.template head<3>();
    const Vec3 phi = xi.template tail<3>();
    return SE3(SO3<Scalar>::Exp(phi), SO3<Scalar>::LeftJacobian(phi) * rho);
  }

  Tangent Log() const {
    const Vec3 phi = rotation_.Log();
    Tangent xi;
    xi.template head<3>() = SO3<Scalar>::LeftJacobianInverse(phi) * translation_;
    xi.template tail<3>() = phi;
    return xi;
  }

  // Matrix of the Lie algebra element (4x4 twist matrix).
  static Mat4 Hat(const Tangent& xi) {
    Mat4 m = Mat4::Zero();
    m.template block<3, 3>(0, 0) = SO3<Scalar>::Hat(xi.template tail<3>());
    m.template block<3, 1>(0, 3) = xi.template head<3>();
    return m;
  }

  // Adjoint of the algebra: ad(x) y = [x, y].
  static Mat6 ad(const Tangent& xi) {
    Mat6 m = Mat6::Zero();
    const Mat3 phi_hat = SO3<Scalar>::Hat(xi.template tail<3>());
    m.template block<3, 3>(0, 0) = phi_hat;
    m.template block<3, 3>(0, 3) = SO3<Scalar>::Hat(xi.template head<3>());
    m.template block<3, 3>(3, 3) = phi_hat;
    return m;
  }

  // Adjoint of the group: T * Exp(x) * T^-1 = Exp(Adj(T) x).
  Mat6 Adj() const {
    Mat6 m = Mat6::Zero();
    const Mat3 r = rotation_.Matrix();
    m.template block<3, 3>(0, 0) = r;
    m.template block<3, 3>(0, 3) = SO3<Scalar>::Hat(translation_) * r;
    m.template block<3, 3>(3, 3) = r;
    return m;
  }

  static Mat6 RightJacobian(const Tangent& xi) { return lie_series::RightJacobian(Mat6(ad(xi))); }
  static Mat6 RightJacobianInverse(const Tangent& xi) {
    return lie_series::RightJacobian(Mat6(ad(xi))).inverse();
  }

  // Geodesic interpolation a -> b (t in [0, 1]); rotation and translation move together.
  static SE3 Interpolate(const SE3& a, const SE3& b, Scalar t) {
    return a * Exp(t * (a.Inverse() * b).Log());
  }

  SE3 Inverse() const {
    const SO3<Scalar> r_inv = rotation_.Inverse();
    return SE3(r_inv, -(r_inv * translation_));
  }
  SE3 operator*(const SE3& o) const {
    return SE3(rotation_ * o.rotation_, rotation_ * o.translation_ + translation_);
  }
  SE3& operator*=(const SE3& o) { return *this = *this * o; }
  Vec3 operator*(const Vec3& p) const { return rotation_ * p + translation_; }

  Mat4 Matrix() const {
    Mat4 m = Mat4::Identity();
    m.template block<3, 3>(0, 0) = rotation_.Matrix();
    m.template block<3, 1>(0, 3) = translation_;
    return m;
  }
  Mat34 Matrix3x4() const { return Matrix().template topRows<3>(); }

  const SO3<Scalar>& so3() const { return rotation_; }
  SO3<Scalar>& so3() { return rotation_; }
  Mat3 RotationMatrix() const { return rotation_.Matrix(); }
  const Quat& quaternion() const { return rotation_.quaternion(); }
  const Vec3& translation() const { return translation_; }
  Vec3& translation() { return translation_; }
  void Normalize() { rotation_.Normalize(); }

  template <typename Other>
  SE3<Other> cast() const {
    return SE3<Other>(rotation_.template cast<Other>(), translation_.template cast<Other>());
  }

 private:
  SO3<Scalar> rotation_;
  Vec3 translation_;
};

using SE3d = SE3<double>;
using SE3f = SE3<float>;

}  // namespace pkslam
