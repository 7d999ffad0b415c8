#include "sim/spline_fit.h"

#include <ceres/ceres.h>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numbers>

#include "core/util/error.h"

namespace pkslam::sim {
namespace {

constexpr int kPos = kPositionOrder;
constexpr int kRot = kRotationOrder;

void CheckSamples(std::size_t n_times, std::size_t n_values, const KnotGrid& grid,
                  int num_control) {
  PKSLAM_CHECK(n_times == n_values, "{} times but {} samples", n_times, n_values);
  PKSLAM_CHECK(static_cast<int>(n_times) >= num_control,
               "{} samples cannot determine {} control points (grid {} segments)", n_times,
               num_control, grid.num_segments);
}

double SampleRate(const std::vector<std::int64_t>& t_ns) {
  const double span = 1e-9 * static_cast<double>(t_ns.back() - t_ns.front());
  return span > 0.0 ? static_cast<double>(t_ns.size() - 1) / span : 1.0;
}

// Gauss-Legendre nodes/weights on [0, 1] (5 points: exact to degree 9).
constexpr std::array<double, 5> kGaussNodes = {0.0469100770306680, 0.2307653449471585, 0.5,
                                               0.7692346550528415, 0.9530899229693320};
constexpr std::array<double, 5> kGaussWeights = {0.1184634425280945, 0.2393143352496832,
                                                 0.2844444444444444, 0.2393143352496832,
                                                 0.1184634425280945};

}  // namespace

PositionSpline6 FitPositionSpline(const std::vector<std::int64_t>& t_ns,
                                  const std::vector<Eigen::Vector3d>& positions,
                                  const KnotGrid& grid, double cutoff_hz) {
  const int n = PositionSpline6::NumControl(grid);
  CheckSamples(t_ns.size(), positions.size(), grid, n);
  const UniformBasis<kPos> basis;
  const double dt = grid.dt_s();

  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 3);
  for (std::size_t k = 0; k < t_ns.size(); ++k) {
    int seg = 0;
    double u = 0.0;
    grid.Locate(t_ns[k], &seg, &u);
    const auto w = basis.Weights(u, dt, 0, false);
    for (int a = 0; a < kPos; ++a) {
      rhs.row(seg + a) += w[a] * positions[k].transpose();
      for (int b = 0; b < kPos; ++b) triplets.emplace_back(seg + a, seg + b, w[a] * w[b]);
    }
  }
  if (cutoff_hz > 0.0) {
    const double lambda = SampleRate(t_ns) / std::pow(2.0 * std::numbers::pi * cutoff_hz, 6);
    Eigen::Matrix<double, kPos, kPos> gram = Eigen::Matrix<double, kPos, kPos>::Zero();
    for (std::size_t q = 0; q < kGaussNodes.size(); ++q) {
      const auto w3 = basis.Weights(kGaussNodes[q], dt, 3, false);
      gram += kGaussWeights[q] * dt * w3 * w3.transpose();  // integral over dt seconds
    }
    for (int s = 0; s < grid.num_segments; ++s) {
      for (int a = 0; a < kPos; ++a) {
        for (int b = 0; b < kPos; ++b) triplets.emplace_back(s + a, s + b, lambda * gram(a, b));
      }
    }
  }
  // A tiny ridge keeps control points that only the spline's far tails touch well defined.
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, i, 1e-9);
  Eigen::SparseMatrix<double> normal(n, n);
  normal.setFromTriplets(triplets.begin(), triplets.end());
  // Solve relative to the mean so the ridge does not pull towards the world origin.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : positions) mean += p;
  mean /= static_cast<double>(positions.size());
  Eigen::VectorXd row_sums = normal * Eigen::VectorXd::Ones(n);
  for (int i = 0; i < n; ++i) rhs.row(i) -= row_sums[i] * mean.transpose();
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
  PKSLAM_CHECK(solver.info() == Eigen::Success, "position spline normal equations singular");
  const Eigen::MatrixXd x = solver.solve(rhs);
  std::vector<Eigen::Vector3d> control(n);
  for (int i = 0; i < n; ++i) control[i] = x.row(i).transpose() + mean;
  return PositionSpline6(grid, std::move(control));
}

std::vector<SO3d> NearestSampleControls(const std::vector<std::int64_t>& t_ns,
                                        const std::vector<SO3d>& rotations, const KnotGrid& grid) {
  PKSLAM_CHECK(!t_ns.empty() && t_ns.size() == rotations.size(), "no rotation samples");
  const int n = RotationSpline4::NumControl(grid);
  std::vector<SO3d> control(n);
  // Control point j of a cubic spline sits nearest the curve at knot j - 1.
  for (int j = 0; j < n; ++j) {
    const std::int64_t t = grid.t0_ns + (j - (kRot - 2) / 2) * grid.dt_ns;
    auto it = std::lower_bound(t_ns.begin(), t_ns.end(), t);
    std::size_t k = static_cast<std::size_t>(it - t_ns.begin());
    if (k == t_ns.size()) k = t_ns.size() - 1;
    if (k > 0 && (t - t_ns[k - 1]) < (t_ns[k] - t)) --k;
    control[j] = rotations[k];
  }
  return control;
}

