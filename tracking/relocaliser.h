// Relocalisation (ORB-SLAM3's Tracking::Relocalization): keyframes that look like the frame
// (BoW place search in the keyframe database) are matched to it, a PnP RANSAC per candidate
// proposes poses, and a pose is accepted once pose optimisation and projection searches
// confirm it with at least kMinRelocalisationInliers inliers.
//
// Tracking thread, Atlas lock held (shared): it reads keyframes and points and writes only the
// frame.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/sensor/camera_rig.h"
#include "map_model/frame.h"
#include "map_model/map_ids.h"
#include "tracking/pose_optimizer.h"

namespace pkslam {

class KeyFrameDatabase;
class Vocabulary;

constexpr int kMinRelocalisationInliers = 50;

struct RelocalisationOptions {
  // The wider place search (lower word and group ratios, at most `wide_candidates` places),
  // for after repeated failure: the view is then likely further from every keyframe than the
  // usual thresholds allow.
  bool wide = false;
  int wide_candidates = 20;
  std::uint64_t seed = 0;  // the PnP RANSAC's
  PoseOptimizerOptions pose;
};

struct RelocalisationResult {
  bool success = false;
  KeyFrameId keyframe = kInvalidId;  // the candidate that confirmed the pose
  int inliers = 0;
  std::size_t places = 0;      // keyframes the place search returned
  std::size_t candidates = 0;  // of them, with enough BoW matches for a PnP
};

// Finds `frame`'s pose in `map` (computes its BoW first). On success the frame has the pose
// and its inlier matches; otherwise it has no matches (its pose is left as the last PnP put it).
RelocalisationResult RelocaliseFrame(const KeyFrameDatabase& database, const Map* map,
                                     const Vocabulary& vocabulary, const CameraRig& rig,
                                     const RelocalisationOptions& options, Frame* frame);

// Tracking's attempts in a row (ORB-SLAM3 retries every frame while lost): after
// `widen_after` failures the place search widens (RelocalisationOptions::wide) until one
// succeeds; successes are counted. Tracking thread.
class RelocalisationAttempts {
 public:
  RelocalisationAttempts(int widen_after, int wide_candidates, const PoseOptimizerOptions& pose)
      : widen_after_(widen_after), wide_candidates_(wide_candidates), pose_(pose) {}

  // RelocaliseFrame for `frame`, its RANSAC seeded by `seed`; logged. Atlas lock held (shared).
  RelocalisationResult Try(const KeyFrameDatabase& database, const Map* map,
                           const Vocabulary& vocabulary, const CameraRig& rig, std::uint64_t seed,
                           Frame* frame);

  int successes() const { return successes_; }
  int failures_in_a_row() const { return failures_in_a_row_; }
  bool NextIsWide() const { return failures_in_a_row_ >= widen_after_; }

 private:
  int widen_after_;
  int wide_candidates_;
  PoseOptimizerOptions pose_;
  int successes_ = 0;
  int failures_in_a_row_ = 0;
};

}  // namespace pkslam
