// Reconstruction from 2-D tracks (seed 002, `pkslam tracks reconstruct`): the geometric core of
// PTAM-style monocular SLAM without feature matching. A processor in two states, as the thesis
// describes it:
//   initialisation  two frames -> fundamental matrix -> E -> [R|t] by cheirality -> linear
//                   triangulation (tracks_two_view.h), from the first two frames (the thesis)
//                   or from the first pair with enough baseline (its proposed fix);
//   frame           PnP (RANSAC + motion-only refinement, estimators/) against the map; when
//                   the keyframe rule fires: triangulate the keyframe's new tracks, then local
//                   bundle adjustment over the latest keyframes (estimators/optim). A global
//                   bundle adjustment closes the run, and each frame is re-posed against
//                   the final map.
// Keyframe rules: the thesis's four, through pkslam's selectors where one exists (ptam,
// match-count and interval are keyframe/baseline_selectors.h; the map-to-new-match ratio is
// here). Every rule shares one safety: a keyframe when the map matches fall below a share of
// those at the last keyframe ("starving"), so no rule lets tracking die silently.
// Single-threaded and deterministic for a given seed.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/geometry/se3.h"
#include "io/track_file.h"
#include "keyframe/baseline_selectors.h"
#include "tracks/track_index.h"
#include "tracks/tracks_two_view.h"

namespace pkslam {

enum class TracksKeyframeRule { kPtam, kMatchCount, kInterval, kRatio };
// "ptam", "match-count", "interval", "ratio"; OptionError otherwise.
TracksKeyframeRule ParseTracksKeyframeRule(std::string_view name);
std::string_view TracksKeyframeRuleName(TracksKeyframeRule rule);

enum class TracksInitMode {
  kAuto,      // the first pair that passes the baseline test: first frame with each later one
              // in a window; if none, the first frame moves on half a window
  kFirstTwo,  // the thesis: the first two frames, whatever their baseline
  kFixed,     // the first frame with `init_second_frame`
};
TracksInitMode ParseTracksInitMode(std::string_view name);  // auto | first-two | fixed
std::string_view TracksInitModeName(TracksInitMode mode);

struct TracksReconstructionOptions {
  TracksKeyframeRule keyframe_rule = TracksKeyframeRule::kPtam;
  // ptam (>= ptam_min_frames since the last keyframe and moved ptam_min_distance_ratio of the
  // median depth), match-count (fewer than match_count_min map points shared with the last
  // keyframe), interval (every interval_frames): keyframe/baseline_selectors.h.
  BaselineOptions baseline;
  // ratio: a keyframe when the tracks already in the map number fewer than ratio_max times
  // the new tracks (seen in the last keyframe, not yet triangulated), at least
  // ratio_min_frames after the last keyframe.
  double ratio_max = 4.0;
  int ratio_min_frames = 5;
  // Every rule: a keyframe when the map matches fall below this share of the last keyframe's.
  double starving_share = 0.5;

  TracksInitMode init_mode = TracksInitMode::kAuto;
  int init_second_frame = -1;          // kFixed
  int init_search_frames = 60;         // kAuto: later frames tried
  double init_min_parallax_deg = 2.0;  // kAuto: the baseline test
  TracksTwoViewOptions two_view;       // sigma, RANSAC, acceptance (min_parallax set by mode)

  // New points need this ray angle between the two keyframes that triangulate them.
  double min_triangulation_parallax_deg = 1.0;
  int local_window = 10;  // keyframes optimised by each local bundle adjustment
  bool global_ba = true;  // one global bundle adjustment at the end
  // Re-solve every non-keyframe pose against the final map (offline: the frames tracked
  // before the last bundle adjustments otherwise only follow their keyframe rigidly).
  bool refine_frames = true;
  int min_tracked = 10;  // fewer PnP inliers: the frame is lost
  std::uint64_t seed = 1;

  void Check() const;
};

struct TracksFrameResult {
  bool tracked = false;
  bool keyframe = false;
  std::string keyframe_reason;  // rule that created it ("init" for the initial pair)
  SE3d camera_from_world;       // final (keyframes after BA; others through their keyframe)
  int observations = 0;         // tracks seen in the frame
  int map_matches = 0;          // of them, tracks with a map point when it was processed
  int inliers = 0;              // PnP inliers (keyframes of the initial pair: triangulated)
};

struct TracksReconstruction {
  std::vector<TracksFrameResult> frames;               // per frame of the tracks file
  std::vector<std::optional<Eigen::Vector3d>> points;  // per dense track (TrackIndex)
  int init_first = -1, init_second = -1;
  TracksTwoViewResult init;
  // Pairs refused before the accepted one.
  struct RefusedPair {
    int first = 0, second = 0;
    std::string reason;
  };
  std::vector<RefusedPair> init_refused;
  std::map<std::string, int> keyframe_reasons;
  int num_keyframes = 0;
  int lost_frames = 0;
  int local_ba_runs = 0;
  double seconds_init = 0, seconds_tracking = 0, seconds_mapping = 0, seconds_total = 0;
};

// Throws Error when no initial pair can be found (the message says why for the last pair).
// progress (may be empty) is called with (frames done, frames) now and then.
TracksReconstruction ReconstructFromTracks(const TrackSet& tracks, const TrackIndex& index,
                                           const TracksReconstructionOptions& options,
                                           const std::function<void(int, int)>& progress = {});

// Reprojection errors (pixels) at the final poses and points of every observation in `frame`
// whose track has a map point in front of the camera (empty for a frame not tracked).
std::vector<double> FrameReprojectionErrors(const TracksReconstruction& r, const TrackIndex& index,
                                            const PinholeIntrinsics& camera, int frame);

}  // namespace pkslam
