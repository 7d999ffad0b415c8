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
#include "estimators/optim/ceres_setup.h"
#include "estimators/optim/marginal_covariance.h"
#include "estimators/optim/se3_manifold.h"
#include "imu/imu_factors.h"
#include "imu/imu_manifolds.h"

namespace pkslam {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// Every block in one buffer, so Ceres' ordering of an elimination group (by address) does not
// depend on where malloc put separate vectors (as in inertial_bundle_solve.cc).
class State {
 public:
  State(int num_kf, int num_points)
      : kf_(num_kf),
        points_(num_points),
        data_(static_cast<std::size_t>((kBodyPoseBlockSize + 9) * num_kf + 3 * num_points +
                                       2 * kCalibIntrinsicsSize + 2 * kCalibExtrinsicSize + 1 + 3 + 3),
              0.0) {}
  double* pose(int i) { return data_.data() + kBodyPoseBlockSize * i; }
  double* v(int i) { return data_.data() + kBodyPoseBlockSize * kf_ + 3 * i; }
  double* bg(int i) { return data_.data() + (kBodyPoseBlockSize + 3) * kf_ + 3 * i; }
  double* ba(int i) { return data_.data() + (kBodyPoseBlockSize + 6) * kf_ + 3 * i; }
  double* point(int i) { return data_.data() + (kBodyPoseBlockSize + 9) * kf_ + 3 * i; }
  double* calibration() { return point(points_); }
  double* intrinsics(int camera) { return calibration() + kCalibIntrinsicsSize * camera; }
  double* cam0_from_body() { return calibration() + 2 * kCalibIntrinsicsSize; }
  double* cam1_from_cam0() { return cam0_from_body() + kCalibExtrinsicSize; }
  double* offset() { return cam1_from_cam0() + kCalibExtrinsicSize; }
  // A constant zero velocity for keyframes without inertial blocks.
  double* no_velocity() { return offset() + 1; }
  // The gyro's per-axis scale-factor error (RigCalibration::gyro_scale).
  double* gyro_scale() { return no_velocity() + 3; }

 private:
  int kf_;
  int points_;
  std::vector<double> data_;
};

void CopyArray(const std::array<double, kCalibIntrinsicsSize>& a, double* out) {
  std::copy(a.begin(), a.end(), out);
}

// The stereo extrinsic's held tangent axes ([rho; phi] of cam1_from_cam0): the baseline and the
// rotation about x (see the prior below).
constexpr std::array<bool, 6> kStereoHeldAxes = {true, true, true, true, false, false};

// The camera-IMU extrinsic's held axes: the translation (rho of cam0_from_body: the camera's
// position in the body stays) unless the lever arm is free, the rotation unless it is free.
std::array<bool, 6> ImuHeldAxes(const CalibrationFreedom& free) {
  const bool t = !free.imu_translation;
  const bool r = !free.imu_rotation;
  return {t, t, t, r, r, r};
}

bool ImuExtrinsicFree(const CalibrationBundleProblem& problem) {
  return problem.inertial && (problem.free.imu_rotation || problem.free.imu_translation);
}

bool StereoExtrinsicFree(const CalibrationBundleProblem& problem) {
  return problem.initial.stereo() && problem.free.stereo_extrinsic;
}

// The calibration blocks' manifolds (Ceres borrows them: they outlive the problem). Held axes of
// the free extrinsics stay put through their manifold; a block that is not free is constant, and
// its manifold holds nothing.
struct CalibrationManifolds {
  explicit CalibrationManifolds(const CalibrationBundleProblem& problem)
      : imu(ImuExtrinsicFree(problem) ? ImuHeldAxes(problem.free) : std::array<bool, 6>{}),
        stereo(StereoExtrinsicFree(problem) ? kStereoHeldAxes : std::array<bool, 6>{}) {}
  // The right camera's fy and cy stay: the stereo matcher measures only its u coordinate.
  ceres::SubsetManifold right_intrinsics{kCalibIntrinsicsSize, {1, 3}};
  SE3LeftSubsetManifold imu;
  SE3LeftSubsetManifold stereo;
};

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
  if (problem.inertial && problem.free.gyro_scale) {
    ceres_problem->AddResidualBlock(
        new EuclideanPriorError(problem.prior.gyro_scale,
                                Eigen::Vector3d::Constant(sig.gyro_scale_pct * 1e-2)),
        nullptr, s->gyro_scale());
  }
}

