#include "tracking/frame_tracking.h"

#include <algorithm>
#include <vector>

#include "core/bow/vocabulary.h"
#include "map_model/keyframe.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"

namespace pkslam {

int DiscardOutliers(Frame* frame) {
  int in_map = 0;
  for (int i = 0; i < frame->size(); ++i) {
    if (!frame->map_points[i]) continue;
    if (frame->outliers[i]) {
      frame->map_points[i].reset();
      frame->outliers[i] = 0;
    } else if (frame->map_points[i]->NumObservations() > 0) {
      ++in_map;
    }
  }
  return in_map;
}

int OptimizeAndDiscard(const PoseOptimizerOptions& options, Frame* frame) {
  frame->outliers.assign(frame->size(), 0);
  OptimizePose(frame, options);
  return DiscardOutliers(frame);
}

int MatchLastFrame(const Frame& last, double radius, bool monocular, int min_matches,
                   Frame* frame) {
  std::fill(frame->map_points.begin(), frame->map_points.end(), nullptr);
  const OrbMatcher matcher(0.9, true);
  int n = matcher.SearchByProjection(frame, last, radius, monocular);
  if (n < min_matches) {
    // Wider window before giving up (ORB-SLAM doubles it).
    std::fill(frame->map_points.begin(), frame->map_points.end(), nullptr);
    n = matcher.SearchByProjection(frame, last, 2 * radius, monocular);
  }
  return n;
}

int MatchLastFramePredicted(const Frame& last, const TrackingOptions& options, bool monocular,
                            bool inertial, Frame* frame) {
  return MatchLastFrame(last, options.MotionModelRadius(monocular, inertial), monocular,
                        options.min_matches_motion_model, frame);
}

int CountLocalMapInliers(bool drop_outliers, Frame* frame) {
  int inliers = 0;
  for (int i = 0; i < frame->size(); ++i) {
    const auto& mp = frame->map_points[i];
    if (!mp) continue;
    if (!frame->outliers[i]) {
      mp->IncreaseFound();
      if (mp->NumObservations() > 0) ++inliers;
    } else if (drop_outliers) {
      frame->map_points[i].reset();
    }
  }
  return inliers;
}

void FollowReplacedPoints(Frame* frame) {
  for (auto& mp : frame->map_points) {
    while (mp && mp->replaced_by()) mp = mp->replaced_by();
  }
}

void DropUnmappedMatches(Frame* frame) {
  for (int i = 0; i < frame->size(); ++i) {
    const auto& mp = frame->map_points[i];
    if (mp && mp->NumObservations() < 1) {
      frame->map_points[i].reset();
      frame->outliers[i] = 0;
    }
  }
}

void DropOutlierMatches(Frame* frame) {
  for (int i = 0; i < frame->size(); ++i) {
    if (frame->map_points[i] && frame->outliers[i]) frame->map_points[i].reset();
  }
}

std::optional<int> TrackToKeyFrame(const KeyFrame& reference, const Vocabulary& vocabulary,
                                   const SE3d& initial, const ReferenceMatching& matching,
                                   const PoseOptimizerOptions& options, Frame* frame) {
  frame->ComputeBoW(vocabulary);
  const OrbMatcher matcher(matching.ratio, true);
  std::vector<MapPointPtr> matches;
  const int n = matcher.SearchByBoW(reference, *frame, &matches);
  if (n < matching.min_matches) return std::nullopt;
  frame->map_points = std::move(matches);
  frame->SetPose(initial);
  return OptimizeAndDiscard(options, frame);
}

}  // namespace pkslam
