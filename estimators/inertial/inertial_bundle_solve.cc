// Solve phase of visual-inertial bundle adjustment: Ceres on a copy of the collected state.
#include <ceres/crs_matrix.h>
#include <ceres/iteration_callback.h>
#include <ceres/loss_function.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <cmath>
#include <memory>
#include <vector>

#include "core/util/error.h"
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

// One solve: the state copied from the problem, the Ceres problem built over it, the passes,
// and the result written back from it.
class InertialSolve {
 public:
  InertialSolve(const InertialBundleProblem& problem, const InertialBundleOptions& options)
      : problem_(problem),
        options_(options),
        visual_(problem.visual),
        num_kf_(static_cast<int>(visual_.keyframes.size())),
        num_points_(static_cast<int>(visual_.points.size())),
        camera_(BodyCamera::Of({visual_.fx, visual_.fy, visual_.cx, visual_.cy, visual_.bf},
                               problem.camera_from_body)),
        body_from_camera_(problem.camera_from_body.Inverse()),
        s_(num_kf_, num_points_),
        losses_(options.chi2_mono, options.chi2_stereo, /*robust=*/true),
        // Removing outlier blocks between the passes needs Ceres' removal index; a single pass
        // (ORB-SLAM3's local inertial BA) only classifies them and skips its upkeep.
        ceres_problem_(ProblemOptions(
            {.loss_functions = true, .fast_removal = options.iterations_second > 0})),
        pose_added_(static_cast<std::size_t>(num_kf_), 0),
        inertial_added_(static_cast<std::size_t>(num_kf_), 0) {
    for (int i = 0; i < num_kf_; ++i) {
      BodyPoseToBlock(visual_.keyframes[i].camera_from_world.Inverse() * problem.camera_from_body,
                      s_.pose(i));
      Eigen::Map<Eigen::Vector3d>(s_.v(i)) = problem.velocities[i];
      Eigen::Map<Eigen::Vector3d>(s_.bg(i)) = problem.biases[i].gyro;
      Eigen::Map<Eigen::Vector3d>(s_.ba(i)) = problem.biases[i].accel;
    }
    for (int i = 0; i < num_points_; ++i) {
      Eigen::Map<Eigen::Vector3d>(s_.point(i)) = visual_.points[i].position_world;
    }
    // With shared biases every keyframe uses the blocks of the first inertial keyframe.
    for (int i = 0; i < num_kf_ && problem.shared_bias; ++i) {
      if (problem.inertial[i] != 0) {
        shared_index_ = i;
        break;
      }
    }
  }

  // The result as the problem stands (`aborted`: before any solve).
  InertialBundleResult Unsolved(bool aborted) {
    result_.visual.aborted = aborted;
    WriteResult();
    return std::move(result_);
  }

  InertialBundleResult Run(const std::atomic<bool>* abort, WorkMeter* work) {
    AddInertialResiduals();
    AddObservations();
    ceres::Solver::Options solver_options = Options();
    AbortCallback abort_callback(abort, work, &ceres_problem_);
    solver_options.callbacks.push_back(&abort_callback);
    BundlePasses passes(&ceres_problem_, &abort_callback, "inertial bundle adjustment");
    passes.Run(options_.iterations_first, &solver_options, &result_.visual);
    ClassifyOutliers();
    if (!result_.visual.aborted && options_.iterations_second > 0) {
      losses_.SetRobust(false);
      passes.Run(options_.iterations_second, &solver_options, &result_.visual);
    }
    if (marginalize_ && marg_edge_ && !result_.visual.aborted) Marginalize();
    WriteResult();
    return std::move(result_);
  }

 private:
  double* bg(int i) { return s_.bg(shared_index_ >= 0 ? shared_index_ : i); }
  double* ba(int i) { return s_.ba(shared_index_ >= 0 ? shared_index_ : i); }

  void WriteResult() {
    result_.visual.camera_from_world.clear();
    result_.visual.points_world.clear();
    result_.velocities.clear();
    result_.biases.clear();
    for (int i = 0; i < num_kf_; ++i) {
      result_.visual.camera_from_world.push_back(
          visual_.keyframes[i].fixed
              ? visual_.keyframes[i].camera_from_world
              : (BodyPoseFromBlock(s_.pose(i)) * body_from_camera_).Inverse());
      result_.velocities.emplace_back(Eigen::Map<const Eigen::Vector3d>(s_.v(i)));
      result_.biases.emplace_back(Eigen::Map<const Eigen::Vector3d>(bg(i)),
                                  Eigen::Map<const Eigen::Vector3d>(ba(i)));
    }
    for (int i = 0; i < num_points_; ++i) {
      result_.visual.points_world.emplace_back(Eigen::Map<const Eigen::Vector3d>(s_.point(i)));
    }
  }

