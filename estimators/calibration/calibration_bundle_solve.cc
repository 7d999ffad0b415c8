// Solve phase of the calibration bundle adjustment: Ceres on a copy of the collected state.
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/wall_time.h"
#include "estimators/calibration/calibration_bundle.h"
#include "estimators/calibration/calibration_residuals.h"
#include "estimators/calibration/calibration_solve_state.h"
#include "estimators/optim/ceres_setup.h"
#include "estimators/optim/marginal_covariance.h"
#include "estimators/optim/se3_manifold.h"
#include "imu/imu_factors.h"
#include "imu/imu_manifolds.h"

namespace pkslam {
namespace {

using calibration_solve::CalibrationManifolds;
using calibration_solve::FillSigmas;
using calibration_solve::ImuExtrinsicFree;
using calibration_solve::kRadToDeg;
using calibration_solve::RemoveNuisanceNullDirections;
using calibration_solve::State;
using calibration_solve::StereoExtrinsicFree;

void CopyArray(const std::array<double, kCalibIntrinsicsSize>& a, double* out) {
  std::copy(a.begin(), a.end(), out);
}

// The calibration blocks (intrinsics, extrinsics, time offset) with their priors around the
// file's values (`sig`: their sigmas); blocks the freedom does not free are constant.
void AddCalibrationBlocks(const CalibrationBundleProblem& problem,
                          const CalibrationPriorOptions& sig, CalibrationManifolds* m,
                          ceres::Problem* ceres_problem, State* s) {
  for (std::size_t c = 0; c < problem.initial.cameras.size() && c < 2; ++c) {
    double* block = s->intrinsics(static_cast<int>(c));
    ceres_problem->AddParameterBlock(block, kCalibIntrinsicsSize,
                                    c == 1 ? &m->right_intrinsics : nullptr);
    const auto mean = IntrinsicsBlock(problem.prior.cameras[c]);
    Eigen::VectorXd sigma(kCalibIntrinsicsSize);
    sigma << sig.focal_px, sig.focal_px, sig.principal_point_px, sig.principal_point_px, sig.k1,
        sig.k2;
    ceres_problem->AddResidualBlock(
        new EuclideanPriorError(Eigen::Map<const Eigen::VectorXd>(mean.data(), kCalibIntrinsicsSize),
                                sigma),
        nullptr, block);
    if (!problem.free.intrinsics[c]) ceres_problem->SetParameterBlockConstant(block);
  }
  ceres_problem->AddParameterBlock(s->cam0_from_body(), kCalibExtrinsicSize, &m->imu);
  ceres_problem->AddParameterBlock(s->cam1_from_cam0(), kCalibExtrinsicSize, &m->stereo);
  ceres_problem->AddParameterBlock(s->offset(), 1);
  ceres_problem->AddParameterBlock(s->no_velocity(), 3);
  ceres_problem->SetParameterBlockConstant(s->no_velocity());
  if (ImuExtrinsicFree(problem)) {
    // A rotation-only (translation-only) freedom holds the other part where it is now through
    // the block's manifold; the free part is drawn to the file's value.
    const SE3d file = problem.prior.body_from_cam0.Inverse();
    const SE3d now = problem.initial.body_from_cam0.Inverse();
    const SE3d mean(problem.free.imu_rotation ? file.so3() : now.so3(),
                    problem.free.imu_translation ? file.translation() : now.translation());
    ceres_problem->AddResidualBlock(
        new ExtrinsicPriorError(mean, sig.imu_translation_mm * 1e-3,
                                sig.imu_rotation_deg / kRadToDeg),
        nullptr, s->cam0_from_body());
  } else {
    ceres_problem->SetParameterBlockConstant(s->cam0_from_body());
  }
  if (StereoExtrinsicFree(problem)) {
    // Only the rotation about the cameras' y and z axes (kStereoHeldAxes): the baseline is the
    // map's scale (with an IMU, the accelerometers' scale factors pull it; the file's baseline is
    // the better-known), and the rotation about x moves the right image's rows, which the
    // matcher does not measure.
    const double t = sig.stereo_translation_mm * 1e-3;
    const double r = sig.stereo_rotation_deg / kRadToDeg;
    ceres_problem->AddResidualBlock(
        new ExtrinsicPriorError(problem.prior.cam1_from_cam0,
                                (Eigen::Matrix<double, 6, 1>() << t, t, t, r, r, r).finished()),
        nullptr, s->cam1_from_cam0());
  } else {
    ceres_problem->SetParameterBlockConstant(s->cam1_from_cam0());
  }
  if (problem.inertial && problem.free.time_offset) {
    ceres_problem->AddResidualBlock(
        new EuclideanPriorError(Eigen::VectorXd::Constant(1, problem.prior.time_offset_s),
                                Eigen::VectorXd::Constant(1, sig.time_offset_ms * 1e-3)),
        nullptr, s->offset());
  } else {
    ceres_problem->SetParameterBlockConstant(s->offset());
  }
  if (problem.inertial && (problem.free.gyro_scale || problem.free.accel_axes)) {
    // Both axis-error blocks enter the inertial edges (ImuAxesInertialError); the one not free
    // is constant, and the accelerometer's diagonal stays unless its scale is free.
    ceres_problem->AddParameterBlock(s->gyro_scale(), 3);
    ceres_problem->AddParameterBlock(s->accel_axes(), 9,
                                     problem.free.accel_scale ? nullptr : &m->accel_misalignment);
    if (!problem.free.gyro_scale) ceres_problem->SetParameterBlockConstant(s->gyro_scale());
    if (!problem.free.accel_axes) ceres_problem->SetParameterBlockConstant(s->accel_axes());
  }
  if (problem.inertial && problem.free.gyro_scale) {
    ceres_problem->AddResidualBlock(
        new EuclideanPriorError(problem.prior.gyro_scale,
                                Eigen::Vector3d::Constant(sig.gyro_scale_pct * 1e-2)),
        nullptr, s->gyro_scale());
  }
  if (problem.inertial && problem.free.accel_axes) {
    Eigen::Matrix<double, 9, 1> mean, sigma;
    for (int i = 0; i < 9; ++i) {
      mean(i) = problem.prior.accel_axes(i / 3, i % 3);
      sigma(i) = i % 4 == 0 ? sig.accel_scale_pct * 1e-2 : sig.accel_misalignment_deg / kRadToDeg;
    }
    ceres_problem->AddResidualBlock(new EuclideanPriorError(mean, sigma), nullptr, s->accel_axes());
  }
}

// One solve: the state copied from the problem, the Ceres problem built over it (calibration
// blocks, the inertial chain, the observations), the two passes, and the result.
class CalibrationSolve {
 public:
  CalibrationSolve(const CalibrationBundleProblem& problem, const CalibrationBundleOptions& options)
      : problem_(problem),
        options_(options),
        visual_(problem.bundle.visual),
        num_kf_(static_cast<int>(visual_.keyframes.size())),
        num_points_(static_cast<int>(visual_.points.size())),
        stereo_(problem.initial.stereo()),
        s_(num_kf_, num_points_),
        // cam1's fy and cy follow cam0's at the file's differences (CalibratedRightError).
        vertical_offset_(
            stereo_ ? Eigen::Vector2d(problem.prior.cameras[1].fy() - problem.prior.cameras[0].fy(),
                                      problem.prior.cameras[1].cy() - problem.prior.cameras[0].cy())
                    : Eigen::Vector2d::Zero()),
        ceres_problem_(ProblemOptions({.loss_functions = true, .fast_removal = true})),
        huber_left_(std::sqrt(options.chi2_left)),
        huber_right_(std::sqrt(options.chi2_right)),
        loss_left_(&huber_left_, ceres::DO_NOT_TAKE_OWNERSHIP),
        loss_right_(&huber_right_, ceres::DO_NOT_TAKE_OWNERSHIP),
        manifolds_(problem),
        pose_added_(static_cast<std::size_t>(num_kf_), 0),
        inertial_added_(static_cast<std::size_t>(num_kf_), 0) {
    for (int i = 0; i < num_kf_; ++i) {
      BodyPoseToBlock(
          visual_.keyframes[i].camera_from_world.Inverse() * problem.bundle.camera_from_body,
          s_.pose(i));
      if (problem.inertial && i < static_cast<int>(problem.bundle.velocities.size())) {
        Eigen::Map<Eigen::Vector3d>(s_.v(i)) = problem.bundle.velocities[i];
        Eigen::Map<Eigen::Vector3d>(s_.bg(i)) = problem.bundle.biases[i].gyro;
        Eigen::Map<Eigen::Vector3d>(s_.ba(i)) = problem.bundle.biases[i].accel;
      }
    }
    for (int i = 0; i < num_points_; ++i) {
      Eigen::Map<Eigen::Vector3d>(s_.point(i)) = visual_.points[i].position_world;
    }
    for (std::size_t c = 0; c < problem.initial.cameras.size() && c < 2; ++c) {
      CopyArray(IntrinsicsBlock(problem.initial.cameras[c]), s_.intrinsics(static_cast<int>(c)));
    }
    PoseToBlock(problem.initial.body_from_cam0.Inverse(), s_.cam0_from_body());
    PoseToBlock(problem.initial.cam1_from_cam0, s_.cam1_from_cam0());
    *s_.offset() = problem.initial.time_offset_s;
    Eigen::Map<Eigen::Vector3d>(s_.gyro_scale()) = problem.initial.gyro_scale;
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(s_.accel_axes()) =
        problem.initial.accel_axes;
    result_.estimate = problem.initial;
  }

