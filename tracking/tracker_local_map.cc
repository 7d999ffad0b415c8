// Frame-to-map tracking: motion model, reference keyframe, local map (ORB-SLAM3's
// TrackWithMotionModel, TrackReferenceKeyFrame, TrackLocalMap; the local map itself is
// tracking/local_map.h) and relocalisation (tracking/relocaliser.h). Runs under the Atlas shared
// lock taken in Tracker::Track.
#include <algorithm>

#include "core/bow/vocabulary.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_point.h"
#include "tracking/frame_tracking.h"
#include "tracking/localisation_tracking.h"
#include "tracking/pose_optimizer.h"
#include "tracking/relocaliser.h"
#include "tracking/tracker.h"

namespace pkslam {

bool Tracker::TrackReferenceKeyFrame() {
  if (!reference_kf_ || reference_kf_->IsBad()) return false;
  const ReferenceMatching matching{options_.reference_kf_ratio, options_.min_matches_reference_kf};
  const std::optional<int> in_map = TrackToKeyFrame(
      *reference_kf_, *vocabulary_, last_.camera_from_world(), matching, options_.pose, &current_);
  return in_map && *in_map >= 10;
}

void Tracker::UpdateLastFrame() {
  // The reference keyframe may have moved (local BA) since the last frame was tracked.
  const FrameRecord& record = records_.back();
  if (record.reference && !record.reference->IsBad()) {
    last_.SetPose(record.camera_from_reference * record.reference->camera_from_world());
  }
  if (options_.localise_only && !IsMonocular(rig_->sensor)) {
    AddVisualOdometryPoints(rig_->th_depth, options_.max_temporal_points, &last_);
  }
}

bool Tracker::TrackWithMotionModel() {
  UpdateLastFrame();
  current_.SetPose(*velocity_ * last_.camera_from_world());
  const bool mono = IsMonocular(rig_->sensor);
  const int n = MatchLastFramePredicted(last_, options_, mono, &current_);
  if (n < options_.min_matches_motion_model) return false;
  const int in_map = OptimizeAndDiscard(options_.pose, &current_);
  if (options_.localise_only && !mono) {
    // Localisation: temporary visual-odometry points count too (LocalisationTracking decides
    // whether the map or odometry placed the frame); ORB-SLAM asks for 20 matches in all.
    return in_map >= 10 || InlierMatches(current_, /*map_only=*/false) >= 20;
  }
  return in_map >= 10;
}

bool Tracker::TrackLocalMap() {
  if (KeyFrame* best = local_map_.Update(&current_)) {
    reference_kf_ = atlas_->current_map()->Share(best);
    if (!reference_kf_) reference_kf_ = best->map() != nullptr ? best->map()->Share(best) : nullptr;
    current_.reference_kf = reference_kf_;
  }
  const bool lost = state_ == TrackingState::kRecentlyLost || state_ == TrackingState::kLost;
  const double radius = options_.LocalSearchRadius(IsRgbd(rig_->sensor),
                                                   current_.id() < last_reloc_frame_id_ + 2, lost);
  local_map_.Search(&current_, *rig_, radius);
  current_.outliers.assign(current_.size(), 0);
  OptimizeCurrentPose();
  inliers_ = CountLocalMapInliers(IsStereo(rig_->sensor), &current_);
  const int max_frames = static_cast<int>(rig_->fps + 0.5);
  if (current_.id() < last_reloc_frame_id_ + max_frames &&
      inliers_ < options_.min_inliers_after_reloc) {
    return false;
  }
  if (state_ == TrackingState::kRecentlyLost && inliers_ > 10) return true;
  return inliers_ >= options_.min_inliers;
}

bool Tracker::Relocalize() {
  const KeyFrameDatabase* database = atlas_->database();
  if (database == nullptr) return false;
  const std::uint64_t seed = MixSeed(options_.seed, static_cast<std::uint64_t>(current_.id()));
  const RelocalisationResult result =
      relocalisation_.Try(*database, atlas_->current_map(), *vocabulary_, *rig_, seed, &current_);
  if (result.success) last_reloc_frame_id_ = current_.id();
  return result.success;
}

}  // namespace pkslam
