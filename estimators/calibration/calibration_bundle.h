// Calibration bundle adjustment: a full (visual or visual-inertial) bundle adjustment that also
// estimates the rig's calibration (docs/calibration.md): each camera's intrinsics (fx, fy, cx,
// cy, k1, k2; the right camera's fy and cy stay, as its vertical coordinate is not measured),
// the stereo extrinsic's rotation about the y and z axes (its translation is the map's scale
// and its rotation about x moves only rows: both stay), the camera-IMU extrinsic cam0_from_body,
// the camera-IMU time offset, the gyroscope's per-axis scale factor and the accelerometer's axis
// errors (scale factors and misalignment), each held to the calibration file's value by a
// Gaussian prior.
//
// The gyro's scale factor belongs here because it is what an unmodelled one turns into
// otherwise: the camera's rotation is seen twice, in the images (through the focal length) and
// by the gyro (through its scale), and a scale error of the gyro pulls the focal length by the
// same fraction (a 0.48% error about the IMU's y axis, cam0's x, held cam0's fy 1.3 px low on a
// realistic V1_02 replay; docs/calibration.md). The inertial edges take it to first order
// (imu/imu_factors.h ImuAxesInertialError). The accelerometer's axis errors belong here for the
// same reason: an unmodelled misalignment tilts the gravity the accelerometer sees, and the
// camera-IMU rotation took the tilt (0.097 deg from the truth on a realistic V1_01 replay, 0.023
// deg with the render's accelerometer errors removed; docs/calibration.md).
//
// Why a separate, whole-map adjustment rather than free calibration blocks in local BA: a
// 10-keyframe window barely sees a camera-IMU rotation or a time offset (they need the motion of
// many seconds), and a sliding window that re-estimates them from overlapping windows counts the
// same observations again and again, so its uncertainty shrinks without new information. Here
// every observation counts once and the file's prior once; local BA, tracking and loop closing
// use the latest estimate (mapping/calibration_refinement.h applies it).
//
// Measurements are the physical pixels. Keypoints are found in rectified (stereo) or raw
// (monocular) images; the map side gives each observation's raw cam0 pixel and, for a stereo
// match, the raw cam1 pixel of its rectified right coordinate, with the whitening that maps a
// raw-pixel error back to the image the keypoint was measured in: the 2x2 Jacobian of the
// rectification for the left keypoint, and for the right only the row of it along the rectified
// u (the stereo matcher measures u_right; the row it searched comes from the rectification
// itself, so the vertical offset of the right image is not a measurement). Residuals:
//   left:  W_l (pi(intrinsics0, cam0_from_body * body_from_world(t) * p) - raw_left)
//   right: w_r (pi(intrinsics1, cam1_from_cam0 * cam0_from_body * body_from_world(t) * p)
//                - raw_right)
// where pi is the radial-tangential projection and body_from_world(t) the body pose at the
// image's IMU time: the keyframe's state was placed at stamp + the offset then applied
// (time_offset_applied), so with the offset estimate td the image lies delta = td - applied
// later: world_from_body(t) = (R Exp(omega delta), p + v delta), omega the body's angular
// velocity and v its velocity at the keyframe.
//
// Visual-only rigs use the same problem without inertial edges; the body is whatever frame the
// keyframes' poses refer to (cam0_from_body then stays at its value: it is not observable).
#pragma once

#include <Eigen/Core>
#include <array>
#include <atomic>
#include <optional>
#include <string>
#include <vector>

#include "core/sensor/rig_calibration.h"
#include "estimators/inertial/inertial_bundle.h"
#include "imu/preintegration.h"

namespace pkslam {

// 1-sigma uncertainty of a calibration file's values: the prior of the estimate. Defaults: the
// upper end of the documented spread of EuRoC calibrations (docs/calibration.md, sources in
// docs/realism.md): Kalibr's formal sigmas are 5-30x smaller than the differences between
// published re-calibrations, and a prior must cover the latter.
struct CalibrationPriorOptions {
  double focal_px = 2.0;              // fx, fy
  double principal_point_px = 2.0;    // cx, cy
  double k1 = 0.01;                   // radial distortion
  double k2 = 0.01;
  double stereo_rotation_deg = 0.1;   // cam1_from_cam0, per axis
  double stereo_translation_mm = 0.5;
  double imu_rotation_deg = 0.35;     // cam0_from_body, per axis
  double imu_translation_mm = 8.0;
  double time_offset_ms = 2.0;
  // The gyroscope's per-axis scale-factor error (%): 0.1-0.5% for MEMS gyros (docs/realism.md).
  double gyro_scale_pct = 0.5;
  // The accelerometer's per-axis scale-factor error (%) and axis misalignment (deg, each
  // off-diagonal term): 0.1-0.5% and up to 0.05 deg for MEMS accelerometers (docs/realism.md).
  double accel_scale_pct = 0.5;
  double accel_misalignment_deg = 0.1;

  void Check() const;
};

// Which parts of the calibration a solve estimates (the others stay at their current value).
struct CalibrationFreedom {
  std::array<bool, 2> intrinsics = {false, false};  // per camera
  bool stereo_extrinsic = false;
  bool imu_rotation = false;
  bool imu_translation = false;
  bool time_offset = false;
  bool gyro_scale = false;
  // The accelerometer's misalignment (E's off-diagonal terms); with `accel_scale` its per-axis
  // scale factors (E's diagonal) too, which are otherwise held by the block's manifold.
  bool accel_axes = false;
  bool accel_scale = false;

