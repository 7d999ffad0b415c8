#include "estimators/optim/sim3_optimization.h"

#include <ceres/ceres.h>

#include <cmath>
#include <limits>
#include <memory>

#include "core/util/error.h"
#include "estimators/optim/ceres_setup.h"

namespace pkslam {
namespace {

// Reprojection of one point of a pair through S12 (forward: point2 into image 1) or its
// inverse (point1 into image 2), whitened by the keypoint sigma. Parameters: the rotation
// quaternion (Eigen order x y z w), the translation and the log-scale of S12.
struct PairReprojection {
  PairReprojection(const Eigen::Vector3d& point, const Eigen::Vector2d& uv, double inv_sigma,
                   const PinholeIntrinsics& camera, bool forward)
      : point(point), uv(uv), inv_sigma(inv_sigma), camera(camera), forward(forward) {}

  template <typename T>
  bool operator()(const T* q, const T* t, const T* log_s, T* residual) const {
    using std::exp;
    const Eigen::Map<const Eigen::Quaternion<T>> rotation(q);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> translation(t);
    const T s = exp(log_s[0]);
    // A collapsing or exploding scale (all pairs inconsistent) is not a valid step.
    if (!(s > T(1e-6) && s < T(1e6))) return false;
    const Eigen::Matrix<T, 3, 1> p = point.cast<T>();
    Eigen::Matrix<T, 3, 1> p_camera;
    if (forward) {
      p_camera = s * (rotation * p) + translation;
    } else {
      p_camera = (rotation.conjugate() * (p - translation)) / s;
    }
    if (ceres::abs(p_camera.z()) < T(1e-9)) return false;
    const Eigen::Matrix<T, 2, 1> uv_hat = camera.Project(p_camera);
    residual[0] = (uv_hat.x() - T(uv.x())) * T(inv_sigma);
    residual[1] = (uv_hat.y() - T(uv.y())) * T(inv_sigma);
    return true;
  }

