// The marginal covariance of a few parameter blocks of a solved Ceres problem: their rows and
// columns of (J^T J)^-1 in the blocks' tangent spaces, J the Jacobian of the whole problem at the
// current values with the loss functions applied (what ceres::Covariance computes with
// apply_loss_function). It factors J^T J once with CHOLMOD's supernodal Cholesky (CHOLMOD forms
// J^T J itself from J) and solves for the requested columns only. ceres::Covariance's SPARSE_QR
// reaches the same matrix through a QR factorisation of all of J, which on the whole-map
// calibration adjustment at the end of a run took 1-2.6 s (docs/calibration.md, "Cost"); the
// normal equations square J's condition number, which is why a rank check guards the result.
#pragma once

#include <ceres/problem.h>

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace pkslam {

struct MarginalCovarianceOptions {
  // J^T J counts as rank-deficient (no covariance) when CHOLMOD's reciprocal condition estimate
  // (min/max of the Cholesky factor's diagonal, squared) falls below this. ceres::Covariance's
  // default threshold for its QR is the same number for the same matrix.
  double min_reciprocal_condition = 1e-14;
  int num_threads = 1;  // Jacobian evaluation
  void Check() const;
};

// One requested block's place in the joint covariance.
struct MarginalBlock {
  const double* block = nullptr;
  int offset = 0;  // first row / column in MarginalCovariance::joint
  int size = 0;    // tangent size
};

struct MarginalCovariance {
  std::vector<MarginalBlock> blocks;  // in the requested order
  Eigen::MatrixXd joint;              // all requested blocks, tangent coordinates

  // One block's own covariance (tangent coordinates).
  Eigen::MatrixXd Block(const double* block) const;
  // A requested block's place in `joint`.
  const MarginalBlock& Find(const double* block) const;
};

// nullopt when J^T J is not positive definite or its condition is below the options' bound.
// Every requested block must be a parameter block of `problem` that is not held constant;
// constant blocks elsewhere take no part (their columns are not in J).
std::optional<MarginalCovariance> ComputeMarginalCovariance(
    ceres::Problem* problem, const std::vector<const double*>& blocks,
    const MarginalCovarianceOptions& options = {});

// The manifold's plus Jacobian at the block's value (ambient x tangent; I without a manifold).
Eigen::MatrixXd PlusJacobianOf(const ceres::Problem& problem, const double* block);

// A block's covariance in its ambient coordinates: P C P^T with P = PlusJacobianOf(block); as
// ceres::Covariance::GetCovarianceMatrix.
Eigen::MatrixXd AmbientCovariance(const ceres::Problem& problem, const double* block,
                                  const Eigen::MatrixXd& tangent_covariance);

}  // namespace pkslam
