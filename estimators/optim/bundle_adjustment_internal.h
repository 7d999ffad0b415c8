// Knobs of SolveBundle that are not part of the public contract: used by tests (to act at a
// given solver iteration) and benchmarks (to compare linear solvers).
#pragma once

#include <ceres/iteration_callback.h>
#include <ceres/types.h>

#include <atomic>
#include <optional>

#include "estimators/optim/bundle_adjustment.h"

namespace pkslam::internal {

struct BundleSolverOverrides {
  // The linear solver of both passes (SPARSE_SCHUR or DENSE_SCHUR); unset: chosen by the
  // number of free keyframes (see bundle_solve.cc).
  std::optional<ceres::LinearSolverType> linear_solver;
  // Called after every solver iteration, before the abort flag is polled (may be null).
  ceres::IterationCallback* callback = nullptr;
  // Counts the residual evaluations (may be null).
  WorkMeter* work = nullptr;
};

BundleResult SolveBundle(const BundleProblem& problem, const BundleAdjustmentOptions& options,
                         const std::atomic<bool>* abort, const BundleSolverOverrides& overrides);

}  // namespace pkslam::internal