  void AddPose(int i) {
    if (pose_added_[i]) return;
    ceres_problem_.AddParameterBlock(s_.pose(i), kBodyPoseBlockSize, &pose_manifold_);
    if (visual_.keyframes[i].fixed) ceres_problem_.SetParameterBlockConstant(s_.pose(i));
    pose_added_[i] = 1;
  }

  // Inertial blocks: constant for anchors (inertial == 2).
  void AddInertial(int i) {
    AddPose(i);
    if (inertial_added_[i]) return;
    inertial_added_[i] = 1;
    ceres_problem_.AddParameterBlock(s_.v(i), 3);
    ceres_problem_.AddParameterBlock(bg(i), 3);
    ceres_problem_.AddParameterBlock(ba(i), 3);
    if (problem_.inertial[i] == 2) {
      ceres_problem_.SetParameterBlockConstant(s_.v(i));
      if (shared_index_ < 0) {
        ceres_problem_.SetParameterBlockConstant(bg(i));
        ceres_problem_.SetParameterBlockConstant(ba(i));
      }
    }
  }

  // The anchor's prior, the preintegration edges with their bias random walks (or the shared
  // biases' priors), noting the residual blocks of the anchor that the marginalisation folds
  // into the next prior.
  void AddInertialResiduals() {
    const int marg_from = problem_.marginalize_from;
    const int marg_to = problem_.marginalize_to;
    marginalize_ = marg_from >= 0 && marg_to >= 0 && shared_index_ < 0;
    if (problem_.anchor_prior && marg_from >= 0 && shared_index_ < 0) {
      AddInertial(marg_from);
      const InertialStatePrior& prior = *problem_.anchor_prior;
      marginalized_.push_back(ceres_problem_.AddResidualBlock(
          prior.sqrt_information
              ? new InertialStatePriorError(prior.mean, prior.bias_mean, *prior.sqrt_information,
                                            InertialStatePriorError::SqrtInformation{})
              : new InertialStatePriorError(prior.mean, prior.bias_mean, prior.information),
          nullptr, {s_.pose(marg_from), s_.v(marg_from), bg(marg_from), ba(marg_from)}));
    }
    for (const auto& e : problem_.edges) {
      AddInertial(e.from);
      AddInertial(e.to);
      const bool marg = marginalize_ && e.from == marg_from && e.to == marg_to;
      marg_edge_ = marg_edge_ || marg;
      const ceres::ResidualBlockId inertial = ceres_problem_.AddResidualBlock(
          new InertialError(e.preintegration, problem_.gravity_world), nullptr,
          {s_.pose(e.from), s_.v(e.from), bg(e.from), ba(e.from), s_.pose(e.to), s_.v(e.to)});
      if (marg) marginalized_.push_back(inertial);
      if (shared_index_ < 0) {
        const ceres::ResidualBlockId gyro = ceres_problem_.AddResidualBlock(
            BiasRandomWalkError::Gyro(e.preintegration).release(), nullptr, bg(e.from), bg(e.to));
        const ceres::ResidualBlockId accel = ceres_problem_.AddResidualBlock(
            BiasRandomWalkError::Accel(e.preintegration).release(), nullptr, ba(e.from), ba(e.to));
        if (marg) {
          marginalized_.push_back(gyro);
          marginalized_.push_back(accel);
        }
      }
    }
    if (shared_index_ >= 0) {
      if (problem_.gyro_prior_information > 0) {
        ceres_problem_.AddResidualBlock(
            new BiasPriorError(Eigen::Vector3d::Zero(), problem_.gyro_prior_information), nullptr,
            bg(shared_index_));
      }
      if (problem_.accel_prior_information > 0) {
        ceres_problem_.AddResidualBlock(
            new BiasPriorError(Eigen::Vector3d::Zero(), problem_.accel_prior_information), nullptr,
            ba(shared_index_));
      }
    }
  }

