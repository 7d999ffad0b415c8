#include "estimators/optim/marginal_covariance.h"

#include <ceres/crs_matrix.h>
#include <ceres/manifold.h>
#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <vector>
#include <unordered_map>

#include "core/util/error.h"

namespace pkslam {
namespace {

// CHOLMOD's workspace and the objects allocated in it, freed in reverse order on every exit.
class Cholmod {
 public:
  Cholmod() {
    cholmod_start(&common_);
    common_.print = 0;  // a matrix that is not positive definite is an answer here, not a warning
  }
  ~Cholmod() {
    if (x_ != nullptr) cholmod_free_dense(&x_, &common_);
    if (b_ != nullptr) cholmod_free_dense(&b_, &common_);
    if (l_ != nullptr) cholmod_free_factor(&l_, &common_);
    if (a_ != nullptr) cholmod_free_sparse(&a_, &common_);
    cholmod_finish(&common_);
  }
  Cholmod(const Cholmod&) = delete;
  Cholmod& operator=(const Cholmod&) = delete;

  // J^T as CHOLMOD's column-compressed matrix (J's compressed rows are J^T's columns), with J's
  // columns scaled to unit norm: the factor then sees D J^T J D (D = the inverse column norms),
  // whose condition does not depend on the parameters' units (pixels beside metres beside
  // radians), so the conditioning test below judges observability, not units.
  void SetJacobianTranspose(const ceres::CRSMatrix& j) {
    a_ = cholmod_allocate_sparse(static_cast<size_t>(j.num_cols), static_cast<size_t>(j.num_rows),
                                 j.values.size(), /*sorted=*/0, /*packed=*/1, /*stype=*/0,
                                 CHOLMOD_REAL, &common_);
    PKSLAM_CHECK(a_ != nullptr, "marginal covariance: CHOLMOD could not allocate {} x {} ({} nnz)",
                 j.num_cols, j.num_rows, j.values.size());
    column_scale_.assign(static_cast<size_t>(j.num_cols), 0.0);
    for (size_t k = 0; k < j.values.size(); ++k) {
      column_scale_[static_cast<size_t>(j.cols[k])] += j.values[k] * j.values[k];
    }
    for (double& scale : column_scale_) scale = scale > 0 ? 1.0 / std::sqrt(scale) : 1.0;
    std::copy(j.rows.begin(), j.rows.end(), static_cast<int*>(a_->p));
    std::copy(j.cols.begin(), j.cols.end(), static_cast<int*>(a_->i));
    auto* values = static_cast<double*>(a_->x);
    for (size_t k = 0; k < j.values.size(); ++k) {
      values[k] = j.values[k] * column_scale_[static_cast<size_t>(j.cols[k])];
    }
    cholmod_sort(a_, &common_);
  }

  // Cholesky of A A^T = J^T J; false when it is not positive definite or too ill-conditioned.
  bool Factor(double min_reciprocal_condition) {
    l_ = cholmod_analyze(a_, &common_);
    if (l_ == nullptr) return false;
    if (!cholmod_factorize(a_, l_, &common_) || common_.status == CHOLMOD_NOT_POSDEF ||
        l_->minor < l_->n) {
      return false;
    }
    return cholmod_rcond(l_, &common_) >= min_reciprocal_condition;
  }

  // (J^T J)^-1 restricted to `columns`: rows and columns in the order given.
  Eigen::MatrixXd InverseColumns(const std::vector<int>& columns) {
    const auto n = static_cast<size_t>(a_->nrow);
    const size_t k = columns.size();
    b_ = cholmod_zeros(n, k, CHOLMOD_REAL, &common_);
    PKSLAM_CHECK(b_ != nullptr, "marginal covariance: CHOLMOD could not allocate {} x {}", n, k);
    auto* b = static_cast<double*>(b_->x);
    for (size_t c = 0; c < k; ++c) b[c * b_->d + static_cast<size_t>(columns[c])] = 1.0;
    x_ = cholmod_solve(CHOLMOD_A, l_, b_, &common_);
    PKSLAM_CHECK(x_ != nullptr, "marginal covariance: CHOLMOD solve failed (status {})",
                 common_.status);
    const auto* x = static_cast<const double*>(x_->x);
    Eigen::MatrixXd out(k, k);
    for (size_t c = 0; c < k; ++c) {
      for (size_t r = 0; r < k; ++r) {
        // (J^T J)^-1 = D (D J^T J D)^-1 D.
        const auto row = static_cast<size_t>(columns[r]);
        const auto col = static_cast<size_t>(columns[c]);
        out(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) =
            x[c * x_->d + row] * column_scale_[row] * column_scale_[col];
      }
    }
    return 0.5 * (out + out.transpose());  // symmetric up to rounding
  }