  // The result as the problem stands (`aborted`: before any solve).
  CalibrationBundleResult Unsolved(bool aborted) {
    result_.bundle.visual.aborted = aborted;
    WriteResult();
    return std::move(result_);
  }

  CalibrationBundleResult Run(const std::atomic<bool>* abort, WorkMeter* work) {
    AddCalibrationBlocks(problem_, options_.prior, &manifolds_, &ceres_problem_, &s_);
    AddInertialChain();
    AddObservations();
    FixGauge();
    ceres::Solver::Options solver_options = Options();
    AbortCallback abort_callback(abort, work, &ceres_problem_,
                                 options_.min_iterations_before_abort);
    solver_options.callbacks.push_back(&abort_callback);
    BundlePasses passes(&ceres_problem_, &abort_callback, "calibration bundle adjustment");
    passes.Run(options_.iterations_first, &solver_options, &result_.bundle.visual);
    RejectOutliers();
    if (!result_.bundle.visual.aborted && options_.iterations_second > 0) {
      loss_left_.Reset(nullptr, ceres::DO_NOT_TAKE_OWNERSHIP);
      loss_right_.Reset(nullptr, ceres::DO_NOT_TAKE_OWNERSHIP);
      passes.Run(options_.iterations_second, &solver_options, &result_.bundle.visual);
    }
    WriteResult();
    if (options_.covariance && !result_.bundle.visual.aborted && problem_.free.Any()) Sigmas();
    return std::move(result_);
  }