namespace {

struct RotationSampleCost {
  SO3d measured_inverse;
  Eigen::Matrix<double, kRot, 1> weights;

  template <typename T>
  bool operator()(const T* q0, const T* q1, const T* q2, const T* q3, T* residual) const {
    const SO3<T> c[kRot] = {SO3<T>(Eigen::Quaternion<T>(q0)), SO3<T>(Eigen::Quaternion<T>(q1)),
                            SO3<T>(Eigen::Quaternion<T>(q2)), SO3<T>(Eigen::Quaternion<T>(q3))};
    const SO3<T> r = RotationSpline4::Blend(c, weights);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> out(residual);
    out = (measured_inverse.cast<T>() * r).Log();
    return true;
  }
};

struct RotationSmoothnessCost {
  double weight;

  template <typename T>
  bool operator()(const T* q0, const T* q1, const T* q2, T* residual) const {
    const SO3<T> a(Eigen::Quaternion<T>{q0});
    const SO3<T> b(Eigen::Quaternion<T>{q1});
    const SO3<T> c(Eigen::Quaternion<T>{q2});
    Eigen::Map<Eigen::Matrix<T, 3, 1>> out(residual);
    out = T(weight) * ((b.Inverse() * c).Log() - (a.Inverse() * b).Log());
    return true;
  }
};

}  // namespace

RotationSpline4 FitRotationSpline(const std::vector<std::int64_t>& t_ns,
                                  const std::vector<SO3d>& rotations, const KnotGrid& grid,
                                  double cutoff_hz) {
  const int n = RotationSpline4::NumControl(grid);
  CheckSamples(t_ns.size(), rotations.size(), grid, n);
  const std::vector<SO3d> init = NearestSampleControls(t_ns, rotations, grid);
  std::vector<Eigen::Quaterniond> q(n);
  for (int j = 0; j < n; ++j) q[j] = init[j].quaternion();

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::EigenQuaternionManifold manifold;
  const UniformBasis<kRot> basis;
  for (std::size_t k = 0; k < t_ns.size(); ++k) {
    int seg = 0;
    double u = 0.0;
    grid.Locate(t_ns[k], &seg, &u);
    // The problem owns cost functions (and they their functors): hand over released pointers.
    auto cost = std::make_unique<ceres::AutoDiffCostFunction<RotationSampleCost, 3, 4, 4, 4, 4>>(
        std::make_unique<RotationSampleCost>(
            RotationSampleCost{rotations[k].Inverse(), basis.Weights(u, 1.0, 0, true)})
            .release());
    problem.AddResidualBlock(cost.release(), nullptr, q[seg].coeffs().data(),
                             q[seg + 1].coeffs().data(), q[seg + 2].coeffs().data(),
                             q[seg + 3].coeffs().data());
  }
  if (cutoff_hz > 0.0) {
    // integral |theta''|^2 dt ~ sum |second difference|^2 / dt^3; lambda as for positions
    // with a 4th-power response (second derivative).
    const double dt = grid.dt_s();
    const double lambda = SampleRate(t_ns) / std::pow(2.0 * std::numbers::pi * cutoff_hz, 4);
    const double weight = std::sqrt(lambda / (dt * dt * dt));
    for (int j = 1; j + 1 < n; ++j) {
      auto cost = std::make_unique<ceres::AutoDiffCostFunction<RotationSmoothnessCost, 3, 4, 4, 4>>(
          std::make_unique<RotationSmoothnessCost>(RotationSmoothnessCost{weight}).release());
      problem.AddResidualBlock(cost.release(), nullptr, q[j - 1].coeffs().data(),
                               q[j].coeffs().data(), q[j + 1].coeffs().data());
    }
  }
  for (int j = 0; j < n; ++j) {
    if (problem.HasParameterBlock(q[j].coeffs().data())) {
      problem.SetManifold(q[j].coeffs().data(), &manifold);
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = 50;
  options.function_tolerance = 1e-14;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-12;
  options.num_threads = 1;  // keeps the result bit-reproducible
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  PKSLAM_CHECK(summary.IsSolutionUsable(), "rotation spline fit failed: {}", summary.BriefReport());
  std::vector<SO3d> control(n);
  for (int j = 0; j < n; ++j) control[j] = SO3d(q[j]);
  return RotationSpline4(grid, std::move(control));
}

}  // namespace pkslam::sim