// Before the covariance (the solve is done), the points whose directions the covariance's rank
// check would take for null ones, so that it refuses the whole covariance (every machine-hall
// replay did when the covariance came from Ceres' sparse QR):
// - a point the outlier pass left with three residuals or fewer (`rows_left`) tells nothing
//   about the other parameters (its own three coordinates absorb them), and with fewer than
//   three it has no position at all; it leaves the problem with its residuals, which keeps the
//   calibration's marginal covariance as it is;
// - a far point seen without stereo from nearby keyframes has almost no depth, numerically a
//   null direction (the rank tolerance is relative to the largest direction); a 100 m
//   prior on every point's position removes those and tells nothing worth the name about
//   anything else.
void RemoveNuisanceNullDirections(const std::vector<int>& rows_left,
                                  const std::vector<std::uint8_t>& point_added,
                                  ceres::Problem* ceres_problem, State* s) {
  constexpr double kPointPriorSigmaM = 100.0;
  for (std::size_t p = 0; p < rows_left.size(); ++p) {
    if (!point_added[p]) continue;
    double* point = s->point(static_cast<int>(p));
    if (rows_left[p] <= 3) {
      ceres_problem->RemoveParameterBlock(point);
      continue;
    }
    ceres_problem->AddResidualBlock(
        new EuclideanPriorError(Eigen::Map<const Eigen::Vector3d>(point),
                                Eigen::Vector3d::Constant(kPointPriorSigmaM)),
        nullptr, point);
  }
}

// The marginal covariance of the free calibration blocks (tangent space), written into the
// parameters' sigmas. False when Ceres cannot compute it (rank-deficient Jacobian).
// `imu_expansion`, `stereo_expansion`: the extrinsic blocks' free tangent axes
// (SE3LeftSubsetManifold::Expansion).
bool FillSigmas(ceres::Problem* ceres_problem, State* s, const CalibrationBundleProblem& problem,
                int num_threads, const Eigen::MatrixXd& imu_expansion,
                const Eigen::MatrixXd& stereo_expansion,
                std::vector<CalibrationParameter>* parameters) {
  // A block's tangent covariance C maps to the reported scalars as J C J^T (report-ordered J).
  struct Entry {
    double* block;
    int first;          // index of its first scalar in `parameters`
    Eigen::MatrixXd j;  // reported scalars x block tangent (units included)
    bool ambient = false;  // intrinsics: ambient covariance (frozen coordinates: 0)
  };
  std::vector<Entry> entries;
  int index = 0;
  for (int c = 0; c < static_cast<int>(problem.initial.cameras.size()) && c < 2; ++c) {
    if (problem.free.intrinsics[c]) {
      entries.push_back({s->intrinsics(c), index,
                         Eigen::MatrixXd::Identity(kCalibIntrinsicsSize, kCalibIntrinsicsSize),
                         true});
    }
    index += kCalibIntrinsicsSize;
  }
  // The block B = X^-1 of the reported X = parent_from_child moves as Exp(e) B, so X moves as
  // X Exp(-e): rotation vector -R_X phi, translation -R_X rho (first order).
  const auto extrinsic_j = [](const SE3d& parent_from_child) {
    Eigen::MatrixXd j = Eigen::MatrixXd::Zero(6, 6);
    const Eigen::Matrix3d r = parent_from_child.RotationMatrix();
    j.block<3, 3>(0, 3) = -r * kRadToDeg;
    j.block<3, 3>(3, 0) = -r * 1e3;
    return j;
  };
  if (problem.initial.stereo()) {
    if (problem.free.stereo_extrinsic) {
      entries.push_back({s->cam1_from_cam0(), index,
                         extrinsic_j(PoseFromBlock(s->cam1_from_cam0()).Inverse()) *
                             stereo_expansion});
    }
    index += 6;
  }
  if (problem.inertial) {
    if (problem.free.imu_rotation || problem.free.imu_translation) {
      entries.push_back({s->cam0_from_body(), index,
                         extrinsic_j(PoseFromBlock(s->cam0_from_body()).Inverse()) *
                             imu_expansion});
    }
    index += 6;
    if (problem.free.time_offset) {
      entries.push_back({s->offset(), index, Eigen::MatrixXd::Constant(1, 1, 1e3)});
    }
    index += 1;
    if (problem.free.gyro_scale) {
      entries.push_back({s->gyro_scale(), index, Eigen::MatrixXd::Identity(3, 3) * 100.0});
    }
  }
  if (entries.empty()) return true;
  std::vector<const double*> blocks;
  for (const Entry& e : entries) blocks.push_back(e.block);
  MarginalCovarianceOptions options;
  options.num_threads = num_threads;
  const std::optional<MarginalCovariance> covariance =
      ComputeMarginalCovariance(ceres_problem, blocks, options);
  if (!covariance) return false;
  for (const Entry& e : entries) {
    const Eigen::MatrixXd tangent = covariance->Block(e.block);
    const Eigen::MatrixXd m =
        e.ambient ? AmbientCovariance(*ceres_problem, e.block, tangent) : tangent;
    const Eigen::MatrixXd reported = e.j * m * e.j.transpose();
    for (int i = 0; i < reported.rows(); ++i) {
      CalibrationParameter& p = (*parameters)[static_cast<std::size_t>(e.first + i)];
      if (p.free) p.sigma = std::sqrt(std::max(0.0, reported(i, i)));
    }
  }
  return true;
}

}  // namespace