 private:
  struct ObsBlocks {
    ceres::ResidualBlockId left = nullptr;
    ceres::ResidualBlockId right = nullptr;
    const CalibratedLeftError* left_cost = nullptr;
  };

  void WriteResult() {
    CalibrationBundleResult& result = result_;
    result.world_from_body.clear();
    result.bundle.velocities.clear();
    result.bundle.biases.clear();
    result.bundle.visual.points_world.clear();
    for (int i = 0; i < num_kf_; ++i) {
      result.world_from_body.push_back(BodyPoseFromBlock(s_.pose(i)));
      result.bundle.velocities.emplace_back(Eigen::Map<const Eigen::Vector3d>(s_.v(i)));
      result.bundle.biases.emplace_back(Eigen::Map<const Eigen::Vector3d>(s_.bg(i)),
                                        Eigen::Map<const Eigen::Vector3d>(s_.ba(i)));
    }
    for (int i = 0; i < num_points_; ++i) {
      result.bundle.visual.points_world.emplace_back(
          Eigen::Map<const Eigen::Vector3d>(s_.point(i)));
    }
    for (std::size_t c = 0; c < result.estimate.cameras.size() && c < 2; ++c) {
      double block[kCalibIntrinsicsSize];
      std::copy(s_.intrinsics(static_cast<int>(c)),
                s_.intrinsics(static_cast<int>(c)) + kCalibIntrinsicsSize, block);
      if (c == 1) {
        block[1] = s_.intrinsics(0)[1] + vertical_offset_[0];
        block[3] = s_.intrinsics(0)[3] + vertical_offset_[1];
      }
      result.estimate.cameras[c] = CameraFromIntrinsicsBlock(problem_.initial.cameras[c], block);
    }
    result.estimate.body_from_cam0 = PoseFromBlock(s_.cam0_from_body()).Inverse();
    result.estimate.cam1_from_cam0 = PoseFromBlock(s_.cam1_from_cam0());
    result.estimate.time_offset_s = *s_.offset();
    if (problem_.inertial) {
      result.estimate.gyro_scale = Eigen::Map<const Eigen::Vector3d>(s_.gyro_scale());
      result.estimate.accel_axes =
          Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(s_.accel_axes());
    }
    result.parameters = CalibrationParameters(problem_.prior, result.estimate, problem_.free,
                                              options_.prior, problem_.inertial);
  }

