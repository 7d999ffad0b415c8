// Internal to the calibration bundle adjustment's solve (calibration_bundle_solve.cc,
// calibration_sigmas.cc): the state buffer the solver works on, the calibration blocks'
// manifolds, and the covariance of the estimate.
#pragma once

#include <ceres/manifold.h>
#include <ceres/problem.h>

#include <array>
#include <cstdint>
#include <vector>

#include "estimators/calibration/calibration_bundle.h"
#include "estimators/calibration/calibration_residuals.h"
#include "estimators/optim/se3_manifold.h"
#include "imu/imu_manifolds.h"

namespace pkslam::calibration_solve {

constexpr double kRadToDeg = 180.0 / M_PI;

// Every block in one buffer, so Ceres' ordering of an elimination group (by address) does not
// depend on where malloc put separate vectors (as in inertial_bundle_solve.cc).
class State {
 public:
  State(int num_kf, int num_points)
      : kf_(num_kf),
        points_(num_points),
        data_(static_cast<std::size_t>((kBodyPoseBlockSize + 9) * num_kf + 3 * num_points +
                                       2 * kCalibIntrinsicsSize + 2 * kCalibExtrinsicSize + 1 + 3 +
                                       3 + 9),
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
  // The accelerometer's axis errors (RigCalibration::accel_axes, row-major).
  double* accel_axes() { return gyro_scale() + 3; }

 private:
  int kf_;
  int points_;
  std::vector<double> data_;
};

// The stereo extrinsic's held tangent axes ([rho; phi] of cam1_from_cam0): the baseline and the
// rotation about x (see the prior below).
constexpr std::array<bool, 6> kStereoHeldAxes = {true, true, true, true, false, false};

// The camera-IMU extrinsic's held axes: the translation (rho of cam0_from_body: the camera's
// position in the body stays) unless the lever arm is free, the rotation unless it is free.
inline std::array<bool, 6> ImuHeldAxes(const CalibrationFreedom& free) {
  const bool t = !free.imu_translation;
  const bool r = !free.imu_rotation;
  return {t, t, t, r, r, r};
}

inline bool ImuExtrinsicFree(const CalibrationBundleProblem& problem) {
  return problem.inertial && (problem.free.imu_rotation || problem.free.imu_translation);
}

inline bool StereoExtrinsicFree(const CalibrationBundleProblem& problem) {
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
  // The accelerometer's axis errors with the diagonal (its scale factors) held.
  ceres::SubsetManifold accel_misalignment{9, {0, 4, 8}};
  SE3LeftSubsetManifold imu;
  SE3LeftSubsetManifold stereo;
};

// Before the covariance (the solve is done): drops the points the outlier pass left with three
// residuals or fewer (`rows_left`) and puts a weak prior on every other point, so that the
// covariance's rank check does not take their directions for null ones
// (calibration_sigmas.cc says why).
void RemoveNuisanceNullDirections(const std::vector<int>& rows_left,
                                  const std::vector<std::uint8_t>& point_added,
                                  ceres::Problem* ceres_problem, State* s);

// The marginal covariance of the free calibration blocks (tangent space), written into the
// parameters' sigmas. False when Ceres cannot compute it (rank-deficient Jacobian).
// `parameter_covariance`: the joint covariance of `parameters` (report units; the rows and
// columns of frozen parameters 0; left empty when it cannot be computed).
// `imu_expansion`, `stereo_expansion`: the extrinsic blocks' free tangent axes
// (SE3LeftSubsetManifold::Expansion).
bool FillSigmas(ceres::Problem* ceres_problem, State* s, const CalibrationBundleProblem& problem,
                int num_threads, const Eigen::MatrixXd& imu_expansion,
                const Eigen::MatrixXd& stereo_expansion,
                std::vector<CalibrationParameter>* parameters,
                Eigen::MatrixXd* parameter_covariance);

}  // namespace pkslam::calibration_solve
