// Tracking a frame against the last frame (motion model, IMU prediction) or against the
// reference keyframe (ORB-SLAM3's TrackWithMotionModel / TrackReferenceKeyFrame matching), as
// functions of the frames they match; the Tracker decides which to use and what counts as
// tracked. Tracking thread, Atlas lock held (shared): they read map points.
#pragma once

#include <optional>

#include "core/geometry/se3.h"
#include "map_model/frame.h"
#include "map_model/map_ids.h"
#include "tracking/pose_optimizer.h"
#include "tracking/tracking_options.h"

namespace pkslam {

class Vocabulary;

// Drops the matches the pose optimisation flagged as outliers (clearing the flags); returns the
// matches left to points in the map (temporary visual-odometry points have no observations).
int DiscardOutliers(Frame* frame);

// Optimises `frame`'s pose on its matches (outlier flags reset first), then DiscardOutliers.
int OptimizeAndDiscard(const PoseOptimizerOptions& options, Frame* frame);

// Projects `last`'s matched points into `frame` at its pose (set by the caller) within `radius`
// pixels (level 0); when fewer than `min_matches` are found, searches again with twice the
// radius (ORB-SLAM3). `frame`'s previous matches are cleared. Returns the matches found.
int MatchLastFrame(const Frame& last, double radius, bool monocular, int min_matches, Frame* frame);

// The threshold MatchLastFrame searches within for a frame predicted by the motion model or the
// IMU: TrackingOptions::MotionModelRadius.
int MatchLastFramePredicted(const Frame& last, const TrackingOptions& options, bool monocular,
                            bool inertial, Frame* frame);

// After the local map's pose optimisation: every inlier's point was found once more; with
// `drop_outliers` (ORB-SLAM3: plain stereo only) the outliers' matches are forgotten now, else
// they stay for a new keyframe's BA and go after the keyframe decision (Tracker::ActOnDecision).
// Returns the inliers to points in the map.
int CountLocalMapInliers(bool drop_outliers, Frame* frame);

// Matches of the last frame to points local mapping fused into others follow them.
void FollowReplacedPoints(Frame* frame);
// Matches to points that are no longer in the map (no observations) are dropped.
void DropUnmappedMatches(Frame* frame);
// Matches flagged as outliers are dropped (the next frame must not use them for its pose).
void DropOutlierMatches(Frame* frame);

struct ReferenceMatching {
  double ratio = 0.7;    // nearest / second-nearest descriptor distance ratio (BoW search)
  int min_matches = 15;  // fewer BoW matches: not tracked
};
// Matches `frame` to `reference` through their BoW (computing the frame's), starts from
// `initial`, optimises and drops outliers. Returns the matches left to map points, or nullopt
// (and leaves the frame's matches as they were) when there are too few BoW matches.
std::optional<int> TrackToKeyFrame(const KeyFrame& reference, const Vocabulary& vocabulary,
                                   const SE3d& initial, const ReferenceMatching& matching,
                                   const PoseOptimizerOptions& options, Frame* frame);

}  // namespace pkslam
