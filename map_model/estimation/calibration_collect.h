// The map side of the calibration bundle adjustment (estimators/calibration/calibration_bundle.h):
// Collect (shared Atlas lock) builds the problem from a whole map with each observation's
// physical pixels; the solve holds no lock; Apply (map_model/estimation/calibration_apply.h) moves
// the map to the new calibration.
#pragma once

#include "core/sensor/rig_calibration.h"
#include "estimators/calibration/calibration_bundle.h"
#include "map_model/map_editor.h"
#include "map_model/map_ids.h"

namespace pkslam {

struct CalibrationCollectOptions {
  // At most this many observations per keyframe (0: all), taken evenly over a 4x4 grid of the
  // image, best-observed points first: the calibration needs the image covered more than it
  // needs every point, and the solve's cost grows with the observations.
  int max_observations_per_keyframe = 0;
  // The IMU axis errors' Jacobians (gyro scale, accelerometer axes) of every inertial edge (one
  // replay of the chain's IMU steps); an adjustment that holds both never reads them.
  bool imu_axes_jacobians = true;

  void Check() const;
};

// Inertial maps (`inertial` and an initialised chain ending
// at `newest`, or at the one of the ten keyframes before it with the longest chain): the chain
// as a full visual-inertial BA (first keyframe fixed; keyframes off the chain fixed, visual
// only); otherwise every live keyframe of newest's map (the first fixed).
// `setup` is the rig the map's keypoints are in (all keyframes share it); `current` its
// calibration, `file` the calibration file's (the prior). The problem's freedom is left empty.
CalibrationBundleProblem CollectCalibrationBundle(const MapLock& lock, KeyFrame* newest,
                                                  bool inertial, const RigSetup& setup,
                                                  const RigCalibration& current,
                                                  const RigCalibration& file,
                                                  const CalibrationCollectOptions& options);

// The body's angular velocity at a keyframe (body frame, bias-corrected): the mean gyro of the
// last `window_s` of its preintegration; zero without one.
Eigen::Vector3d AngularVelocityAt(const KeyFrame& kf, double window_s = 0.025);

}  // namespace pkslam
