// Local mapping's options (mapping/local_mapper.h): the per-keyframe steps
// (mapping/keyframe_steps.h), the keyframe queue's bound, the inertial stages and online
// calibration. Check() refuses values the steps cannot run with.
#pragma once

#include "estimators/optim/bundle_adjustment.h"
#include "mapping/calibration_refinement.h"
#include "mapping/inertial_mapping.h"

namespace pkslam {

struct LocalMappingOptions {
  // Covisible keyframes used for triangulation (stereo/RGB-D, monocular).
  int triangulation_neighbours_stereo = 10;
  int triangulation_neighbours_mono = 20;
  // Keyframe culling: a keyframe is redundant when this share of its (close) points is seen
  // by at least `culling_observers` other keyframes at the same or a finer scale.
  double culling_redundancy = 0.9;
  int culling_observers = 3;
  bool cull_keyframes = true;
  // Recent points: culled when found/visible < this ratio.
  double min_found_ratio = 0.25;
  // The keyframe queue's bound (backpressure, MappingBackend::QueueFull): tracking declines a
  // keyframe while this many wait, and a keyframe it cannot decline (a new map's first two)
  // waits for room. ORB-SLAM3's rule already keeps the queue at 3 or fewer (it declines while
  // three wait, or while mapping is busy for monocular), so in ordinary runs the bound is
  // never reached; it holds for every selector and for mapping held by loop closing too.
  // At least 2: a map's initialisation inserts two keyframes at once.
  int max_queued_keyframes = 8;
  BundleAdjustmentOptions ba;
  // Inertial sensors: IMU initialisation stages and local inertial BA.
  InertialMappingOptions inertial;
  // Online calibration (mapping/calibration_refinement.h); off by default.
  OnlineCalibrationOptions calibration;

  void Check() const;
};

}  // namespace pkslam
