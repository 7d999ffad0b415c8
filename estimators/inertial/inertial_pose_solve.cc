#include "estimators/inertial/inertial_pose_solve.h"

#include <ceres/crs_matrix.h>
#include <ceres/loss_function.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <cmath>
#include <memory>
#include <vector>

#include "core/util/error.h"
#include "estimators/optim/ceres_setup.h"
#include "imu/imu_factors.h"
#include "imu/imu_manifolds.h"

namespace pkslam {
namespace {

using Correspondence = PoseCorrespondence;

double Chi2(const BodyCamera& camera, const SE3d& world_from_body, const Correspondence& c) {
  return c.stereo ? BodyStereoChi2(camera, world_from_body, c.p_world, c.obs, c.inv_sigma2)
                  : BodyMonoChi2(camera, world_from_body, c.p_world, c.obs.head<2>(), c.inv_sigma2);
}

// Blocks of one inertial state.
struct StateBlocks {
  double pose[kBodyPoseBlockSize];
  double v[3];
  double bg[3];
  double ba[3];
  void Set(const NavState& s, const ImuBias& b) {
    BodyPoseToBlock(s.world_from_body, pose);
    Eigen::Vector3d::Map(v) = s.velocity_world;
    Eigen::Vector3d::Map(bg) = b.gyro;
    Eigen::Vector3d::Map(ba) = b.accel;
  }
  NavState State() const { return {BodyPoseFromBlock(pose), Eigen::Map<const Eigen::Vector3d>(v)}; }
  ImuBias Bias() const {
    return {Eigen::Map<const Eigen::Vector3d>(bg), Eigen::Map<const Eigen::Vector3d>(ba)};
  }
};

// J^T J of the problem's residuals over `blocks` (tangent coordinates, in that order).
Eigen::MatrixXd Hessian(ceres::Problem* problem, const std::vector<double*>& blocks) {
  ceres::Problem::EvaluateOptions eval;
  eval.parameter_blocks = blocks;
  eval.apply_loss_function = false;
  ceres::CRSMatrix jacobian;
  problem->Evaluate(eval, nullptr, nullptr, nullptr, &jacobian);
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(jacobian.num_cols, jacobian.num_cols);
  for (int r = 0; r < jacobian.num_rows; ++r) {
    const int begin = jacobian.rows[r];
    const int end = jacobian.rows[r + 1];
    for (int a = begin; a < end; ++a) {
      for (int b = begin; b < end; ++b) {
        h(jacobian.cols[a], jacobian.cols[b]) += jacobian.values[a] * jacobian.values[b];
      }
    }
  }
  return h;
}

}  // namespace

InertialPoseOutput SolveInertialPose(const BodyCamera& camera, const NavState& initial_state,
                                     const ImuBias& initial_bias,
                                     std::vector<PoseCorrespondence>* correspondences,
                                     const InertialPoseInput& input,
                                     const PoseOptimizerOptions& options) {
  options.Check();
  PKSLAM_CHECK(input.preintegration != nullptr, "inertial pose optimisation without IMU");
  ReprojectionLosses losses(options.chi2_mono, options.chi2_stereo, /*robust=*/false);
  BodyPoseManifold pose_manifold;
  ceres::Problem problem(
      ProblemOptions({.cost_functions = true, .loss_functions = true, .fast_removal = true}));

  StateBlocks cur;
  StateBlocks prev;
  cur.Set(initial_state, initial_bias);
  prev.Set(input.previous_state, input.previous_bias);
  const bool prev_free = input.previous_information.has_value();
  for (StateBlocks* s : {&cur, &prev}) {
    problem.AddParameterBlock(s->pose, kBodyPoseBlockSize, &pose_manifold);
    problem.AddParameterBlock(s->v, 3);
    problem.AddParameterBlock(s->bg, 3);
    problem.AddParameterBlock(s->ba, 3);
  }
  if (!prev_free) {
    for (double* b : {prev.pose, prev.v, prev.bg, prev.ba}) problem.SetParameterBlockConstant(b);
  }

  // Inertial edge (with the frame's biases, as ORB-SLAM3), bias walks, and the prior.
  const PreintegratedImu& pim = *input.preintegration;
  InertialError inertial(pim, input.gravity_world);
  problem.AddResidualBlock(&inertial, nullptr,
                           {prev.pose, prev.v, cur.bg, cur.ba, cur.pose, cur.v});
  const auto walk_g = BiasRandomWalkError::Gyro(pim);
  const auto walk_a = BiasRandomWalkError::Accel(pim);
  problem.AddResidualBlock(walk_g.get(), nullptr, prev.bg, cur.bg);
  problem.AddResidualBlock(walk_a.get(), nullptr, prev.ba, cur.ba);
  std::unique_ptr<InertialStatePriorError> prior;
  if (prev_free) {
    prior = std::make_unique<InertialStatePriorError>(input.previous_state, input.previous_bias,
                                                      *input.previous_information);
    problem.AddResidualBlock(prior.get(), nullptr, {prev.pose, prev.v, prev.bg, prev.ba});
  }

  auto add = [&](Correspondence& c) {
    if (!c.cost) {
      if (c.stereo) {
        c.cost = std::make_unique<BodyStereoPoseOnlyError>(camera, c.p_world, c.obs, c.inv_sigma2);
      } else {
        c.cost = std::make_unique<BodyMonoPoseOnlyError>(camera, c.p_world, c.obs.head<2>(),
                                                         c.inv_sigma2);
      }
    }
    c.block = problem.AddResidualBlock(c.cost.get(), c.stereo ? losses.stereo() : losses.mono(),
                                       cur.pose);
  };
  for (Correspondence& c : *correspondences) {
    if (std::isfinite(Chi2(camera, cur.State().world_from_body, c))) add(c);
  }

  // The (many) reprojection rows touch only the frame's pose: Schur-eliminating the pose folds
  // them into a 6 x 6 block, instead of a dense rows x 30 Jacobian (measured 2x faster tracking).
  ceres::Solver::Options solver_options =
      SolverOptions(ceres::DENSE_SCHUR, options.iterations_per_round, options.num_threads);
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  ordering->AddElementToGroup(cur.pose, 0);
  for (double* b : {cur.v, cur.bg, cur.ba, prev.pose, prev.v, prev.bg, prev.ba}) {
    ordering->AddElementToGroup(b, 1);
  }
  solver_options.linear_solver_ordering = ordering;

  int inliers = 0;
  for (int round = 0; round < options.rounds; ++round) {
    const bool robust = round < options.robust_rounds;
    losses.SetRobust(robust);
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    const SE3d world_from_body = cur.State().world_from_body;
    inliers = ReclassifyCorrespondences(
        correspondences, &problem, options.chi2_mono, options.chi2_stereo,
        [&](const Correspondence& c) { return Chi2(camera, world_from_body, c); }, add);
  }
  losses.SetRobust(false);

  InertialPoseOutput out;
  out.inliers = inliers;
  out.state = cur.State();
  out.bias = cur.Bias();
  // Marginal information of the frame's state: Schur complement of the previous state's block.
  std::vector<double*> blocks = {cur.pose, cur.v, cur.bg, cur.ba};
  if (prev_free) {
    for (double* b : {prev.pose, prev.v, prev.bg, prev.ba}) blocks.push_back(b);
  }
  const Eigen::MatrixXd h = Hessian(&problem, blocks);
  if (prev_free) {
    const Eigen::MatrixXd h_pp = h.bottomRightCorner(15, 15);
    const Eigen::MatrixXd h_cp = h.topRightCorner(15, 15);
    const Eigen::MatrixXd h_pp_inv =
        h_pp.selfadjointView<Eigen::Lower>().ldlt().solve(Eigen::MatrixXd::Identity(15, 15));
    out.information = h.topLeftCorner(15, 15) - h_cp * h_pp_inv * h_cp.transpose();
  } else {
    out.information = h.topLeftCorner(15, 15);
  }
  out.information = 0.5 * (out.information + out.information.transpose()).eval();
  return out;
}

}  // namespace pkslam
