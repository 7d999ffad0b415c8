// Solve phase of visual-inertial bundle adjustment: Ceres on a copy of the collected state.
#include <ceres/crs_matrix.h>
#include <ceres/iteration_callback.h>
#include <ceres/loss_function.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/util/error.h"
#include "core/util/log.h"
#include "estimators/inertial/inertial_bundle.h"
#include "estimators/inertial/marginalization.h"
#include "estimators/optim/ceres_setup.h"
#include "imu/body_reprojection_error.h"
#include "imu/imu_factors.h"
#include "imu/imu_manifolds.h"

namespace pkslam {
namespace {

// Every block in one buffer (poses, velocities, gyro biases, accel biases, points): Ceres orders
// the blocks of an elimination group by address, so separate vectors made the order of the
// reduced system, and with it the last bits of the result, depend on where malloc put them
// (--deterministic runs differed with the address layout).
struct State {
  State(int num_kf, int num_points)
      : kf(num_kf),
        data(static_cast<std::size_t>((kBodyPoseBlockSize + 9) * num_kf + 3 * num_points)) {}
  int kf;
  std::vector<double> data;
  double* pose(int i) { return data.data() + kBodyPoseBlockSize * i; }
  double* v(int i) { return data.data() + kBodyPoseBlockSize * kf + 3 * i; }
  double* bg(int i) { return data.data() + (kBodyPoseBlockSize + 3) * kf + 3 * i; }
  double* ba(int i) { return data.data() + (kBodyPoseBlockSize + 6) * kf + 3 * i; }
  double* point(int i) { return data.data() + (kBodyPoseBlockSize + 9) * kf + 3 * i; }
};

double ObservationChi2(const BodyCamera& camera, const BundleProblem::ObservationState& o,
                       State& s) {
  const SE3d world_from_body = BodyPoseFromBlock(s.pose(o.keyframe_index));
  const Eigen::Map<const Eigen::Vector3d> p(s.point(o.point_index));
  if (o.u_right >= 0) {
    return BodyStereoChi2(camera, world_from_body, p,
                          Eigen::Vector3d(o.uv.x(), o.uv.y(), o.u_right), o.inv_sigma2);
  }
  return BodyMonoChi2(camera, world_from_body, p, o.uv, o.inv_sigma2);
}

// The marginal of the anchor's factors (`residuals`, at the current values) on the next
// keyframe's state: `blocks` are the anchor's then the next keyframe's {pose, v, b_g, b_a}.
// Residual blocks from `first_visual` on are reprojections, weighted by
// options.marginalization_visual_weight.
std::optional<InertialStatePrior> MarginalPrior(
    ceres::Problem& problem, const std::vector<double*>& blocks,
    const std::vector<ceres::ResidualBlockId>& residuals, std::size_t first_visual,
    const InertialBundleOptions& options) {
  constexpr int kState = 15;
  // A fixed anchor (no prior of its own) is marginalised as a free state.
  for (int k = 0; k < 4; ++k) problem.SetParameterBlockVariable(blocks[k]);
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.parameter_blocks = blocks;
  evaluate.residual_blocks = residuals;
  evaluate.apply_loss_function = true;
  evaluate.num_threads = options.num_threads;
  double cost = 0;
  std::vector<double> r;
  ceres::CRSMatrix crs;
  if (!problem.Evaluate(evaluate, &cost, &r, nullptr, &crs) || crs.num_cols != 2 * kState) {
    return std::nullopt;
  }
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) j(row, crs.cols[k]) = crs.values[k];
  }
  Eigen::VectorXd residual =
      Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
  int visual_row = 0;
  for (std::size_t i = 0; i < first_visual && i < residuals.size(); ++i) {
    visual_row += problem.GetCostFunctionForResidualBlock(residuals[i])->num_residuals();
  }
  if (options.marginalization_visual_weight != 1.0 && visual_row < crs.num_rows) {
    const double w = std::sqrt(options.marginalization_visual_weight);
    j.bottomRows(crs.num_rows - visual_row) *= w;
    residual.tail(crs.num_rows - visual_row) *= w;
  }
  const Eigen::MatrixXd h = j.transpose() * j;
  const Eigen::VectorXd b = j.transpose() * residual;
  Eigen::MatrixXd h_next;
  Eigen::VectorXd b_next;
  MarginalizeLeading(h, b, kState, &h_next, &b_next, options.marginalization_threshold);
  if (!h_next.allFinite() || !b_next.allFinite()) return std::nullopt;
  NavState next;
  next.world_from_body = BodyPoseFromBlock(blocks[4]);
  next.velocity_world = Eigen::Map<const Eigen::Vector3d>(blocks[5]);
  const ImuBias bias{Eigen::Vector3d(Eigen::Map<const Eigen::Vector3d>(blocks[6])),
                     Eigen::Vector3d(Eigen::Map<const Eigen::Vector3d>(blocks[7]))};
  return MakeInertialStatePrior(next, bias, h_next, b_next);
}

}  // namespace