  void AddPose(int i) {
    if (pose_added_[i]) return;
    ceres_problem_.AddParameterBlock(s_.pose(i), kBodyPoseBlockSize, &pose_manifold_);
    if (visual_.keyframes[i].fixed) ceres_problem_.SetParameterBlockConstant(s_.pose(i));
    pose_added_[i] = 1;
  }

  void AddInertial(int i) {
    AddPose(i);
    if (inertial_added_[i]) return;
    inertial_added_[i] = 1;
    ceres_problem_.AddParameterBlock(s_.v(i), 3);
    ceres_problem_.AddParameterBlock(s_.bg(i), 3);
    ceres_problem_.AddParameterBlock(s_.ba(i), 3);
  }

  // Keyframes and the inertial chain, with the IMU's axis errors when either is free (the other
  // held constant).
  void AddInertialChain() {
    if (!problem_.inertial) return;
    const bool axes_free = problem_.free.gyro_scale || problem_.free.accel_axes;
    const std::size_t num_edges = problem_.bundle.edges.size();
    PKSLAM_CHECK(
        problem_.gyro_scale_jacobians.empty() || problem_.gyro_scale_jacobians.size() == num_edges,
        "calibration BA: {} gyro scale Jacobians for {} inertial edges",
        problem_.gyro_scale_jacobians.size(), num_edges);
    PKSLAM_CHECK(
        problem_.accel_axes_jacobians.empty() || problem_.accel_axes_jacobians.size() == num_edges,
        "calibration BA: {} accelerometer axes Jacobians for {} inertial edges",
        problem_.accel_axes_jacobians.size(), num_edges);
    for (std::size_t edge = 0; edge < num_edges; ++edge) {
      const auto& e = problem_.bundle.edges[edge];
      AddInertial(e.from);
      AddInertial(e.to);
      if (axes_free) {
        ceres_problem_.AddResidualBlock(
            new ImuAxesInertialError(
                e.preintegration, problem_.bundle.gravity_world,
                problem_.gyro_scale_jacobians.empty() ? GyroScaleJacobiansOf(e.preintegration)
                                                      : problem_.gyro_scale_jacobians[edge],
                problem_.accel_axes_jacobians.empty() ? AccelAxesJacobiansOf(e.preintegration)
                                                      : problem_.accel_axes_jacobians[edge],
                problem_.initial.gyro_scale, problem_.initial.accel_axes),
            nullptr,
            {s_.pose(e.from), s_.v(e.from), s_.bg(e.from), s_.ba(e.from), s_.pose(e.to), s_.v(e.to),
             s_.gyro_scale(), s_.accel_axes()});
      } else {
        ceres_problem_.AddResidualBlock(
            new InertialError(e.preintegration, problem_.bundle.gravity_world), nullptr,
            {s_.pose(e.from), s_.v(e.from), s_.bg(e.from), s_.ba(e.from), s_.pose(e.to),
             s_.v(e.to)});
      }
      ceres_problem_.AddResidualBlock(BiasRandomWalkError::Gyro(e.preintegration).release(),
                                      nullptr, s_.bg(e.from), s_.bg(e.to));
      ceres_problem_.AddResidualBlock(BiasRandomWalkError::Accel(e.preintegration).release(),
                                      nullptr, s_.ba(e.from), s_.ba(e.to));
    }
  }

  // The image timing of keyframe k's observations (the time offset's model).
  ImageTiming TimingOf(int k) const {
    ImageTiming timing;
    if (problem_.inertial && inertial_added_[k]) {
      if (k < static_cast<int>(problem_.angular_velocity.size())) {
        timing.angular_velocity = problem_.angular_velocity[k];
      }
      if (k < static_cast<int>(problem_.time_offset_applied.size())) {
        timing.offset_applied = problem_.time_offset_applied[k];
      }
    } else {
      timing.offset_applied = problem_.initial.time_offset_s;
    }
    return timing;
  }

