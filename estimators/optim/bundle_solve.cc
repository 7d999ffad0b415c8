// Solve phase of bundle adjustment: Ceres on a copy of the collected state, no lock held.
#include <ceres/loss_function.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <cmath>
#include <memory>
#include <vector>

#include "core/util/error.h"
#include "estimators/optim/bundle_adjustment.h"
#include "estimators/optim/bundle_adjustment_internal.h"
#include "estimators/optim/ceres_setup.h"
#include "estimators/optim/reprojection_error.h"
#include "estimators/optim/se3_manifold.h"

namespace pkslam {
namespace {

// The solver's working copy of the problem state.
struct State {
  std::vector<double> poses;   // 7 per keyframe
  std::vector<double> points;  // 3 per point
  double* pose(int i) { return poses.data() + kPoseBlockSize * i; }
  double* point(int i) { return points.data() + 3 * i; }
};

double ObservationChi2(const PinholeIntrinsics& k, const BundleProblem::ObservationState& o,
                       State& s) {
  const SE3d camera_from_world = PoseFromBlock(s.pose(o.keyframe_index));
  const Eigen::Map<const Eigen::Vector3d> p(s.point(o.point_index));
  if (o.u_right >= 0) {
    return StereoChi2(k, camera_from_world, p, Eigen::Vector3d(o.uv.x(), o.uv.y(), o.u_right),
                      o.inv_sigma2, o.disparity_inv_sigma2);
  }
  return MonoChi2(k, camera_from_world, p, o.uv, o.inv_sigma2);
}

bool IsOutlier(const PinholeIntrinsics& k, const BundleProblem::ObservationState& o, State& s,
               const BundleAdjustmentOptions& options) {
  // Infinite (point behind the camera) fails the comparison too.
  return !(ObservationChi2(k, o, s) <= (o.u_right >= 0 ? options.chi2_stereo : options.chi2_mono));
}

}  // namespace

void BundleAdjustmentOptions::Check() const {
  PKSLAM_CHECK_OPTION(iterations_first >= 1, "ba.iterations_first", "{}", iterations_first);
  PKSLAM_CHECK_OPTION(iterations_second >= 0, "ba.iterations_second", "{}", iterations_second);
  PKSLAM_CHECK_OPTION(chi2_mono > 0, "ba.chi2_mono", "{}", chi2_mono);
  PKSLAM_CHECK_OPTION(chi2_stereo > 0, "ba.chi2_stereo", "{}", chi2_stereo);
  PKSLAM_CHECK_OPTION(num_threads >= 1, "ba.num_threads", "{}", num_threads);
  PKSLAM_CHECK_OPTION(max_local_keyframes >= 0, "ba.max_local_keyframes", "{}",
                      max_local_keyframes);
}

BundleResult SolveBundle(const BundleProblem& problem, const BundleAdjustmentOptions& options,
                         const std::atomic<bool>* abort, WorkMeter* work) {
  internal::BundleSolverOverrides overrides;
  overrides.work = work;
  return internal::SolveBundle(problem, options, abort, overrides);
}

namespace internal {

BundleResult SolveBundle(const BundleProblem& problem, const BundleAdjustmentOptions& options,
                         const std::atomic<bool>* abort, const BundleSolverOverrides& overrides) {
  options.Check();
  BundleResult result;
  const int num_keyframes = static_cast<int>(problem.keyframes.size());
  const int num_points = static_cast<int>(problem.points.size());
  State state;
  state.poses.resize(static_cast<std::size_t>(kPoseBlockSize * num_keyframes));
  state.points.resize(static_cast<std::size_t>(3 * num_points));
  for (int i = 0; i < num_keyframes; ++i) {
    PoseToBlock(problem.keyframes[i].camera_from_world, state.pose(i));
  }
  for (int i = 0; i < num_points; ++i) {
    Eigen::Map<Eigen::Vector3d>(state.point(i)) = problem.points[i].position_world;
  }
  auto write_result = [&]() {
    result.camera_from_world.clear();
    result.points_world.clear();
    for (int i = 0; i < num_keyframes; ++i) {
      // Fixed keyframes are returned bit-exact (no quaternion round trip).
      result.camera_from_world.push_back(problem.keyframes[i].fixed
                                             ? problem.keyframes[i].camera_from_world
                                             : PoseFromBlock(state.pose(i)));
    }
    for (int i = 0; i < num_points; ++i) {
      result.points_world.emplace_back(Eigen::Map<const Eigen::Vector3d>(state.point(i)));
    }
  };
  if (problem.empty() || (abort != nullptr && abort->load())) {
    result.aborted = !problem.empty();
    write_result();
    return result;
  }

  const PinholeIntrinsics k{problem.fx, problem.fy, problem.cx, problem.cy, problem.bf};
  ReprojectionLosses losses(options.chi2_mono, options.chi2_stereo, /*robust=*/true);
  SE3LeftManifold manifold;
  ceres::Problem ceres_problem(ProblemOptions({.loss_functions = true, .fast_removal = true}));

  // Observations whose point is behind the camera cannot be evaluated: outliers from the
  // start. Parameter blocks enter the problem with their first residual, so every block in
  // the problem is constrained.
  const int num_obs = static_cast<int>(problem.observations.size());
  std::vector<ceres::ResidualBlockId> blocks(static_cast<std::size_t>(num_obs), nullptr);
  std::vector<std::uint8_t> pose_added(static_cast<std::size_t>(num_keyframes), 0);
  std::vector<std::uint8_t> point_added(static_cast<std::size_t>(num_points), 0);
  for (int i = 0; i < num_obs; ++i) {
    const BundleProblem::ObservationState& o = problem.observations[i];
    if (!std::isfinite(ObservationChi2(k, o, state))) continue;
    double* pose = state.pose(o.keyframe_index);
    double* point = state.point(o.point_index);
    if (!pose_added[o.keyframe_index]) {
      ceres_problem.AddParameterBlock(pose, kPoseBlockSize, &manifold);
      if (problem.keyframes[o.keyframe_index].fixed) ceres_problem.SetParameterBlockConstant(pose);
      pose_added[o.keyframe_index] = 1;
    }
    point_added[o.point_index] = 1;
    if (o.u_right >= 0) {
      blocks[i] = ceres_problem.AddResidualBlock(
          new StereoReprojectionError(k, Eigen::Vector3d(o.uv.x(), o.uv.y(), o.u_right),
                                      o.inv_sigma2, o.disparity_inv_sigma2),
          losses.stereo(), pose, point);
    } else {
      blocks[i] = ceres_problem.AddResidualBlock(new MonoReprojectionError(k, o.uv, o.inv_sigma2),
                                                 losses.mono(), pose, point);
    }
  }

  SchurBlocks schur;
  for (int i = 0; i < num_points; ++i) {
    if (point_added[i]) schur.AddPoint(state.point(i));
  }
  for (int i = 0; i < num_keyframes; ++i) {
    if (!pose_added[i]) continue;
    schur.AddOther(state.pose(i));
    schur.free_poses += problem.keyframes[i].fixed ? 0 : 1;
  }
  ceres::Solver::Options solver_options =
      SchurSolverOptions(schur, options.num_threads, overrides.linear_solver);
  AbortCallback abort_callback(abort, overrides.work, &ceres_problem);
  if (overrides.callback != nullptr) solver_options.callbacks.push_back(overrides.callback);
  if (abort_callback.active()) solver_options.callbacks.push_back(&abort_callback);

  BundlePasses passes(&ceres_problem, &abort_callback, "bundle adjustment");

  // Pass 1: robust. Then drop the outliers and (unless aborted) refine without the loss.
  passes.Run(options.iterations_first, &solver_options, &result);
  std::vector<std::uint8_t> outlier(static_cast<std::size_t>(num_obs), 0);
  for (int i = 0; i < num_obs; ++i) {
    outlier[i] = blocks[i] == nullptr || IsOutlier(k, problem.observations[i], state, options);
  }
  const bool second =
      options.iterations_second > 0 && !result.aborted && !(abort != nullptr && abort->load());
  if (second) {
    for (int i = 0; i < num_obs; ++i) {
      if (outlier[i] && blocks[i] != nullptr) {
        ceres_problem.RemoveResidualBlock(blocks[i]);
        blocks[i] = nullptr;
      }
    }
    losses.SetRobust(false);
    passes.Run(options.iterations_second, &solver_options, &result);
    for (int i = 0; i < num_obs; ++i) {
      if (!outlier[i]) outlier[i] = IsOutlier(k, problem.observations[i], state, options);
    }
  }
  for (int i = 0; i < num_obs; ++i) {
    if (outlier[i]) result.outlier_observations.push_back(i);
  }
  write_result();
  return result;
}

}  // namespace internal
}  // namespace pkslam
