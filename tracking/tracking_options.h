// Options of the tracking thread (ORB-SLAM3 defaults; see ORBSLAM3_FACTS.md "Tracking").
#pragma once

#include <cstdint>

#include "tracking/pose_optimizer.h"

namespace pkslam {

struct TrackingOptions {
  // Stereo/RGB-D: features needed in the first frame to initialise a map.
  int min_features_stereo_init = 500;
  // ... of which at least this many with depth. Without it an all-zero depth image (or a
  // stereo pair without one match) started a map of zero points and the run reported its
  // frames as tracked while it wrote an empty trajectory. (ORB-SLAM3 checks the feature count
  // only.)
  int min_depth_points_stereo_init = 50;
  // Monocular: the fewest points the second keyframe of a two-view map must track after its
  // refinement for the map to be kept (ORB-SLAM3: 50); a map below it is refused and reset.
  int min_two_view_map_points = 50;
  // Stereo/RGB-D initialisation creates points for keypoints closer than this many
  // th_depth... ORB-SLAM uses every keypoint with positive depth; kept as a switch.
  bool init_only_close_points = false;
  // Motion-model search radius (pixels at level 0), stereo/RGB-D and monocular.
  double motion_model_radius_stereo = 7.0;
  double motion_model_radius_mono = 15.0;
  // Inertial sensors: how a tracked frame finds its matches.
  //  kLastFrame (pkslam): the IMU-predicted frame is matched against the last frame within the
  //    motion-model radius, then against the local map at local_map_radius.
  //  kOrbSlam3 (ORB-SLAM3 v1.0's TrackWithMotionModel and SearchLocalPoints): once the IMU is
  //    initialised the prediction stands alone (no last-frame matching, except within a second of
  //    a relocalisation), so the local map is searched wider: 10x the octave scale before the IMU
  //    is initialised, 6x until the second inertial BA, 2x after; stereo-inertial's motion model
  //    (before IMU initialisation) searches at the monocular radius (ORB-SLAM3 narrows it to 7 px
  //    for plain stereo only). For studies of keyframe rules that read tracking's match counts:
  //    with it, the `orbslam3-v03` reading makes the v0.3 binary's keyframes (docs/pks_study.md).
  enum class InertialSearch { kLastFrame, kOrbSlam3 };
  InertialSearch inertial_search = InertialSearch::kLastFrame;
  // Its names on the command line and in stats.json: "last-frame", "orbslam3".
  static const char* InertialSearchName(InertialSearch search) {
    return search == InertialSearch::kOrbSlam3 ? "orbslam3" : "last-frame";
  }
  // Minimum matches for motion-model / reference-keyframe tracking to succeed.
  int min_matches_motion_model = 20;
  int min_matches_reference_kf = 15;
  // Lowe ratio for reference-keyframe BoW matching.
  double reference_kf_ratio = 0.7;
  // Local map: maximum local keyframes.
  int max_local_keyframes = 80;
  // Local-map search radius (pixels, times the octave scale); larger right after
  // relocalisation.
  double local_map_radius = 1.0;
  double local_map_radius_after_reloc = 5.0;
  // Inliers required for tracking to be OK: right after relocalisation / otherwise.
  int min_inliers_after_reloc = 50;
  int min_inliers = 30;
  // Stereo: temporary "visual odometry" points for close untracked keypoints of the last
  // frame, at most this many (ORB-SLAM's UpdateLastFrame creates up to 100).
  int max_temporal_points = 100;
  // New keyframes (stereo/RGB-D): create points from close untracked keypoints, at least
  // this many (ORB-SLAM: 100 closest, and all closer than th_depth).
  int new_keyframe_min_close_points = 100;
  // Seconds in RECENTLY_LOST before declaring LOST (inertial).
  double recently_lost_timeout_s = 5.0;
  // A lost monocular map with at most this many keyframes is reset instead of kept in the Atlas
  // (stereo and RGB-D maps are always kept: metric from their first keyframe).
  int min_keyframes_to_keep_map = 10;
  // Relocalisation widens its search after this many failed attempts in a row (localisation
  // mode tries on every frame without a pose): the place query keeps keyframes sharing half the
  // best one's words (ORB-SLAM: 80%) and groups scoring half the best group's (75%), at most
  // relocalisation_wide_candidates of them.
  int relocalisation_widen_after = 5;
  int relocalisation_wide_candidates = 20;
  // Deterministic mode: wait for local mapping to finish each keyframe before going on.
  bool lockstep = false;
  // Localisation only (--localise-only, on a loaded map; ORB-SLAM3's localisation mode):
  // track against the map without creating keyframes or points; a lost frame is
  // relocalised (the map is never reset), the inertial paths are not used.
  bool localise_only = false;
  // Monocular sensors, while local mapping is busy (ORB-SLAM refuses monocular keyframes
  // then): tracking inserts a keyframe anyway, interrupting the local BA, when its map is
  // about to starve: the selector wanted one and tracking holds fewer than
  // `starving_inliers`, or tracking holds fewer than `starving_ratio` of the reference
  // keyframe's points whatever the selector said. Mapping's queue must be short (< 3).
  // ORB-SLAM3 inserts while busy for stereo and RGB-D only; on a mono-inertial V1_02 replay
  // with live timing tracking was lost at 28 s in 2 of 3 runs without it (mapping busy
  // 350 ms, inliers 215 -> 31). 0 switches either rule off (ORB-SLAM3's behaviour).
  int starving_inliers = 75;
  double starving_ratio = 0.5;
  // Mixed into every RANSAC seed (two-view initialisation, relocalisation PnP): runs with
  // different seeds differ, runs with the same seed in deterministic mode are identical.
  std::uint64_t seed = 0;
  PoseOptimizerOptions pose;

  void Check() const;

  // Keyframes a lost map needs to be kept (else it is reset). A monocular map of a few
  // keyframes is mostly its two-view initialisation, with a scale of its own: ORB-SLAM3 resets
  // it. A stereo or RGB-D map is metric from its first keyframe: it is kept, so a short loss (20
  // black frames) no longer drops the frames tracked before it, and the next map may be merged
  // with it.
  int MinKeyFramesToKeepMap(bool monocular) const {
    return monocular ? min_keyframes_to_keep_map : 0;
  }
  // The local map's search radius (pixels at level 0) for a frame: RGB-D's narrow one, wider
  // right after a relocalisation, widest while lost (ORB-SLAM3's SearchLocalPoints).
  double LocalSearchRadius(bool rgbd, bool just_relocalised, bool lost) const {
    double radius = rgbd ? 3.0 : local_map_radius;
    if (just_relocalised) radius = local_map_radius_after_reloc;
    if (lost) radius = 15.0;
    return radius;
  }
  // kOrbSlam3's local-map radius for a tracked inertial frame (not just relocalised, not lost).
  static double InertialLocalSearchRadius(bool imu_initialised, bool inertial_ba2_done) {
    if (!imu_initialised) return 10.0;
    return inertial_ba2_done ? 2.0 : 6.0;
  }
  // The motion model's radius (pixels at level 0).
  double MotionModelRadius(bool monocular, bool inertial) const {
    const bool wide = monocular || (inertial && inertial_search == InertialSearch::kOrbSlam3);
    return wide ? motion_model_radius_mono : motion_model_radius_stereo;
  }
};

// A RANSAC seed from the run seed and a per-call value (a frame id). Run seed 0 gives the
// per-call value itself.
inline std::uint64_t MixSeed(std::uint64_t run_seed, std::uint64_t value) {
  return value + run_seed * 0x9E3779B97F4A7C15ULL;
}

}  // namespace pkslam
