#include "sim/bspline.h"

#include <Eigen/Dense>
#include <cmath>

#include "core/util/error.h"

namespace pkslam::sim {

void KnotGrid::Locate(std::int64_t t_ns, int* segment, double* u) const {
  const std::int64_t rel = t_ns - t0_ns;
  std::int64_t seg = rel >= 0 ? rel / dt_ns : -1;
  if (seg < 0) {
    *segment = 0;
    *u = 0.0;
    return;
  }
  if (seg >= num_segments) {
    *segment = num_segments - 1;
    *u = rel >= num_segments * dt_ns ? 1.0 : static_cast<double>(rel - seg * dt_ns) / dt_ns;
    return;
  }
  *segment = static_cast<int>(seg);
  *u = static_cast<double>(rel - seg * dt_ns) / static_cast<double>(dt_ns);
}

KnotGrid KnotGrid::Covering(std::int64_t begin_ns, std::int64_t end_ns, std::int64_t dt_ns) {
  PKSLAM_CHECK(dt_ns > 0 && end_ns > begin_ns, "bad knot grid [{}, {}] dt {}", begin_ns, end_ns,
               dt_ns);
  KnotGrid grid;
  grid.t0_ns = begin_ns;
  grid.dt_ns = dt_ns;
  grid.num_segments = static_cast<int>((end_ns - begin_ns + dt_ns - 1) / dt_ns);
  return grid;
}

namespace {

// Cardinal B-spline of order k on integer knots, supported on [0, k).
double Cardinal(int k, double x) {
  if (k == 1) return (x >= 0.0 && x < 1.0) ? 1.0 : 0.0;
  return (x * Cardinal(k - 1, x) + (k - x) * Cardinal(k - 1, x - 1.0)) / (k - 1);
}

}  // namespace

template <int Order>
UniformBasis<Order>::UniformBasis() {
  // Fit each blending polynomial through Order samples of the cardinal spline (exact: the
  // blending function is a polynomial of degree Order-1 on the segment).
  Mat vandermonde;
  Mat values;
  for (int s = 0; s < Order; ++s) {
    const double u = (s + 0.5) / Order;
    for (int n = 0; n < Order; ++n) vandermonde(s, n) = std::pow(u, n);
    for (int j = 0; j < Order; ++j) values(s, j) = Cardinal(Order, u + Order - 1 - j);
  }
  const Mat coeffs = vandermonde.fullPivLu().solve(values);  // coeffs(n, j)
  blend_ = coeffs.transpose();
  for (int j = 0; j < Order; ++j) {
    cumulative_.row(j) = blend_.bottomRows(Order - j).colwise().sum();
  }
}

template <int Order>
typename UniformBasis<Order>::Vec UniformBasis<Order>::Weights(double u, double dt_s, int d,
                                                               bool cumulative) const {
  Vec powers = Vec::Zero();
  // d^d/du^d of u^n = n!/(n-d)! u^(n-d); then chain rule (du/dt)^d.
  double scale = 1.0;
  for (int k = 0; k < d; ++k) scale /= dt_s;
  for (int n = d; n < Order; ++n) {
    double falling = 1.0;
    for (int k = 0; k < d; ++k) falling *= (n - k);
    powers[n] = falling * std::pow(u, n - d) * scale;
  }
  return matrix(cumulative) * powers;
}

template <int Order>
PositionSpline<Order>::PositionSpline(KnotGrid grid, std::vector<Eigen::Vector3d> control)
    : grid_(grid), control_(std::move(control)) {
  PKSLAM_CHECK(grid_.num_segments > 0 && static_cast<int>(control_.size()) == NumControl(grid_),
               "position spline: {} control points for {} segments", control_.size(),
               grid_.num_segments);
}

template <int Order>
Eigen::Vector3d PositionSpline<Order>::Evaluate(std::int64_t t_ns, Eigen::Vector3d* velocity,
                                                Eigen::Vector3d* acceleration,
                                                Eigen::Vector3d* jerk) const {
  int seg = 0;
  double u = 0.0;
  grid_.Locate(t_ns, &seg, &u);
  const double dt = grid_.dt_s();
  auto blend = [&](int d) {
    const auto w = basis_.Weights(u, dt, d, false);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int j = 0; j < Order; ++j) sum += w[j] * control_[seg + j];
    return sum;
  };
  if (velocity) *velocity = blend(1);
  if (acceleration) *acceleration = blend(2);
  if (jerk) *jerk = blend(3);
  return blend(0);
}

template <int Order>
RotationSpline<Order>::RotationSpline(KnotGrid grid, std::vector<SO3d> control)
    : grid_(grid), control_(std::move(control)) {
  PKSLAM_CHECK(grid_.num_segments > 0 && static_cast<int>(control_.size()) == NumControl(grid_),
               "rotation spline: {} control points for {} segments", control_.size(),
               grid_.num_segments);
}

template <int Order>
SO3d RotationSpline<Order>::Evaluate(std::int64_t t_ns, Eigen::Vector3d* omega_body,
                                     Eigen::Vector3d* alpha_body) const {
  int seg = 0;
  double u = 0.0;
  grid_.Locate(t_ns, &seg, &u);
  const double dt = grid_.dt_s();
  const auto w0 = basis_.Weights(u, dt, 0, true);
  const auto w1 = basis_.Weights(u, dt, 1, true);
  const auto w2 = basis_.Weights(u, dt, 2, true);
  SO3d r = control_[seg];
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
  Eigen::Vector3d alpha = Eigen::Vector3d::Zero();
  for (int j = 1; j < Order; ++j) {
    const Eigen::Vector3d d = (control_[seg + j - 1].Inverse() * control_[seg + j]).Log();
    const SO3d a = SO3d::Exp(w0[j] * d);
    const SO3d a_inv = a.Inverse();
    r = r * a;
    // R_j = R_(j-1) A_j: body rates transform by A_j^-1 and gain the new term's rate.
    const Eigen::Vector3d omega_rot = a_inv * omega;
    alpha = a_inv * alpha + omega_rot.cross(w1[j] * d) + w2[j] * d;
    omega = omega_rot + w1[j] * d;
  }
  if (omega_body) *omega_body = omega;
  if (alpha_body) *alpha_body = alpha;
  return r;
}

template class UniformBasis<4>;
template class UniformBasis<6>;
template class PositionSpline<4>;
template class PositionSpline<6>;
template class RotationSpline<4>;
template class RotationSpline<6>;

}  // namespace pkslam::sim
