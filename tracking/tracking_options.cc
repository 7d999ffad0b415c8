#include "tracking/tracking_options.h"

#include "core/util/error.h"

namespace pkslam {

void TrackingOptions::Check() const {
  PKSLAM_CHECK_OPTION(min_features_stereo_init > 0, "Tracking.min_features_stereo_init", "{}",
                      min_features_stereo_init);
  PKSLAM_CHECK_OPTION(min_depth_points_stereo_init > 0, "Tracking.min_depth_points_stereo_init",
                      "{}", min_depth_points_stereo_init);
  PKSLAM_CHECK_OPTION(min_two_view_map_points > 0, "Tracking.min_two_view_map_points", "{}",
                      min_two_view_map_points);
  PKSLAM_CHECK_OPTION(starving_inliers >= 0 && starving_ratio >= 0 && starving_ratio < 1,
                      "Tracking.starving", "{} / {}", starving_inliers, starving_ratio);
  PKSLAM_CHECK_OPTION(max_local_keyframes > 0, "Tracking.max_local_keyframes", "{}",
                      max_local_keyframes);
  PKSLAM_CHECK_OPTION(min_inliers > 0 && min_inliers_after_reloc > 0, "Tracking.min_inliers",
                      "{} / {}", min_inliers, min_inliers_after_reloc);
  PKSLAM_CHECK_OPTION(motion_model_radius_stereo > 0 && motion_model_radius_mono > 0,
                      "Tracking.motion_model_radius", "{} / {}", motion_model_radius_stereo,
                      motion_model_radius_mono);
  PKSLAM_CHECK_OPTION(relocalisation_widen_after >= 0 && relocalisation_wide_candidates > 0,
                      "Tracking.relocalisation_widen_after", "{} / {}", relocalisation_widen_after,
                      relocalisation_wide_candidates);
  pose.Check();
}

}  // namespace pkslam