 private:
  cholmod_common common_{};
  cholmod_sparse* a_ = nullptr;
  cholmod_factor* l_ = nullptr;
  cholmod_dense* b_ = nullptr;
  cholmod_dense* x_ = nullptr;
  std::vector<double> column_scale_;  // D: 1 / the norm of each column of J
};

}  // namespace

void MarginalCovarianceOptions::Check() const {
  PKSLAM_CHECK(min_reciprocal_condition >= 0 && min_reciprocal_condition < 1,
               "marginal covariance: min_reciprocal_condition {} not in [0, 1)",
               min_reciprocal_condition);
  PKSLAM_CHECK(num_threads >= 1, "marginal covariance: num_threads {} < 1", num_threads);
}

const MarginalBlock& MarginalCovariance::Find(const double* block) const {
  for (const MarginalBlock& b : blocks) {
    if (b.block == block) return b;
  }
  PKSLAM_CHECK(false, "marginal covariance: block {} was not requested",
               static_cast<const void*>(block));
  return blocks.front();
}

Eigen::MatrixXd MarginalCovariance::Block(const double* block) const {
  const MarginalBlock& b = Find(block);
  return joint.block(b.offset, b.offset, b.size, b.size);
}

std::optional<MarginalCovariance> ComputeMarginalCovariance(
    ceres::Problem* problem, const std::vector<const double*>& blocks,
    const MarginalCovarianceOptions& options) {
  options.Check();
  // J's columns: the blocks that are not held constant, in the problem's order.
  std::vector<double*> all;
  problem->GetParameterBlocks(&all);
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.apply_loss_function = true;
  evaluate.num_threads = options.num_threads;
  std::unordered_map<const double*, int> column_of;
  int columns = 0;
  for (double* block : all) {
    if (problem->IsParameterBlockConstant(block)) continue;
    evaluate.parameter_blocks.push_back(block);
    column_of[block] = columns;
    columns += problem->ParameterBlockTangentSize(block);
  }
  MarginalCovariance out;
  std::vector<int> wanted;
  for (const double* block : blocks) {
    const auto it = column_of.find(block);
    PKSLAM_CHECK(it != column_of.end(),
                 "marginal covariance: block {} is not a free parameter block of the problem",
                 static_cast<const void*>(block));
    const int size = problem->ParameterBlockTangentSize(block);
    out.blocks.push_back({block, static_cast<int>(wanted.size()), size});
    for (int i = 0; i < size; ++i) wanted.push_back(it->second + i);
  }
  if (wanted.empty()) return out;
  ceres::CRSMatrix jacobian;
  if (!problem->Evaluate(evaluate, nullptr, nullptr, nullptr, &jacobian)) return std::nullopt;
  Cholmod cholmod;
  cholmod.SetJacobianTranspose(jacobian);
  if (!cholmod.Factor(options.min_reciprocal_condition)) return std::nullopt;
  out.joint = cholmod.InverseColumns(wanted);
  return out;
}

Eigen::MatrixXd PlusJacobianOf(const ceres::Problem& problem, const double* block) {
  const ceres::Manifold* manifold = problem.GetManifold(block);
  if (manifold == nullptr) {
    const int size = problem.ParameterBlockSize(block);
    return Eigen::MatrixXd::Identity(size, size);
  }
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> plus(
      manifold->AmbientSize(), manifold->TangentSize());
  PKSLAM_CHECK(manifold->PlusJacobian(block, plus.data()),
               "marginal covariance: the manifold's plus Jacobian failed");
  return plus;
}

Eigen::MatrixXd AmbientCovariance(const ceres::Problem& problem, const double* block,
                                  const Eigen::MatrixXd& tangent_covariance) {
  if (problem.GetManifold(block) == nullptr) return tangent_covariance;
  const Eigen::MatrixXd plus = PlusJacobianOf(problem, block);
  return plus * tangent_covariance * plus.transpose();
}

}  // namespace pkslam
