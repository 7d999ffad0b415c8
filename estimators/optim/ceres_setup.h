// One Ceres setup for every optimiser of pkslam (bundle adjustments visual and inertial, pose
// optimisations, Sim(3), essential graph, inertial initialisation): quiet solver options with a
// fixed thread count, the dense/sparse Schur choice, the abort callback a running local BA
// obeys, and the robust kernels of the reprojection residuals.
#pragma once

#include <ceres/iteration_callback.h>
#include <ceres/loss_function.h>
#include <ceres/solver.h>
#include <ceres/types.h>

#include <atomic>
#include <optional>
#include <vector>

#include "core/util/work_meter.h"

namespace ceres {
class Problem;
}

namespace pkslam {

struct BundleResult;

// Stops the solver once *abort is set (never with a null flag). It returns
// SOLVER_TERMINATE_SUCCESSFULLY, not SOLVER_ABORT: Ceres then writes the best iterate so far back
// to the parameter blocks, so an interrupted BA still delivers its progress (as g2o's force-stop
// does in ORB-SLAM). SOLVER_ABORT leaves the blocks unchanged, and combined with
// update_state_every_iteration it was measured to leave a state worse than the initial one
// (Ceres 2.1).
// With a work meter, every iteration (the initial evaluation included) adds the problem's scalar
// residual count to WorkKind::kSolverResidual as it happens, so live emulation's work clock
// advances during a long solve and not only at its end, then calls the meter's pacer (which may
// block until tracking has caught up; solvers run with no map lock held).
class AbortCallback final : public ceres::IterationCallback {
 public:
  // Meters `problem`'s residual evaluations into `work` (both may be null; `problem` must
  // outlive the solves). `min_iterations`: the flag is obeyed only from this iteration on (a
  // solve that would never finish between two interruptions still makes that much progress).
  AbortCallback(const std::atomic<bool>* abort, WorkMeter* work, const ceres::Problem* problem,
                int min_iterations = 0)
      : abort_(abort), min_iterations_(min_iterations), work_(work), problem_(problem) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override;
  bool fired() const { return fired_; }
  // Whether the solver needs this callback at all.
  bool active() const { return abort_ != nullptr || (work_ != nullptr && problem_ != nullptr); }

 private:
  const std::atomic<bool>* abort_;
  int min_iterations_ = 0;
  WorkMeter* work_ = nullptr;
  const ceres::Problem* problem_ = nullptr;
  bool fired_ = false;
};

// Reduced camera systems up to this many free poses are solved densely. Measured with
// bundle_adjustment_benchmark.cc: DENSE_SCHUR executes 2-3% fewer instructions (callgrind)
// than SPARSE_SCHUR at 10-20 free keyframes; CPU time is about equal at 40 and DENSE_SCHUR is
// ~14% slower at 80 (global BA).
inline constexpr int kMaxFreePosesForDenseSchur = 40;
ceres::LinearSolverType SchurSolverFor(int free_poses);

// Silent options with `linear_solver`, `max_iterations` and `num_threads`. Ceres's result for a
// given problem and thread count is deterministic (--deterministic runs fix the counts).
ceres::Solver::Options SolverOptions(ceres::LinearSolverType linear_solver, int max_iterations,
                                     int num_threads);

// A bundle adjustment's Schur elimination: the points are eliminated first (group 0), then the
// reduced system over everything else (poses, velocities, biases, calibration: group 1) is solved.
// Ceres keeps each group as a set, so the order blocks are listed in does not matter.
struct SchurBlocks {
  std::vector<double*> points;
  std::vector<double*> others;
  int free_poses = 0;  // chooses dense or sparse Schur (SchurSolverFor)
  void AddPoint(double* block) { points.push_back(block); }
  void AddOther(double* block) { others.push_back(block); }
};
// SolverOptions (no iteration limit: each pass sets its own) with the ordering of `blocks` and
// `linear_solver`, by default SchurSolverFor(blocks.free_poses).
ceres::Solver::Options SchurSolverOptions(
    const SchurBlocks& blocks, int num_threads,
    std::optional<ceres::LinearSolverType> linear_solver = std::nullopt);

// What a ceres::Problem borrows from its caller instead of owning (Ceres deletes what it owns).
// Manifolds are always borrowed: every optimiser keeps them on its stack, shared by its blocks.
struct ProblemBorrows {
  bool cost_functions = false;  // the caller re-adds or reuses them (rounds, several problems)
  bool loss_functions = false;  // ReprojectionLosses' wrappers and other stack losses
  // Ceres' removal index: needed when residual blocks are removed between rounds or passes.
  bool fast_removal = false;
};
ceres::Problem::Options ProblemOptions(const ProblemBorrows& borrows);

// Huber kernels at the mono and stereo chi-square thresholds (pixels: sqrt(chi2)), behind
// wrappers the residual blocks keep, so the kernels can be switched off between passes (the
// outlier-free refinement) without rebuilding the problem. Not movable: blocks hold the
// wrappers' addresses.
class ReprojectionLosses {
 public:
  ReprojectionLosses(double chi2_mono, double chi2_stereo, bool robust);
  ReprojectionLosses(const ReprojectionLosses&) = delete;
  ReprojectionLosses& operator=(const ReprojectionLosses&) = delete;
  void SetRobust(bool robust);
  ceres::LossFunction* mono() { return &mono_; }
  ceres::LossFunction* stereo() { return &stereo_; }

 private:
  ceres::HuberLoss huber_mono_;
  ceres::HuberLoss huber_stereo_;
  ceres::LossFunctionWrapper mono_;
  ceres::LossFunctionWrapper stereo_;
};

// One pass of a bundle adjustment solved in passes (robust, then the refinement without the
// outliers): solves `problem` for at most `iterations` and adds the pass to `result`. The cost
// before the first pass and after the last, iterations summed, and whether the abort flag stopped
// it. An empty problem is not solved. On a numerical failure Ceres leaves the blocks at their
// initial values, so the map stays consistent: it is logged (naming `what`), not thrown from a
// mapping thread.
class BundlePasses {
 public:
  BundlePasses(ceres::Problem* problem, const AbortCallback* abort_callback, const char* what)
      : problem_(problem), abort_callback_(abort_callback), what_(what) {}
  void Run(int iterations, ceres::Solver::Options* options, BundleResult* result);

 private:
  ceres::Problem* problem_;
  const AbortCallback* abort_callback_;
  const char* what_;
  bool first_ = true;
};

}  // namespace pkslam
