#include "estimators/optim/essential_graph.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "core/util/error.h"
#include "estimators/optim/ceres_setup.h"
#include "estimators/optim/yaw_manifold.h"

namespace pkslam {
namespace {

// Parameter layout of one vertex: quaternion (Eigen order x y z w), translation, log-scale of
// its camera_from_world Sim3.
constexpr int kQ = 0;
constexpr int kT = 4;
constexpr int kS = 7;
constexpr int kVertexSize = 8;

template <typename T>
Sim3<T> VertexSim3(const T* q, const T* t, const T* log_s) {
  using std::exp;
  const Eigen::Quaternion<T> quat(q[3], q[0], q[1], q[2]);
  return Sim3<T>(exp(log_s[0]), SO3<T>(quat), Eigen::Matrix<T, 3, 1>(t[0], t[1], t[2]));
}

// ORB-SLAM's EdgeSim3 error: log(S_ji * S_iw * S_jw^-1), zero when the two vertices keep the
// relative pose they had before the correction. Identity information, as ORB-SLAM.
// With exact_log = false the error is [t; Log(R); log s] of the same transform, which agrees
// with the logarithm to first order and skips the series of Sim3's V-matrix.
struct RelativeSim3Cost {
  RelativeSim3Cost(const Sim3d& j_from_i, bool exact_log)
      : j_from_i(j_from_i), exact_log(exact_log) {}

  template <typename T>
  bool operator()(const T* qi, const T* ti, const T* si, const T* qj, const T* tj, const T* sj,
                  T* residual) const {
    using std::log;
    const Sim3<T> i_from_world = VertexSim3(qi, ti, si);
    const Sim3<T> j_from_world = VertexSim3(qj, tj, sj);
    const Sim3<T> error = j_from_i.cast<T>() * i_from_world * j_from_world.Inverse();
    if (exact_log) {
      const typename Sim3<T>::Tangent xi = error.Log();
      for (int k = 0; k < 7; ++k) residual[k] = xi(k);
    } else {
      const Eigen::Matrix<T, 3, 1> phi = error.so3().Log();
      for (int k = 0; k < 3; ++k) {
        residual[k] = error.translation()(k);
        residual[3 + k] = phi(k);
      }
      residual[6] = log(error.scale());
    }
    return true;
  }

  Sim3d j_from_i;
  bool exact_log;
};

// Ceres takes ownership of cost functions and their functors through raw pointers.
template <typename Functor, int... kDims>
ceres::CostFunction* MakeAutoDiff(Functor functor) {
  auto owned = std::make_unique<Functor>(std::move(functor));
  return std::make_unique<ceres::AutoDiffCostFunction<Functor, kDims...>>(owned.release())
      .release();
}

}  // namespace

void EssentialGraphOptions::Check() const {
  PKSLAM_CHECK_OPTION(min_covisibility_weight >= 1, "min_covisibility_weight", "{}",
                      min_covisibility_weight);
  PKSLAM_CHECK_OPTION(iterations >= 1, "iterations", "{}", iterations);
  PKSLAM_CHECK_OPTION(num_threads >= 1, "num_threads", "{}", num_threads);
}

int EssentialGraphProblem::CountEdges(EdgeKind kind) const {
  return static_cast<int>(
      std::count_if(edges.begin(), edges.end(), [kind](const Edge& e) { return e.kind == kind; }));
}

EssentialGraphResult SolveEssentialGraph(const EssentialGraphProblem& problem,
                                         const EssentialGraphOptions& options) {
  options.Check();
  EssentialGraphResult result;
  const std::size_t n = problem.vertices.size();
  std::vector<double> params(n * kVertexSize);
  for (std::size_t v = 0; v < n; ++v) {
    const Sim3d& s = problem.vertices[v].camera_from_world;
    double* p = &params[v * kVertexSize];
    const Eigen::Quaterniond& q = s.so3().quaternion();
    p[kQ + 0] = q.x();
    p[kQ + 1] = q.y();
    p[kQ + 2] = q.z();
    p[kQ + 3] = q.w();
    for (int k = 0; k < 3; ++k) p[kT + k] = s.translation()(k);
    p[kS] = std::log(s.scale());
  }
  auto read = [&params](std::size_t v) {
    const double* p = &params[v * kVertexSize];
    return Sim3d(std::exp(p[kS]), SO3d(Eigen::Quaterniond(p[kQ + 3], p[kQ], p[kQ + 1], p[kQ + 2])),
                 Eigen::Vector3d(p[kT], p[kT + 1], p[kT + 2]));
  };
  if (problem.edges.empty()) {
    for (std::size_t v = 0; v < n; ++v) result.camera_from_world.push_back(read(v));
    return result;
  }

  // Shared by all rotation blocks.
  ceres::EigenQuaternionManifold quaternion_manifold;
  YawQuaternionManifold yaw_manifold;
  const bool yaw_only = problem.dof == PoseGraphDof::kYawTranslation;
  ceres::Problem ceres_problem(ProblemOptions({}));
  for (std::size_t v = 0; v < n; ++v) {
    double* p = &params[v * kVertexSize];
    ceres_problem.AddParameterBlock(
        p + kQ, 4, yaw_only ? static_cast<ceres::Manifold*>(&yaw_manifold) : &quaternion_manifold);
    ceres_problem.AddParameterBlock(p + kT, 3);
    ceres_problem.AddParameterBlock(p + kS, 1);
    const bool fixed = problem.vertices[v].fixed;
    if (fixed) {
      ceres_problem.SetParameterBlockConstant(p + kQ);
      ceres_problem.SetParameterBlockConstant(p + kT);
    }
    if (fixed || problem.dof != PoseGraphDof::kSim3)
      ceres_problem.SetParameterBlockConstant(p + kS);
  }
  for (const auto& e : problem.edges) {
    double* pi = &params[static_cast<std::size_t>(e.i) * kVertexSize];
    double* pj = &params[static_cast<std::size_t>(e.j) * kVertexSize];
    ceres::CostFunction* cost = MakeAutoDiff<RelativeSim3Cost, 7, 4, 3, 1, 4, 3, 1>(
        RelativeSim3Cost(e.j_from_i, options.exact_log));
    ceres_problem.AddResidualBlock(cost, nullptr, pi + kQ, pi + kT, pi + kS, pj + kQ, pj + kT,
                                   pj + kS);
  }

  const ceres::Solver::Options solver_options =
      SolverOptions(ceres::SPARSE_NORMAL_CHOLESKY, options.iterations, options.num_threads);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &ceres_problem, &summary);
  result.iterations = static_cast<int>(summary.iterations.size());
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  for (std::size_t v = 0; v < n; ++v) result.camera_from_world.push_back(read(v));
  return result;
}

}  // namespace pkslam
