// Uniform B-splines over int64 ns time: a Euclidean spline for positions and a cumulative
// B-spline on SO(3) for orientations, with analytic time derivatives (velocity, acceleration,
// body angular velocity and acceleration). Both are C^(order-2) continuous.
//
// Segment i spans [t0 + i*dt, t0 + (i+1)*dt) and blends control points i .. i+order-1.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/geometry/so3.h"

namespace pkslam::sim {

struct KnotGrid {
  std::int64_t t0_ns = 0;
  std::int64_t dt_ns = 0;
  int num_segments = 0;

  std::int64_t end_ns() const { return t0_ns + num_segments * dt_ns; }
  bool Contains(std::int64_t t_ns) const { return t_ns >= t0_ns && t_ns <= end_ns(); }
  double dt_s() const { return 1e-9 * static_cast<double>(dt_ns); }
  // Segment index and local parameter u in [0, 1]; t outside the grid is clamped.
  void Locate(std::int64_t t_ns, int* segment, double* u) const;
  // Smallest grid of knot spacing dt covering [begin, end].
  static KnotGrid Covering(std::int64_t begin_ns, std::int64_t end_ns, std::int64_t dt_ns);
};

// Blending polynomials of the uniform B-spline of `Order` (degree Order-1): the weight of
// control point (segment + j) is sum_n M(j, n) u^n. The cumulative form sums rows j..Order-1.
template <int Order>
class UniformBasis {
 public:
  using Vec = Eigen::Matrix<double, Order, 1>;
  using Mat = Eigen::Matrix<double, Order, Order>;

  UniformBasis();
  // Weights (derivative `d` w.r.t. time, dt in seconds) of the segment's control points.
  Vec Weights(double u, double dt_s, int d, bool cumulative) const;
  const Mat& matrix(bool cumulative) const { return cumulative ? cumulative_ : blend_; }

 private:
  Mat blend_;
  Mat cumulative_;
};

// p(t) = sum_j B_j(u) P_(i+j).
template <int Order>
class PositionSpline {
 public:
  static constexpr int kOrder = Order;
  PositionSpline() = default;
  PositionSpline(KnotGrid grid, std::vector<Eigen::Vector3d> control);

  const KnotGrid& grid() const { return grid_; }
  const std::vector<Eigen::Vector3d>& control() const { return control_; }
  static int NumControl(const KnotGrid& grid) { return grid.num_segments + Order - 1; }

  // Position and (optionally) velocity, acceleration, jerk in world units per second.
  Eigen::Vector3d Evaluate(std::int64_t t_ns, Eigen::Vector3d* velocity = nullptr,
                           Eigen::Vector3d* acceleration = nullptr,
                           Eigen::Vector3d* jerk = nullptr) const;

 private:
  KnotGrid grid_;
  std::vector<Eigen::Vector3d> control_;
  UniformBasis<Order> basis_;
};

// R(t) = R_i * prod_{j=1}^{Order-1} Exp(Bc_j(u) * Log(R_(i+j-1)^-1 R_(i+j))).
template <int Order>
class RotationSpline {
 public:
  static constexpr int kOrder = Order;
  RotationSpline() = default;
  RotationSpline(KnotGrid grid, std::vector<SO3d> control);

  const KnotGrid& grid() const { return grid_; }
  const std::vector<SO3d>& control() const { return control_; }
  static int NumControl(const KnotGrid& grid) { return grid.num_segments + Order - 1; }

  // world_from_body rotation and, optionally, body-frame angular velocity (rad/s) and
  // angular acceleration (rad/s^2).
  SO3d Evaluate(std::int64_t t_ns, Eigen::Vector3d* omega_body = nullptr,
                Eigen::Vector3d* alpha_body = nullptr) const;

  // The rotation of one segment from its Order control rotations and cumulative weights;
  // templated so Ceres Jets flow through it (used by the fit).
  template <typename T>
  static SO3<T> Blend(const SO3<T>* controls, const Eigen::Matrix<double, Order, 1>& weights) {
    SO3<T> r = controls[0];
    for (int j = 1; j < Order; ++j) {
      const Eigen::Matrix<T, 3, 1> d = (controls[j - 1].Inverse() * controls[j]).Log();
      r = r * SO3<T>::Exp(T(weights[j]) * d);
    }
    return r;
  }

 private:
  KnotGrid grid_;
  std::vector<SO3d> control_;
  UniformBasis<Order> basis_;
};

// The orders used by the simulator: quintic positions (acceleration C^2, so a high-order
// integrator of the IMU converges) and cubic rotations (angular velocity C^1).
inline constexpr int kPositionOrder = 6;
inline constexpr int kRotationOrder = 4;
using PositionSpline6 = PositionSpline<kPositionOrder>;
using RotationSpline4 = RotationSpline<kRotationOrder>;

}  // namespace pkslam::sim