  void AddObservations() {
    const int num_obs = static_cast<int>(visual_.observations.size());
    blocks_.assign(static_cast<std::size_t>(num_obs), nullptr);
    point_added_.assign(static_cast<std::size_t>(num_points_), 0);
    for (int i = 0; i < num_obs; ++i) {
      const BundleProblem::ObservationState& o = visual_.observations[i];
      if (!std::isfinite(ObservationChi2(camera_, o, s_))) continue;
      AddPose(o.keyframe_index);
      point_added_[o.point_index] = 1;
      double* pose = s_.pose(o.keyframe_index);
      double* point = s_.point(o.point_index);
      if (o.u_right >= 0) {
        blocks_[i] = ceres_problem_.AddResidualBlock(
            new BodyStereoReprojectionError(camera_, Eigen::Vector3d(o.uv.x(), o.uv.y(), o.u_right),
                                            o.inv_sigma2),
            losses_.stereo(), pose, point);
      } else {
        blocks_[i] = ceres_problem_.AddResidualBlock(
            new BodyMonoReprojectionError(camera_, o.uv, o.inv_sigma2), losses_.mono(), pose,
            point);
      }
    }
  }

  // Schur elimination: points first, then poses and inertial blocks.
  ceres::Solver::Options Options() {
    SchurBlocks schur;
    for (int i = 0; i < num_points_; ++i) {
      if (point_added_[i]) schur.AddPoint(s_.point(i));
    }
    for (int i = 0; i < num_kf_; ++i) {
      if (pose_added_[i]) {
        schur.AddOther(s_.pose(i));
        schur.free_poses += visual_.keyframes[i].fixed ? 0 : 1;
      }
      if (!inertial_added_[i]) continue;
      schur.AddOther(s_.v(i));
      if (shared_index_ < 0 || i == shared_index_) {
        schur.AddOther(bg(i));
        schur.AddOther(ba(i));
      }
    }
    return SchurSolverOptions(schur, options_.num_threads);
  }

  // Outliers after the robust pass; removed before a second pass.
  void ClassifyOutliers() {
    const int num_obs = static_cast<int>(visual_.observations.size());
    for (int i = 0; i < num_obs; ++i) {
      const auto& o = visual_.observations[i];
      const bool outlier = !(ObservationChi2(camera_, o, s_) <=
                             (o.u_right >= 0 ? options_.chi2_stereo : options_.chi2_mono));
      if (!outlier) continue;
      result_.visual.outlier_observations.push_back(i);
      if (blocks_[i] != nullptr && options_.iterations_second > 0) {
        ceres_problem_.RemoveResidualBlock(blocks_[i]);
        blocks_[i] = nullptr;
      }
    }
  }

  // The next keyframe's prior: the anchor's inertial factors and its inlier reprojections
  // marginalised onto it.
  void Marginalize() {
    const int marg_from = problem_.marginalize_from;
    const int marg_to = problem_.marginalize_to;
    const int num_obs = static_cast<int>(visual_.observations.size());
    std::vector<std::uint8_t> outlier(static_cast<std::size_t>(num_obs), 0);
    for (int i : result_.visual.outlier_observations) outlier[i] = 1;
    const std::size_t first_visual = marginalized_.size();
    for (int i = 0; i < num_obs; ++i) {
      if (blocks_[i] != nullptr && outlier[i] == 0 &&
          visual_.observations[i].keyframe_index == marg_from) {
        marginalized_.push_back(blocks_[i]);
      }
    }
    result_.next_prior =
        MarginalPrior(ceres_problem_,
                      {s_.pose(marg_from), s_.v(marg_from), bg(marg_from), ba(marg_from),
                       s_.pose(marg_to), s_.v(marg_to), bg(marg_to), ba(marg_to)},
                      marginalized_, first_visual, options_);
  }

  const InertialBundleProblem& problem_;
  const InertialBundleOptions& options_;
  const BundleProblem& visual_;
  const int num_kf_;
  const int num_points_;
  const BodyCamera camera_;
  const SE3d body_from_camera_;
  State s_;
  int shared_index_ = -1;
  InertialBundleResult result_;
  ReprojectionLosses losses_;
  BodyPoseManifold pose_manifold_;
  ceres::Problem ceres_problem_;
  std::vector<std::uint8_t> pose_added_;
  std::vector<std::uint8_t> inertial_added_;
  bool marginalize_ = false;
  bool marg_edge_ = false;
  std::vector<ceres::ResidualBlockId> marginalized_;
  std::vector<ceres::ResidualBlockId> blocks_;
  std::vector<std::uint8_t> point_added_;
};

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
  InertialSolve solve(problem, options);
  if (problem.empty() || (abort != nullptr && abort->load())) {
    return solve.Unsolved(/*aborted=*/!problem.empty());
  }
  return solve.Run(abort, work);
}

}  // namespace pkslam
