// Options of local mapping's inertial work (mapping/local_mapper_inertial.cc): the staged IMU
// initialisation of ORB-SLAM3 (../shared/docs/ORBSLAM3_FACTS.md "IMU") and local inertial BA.
//
// Stages, per map: (1) once the temporal keyframe chain holds >= min_keyframes spanning
// >= min_time_*_s: inertial-only MAP (imu/inertial_initializer.h) over gravity direction,
// scale (monocular), one bias pair and the velocities, with zero-mean bias priors; the map is
// rotated to gravity (and scaled), then a full visual-inertial BA with shared biases refines
// it. (2) VIBA1 after viba1_s and (3) VIBA2 after viba2_s of motion since the initialisation
// (time over which the keyframes moved; a stand-still does not count): the same with weaker bias
// priors. In between, local inertial BA over a sliding window.
// Not moving: a stereo map initialises (gravity and gyro bias are observable at rest; the
// accelerometer bias is held by its prior); a monocular map waits until its keyframes have
// travelled mono_min_travel (map units, i.e. initial median scene depths), since scale is not
// observable at rest.
#pragma once

#include "mapping/inertial_bundle.h"
#include "mapping/inertial_culling.h"

namespace pkslam {

struct InertialMappingOptions {
  // Keyframes in the chain and seconds it spans before the first initialisation.
  int min_keyframes = 10;
  double min_time_stereo_s = 1.0;
  double min_time_mono_s = 2.0;
  // Monocular: keyframe path length needed before initialising (map units).
  double mono_min_travel = 0.25;
  // Bias prior informations of the first initialisation (ORB-SLAM3: 1e2 gyro; accel 1e10
  // monocular, 1e5 stereo) and of VIBA1 (1, 1e5) and VIBA2 (0, 0).
  double init_gyro_prior = 1e2;
  double init_accel_prior_mono = 1e10;
  double init_accel_prior_stereo = 1e5;
  double viba1_gyro_prior = 1.0;
  double viba1_accel_prior = 1e2;
  // Seconds of motion after the initialisation for the refinements (ORB-SLAM3: 5 s and 15 s).
  double viba1_s = 5.0;
  double viba2_s = 15.0;
  // Motion time: the interval between consecutive keyframes counts (up to
  // moving_max_interval_s) when the body moved more than moving_distance (map units) or turned
  // more than moving_angle_rad over it.
  // false: clock time since the initialisation instead.
  bool viba_motion_time = false;
  double moving_distance = 0.02;
  double moving_angle_rad = 0.035;
  double moving_max_interval_s = 1.0;
  // Iterations of the full visual-inertial BA after each stage.
  int full_ba_iterations = 15;
  // Local inertial BA.
  InertialBundleOptions local_ba;
  // Keyframe culling with the time-spacing rules of the temporal chain.
  InertialCullingOptions culling;

  void Check() const;
};

}  // namespace pkslam
