// How tracking starts a map (ORB-SLAM3's StereoInitialization and MonocularInitialization /
// CreateInitialMapMonocular), as parts the Tracker calls: a stereo or RGB-D frame becomes the
// first keyframe with a point per depth reading; monocular frames are paired until two views
// reconstruct, then become two keyframes, refined together and scaled to a unit median depth.
//
// Tracking thread. The map-building steps take the Atlas's write lock as a parameter (they add
// keyframes and points); RefineTwoViewMap takes the locks itself (its solve runs unlocked).
#pragma once

#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "map_model/frame.h"
#include "map_model/map_ids.h"
#include "tracking/tracking_options.h"
#include "tracking/two_view_initializer.h"

namespace pkslam {

class Atlas;
class MapWriteLock;
class Vocabulary;

// Joins a keyframe just made from `frame` to its map's inertial chain after `previous` (null:
// it starts the chain): the Tracker's AttachImu, which does nothing for visual sensors.
using AttachKeyFrame = std::function<void(const MapWriteLock&, KeyFrame* keyframe,
                                          KeyFrame* previous, const Frame& frame)>;

// --- stereo and RGB-D ---

// Whether `frame` has enough keypoints, and enough of them with depth, to start a map
// (TrackingOptions::min_features_stereo_init, min_depth_points_stereo_init).
bool CanStartDepthMap(const Frame& frame, const TrackingOptions& options);

struct DepthMapStart {
  KeyFramePtr keyframe;
  int points = 0;
};
// `frame` at the origin becomes the first keyframe of the Atlas's current map, and every
// keypoint with depth a map point at its stereo/depth position, observed by that keyframe and
// put into the frame's slot.
DepthMapStart StartDepthMap(const MapWriteLock& lock, Atlas* atlas, const Vocabulary& vocabulary,
                            const AttachKeyFrame& attach, Frame* frame);

// --- monocular ---

// The first frame of a candidate pair and where its keypoints were last matched.
class TwoViewStart {
 public:
  // Frames with no more keypoints than this neither start nor complete a pair.
  static constexpr int kMinFeatures = 100;

  // Offers the next frame. With no first frame it becomes the first (if it has enough
  // keypoints). Otherwise its keypoints are matched to the first frame's; too few keypoints or
  // matches drop the first frame; enough matches are reconstructed (`seed` drives the RANSAC)
  // and the reconstruction is returned, with matches() cut to its triangulated points.
  std::optional<TwoViewResult> Offer(const Frame& frame, std::uint64_t seed);

  bool started() const { return first_.has_value(); }
  Frame& first() { return *first_; }
  const Frame& first() const { return *first_; }
  // Per keypoint of the first frame: the matched keypoint of the last offered frame, or -1.
  const std::vector<int>& matches() const { return matches_; }
  void Reset() { first_.reset(); }

 private:
  std::optional<Frame> first_;
  std::vector<cv::Point2f> last_matched_;  // where the first frame's keypoints were last seen
  std::vector<int> matches_;
};

struct TwoViewKeyFrames {
  KeyFramePtr first;
  KeyFramePtr second;
};
// The two frames of `reconstruction` (first at the origin, second at its relative pose) become
// keyframes of the Atlas's current map, and every triangulated match a map point observed by
// both and put into `second`'s slot.
TwoViewKeyFrames CreateTwoViewMap(const MapWriteLock& lock, Atlas* atlas,
                                  const Vocabulary& vocabulary, const AttachKeyFrame& attach,
                                  const TwoViewResult& reconstruction,
                                  const std::vector<int>& matches, Frame* first, Frame* second);

// A full bundle adjustment of the current map (the two views and their points), before the
// scale is fixed. Takes the Atlas locks itself.
void RefineTwoViewMap(Atlas* atlas);

// Makes the map's unit the first keyframe's median scene depth: the second keyframe, its frame
// `second` and the points are scaled. Refused (nothing changes) when the map is unusable: no
// positive median depth, or the second keyframe tracks fewer than `min_points` points.
struct TwoViewScaling {
  double median_depth = 0;
  bool accepted = false;
};
TwoViewScaling NormaliseTwoViewScale(const MapWriteLock& lock, const TwoViewKeyFrames& map,
                                     int min_points, Frame* second);

}  // namespace pkslam