void InertialBundleOptions::Check() const {
  PKSLAM_CHECK_OPTION(window >= 2, "inertial_ba.window", "{}", window);
  PKSLAM_CHECK_OPTION(max_fixed_keyframes >= 0, "inertial_ba.max_fixed_keyframes", "{}",
                      max_fixed_keyframes);
  PKSLAM_CHECK_OPTION(iterations_first >= 1 && iterations_second >= 0, "inertial_ba.iterations",
                      "{} / {}", iterations_first, iterations_second);
  PKSLAM_CHECK_OPTION(chi2_mono > 0 && chi2_stereo > 0, "inertial_ba.chi2", "{} / {}", chi2_mono,
                      chi2_stereo);
  PKSLAM_CHECK_OPTION(num_threads >= 1, "inertial_ba.num_threads", "{}", num_threads);
  PKSLAM_CHECK_OPTION(gravity_magnitude > 0, "inertial_ba.gravity_magnitude", "{}",
                      gravity_magnitude);
  PKSLAM_CHECK_OPTION(marginalization_threshold >= 0 && marginalization_threshold < 1,
                      "inertial_ba.marginalization_threshold", "{}", marginalization_threshold);
  PKSLAM_CHECK_OPTION(marginalization_visual_weight > 0 && marginalization_visual_weight <= 1,
                      "inertial_ba.marginalization_visual_weight", "{}",
                      marginalization_visual_weight);
}

