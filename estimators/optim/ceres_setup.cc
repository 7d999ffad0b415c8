#include "estimators/optim/ceres_setup.h"

#include <ceres/problem.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "core/util/log.h"
#include "estimators/optim/bundle_adjustment.h"

namespace pkslam {

ceres::CallbackReturnType AbortCallback::operator()(const ceres::IterationSummary& summary) {
  if (work_ != nullptr && problem_ != nullptr) {
    work_->Add(WorkKind::kSolverResidual, problem_->NumResiduals());
    work_->Pace();
  }
  if (abort_ == nullptr || !abort_->load(std::memory_order_relaxed)) return ceres::SOLVER_CONTINUE;
  if (summary.iteration < min_iterations_) return ceres::SOLVER_CONTINUE;
  fired_ = true;
  return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
}

ceres::LinearSolverType SchurSolverFor(int free_poses) {
  return free_poses <= kMaxFreePosesForDenseSchur ? ceres::DENSE_SCHUR : ceres::SPARSE_SCHUR;
}

ceres::Problem::Options ProblemOptions(const ProblemBorrows& borrows) {
  ceres::Problem::Options options;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  if (borrows.cost_functions) options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  if (borrows.loss_functions) options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.enable_fast_removal = borrows.fast_removal;
  return options;
}

ceres::Solver::Options SolverOptions(ceres::LinearSolverType linear_solver, int max_iterations,
                                     int num_threads) {
  ceres::Solver::Options o;
  o.linear_solver_type = linear_solver;
  o.max_num_iterations = max_iterations;
  o.num_threads = num_threads;
  o.logging_type = ceres::SILENT;
  return o;
}

ceres::Solver::Options SchurSolverOptions(const SchurBlocks& blocks, int num_threads,
                                          std::optional<ceres::LinearSolverType> linear_solver) {
  ceres::Solver::Options o =
      SolverOptions(linear_solver.value_or(SchurSolverFor(blocks.free_poses)), 0, num_threads);
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (double* block : blocks.points) ordering->AddElementToGroup(block, 0);
  for (double* block : blocks.others) ordering->AddElementToGroup(block, 1);
  o.linear_solver_ordering = std::move(ordering);
  return o;
}

ReprojectionLosses::ReprojectionLosses(double chi2_mono, double chi2_stereo, bool robust)
    : huber_mono_(std::sqrt(chi2_mono)),
      huber_stereo_(std::sqrt(chi2_stereo)),
      mono_(robust ? &huber_mono_ : nullptr, ceres::DO_NOT_TAKE_OWNERSHIP),
      stereo_(robust ? &huber_stereo_ : nullptr, ceres::DO_NOT_TAKE_OWNERSHIP) {}

void ReprojectionLosses::SetRobust(bool robust) {
  mono_.Reset(robust ? &huber_mono_ : nullptr, ceres::DO_NOT_TAKE_OWNERSHIP);
  stereo_.Reset(robust ? &huber_stereo_ : nullptr, ceres::DO_NOT_TAKE_OWNERSHIP);
}

void BundlePasses::Run(int iterations, ceres::Solver::Options* options, BundleResult* result) {
  if (problem_->NumResidualBlocks() == 0) return;
  options->max_num_iterations = iterations;
  ceres::Solver::Summary summary;
  ceres::Solve(*options, problem_, &summary);
  if (first_) result->initial_cost = summary.initial_cost;
  first_ = false;
  result->final_cost = summary.final_cost;
  // summary.iterations starts with iteration 0 (the initial evaluation).
  result->iterations += std::max(0, static_cast<int>(summary.iterations.size()) - 1);
  result->aborted = abort_callback_->fired();
  if (summary.termination_type == ceres::FAILURE) {
    PKSLAM_LOG_WARN("{}: solver failure: {}", what_, summary.message);
  }
}

}  // namespace pkslam