  Eigen::Vector3d point;
  Eigen::Vector2d uv;
  double inv_sigma;
  PinholeIntrinsics camera;
  bool forward;
};

// Ceres takes ownership of cost functions and their functors through raw pointers.
template <typename Functor, int... kDims>
ceres::CostFunction* MakeAutoDiff(Functor functor) {
  auto owned = std::make_unique<Functor>(std::move(functor));
  return std::make_unique<ceres::AutoDiffCostFunction<Functor, kDims...>>(owned.release())
      .release();
}

struct State {
  Eigen::Quaterniond q;
  Eigen::Vector3d t;
  double log_s;
};

// Whitened squared errors (chi2) of one pair under the current state.
std::pair<double, double> PairChi2(const Sim3Match& m, const PinholeIntrinsics& camera1,
                                   const PinholeIntrinsics& camera2, const State& state) {
  const Sim3d s12(std::exp(state.log_s), SO3d(state.q), state.t);
  const Eigen::Vector3d in1 = s12 * m.point2;
  const Eigen::Vector3d in2 = s12.Inverse() * m.point1;
  const double inf = std::numeric_limits<double>::infinity();
  const double e1 = in1.z() > 0 ? (camera1.Project(in1) - m.uv1).squaredNorm() / m.sigma2_1 : inf;
  const double e2 = in2.z() > 0 ? (camera2.Project(in2) - m.uv2).squaredNorm() / m.sigma2_2 : inf;
  return {e1, e2};
}

}  // namespace

void Sim3OptimizationOptions::Check() const {
  PKSLAM_CHECK_OPTION(chi2 > 0, "chi2", "{}", chi2);
  PKSLAM_CHECK_OPTION(iterations_first >= 1, "iterations_first", "{}", iterations_first);
  PKSLAM_CHECK_OPTION(iterations_second >= 0, "iterations_second", "{}", iterations_second);
  PKSLAM_CHECK_OPTION(min_pairs_after_first >= 0, "min_pairs_after_first", "{}",
                      min_pairs_after_first);
  PKSLAM_CHECK_OPTION(num_threads >= 1, "num_threads", "{}", num_threads);
}

Sim3OptimizationResult OptimizeSim3(const std::vector<Sim3Match>& matches,
                                    const PinholeIntrinsics& camera1,
                                    const PinholeIntrinsics& camera2, const Sim3d& initial,
                                    const Sim3OptimizationOptions& options) {
  options.Check();
  PKSLAM_CHECK(initial.scale() > 0, "initial scale {}", initial.scale());
  Sim3OptimizationResult result;
  result.camera1_from_camera2 = initial;
  result.inliers.assign(matches.size(), false);
  if (matches.empty()) return result;

  State state{initial.so3().quaternion(), initial.translation(), std::log(initial.scale())};
  // Declared before the problem so they outlive it.
  ceres::EigenQuaternionManifold quaternion_manifold;
  ceres::HuberLoss huber(std::sqrt(options.chi2));
  ceres::Problem problem(ProblemOptions({.loss_functions = true}));
  problem.AddParameterBlock(state.q.coeffs().data(), 4, &quaternion_manifold);
  problem.AddParameterBlock(state.t.data(), 3);
  problem.AddParameterBlock(&state.log_s, 1);
  if (options.fix_scale) problem.SetParameterBlockConstant(&state.log_s);

  // Two residual blocks per pair (one per image).
  std::vector<std::pair<ceres::ResidualBlockId, ceres::ResidualBlockId>> blocks;
  blocks.reserve(matches.size());
  for (const Sim3Match& m : matches) {
    ceres::CostFunction* forward = MakeAutoDiff<PairReprojection, 2, 4, 3, 1>(
        PairReprojection(m.point2, m.uv1, 1.0 / std::sqrt(m.sigma2_1), camera1, true));
    ceres::CostFunction* backward = MakeAutoDiff<PairReprojection, 2, 4, 3, 1>(
        PairReprojection(m.point1, m.uv2, 1.0 / std::sqrt(m.sigma2_2), camera2, false));
    blocks.emplace_back(problem.AddResidualBlock(forward, &huber, state.q.coeffs().data(),
                                                 state.t.data(), &state.log_s),
                        problem.AddResidualBlock(backward, &huber, state.q.coeffs().data(),
                                                 state.t.data(), &state.log_s));
  }

  ceres::Solver::Options solver_options =
      SolverOptions(ceres::DENSE_QR, options.iterations_first, options.num_threads);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  result.initial_cost = summary.initial_cost;

  // Drop the pairs that are outliers in either image.
  std::vector<bool> active(matches.size(), true);
  int bad = 0;
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const auto [e1, e2] = PairChi2(matches[i], camera1, camera2, state);
    if (e1 > options.chi2 || e2 > options.chi2) {
      problem.RemoveResidualBlock(blocks[i].first);
      problem.RemoveResidualBlock(blocks[i].second);
      active[i] = false;
      ++bad;
    }
  }
  const int remaining = static_cast<int>(matches.size()) - bad;
  if (remaining < options.min_pairs_after_first || remaining == 0 ||
      summary.termination_type == ceres::FAILURE) {
    result.camera1_from_camera2 = Sim3d(std::exp(state.log_s), SO3d(state.q), state.t);
    return result;
  }

  solver_options.max_num_iterations =
      bad > 0 ? options.iterations_second : options.iterations_first;
  if (solver_options.max_num_iterations > 0) {
    ceres::Solve(solver_options, &problem, &summary);
    result.final_cost = summary.final_cost;
  }

  for (std::size_t i = 0; i < matches.size(); ++i) {
    if (!active[i]) continue;
    const auto [e1, e2] = PairChi2(matches[i], camera1, camera2, state);
    if (e1 <= options.chi2 && e2 <= options.chi2) {
      result.inliers[i] = true;
      ++result.num_inliers;
    }
  }
  result.camera1_from_camera2 = Sim3d(std::exp(state.log_s), SO3d(state.q), state.t);
  return result;
}

}  // namespace pkslam