  bool Any() const {
    return intrinsics[0] || intrinsics[1] || stereo_extrinsic || imu_rotation || imu_translation ||
           time_offset || gyro_scale || accel_axes;
  }
};

struct CalibrationBundleOptions {
  // Robust pass, then a pass without the outliers (0 skips it).
  int iterations_first = 15;
  int iterations_second = 10;
  // chi2 thresholds of a left keypoint (2 DoF) and of a right coordinate (1 DoF), 95%.
  double chi2_left = 5.991;
  double chi2_right = 3.841;
  int num_threads = 1;
  double gravity_magnitude = 9.81;
  // Compute the marginal covariance of the calibration (sigma in the report).
  bool covariance = true;
  // An abort request is obeyed from this iteration on: an adjustment interrupted by every new
  // keyframe would otherwise never move the calibration on a busy map.
  int min_iterations_before_abort = 0;
  CalibrationPriorOptions prior;

  void Check() const;
};

struct CalibrationBundleProblem {
  // Keyframes (camera_from_world of the tracking camera), points, observations and, for inertial
  // maps, the chain's edges, velocities and biases. visual.observations' pixels are not used:
  // `raw` holds each observation's physical measurement. camera_from_body: the tracking
  // camera's (rectified left) extrinsic in the calibration being refined, so keyframe poses
  // convert to body poses.
  InertialBundleProblem bundle;
  bool inertial = false;
  struct RawObservation {
    Eigen::Vector2d left = Eigen::Vector2d::Zero();  // raw cam0 pixel
    Eigen::Matrix2d left_whitening = Eigen::Matrix2d::Identity();
    bool has_right = false;
    Eigen::Vector2d right = Eigen::Vector2d::Zero();  // raw cam1 pixel
    Eigen::RowVector2d right_whitening = Eigen::RowVector2d::Zero();
  };
  std::vector<RawObservation> raw;  // parallel to bundle.visual.observations
  // Per keyframe (inertial maps): the body's angular velocity at the keyframe (body frame,
  // bias-corrected) and the time offset its stamp was shifted by.
  std::vector<Eigen::Vector3d> angular_velocity;
  std::vector<double> time_offset_applied;
  // Per bundle.edges entry: GyroScaleJacobiansOf its preintegration (the edges' copies carry no
  // steps). Empty: computed from the edges' own steps (hand-made problems).
  std::vector<GyroScaleJacobians> gyro_scale_jacobians;
  // Likewise AccelAxesJacobiansOf each edge's preintegration (empty: from the edges' steps).
  std::vector<AccelAxesJacobians> accel_axes_jacobians;
  // The calibration the keyframes' measurements were taken with (the starting point) and the
  // calibration file's (the prior's mean).
  RigCalibration initial;
  RigCalibration prior;
  CalibrationFreedom free;

  bool empty() const { return bundle.visual.observations.empty(); }
};

// One estimated scalar of the calibration, for reports. Extrinsic entries are the change of the
// transform a calibration file holds, as a user would edit it: imu.* of body_from_cam0 (EuRoC's
// cam0 T_BS, ORB-SLAM3's IMU.T_b_c1), stereo.* of cam0_from_cam1 (ORB-SLAM3's Stereo.T_c1_c2,
// cam1's position in cam0): r* the rotation vector of R_estimate R_file^T (deg), t* the
// translation difference (mm), both in the parent frame's axes (body, cam0).
struct CalibrationParameter {
  // cam0.fx, cam1.k1, stereo.rx, imu.tz, time_offset, gyro.sx, accel.sx (E's diagonal, %),
  // accel.mxy (E's row x, column y: misalignment, deg), ...
  std::string name;
  std::string unit;  // px, "", deg, mm, ms, %
  double file = 0;   // the prior's mean
  double estimate = 0;
  double sigma = 0;        // posterior 1-sigma (0 when not computed or not free)
  double prior_sigma = 0;  // the prior's 1-sigma
  bool free = false;
};

struct CalibrationBundleResult {
  // Points, velocities, biases, outliers and solver statistics; bundle.visual.camera_from_world
  // is left empty: the tracking camera of `estimate` is a new rectified camera, so the keyframes
  // come as body poses and the map side turns them into camera poses of its new rig.
  InertialBundleResult bundle;
  std::vector<SE3d> world_from_body;  // per problem keyframe
  RigCalibration estimate;
  std::vector<CalibrationParameter> parameters;
  bool covariance_ok = false;
  // The joint covariance of `parameters` (same order, report units; the rows and columns of
  // frozen parameters 0); empty unless covariance_ok. The sigmas are its diagonal's roots.
  Eigen::MatrixXd parameter_covariance;
  int outliers = 0;
  // Wall time of the whole solve and of its covariance (0 when not computed), for the reports.
  double solve_ms = 0.0;
  double covariance_ms = 0.0;
};

// The scalar parameters of `estimate` against `prior` (sigma left 0).
std::vector<CalibrationParameter> CalibrationParameters(const RigCalibration& prior,
                                                        const RigCalibration& estimate,
                                                        const CalibrationFreedom& free,
                                                        const CalibrationPriorOptions& sigmas,
                                                        bool inertial);

// Pure computation; `abort` (may be null) is polled between iterations (the best iterate so far
// is returned); `work` (may be null) counts the residual evaluations (core/util/work_meter.h).
CalibrationBundleResult SolveCalibrationBundle(const CalibrationBundleProblem& problem,
                                               const CalibrationBundleOptions& options,
                                               const std::atomic<bool>* abort = nullptr,
                                               WorkMeter* work = nullptr);

}  // namespace pkslam