InertialBundleResult SolveInertialBundle(const InertialBundleProblem& problem,
                                         const InertialBundleOptions& options,
                                         const std::atomic<bool>* abort, WorkMeter* work) {
  options.Check();
  const BundleProblem& visual = problem.visual;
  const int num_kf = static_cast<int>(visual.keyframes.size());
  const int num_points = static_cast<int>(visual.points.size());
  const BodyCamera camera = BodyCamera::Of({visual.fx, visual.fy, visual.cx, visual.cy, visual.bf},
                                           problem.camera_from_body);
  const SE3d body_from_camera = problem.camera_from_body.Inverse();

  State s(num_kf, num_points);
  for (int i = 0; i < num_kf; ++i) {
    BodyPoseToBlock(visual.keyframes[i].camera_from_world.Inverse() * problem.camera_from_body,
                    s.pose(i));
    Eigen::Map<Eigen::Vector3d>(s.v(i)) = problem.velocities[i];
    Eigen::Map<Eigen::Vector3d>(s.bg(i)) = problem.biases[i].gyro;
    Eigen::Map<Eigen::Vector3d>(s.ba(i)) = problem.biases[i].accel;
  }
  for (int i = 0; i < num_points; ++i) {
    Eigen::Map<Eigen::Vector3d>(s.point(i)) = visual.points[i].position_world;
  }
  // With shared biases every keyframe uses the blocks of the first inertial keyframe.
  int shared_index = -1;
  for (int i = 0; i < num_kf && problem.shared_bias; ++i) {
    if (problem.inertial[i] != 0) {
      shared_index = i;
      break;
    }
  }
  auto bg = [&](int i) { return s.bg(shared_index >= 0 ? shared_index : i); };
  auto ba = [&](int i) { return s.ba(shared_index >= 0 ? shared_index : i); };

  InertialBundleResult result;
  auto write_result = [&]() {
    result.visual.camera_from_world.clear();
    result.visual.points_world.clear();
    result.velocities.clear();
    result.biases.clear();
    for (int i = 0; i < num_kf; ++i) {
      result.visual.camera_from_world.push_back(
          visual.keyframes[i].fixed ? visual.keyframes[i].camera_from_world
                                    : (BodyPoseFromBlock(s.pose(i)) * body_from_camera).Inverse());
      result.velocities.emplace_back(Eigen::Map<const Eigen::Vector3d>(s.v(i)));
      result.biases.emplace_back(Eigen::Map<const Eigen::Vector3d>(bg(i)),
                                 Eigen::Map<const Eigen::Vector3d>(ba(i)));
    }
    for (int i = 0; i < num_points; ++i) {
      result.visual.points_world.emplace_back(Eigen::Map<const Eigen::Vector3d>(s.point(i)));
    }
  };
  if (problem.empty() || (abort != nullptr && abort->load())) {
    result.visual.aborted = !problem.empty();
    write_result();
    return result;
  }

  ReprojectionLosses losses(options.chi2_mono, options.chi2_stereo, /*robust=*/true);
  BodyPoseManifold pose_manifold;
  // Removing outlier blocks between the passes needs Ceres' removal index; a single pass
  // (ORB-SLAM3's local inertial BA) only classifies them and skips its upkeep.
  ceres::Problem ceres_problem(
      ProblemOptions({.loss_functions = true, .fast_removal = options.iterations_second > 0}));

  std::vector<std::uint8_t> pose_added(static_cast<std::size_t>(num_kf), 0);
  auto add_pose = [&](int i) {
    if (pose_added[i]) return;
    ceres_problem.AddParameterBlock(s.pose(i), kBodyPoseBlockSize, &pose_manifold);
    if (visual.keyframes[i].fixed) ceres_problem.SetParameterBlockConstant(s.pose(i));
    pose_added[i] = 1;
  };
  // Inertial blocks: constant for anchors (inertial == 2).
  std::vector<std::uint8_t> inertial_added(static_cast<std::size_t>(num_kf), 0);
  auto add_inertial = [&](int i) {
    add_pose(i);
    if (inertial_added[i]) return;
    inertial_added[i] = 1;
    ceres_problem.AddParameterBlock(s.v(i), 3);
    ceres_problem.AddParameterBlock(bg(i), 3);
    ceres_problem.AddParameterBlock(ba(i), 3);
    if (problem.inertial[i] == 2) {
      ceres_problem.SetParameterBlockConstant(s.v(i));
      if (shared_index < 0) {
        ceres_problem.SetParameterBlockConstant(bg(i));
        ceres_problem.SetParameterBlockConstant(ba(i));
      }
    }
  };

  // The residual blocks of the anchor that the marginalisation folds into the next prior.
  const int marg_from = problem.marginalize_from;
  const int marg_to = problem.marginalize_to;
  const bool marginalize = marg_from >= 0 && marg_to >= 0 && shared_index < 0;
  std::vector<ceres::ResidualBlockId> marginalized;
  bool marg_edge = false;
  if (problem.anchor_prior && marg_from >= 0 && shared_index < 0) {
    add_inertial(marg_from);
    const InertialStatePrior& prior = *problem.anchor_prior;
    marginalized.push_back(ceres_problem.AddResidualBlock(
        prior.sqrt_information
            ? new InertialStatePriorError(prior.mean, prior.bias_mean, *prior.sqrt_information,
                                          InertialStatePriorError::SqrtInformation{})
            : new InertialStatePriorError(prior.mean, prior.bias_mean, prior.information),
        nullptr, {s.pose(marg_from), s.v(marg_from), bg(marg_from), ba(marg_from)}));
  }
  for (const auto& e : problem.edges) {
    add_inertial(e.from);
    add_inertial(e.to);
    const bool marg = marginalize && e.from == marg_from && e.to == marg_to;
    marg_edge = marg_edge || marg;
    const ceres::ResidualBlockId inertial = ceres_problem.AddResidualBlock(
        new InertialError(e.preintegration, problem.gravity_world), nullptr,
        {s.pose(e.from), s.v(e.from), bg(e.from), ba(e.from), s.pose(e.to), s.v(e.to)});
    if (marg) marginalized.push_back(inertial);
    if (shared_index < 0) {
      const ceres::ResidualBlockId gyro = ceres_problem.AddResidualBlock(
          BiasRandomWalkError::Gyro(e.preintegration).release(), nullptr, bg(e.from), bg(e.to));
      const ceres::ResidualBlockId accel = ceres_problem.AddResidualBlock(
          BiasRandomWalkError::Accel(e.preintegration).release(), nullptr, ba(e.from), ba(e.to));
      if (marg) {
        marginalized.push_back(gyro);
        marginalized.push_back(accel);
      }
    }
  }
  if (shared_index >= 0) {
    if (problem.gyro_prior_information > 0) {
      ceres_problem.AddResidualBlock(
          new BiasPriorError(Eigen::Vector3d::Zero(), problem.gyro_prior_information), nullptr,
          bg(shared_index));
    }
    if (problem.accel_prior_information > 0) {
      ceres_problem.AddResidualBlock(
          new BiasPriorError(Eigen::Vector3d::Zero(), problem.accel_prior_information), nullptr,
          ba(shared_index));
    }
  }

  const int num_obs = static_cast<int>(visual.observations.size());
  std::vector<ceres::ResidualBlockId> blocks(static_cast<std::size_t>(num_obs), nullptr);
  std::vector<std::uint8_t> point_added(static_cast<std::size_t>(num_points), 0);
  for (int i = 0; i < num_obs; ++i) {
    const BundleProblem::ObservationState& o = visual.observations[i];
    if (!std::isfinite(ObservationChi2(camera, o, s))) continue;
    add_pose(o.keyframe_index);
    point_added[o.point_index] = 1;
    double* pose = s.pose(o.keyframe_index);
    double* point = s.point(o.point_index);
    if (o.u_right >= 0) {
      blocks[i] = ceres_problem.AddResidualBlock(
          new BodyStereoReprojectionError(camera, Eigen::Vector3d(o.uv.x(), o.uv.y(), o.u_right),
                                          o.inv_sigma2),
          losses.stereo(), pose, point);
    } else {
      blocks[i] = ceres_problem.AddResidualBlock(
          new BodyMonoReprojectionError(camera, o.uv, o.inv_sigma2), losses.mono(), pose, point);
    }
  }

  int free_poses = 0;
  for (int i = 0; i < num_kf; ++i) free_poses += pose_added[i] && !visual.keyframes[i].fixed;
  ceres::Solver::Options solver_options =
      SolverOptions(SchurSolverFor(free_poses), 0, options.num_threads);
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (int i = 0; i < num_points; ++i) {
    if (point_added[i]) ordering->AddElementToGroup(s.point(i), 0);
  }
  for (int i = 0; i < num_kf; ++i) {
    if (pose_added[i]) ordering->AddElementToGroup(s.pose(i), 1);
    if (inertial_added[i]) {
      ordering->AddElementToGroup(s.v(i), 1);
      if (shared_index < 0 || i == shared_index) {
        ordering->AddElementToGroup(bg(i), 1);
        ordering->AddElementToGroup(ba(i), 1);
      }
    }
  }
  solver_options.linear_solver_ordering = ordering;
  AbortCallback abort_callback(abort, work, &ceres_problem);
  solver_options.callbacks.push_back(&abort_callback);

  bool first = true;
  auto solve = [&](int iterations) {
    if (ceres_problem.NumResidualBlocks() == 0) return;
    solver_options.max_num_iterations = iterations;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &ceres_problem, &summary);
    if (first) result.visual.initial_cost = summary.initial_cost;
    first = false;
    result.visual.final_cost = summary.final_cost;
    result.visual.iterations += std::max(0, static_cast<int>(summary.iterations.size()) - 1);
    result.visual.aborted = abort_callback.fired();
    if (summary.termination_type == ceres::FAILURE) {
      PKSLAM_LOG_WARN("inertial bundle adjustment: solver failure: {}", summary.message);
    }
  };

  solve(options.iterations_first);
  for (int i = 0; i < num_obs; ++i) {
    const auto& o = visual.observations[i];
    const bool outlier = !(ObservationChi2(camera, o, s) <=
                           (o.u_right >= 0 ? options.chi2_stereo : options.chi2_mono));
    if (!outlier) continue;
    result.visual.outlier_observations.push_back(i);
    if (blocks[i] != nullptr && options.iterations_second > 0) {
      ceres_problem.RemoveResidualBlock(blocks[i]);
      blocks[i] = nullptr;
    }
  }
  if (!result.visual.aborted && options.iterations_second > 0) {
    losses.SetRobust(false);
    solve(options.iterations_second);
  }
  if (marginalize && marg_edge && !result.visual.aborted) {
    std::vector<std::uint8_t> outlier(static_cast<std::size_t>(num_obs), 0);
    for (int i : result.visual.outlier_observations) outlier[i] = 1;
    const std::size_t first_visual = marginalized.size();
    for (int i = 0; i < num_obs; ++i) {
      if (blocks[i] != nullptr && outlier[i] == 0 &&
          visual.observations[i].keyframe_index == marg_from) {
        marginalized.push_back(blocks[i]);
      }
    }
    result.next_prior =
        MarginalPrior(ceres_problem,
                      {s.pose(marg_from), s.v(marg_from), bg(marg_from), ba(marg_from),
                       s.pose(marg_to), s.v(marg_to), bg(marg_to), ba(marg_to)},
                      marginalized, first_visual, options);
  }
  write_result();
  return result;
}

}  // namespace pkslam
