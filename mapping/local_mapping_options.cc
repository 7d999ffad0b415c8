#include "mapping/local_mapping_options.h"

#include "core/util/error.h"

namespace pkslam {

void LocalMappingOptions::Check() const {
  PKSLAM_CHECK_OPTION(triangulation_neighbours_stereo > 0 && triangulation_neighbours_mono > 0,
                      "LocalMapping.triangulation_neighbours", "{} / {}",
                      triangulation_neighbours_stereo, triangulation_neighbours_mono);
  PKSLAM_CHECK_OPTION(culling_redundancy > 0 && culling_redundancy <= 1,
                      "LocalMapping.culling_redundancy", "{}", culling_redundancy);
  PKSLAM_CHECK_OPTION(culling_observers > 0, "LocalMapping.culling_observers", "{}",
                      culling_observers);
  PKSLAM_CHECK_OPTION(min_found_ratio >= 0 && min_found_ratio < 1, "LocalMapping.min_found_ratio",
                      "{}", min_found_ratio);
  PKSLAM_CHECK_OPTION(max_queued_keyframes >= 2, "LocalMapping.max_queued_keyframes",
                      "{} (a map's initialisation inserts two keyframes)", max_queued_keyframes);
  ba.Check();
  inertial.Check();
  calibration.Check();
}

void InertialMappingOptions::Check() const {
  PKSLAM_CHECK_OPTION(min_keyframes >= 3, "inertial.min_keyframes", "{}", min_keyframes);
  PKSLAM_CHECK_OPTION(min_time_stereo_s >= 0 && min_time_mono_s >= 0, "inertial.min_time",
                      "{} / {}", min_time_stereo_s, min_time_mono_s);
  PKSLAM_CHECK_OPTION(mono_min_travel >= 0, "inertial.mono_min_travel", "{}", mono_min_travel);
  PKSLAM_CHECK_OPTION(init_gyro_prior >= 0 && init_accel_prior_mono >= 0 &&
                          init_accel_prior_stereo >= 0 && viba1_gyro_prior >= 0 &&
                          viba1_accel_prior >= 0 && viba2_gyro_prior >= 0 && viba2_accel_prior >= 0,
                      "inertial.priors", "{}", "negative");
  PKSLAM_CHECK_OPTION(viba1_s > 0 && viba2_s > viba1_s, "inertial.viba", "{} / {}", viba1_s,
                      viba2_s);
  PKSLAM_CHECK_OPTION(moving_distance >= 0 && moving_angle_rad >= 0 && moving_max_interval_s > 0,
                      "inertial.moving", "{} / {} / {}", moving_distance, moving_angle_rad,
                      moving_max_interval_s);
  PKSLAM_CHECK_OPTION(full_ba_iterations >= 1, "inertial.full_ba_iterations", "{}",
                      full_ba_iterations);
  local_ba.Check();
  culling.Check();
}

}  // namespace pkslam
