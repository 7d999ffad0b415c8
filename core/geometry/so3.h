// SO(3) as a value type on Eigen, templated on the scalar so Ceres Jets flow through it.
//
// Conventions (shared by SE3 and Sim3):
// - Hamilton unit quaternion storage (Eigen), always normalised by the constructors.
// - Exp/Log map between the group and R^3 (axis * angle); Log returns angles in [-pi, pi].
// - Right Jacobian Jr(w): Exp(w + d) ~= Exp(w) * Exp(Jr(w) d) for small d.
//   Left Jacobian Jl(w) = Jr(-w): Exp(w + d) ~= Exp(Jl(w) d) * Exp(w).
// - Names say which frames a rotation maps: R_world_from_body * p_body = p_world.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>

namespace pkslam {

template <typename Scalar_>
class SO3 {
 public:
  using Scalar = Scalar_;
  using Vec3 = Eigen::Matrix<Scalar, 3, 1>;
  using Mat3 = Eigen::Matrix<Scalar, 3, 3>;
  using Quat = Eigen::Quaternion<Scalar>;
  using Tangent = Vec3;
  static constexpr int kDof = 3;

  SO3() : q_(Quat::Identity()) {}
  // Normalises q (a non-unit quaternion is accepted and projected).
  explicit SO3(const Quat& q) : q_(q.normalized()) {}
  // A quaternion an SO3 gave out (quaternion()), taken back bit for bit: no re-normalisation,
  // which would change the last bits (map files restore poses exactly).
  static SO3 FromStoredQuaternion(const Quat& q) {
    SO3 r;
    r.q_ = q;
    return r;
  }
  // From a rotation matrix; a slightly non-orthonormal matrix is projected (via quaternion).
  explicit SO3(const Mat3& rotation) : q_(Quat(rotation).normalized()) {}

  // The rotation matrix nearest (Frobenius) to an arbitrary 3x3 matrix, via SVD.
  static SO3 FitToMatrix(const Mat3& m) {
    const Eigen::JacobiSVD<Mat3> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Mat3 d = Mat3::Identity();
    d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < Scalar(0) ? Scalar(-1)
                                                                                    : Scalar(1);
    return SO3(Mat3(svd.matrixU() * d * svd.matrixV().transpose()));
  }

  static SO3 Exp(const Vec3& omega) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const Scalar theta_sq = omega.squaredNorm();
    Scalar real;
    Scalar imag_factor;
    if (theta_sq < Scalar(kSmallAngleSq)) {
      // Taylor expansion: avoids sqrt(0) (infinite derivative for Jets).
      real = Scalar(1) - theta_sq / Scalar(8) + theta_sq * theta_sq / Scalar(384);
      imag_factor = Scalar(0.5) - theta_sq / Scalar(48) + theta_sq * theta_sq / Scalar(3840);
    } else {
      const Scalar theta = sqrt(theta_sq);
      const Scalar half = theta / Scalar(2);
      real = cos(half);
      imag_factor = sin(half) / theta;
    }
    SO3 r;
    r.q_ = Quat(real, imag_factor * omega.x(), imag_factor * omega.y(), imag_factor * omega.z());
    return r;
  }

  Vec3 Log() const {
    using std::atan2;
    using std::sqrt;
    const Scalar w = q_.w();
    const Vec3 v = q_.vec();
    const Scalar n_sq = v.squaredNorm();
    if (n_sq < Scalar(kSmallAngleSq)) {
      // 2*atan(n/w)/n ~= 2/w * (1 - n^2/(3w^2)); w is ~ +-1 here.
      return (Scalar(2) / w - Scalar(2) / Scalar(3) * n_sq / (w * w * w)) * v;
    }
    const Scalar n = sqrt(n_sq);
    // q and -q are the same rotation; picking w >= 0 keeps the angle in [-pi, pi].
    const Scalar two_atan = w < Scalar(0) ? Scalar(2) * atan2(-n, -w) : Scalar(2) * atan2(n, w);
    return (two_atan / n) * v;
  }

  static Mat3 Hat(const Vec3& v) {
    Mat3 m;
    m << Scalar(0), -v.z(), v.y(), v.z(), Scalar(0), -v.x(), -v.y(), v.x(), Scalar(0);
    return m;
  }
  static Vec3 Vee(const Mat3& m) { return Vec3(m(2, 1), m(0, 2), m(1, 0)); }

  // Jr(w); used by IMU preintegration and on-manifold optimisation.
  static Mat3 RightJacobian(const Vec3& omega) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const Scalar theta_sq = omega.squaredNorm();
    const Mat3 w = Hat(omega);
    if (theta_sq < Scalar(kSmallAngleSq)) {
      return Mat3::Identity() - Scalar(0.5) * w + (Scalar(1) / Scalar(6)) * w * w;
    }
    const Scalar theta = sqrt(theta_sq);
    return Mat3::Identity() - (Scalar(1) - cos(theta)) / theta_sq * w +
           (theta - sin(theta)) / (theta_sq * theta) * w * w;
  }
  static Mat3 RightJacobianInverse(const Vec3& omega) {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const Scalar theta_sq = omega.squaredNorm();
    const Mat3 w = Hat(omega);
    if (theta_sq < Scalar(kSmallAngleSq)) {
      return Mat3::Identity() + Scalar(0.5) * w + (Scalar(1) / Scalar(12)) * w * w;
    }
    const Scalar theta = sqrt(theta_sq);
    return Mat3::Identity() + Scalar(0.5) * w +
           (Scalar(1) / theta_sq - (Scalar(1) + cos(theta)) / (Scalar(2) * theta * sin(theta))) *
               w * w;
  }
  static Mat3 LeftJacobian(const Vec3& omega) { return RightJacobian(-omega); }
  static Mat3 LeftJacobianInverse(const Vec3& omega) { return RightJacobianInverse(-omega); }

  // a * Exp(t * Log(a^-1 * b)): geodesic from a (t = 0) to b (t = 1).
  static SO3 Interpolate(const SO3& a, const SO3& b, Scalar t) {
    return a * Exp(t * (a.Inverse() * b).Log());
  }

  SO3 Inverse() const {
    SO3 r;
    r.q_ = q_.conjugate();
    return r;
  }
  SO3 operator*(const SO3& other) const {
    SO3 r;
    r.q_ = q_ * other.q_;
    // Products drift off the unit sphere over long chains; renormalise cheaply.
    r.q_.normalize();
    return r;
  }
  SO3& operator*=(const SO3& other) { return *this = *this * other; }
  Vec3 operator*(const Vec3& p) const { return q_ * p; }

  Mat3 Matrix() const { return q_.toRotationMatrix(); }
  const Quat& quaternion() const { return q_; }
  Mat3 Adj() const { return Matrix(); }
  Scalar Angle() const { return Log().norm(); }
  void Normalize() { q_.normalize(); }

  template <typename Other>
  SO3<Other> cast() const {
    return SO3<Other>(q_.template cast<Other>());
  }

 private:
  static constexpr double kSmallAngleSq = 1e-10;
  Quat q_;
};

using SO3d = SO3<double>;
using SO3f = SO3<float>;

}  // namespace pkslam