  // Observations: points need at least three residuals (a monocular point seen once has no
  // depth, which would make the covariance rank-deficient).
  void AddObservations() {
    const int num_obs = static_cast<int>(visual_.observations.size());
    std::vector<int> rows(static_cast<std::size_t>(num_points_), 0);
    for (int i = 0; i < num_obs; ++i) {
      rows[visual_.observations[i].point_index] +=
          2 + (problem_.raw[i].has_right && stereo_ ? 1 : 0);
    }
    blocks_.assign(static_cast<std::size_t>(num_obs), ObsBlocks{});
    point_added_.assign(static_cast<std::size_t>(num_points_), 0);
    for (int i = 0; i < num_obs; ++i) {
      const BundleProblem::ObservationState& o = visual_.observations[i];
      const CalibrationBundleProblem::RawObservation& raw = problem_.raw[i];
      if (rows[o.point_index] < 3) continue;
      const int k = o.keyframe_index;
      const ImageTiming timing = TimingOf(k);
      double* velocity = problem_.inertial && inertial_added_[k] ? s_.v(k) : s_.no_velocity();
      auto* left = new CalibratedLeftError(raw.left, raw.left_whitening,
                                           FixedDistortionOf(problem_.initial.cameras[0]), timing);
      const double* params[6] = {s_.pose(k),       s_.point(o.point_index),
                                 s_.intrinsics(0), s_.cam0_from_body(),
                                 s_.offset(),      velocity};
      Eigen::Vector2d error;
      if (!left->PixelError(params, &error)) {  // behind the camera at the start: an outlier
        delete left;
        continue;
      }
      AddPose(k);
      point_added_[o.point_index] = 1;
      blocks_[i].left_cost = left;
      blocks_[i].left =
          ceres_problem_.AddResidualBlock(left, &loss_left_,
                                          {s_.pose(k), s_.point(o.point_index), s_.intrinsics(0),
                                           s_.cam0_from_body(), s_.offset(), velocity});
      if (raw.has_right && stereo_) {
        blocks_[i].right = ceres_problem_.AddResidualBlock(
            new CalibratedRightError(raw.right, raw.right_whitening,
                                     FixedDistortionOf(problem_.initial.cameras[1]), timing,
                                     vertical_offset_),
            &loss_right_,
            {s_.pose(k), s_.point(o.point_index), s_.intrinsics(1), s_.intrinsics(0),
             s_.cam0_from_body(), s_.cam1_from_cam0(), s_.offset(), velocity});
      }
    }
  }

  // The gauge: the problem's fixed keyframes; with none (a hand-made problem), the first.
  void FixGauge() {
    bool any_fixed = false;
    for (int i = 0; i < num_kf_; ++i) {
      any_fixed = any_fixed || (pose_added_[i] && visual_.keyframes[i].fixed);
    }
    if (any_fixed) return;
    for (int i = 0; i < num_kf_; ++i) {
      if (pose_added_[i]) {
        ceres_problem_.SetParameterBlockConstant(s_.pose(i));
        break;
      }
    }
  }

  // Schur elimination: points first, then keyframes and the calibration blocks.
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
      if (inertial_added_[i]) {
        for (double* block : {s_.v(i), s_.bg(i), s_.ba(i)}) schur.AddOther(block);
      }
    }
    for (std::size_t c = 0; c < problem_.initial.cameras.size() && c < 2; ++c) {
      schur.AddOther(s_.intrinsics(static_cast<int>(c)));
    }
    for (double* block :
         {s_.cam0_from_body(), s_.cam1_from_cam0(), s_.offset(), s_.no_velocity()}) {
      schur.AddOther(block);
    }
    if (problem_.inertial && (problem_.free.gyro_scale || problem_.free.accel_axes)) {
      schur.AddOther(s_.gyro_scale());
      schur.AddOther(s_.accel_axes());
    }
    return SchurSolverOptions(schur, options_.num_threads);
  }

