// Frame-to-map tracking: motion model, reference keyframe, local map (ORB-SLAM3's
// TrackWithMotionModel, TrackReferenceKeyFrame, TrackLocalMap; the local map itself is
// tracking/local_map.h). Runs under the Atlas shared
// lock taken in Tracker::Track.
#include <algorithm>

#include "core/bow/vocabulary.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_point.h"
#include "tracking/frame_tracking.h"
#include "tracking/pose_optimizer.h"
#include "tracking/tracker.h"

namespace pkslam {
bool Tracker::TrackReferenceKeyFrame() {
  if (!reference_kf_ || reference_kf_->IsBad()) return false;
  const ReferenceMatching matching{options_.reference_kf_ratio, options_.min_matches_reference_kf};
  const std::optional<int> in_map = TrackToKeyFrame(
      *reference_kf_, *vocabulary_, last_.camera_from_world(), matching, options_.pose, &current_);
  return in_map && *in_map >= 10;
}

int Tracker::InlierMatches(const Frame& frame, bool map_only) {
  int n = 0;
  for (int i = 0; i < frame.size(); ++i) {
    const auto& mp = frame.map_points[i];
    const bool outlier = i < static_cast<int>(frame.outliers.size()) && frame.outliers[i];
    if (mp && !outlier && (!map_only || mp->NumObservations() > 0)) ++n;
  }
  return n;
}

void Tracker::UpdateLastFrame() {
  // The reference keyframe may have moved (local BA) since the last frame was tracked.
  const FrameRecord& record = records_.back();
  if (record.reference && !record.reference->IsBad()) {
    last_.SetPose(record.camera_from_reference * record.reference->camera_from_world());
  }
  if (options_.localise_only && !IsMonocular(rig_->sensor)) AddVisualOdometryPoints();
}

void Tracker::AddVisualOdometryPoints() {
  // The closest keypoints with depth that have no map point: all closer than th_depth, and at
  // least max_temporal_points of them (ORB-SLAM's UpdateLastFrame does the same in its
  // localisation mode).
  std::vector<std::pair<float, int>> by_depth;
  for (int i = 0; i < last_.size(); ++i) {
    if (!last_.HasDepth(i)) continue;
    const auto& mp = last_.map_points[i];
    if (mp && mp->NumObservations() > 0) continue;
    by_depth.emplace_back(last_.depth()[i], i);
  }
  std::sort(by_depth.begin(), by_depth.end());
  int added = 0;
  for (const auto& [depth, i] : by_depth) {
    if (depth > rig_->th_depth && added >= options_.max_temporal_points) break;
    const auto world = last_.UnprojectStereo(i);
    if (!world) continue;
    last_.map_points[i] = MapPoint::Temporary(*world, last_.descriptors()[i]);
    if (i < static_cast<int>(last_.outliers.size())) last_.outliers[i] = 0;
    ++added;
  }
}

bool Tracker::TrackWithMotionModel() {
  UpdateLastFrame();
  current_.SetPose(*velocity_ * last_.camera_from_world());
  const bool mono = IsMonocular(rig_->sensor);
  const double th = mono ? options_.motion_model_radius_mono : options_.motion_model_radius_stereo;
  const int n = MatchLastFrame(last_, th, mono, options_.min_matches_motion_model, &current_);
  if (n < options_.min_matches_motion_model) return false;
  const int in_map = OptimizeAndDiscard(options_.pose, &current_);
  if (options_.localise_only && !mono) {
    // Localisation: temporary visual-odometry points count too (TrackLocalisationOnly decides
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
  local_map_.Search(&current_, *rig_, LocalSearchRadius());
  current_.outliers.assign(current_.size(), 0);
  OptimizeCurrentPose();
  inliers_ = 0;
  for (int i = 0; i < current_.size(); ++i) {
    const auto& mp = current_.map_points[i];
    if (!mp) continue;
    if (!current_.outliers[i]) {
      mp->IncreaseFound();
      if (mp->NumObservations() > 0) ++inliers_;
    } else if (IsStereo(rig_->sensor)) {
      current_.map_points[i].reset();
    }
  }
  const int max_frames = static_cast<int>(rig_->fps + 0.5);
  if (current_.id() < last_reloc_frame_id_ + max_frames &&
      inliers_ < options_.min_inliers_after_reloc) {
    return false;
  }
  if (state_ == TrackingState::kRecentlyLost && inliers_ > 10) return true;
  return inliers_ >= options_.min_inliers;
}

double Tracker::LocalSearchRadius() const {
  double radius = IsRgbd(rig_->sensor) ? 3.0 : options_.local_map_radius;
  if (current_.id() < last_reloc_frame_id_ + 2) radius = options_.local_map_radius_after_reloc;
  if (state_ == TrackingState::kRecentlyLost || state_ == TrackingState::kLost) radius = 15.0;
  return radius;
}

}  // namespace pkslam