CalibrationBundleResult SolveCalibrationBundle(const CalibrationBundleProblem& problem,
                                               const CalibrationBundleOptions& options,
                                               const std::atomic<bool>* abort, WorkMeter* work) {
  const auto solve_start = std::chrono::steady_clock::now();
  options.Check();
  const BundleProblem& visual = problem.bundle.visual;
  PKSLAM_CHECK(problem.raw.size() == visual.observations.size(),
               "calibration BA: {} raw observations for {} observations", problem.raw.size(),
               visual.observations.size());
  PKSLAM_CHECK(!problem.initial.cameras.empty() &&
                   problem.prior.cameras.size() == problem.initial.cameras.size(),
               "calibration BA: cameras of the estimate and the prior differ");
  const int num_kf = static_cast<int>(visual.keyframes.size());
  const int num_points = static_cast<int>(visual.points.size());
  const bool stereo = problem.initial.stereo();
  State s(num_kf, num_points);
  for (int i = 0; i < num_kf; ++i) {
    BodyPoseToBlock(visual.keyframes[i].camera_from_world.Inverse() * problem.bundle.camera_from_body,
                    s.pose(i));
    if (problem.inertial && i < static_cast<int>(problem.bundle.velocities.size())) {
      Eigen::Map<Eigen::Vector3d>(s.v(i)) = problem.bundle.velocities[i];
      Eigen::Map<Eigen::Vector3d>(s.bg(i)) = problem.bundle.biases[i].gyro;
      Eigen::Map<Eigen::Vector3d>(s.ba(i)) = problem.bundle.biases[i].accel;
    }
  }
  for (int i = 0; i < num_points; ++i) {
    Eigen::Map<Eigen::Vector3d>(s.point(i)) = visual.points[i].position_world;
  }
  for (std::size_t c = 0; c < problem.initial.cameras.size() && c < 2; ++c) {
    CopyArray(IntrinsicsBlock(problem.initial.cameras[c]), s.intrinsics(static_cast<int>(c)));
  }
  PoseToBlock(problem.initial.body_from_cam0.Inverse(), s.cam0_from_body());
  PoseToBlock(problem.initial.cam1_from_cam0, s.cam1_from_cam0());
  *s.offset() = problem.initial.time_offset_s;
  Eigen::Map<Eigen::Vector3d>(s.gyro_scale()) = problem.initial.gyro_scale;

  // cam1's fy and cy follow cam0's at the file's differences (CalibratedRightError).
  const Eigen::Vector2d vertical_offset =
      stereo ? Eigen::Vector2d(problem.prior.cameras[1].fy() - problem.prior.cameras[0].fy(),
                               problem.prior.cameras[1].cy() - problem.prior.cameras[0].cy())
             : Eigen::Vector2d::Zero();
  CalibrationBundleResult result;
  result.estimate = problem.initial;
  auto write_result = [&]() {
    result.world_from_body.clear();
    result.bundle.velocities.clear();
    result.bundle.biases.clear();
    result.bundle.visual.points_world.clear();
    for (int i = 0; i < num_kf; ++i) {
      result.world_from_body.push_back(BodyPoseFromBlock(s.pose(i)));
      result.bundle.velocities.emplace_back(Eigen::Map<const Eigen::Vector3d>(s.v(i)));
      result.bundle.biases.emplace_back(Eigen::Map<const Eigen::Vector3d>(s.bg(i)),
                                        Eigen::Map<const Eigen::Vector3d>(s.ba(i)));
    }
    for (int i = 0; i < num_points; ++i) {
      result.bundle.visual.points_world.emplace_back(Eigen::Map<const Eigen::Vector3d>(s.point(i)));
    }
    for (std::size_t c = 0; c < result.estimate.cameras.size() && c < 2; ++c) {
      double block[kCalibIntrinsicsSize];
      std::copy(s.intrinsics(static_cast<int>(c)),
                s.intrinsics(static_cast<int>(c)) + kCalibIntrinsicsSize, block);
      if (c == 1) {
        block[1] = s.intrinsics(0)[1] + vertical_offset[0];
        block[3] = s.intrinsics(0)[3] + vertical_offset[1];
      }
      result.estimate.cameras[c] = CameraFromIntrinsicsBlock(problem.initial.cameras[c], block);
    }
    result.estimate.body_from_cam0 = PoseFromBlock(s.cam0_from_body()).Inverse();
    result.estimate.cam1_from_cam0 = PoseFromBlock(s.cam1_from_cam0());
    result.estimate.time_offset_s = *s.offset();
    if (problem.inertial) {
      result.estimate.gyro_scale = Eigen::Map<const Eigen::Vector3d>(s.gyro_scale());
    }
    result.parameters = CalibrationParameters(problem.prior, result.estimate, problem.free,
                                              options.prior, problem.inertial);
  };
  if (problem.empty() || (abort != nullptr && abort->load())) {
    result.bundle.visual.aborted = !problem.empty();
    write_result();
    return result;
  }

  ceres::Problem ceres_problem(ProblemOptions({.loss_functions = true, .fast_removal = true}));
  BodyPoseManifold pose_manifold;
  ceres::HuberLoss huber_left(std::sqrt(options.chi2_left));
  ceres::HuberLoss huber_right(std::sqrt(options.chi2_right));
  ceres::LossFunctionWrapper loss_left(&huber_left, ceres::DO_NOT_TAKE_OWNERSHIP);
  ceres::LossFunctionWrapper loss_right(&huber_right, ceres::DO_NOT_TAKE_OWNERSHIP);

  CalibrationManifolds manifolds(problem);
  AddCalibrationBlocks(problem, options.prior, &manifolds, &ceres_problem, &s);
  const bool gyro_scale_free = problem.inertial && problem.free.gyro_scale;

  // Keyframes and the inertial chain.
  std::vector<std::uint8_t> pose_added(static_cast<std::size_t>(num_kf), 0);
  auto add_pose = [&](int i) {
    if (pose_added[i]) return;
    ceres_problem.AddParameterBlock(s.pose(i), kBodyPoseBlockSize, &pose_manifold);
    if (visual.keyframes[i].fixed) ceres_problem.SetParameterBlockConstant(s.pose(i));
    pose_added[i] = 1;
  };
  std::vector<std::uint8_t> inertial_added(static_cast<std::size_t>(num_kf), 0);
  auto add_inertial = [&](int i) {
    add_pose(i);
    if (inertial_added[i]) return;
    inertial_added[i] = 1;
    ceres_problem.AddParameterBlock(s.v(i), 3);
    ceres_problem.AddParameterBlock(s.bg(i), 3);
    ceres_problem.AddParameterBlock(s.ba(i), 3);
  };
  if (problem.inertial) {
    PKSLAM_CHECK(problem.gyro_scale_jacobians.empty() ||
                     problem.gyro_scale_jacobians.size() == problem.bundle.edges.size(),
                 "calibration BA: {} gyro scale Jacobians for {} inertial edges",
                 problem.gyro_scale_jacobians.size(), problem.bundle.edges.size());
    for (std::size_t edge = 0; edge < problem.bundle.edges.size(); ++edge) {
      const auto& e = problem.bundle.edges[edge];
      add_inertial(e.from);
      add_inertial(e.to);
      if (gyro_scale_free) {
        ceres_problem.AddResidualBlock(
            new GyroScaledInertialError(e.preintegration, problem.bundle.gravity_world,
                                        problem.gyro_scale_jacobians.empty()
                                            ? GyroScaleJacobiansOf(e.preintegration)
                                            : problem.gyro_scale_jacobians[edge],
                                        problem.initial.gyro_scale),
            nullptr,
            {s.pose(e.from), s.v(e.from), s.bg(e.from), s.ba(e.from), s.pose(e.to), s.v(e.to),
             s.gyro_scale()});
      } else {
        ceres_problem.AddResidualBlock(
            new InertialError(e.preintegration, problem.bundle.gravity_world), nullptr,
            {s.pose(e.from), s.v(e.from), s.bg(e.from), s.ba(e.from), s.pose(e.to), s.v(e.to)});
      }
      ceres_problem.AddResidualBlock(BiasRandomWalkError::Gyro(e.preintegration).release(),
                                     nullptr, s.bg(e.from), s.bg(e.to));
      ceres_problem.AddResidualBlock(BiasRandomWalkError::Accel(e.preintegration).release(),
                                     nullptr, s.ba(e.from), s.ba(e.to));
    }
  }

  // Observations: points need at least three residuals (a monocular point seen once has no
  // depth, which would make the covariance rank-deficient).
  const int num_obs = static_cast<int>(visual.observations.size());
  std::vector<int> rows(static_cast<std::size_t>(num_points), 0);
  for (int i = 0; i < num_obs; ++i) {
    rows[visual.observations[i].point_index] += 2 + (problem.raw[i].has_right && stereo ? 1 : 0);
  }
  struct ObsBlocks {
    ceres::ResidualBlockId left = nullptr;
    ceres::ResidualBlockId right = nullptr;
    const CalibratedLeftError* left_cost = nullptr;
  };
  std::vector<ObsBlocks> blocks(static_cast<std::size_t>(num_obs));
  std::vector<std::uint8_t> point_added(static_cast<std::size_t>(num_points), 0);
  for (int i = 0; i < num_obs; ++i) {
    const BundleProblem::ObservationState& o = visual.observations[i];
    const CalibrationBundleProblem::RawObservation& raw = problem.raw[i];
    if (rows[o.point_index] < 3) continue;
    const int k = o.keyframe_index;
    ImageTiming timing;
    if (problem.inertial && inertial_added[k]) {
      if (k < static_cast<int>(problem.angular_velocity.size())) {
        timing.angular_velocity = problem.angular_velocity[k];
      }
      if (k < static_cast<int>(problem.time_offset_applied.size())) {
        timing.offset_applied = problem.time_offset_applied[k];
      }
    } else {
      timing.offset_applied = problem.initial.time_offset_s;
    }
    double* velocity = problem.inertial && inertial_added[k] ? s.v(k) : s.no_velocity();
    auto* left = new CalibratedLeftError(raw.left, raw.left_whitening,
                                         FixedDistortionOf(problem.initial.cameras[0]), timing);
    const double* params[6] = {s.pose(k), s.point(o.point_index), s.intrinsics(0),
                               s.cam0_from_body(), s.offset(), velocity};
    Eigen::Vector2d error;
    if (!left->PixelError(params, &error)) {  // behind the camera at the start: an outlier
      delete left;
      continue;
    }
    add_pose(k);
    point_added[o.point_index] = 1;
    blocks[i].left_cost = left;
    blocks[i].left = ceres_problem.AddResidualBlock(
        left, &loss_left,
        {s.pose(k), s.point(o.point_index), s.intrinsics(0), s.cam0_from_body(), s.offset(),
         velocity});
    if (raw.has_right && stereo) {
      blocks[i].right = ceres_problem.AddResidualBlock(
          new CalibratedRightError(raw.right, raw.right_whitening,
                                   FixedDistortionOf(problem.initial.cameras[1]), timing,
                                   vertical_offset),
          &loss_right,
          {s.pose(k), s.point(o.point_index), s.intrinsics(1), s.intrinsics(0),
           s.cam0_from_body(), s.cam1_from_cam0(), s.offset(), velocity});
    }
  }
  // The gauge: the problem's fixed keyframes; with none (a hand-made problem), the first.
  bool any_fixed = false;
  for (int i = 0; i < num_kf; ++i) any_fixed = any_fixed || (pose_added[i] && visual.keyframes[i].fixed);
  if (!any_fixed) {
    for (int i = 0; i < num_kf; ++i) {
      if (pose_added[i]) {
        ceres_problem.SetParameterBlockConstant(s.pose(i));
        break;
      }
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
      ordering->AddElementToGroup(s.bg(i), 1);
      ordering->AddElementToGroup(s.ba(i), 1);
    }
  }
  for (std::size_t c = 0; c < problem.initial.cameras.size() && c < 2; ++c) {
    ordering->AddElementToGroup(s.intrinsics(static_cast<int>(c)), 1);
  }
  for (double* block : {s.cam0_from_body(), s.cam1_from_cam0(), s.offset(), s.no_velocity()}) {
    ordering->AddElementToGroup(block, 1);
  }
  if (gyro_scale_free) ordering->AddElementToGroup(s.gyro_scale(), 1);
  solver_options.linear_solver_ordering = ordering;
  AbortCallback abort_callback(abort, work, &ceres_problem, options.min_iterations_before_abort);
  solver_options.callbacks.push_back(&abort_callback);

  bool first = true;
  auto solve = [&](int iterations) {
    if (ceres_problem.NumResidualBlocks() == 0) return;
    solver_options.max_num_iterations = iterations;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &ceres_problem, &summary);
    if (first) result.bundle.visual.initial_cost = summary.initial_cost;
    first = false;
    result.bundle.visual.final_cost = summary.final_cost;
    result.bundle.visual.iterations += std::max(0, static_cast<int>(summary.iterations.size()) - 1);
    result.bundle.visual.aborted = abort_callback.fired();
    if (summary.termination_type == ceres::FAILURE) {
      PKSLAM_LOG_WARN("calibration bundle adjustment: solver failure: {}", summary.message);
    }
  };

  solve(options.iterations_first);
  // Outliers after the robust pass: whitened chi2 of the left keypoint or the right coordinate.
  for (int i = 0; i < num_obs; ++i) {
    ObsBlocks& b = blocks[i];
    if (b.left == nullptr) {
      result.bundle.visual.outlier_observations.push_back(i);
      continue;
    }
    double cost = 0;
    bool outlier = false;
    for (ceres::ResidualBlockId id : {b.left, b.right}) {
      if (id == nullptr) continue;
      double r[2] = {0, 0};
      if (!ceres_problem.EvaluateResidualBlock(id, /*apply_loss_function=*/false, &cost, r,
                                              nullptr)) {
        outlier = true;
        continue;
      }
      const double chi2 = r[0] * r[0] + (id == b.left ? r[1] * r[1] : 0.0);
      outlier = outlier || chi2 > (id == b.left ? options.chi2_left : options.chi2_right);
    }
    if (!outlier) continue;
    result.bundle.visual.outlier_observations.push_back(i);
    if (options.iterations_second > 0) {
      ceres_problem.RemoveResidualBlock(b.left);
      if (b.right != nullptr) ceres_problem.RemoveResidualBlock(b.right);
      b = {};
    }
  }
  result.outliers = static_cast<int>(result.bundle.visual.outlier_observations.size());
  if (!result.bundle.visual.aborted && options.iterations_second > 0) {
    loss_left.Reset(nullptr, ceres::DO_NOT_TAKE_OWNERSHIP);
    loss_right.Reset(nullptr, ceres::DO_NOT_TAKE_OWNERSHIP);
    solve(options.iterations_second);
  }
  write_result();
  if (options.covariance && !result.bundle.visual.aborted && problem.free.Any()) {
    std::vector<int> rows_left(static_cast<std::size_t>(num_points), 0);
    for (int i = 0; i < num_obs; ++i) {
      const ObsBlocks& b = blocks[static_cast<std::size_t>(i)];
      rows_left[visual.observations[i].point_index] +=
          (b.left != nullptr ? 2 : 0) + (b.right != nullptr ? 1 : 0);
    }
    RemoveNuisanceNullDirections(rows_left, point_added, &ceres_problem, &s);
    const auto start = std::chrono::steady_clock::now();
    result.covariance_ok = FillSigmas(&ceres_problem, &s, problem, options.num_threads,
                                      manifolds.imu.Expansion(), manifolds.stereo.Expansion(),
                                      &result.parameters);
    result.covariance_ms = WallMsSince(start);
    PKSLAM_LOG_DEBUG("calibration bundle adjustment: covariance {} in {:.0f} ms",
                     result.covariance_ok ? "computed" : "not computable", result.covariance_ms);
  }
  result.solve_ms = WallMsSince(solve_start);
  return result;
}

}  // namespace pkslam