  // Outliers after the robust pass: whitened chi2 of the left keypoint or the right coordinate.
  void RejectOutliers() {
    const int num_obs = static_cast<int>(visual_.observations.size());
    for (int i = 0; i < num_obs; ++i) {
      ObsBlocks& b = blocks_[i];
      if (b.left == nullptr) {
        result_.bundle.visual.outlier_observations.push_back(i);
        continue;
      }
      double cost = 0;
      bool outlier = false;
      for (ceres::ResidualBlockId id : {b.left, b.right}) {
        if (id == nullptr) continue;
        double r[2] = {0, 0};
        if (!ceres_problem_.EvaluateResidualBlock(id, /*apply_loss_function=*/false, &cost, r,
                                                  nullptr)) {
          outlier = true;
          continue;
        }
        const double chi2 = r[0] * r[0] + (id == b.left ? r[1] * r[1] : 0.0);
        outlier = outlier || chi2 > (id == b.left ? options_.chi2_left : options_.chi2_right);
      }
      if (!outlier) continue;
      result_.bundle.visual.outlier_observations.push_back(i);
      if (options_.iterations_second > 0) {
        ceres_problem_.RemoveResidualBlock(b.left);
        if (b.right != nullptr) ceres_problem_.RemoveResidualBlock(b.right);
        b = {};
      }
    }
    result_.outliers = static_cast<int>(result_.bundle.visual.outlier_observations.size());
  }

  // The estimate's sigmas (the covariance of the free calibration blocks).
  void Sigmas() {
    std::vector<int> rows_left(static_cast<std::size_t>(num_points_), 0);
    for (std::size_t i = 0; i < blocks_.size(); ++i) {
      const ObsBlocks& b = blocks_[i];
      rows_left[visual_.observations[i].point_index] +=
          (b.left != nullptr ? 2 : 0) + (b.right != nullptr ? 1 : 0);
    }
    RemoveNuisanceNullDirections(rows_left, point_added_, &ceres_problem_, &s_);
    const auto start = std::chrono::steady_clock::now();
    result_.covariance_ok = FillSigmas(&ceres_problem_, &s_, problem_, options_.num_threads,
                                       manifolds_.imu.Expansion(), manifolds_.stereo.Expansion(),
                                       &result_.parameters, &result_.parameter_covariance);
    result_.covariance_ms = WallMsSince(start);
    PKSLAM_LOG_DEBUG("calibration bundle adjustment: covariance {} in {:.0f} ms",
                     result_.covariance_ok ? "computed" : "not computable", result_.covariance_ms);
  }

  const CalibrationBundleProblem& problem_;
  const CalibrationBundleOptions& options_;
  const BundleProblem& visual_;
  const int num_kf_;
  const int num_points_;
  const bool stereo_;
  State s_;
  const Eigen::Vector2d vertical_offset_;
  CalibrationBundleResult result_;
  ceres::Problem ceres_problem_;
  BodyPoseManifold pose_manifold_;
  ceres::HuberLoss huber_left_;
  ceres::HuberLoss huber_right_;
  ceres::LossFunctionWrapper loss_left_;
  ceres::LossFunctionWrapper loss_right_;
  CalibrationManifolds manifolds_;
  std::vector<std::uint8_t> pose_added_;
  std::vector<std::uint8_t> inertial_added_;
  std::vector<ObsBlocks> blocks_;
  std::vector<std::uint8_t> point_added_;
};

}  // namespace

CalibrationBundleResult SolveCalibrationBundle(const CalibrationBundleProblem& problem,
                                               const CalibrationBundleOptions& options,
                                               const std::atomic<bool>* abort, WorkMeter* work) {
  const auto solve_start = std::chrono::steady_clock::now();
  options.Check();
  PKSLAM_CHECK(problem.raw.size() == problem.bundle.visual.observations.size(),
               "calibration BA: {} raw observations for {} observations", problem.raw.size(),
               problem.bundle.visual.observations.size());
  PKSLAM_CHECK(!problem.initial.cameras.empty() &&
                   problem.prior.cameras.size() == problem.initial.cameras.size(),
               "calibration BA: cameras of the estimate and the prior differ");
  CalibrationSolve solve(problem, options);
  if (problem.empty() || (abort != nullptr && abort->load())) {
    return solve.Unsolved(/*aborted=*/!problem.empty());
  }
  CalibrationBundleResult result = solve.Run(abort, work);
  result.solve_ms = WallMsSince(solve_start);
  return result;
}

}  // namespace pkslam
