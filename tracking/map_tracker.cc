#include "tracking/map_tracker.h"

#include <algorithm>

#include "core/bow/vocabulary.h"
#include "core/util/error.h"
#include "map_model/atlas.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_point.h"
#include "tracking/frame_tracking.h"
#include "tracking/localisation_tracking.h"
#include "tracking/pose_optimizer.h"

namespace pkslam {

MapTracker::MapTracker(const Atlas* atlas, const Vocabulary* vocabulary,
                       const TrackingOptions& options, std::shared_ptr<const CameraRig> rig,
                       InertialTracking* imu)
    : atlas_(atlas),
      vocabulary_(vocabulary),
      options_(options),
      rig_(std::move(rig)),
      imu_(imu),
      local_map_(options.max_local_keyframes),
      relocalisation_(options.relocalisation_widen_after, options.relocalisation_wide_candidates,
                      options.pose) {
  PKSLAM_CHECK(atlas_ != nullptr && vocabulary_ != nullptr && rig_ != nullptr,
               "map tracking needs an atlas, a vocabulary and a rig");
}

bool MapTracker::TrackReferenceKeyFrame(TrackedFrames* frames) const {
  const KeyFramePtr& reference = frames->reference_kf;
  if (!reference || reference->IsBad()) return false;
  const ReferenceMatching matching{options_.reference_kf_ratio, options_.min_matches_reference_kf};
  const std::optional<int> in_map =
      TrackToKeyFrame(*reference, *vocabulary_, frames->last.camera_from_world(), matching,
                      options_.pose, &frames->current);
  return in_map && *in_map >= 10;
}

void MapTracker::UpdateLastFrame(const FrameRecord& last_record, TrackedFrames* frames) const {
  if (last_record.reference && !last_record.reference->IsBad()) {
    frames->last.SetPose(last_record.camera_from_reference *
                         last_record.reference->camera_from_world());
  }
  if (options_.localise_only && !IsMonocular(rig_->sensor)) {
    AddVisualOdometryPoints(rig_->th_depth, options_.max_temporal_points, &frames->last);
  }
}

bool MapTracker::TrackWithMotionModel(const FrameRecord& last_record, TrackedFrames* frames) const {
  PKSLAM_CHECK(frames->velocity.has_value(), "the motion model needs a velocity");
  UpdateLastFrame(last_record, frames);
  Frame& current = frames->current;
  current.SetPose(*frames->velocity * frames->last.camera_from_world());
  const bool mono = IsMonocular(rig_->sensor);
  const int n =
      MatchLastFramePredicted(frames->last, options_, mono, IsInertial(rig_->sensor), &current);
  if (n < options_.min_matches_motion_model) return false;
  const int in_map = OptimizeAndDiscard(options_.pose, &current);
  if (options_.localise_only && !mono) {
    // Localisation: temporary visual-odometry points count too (LocalisationTracking decides
    // whether the map or odometry placed the frame); ORB-SLAM asks for 20 matches in all.
    return in_map >= 10 || InlierMatches(current, /*map_only=*/false) >= 20;
  }
  return in_map >= 10;
}

bool MapTracker::PredictWithImu(TrackedFrames* frames) const {
  PKSLAM_CHECK(imu_ != nullptr, "IMU prediction without an IMU");
  return imu_->Predict(frames->last, frames->last_kf.get(), *rig_, &frames->current);
}

bool MapTracker::TrackWithImu(const FrameRecord& last_record, TrackedFrames* frames) const {
  UpdateLastFrame(last_record, frames);
  if (!PredictWithImu(frames)) return false;
  Frame& current = frames->current;
  // ORB-SLAM3's front end trusts the prediction alone once the IMU is initialised, except in
  // the second after a relocalisation; the local map search is then wider (TrackLocalMap).
  if (options_.inertial_search == TrackingOptions::InertialSearch::kLastFrame ||
      WithinASecondOfRelocalisation(*frames)) {
    MatchLastFramePredicted(frames->last, options_, IsMonocular(rig_->sensor), /*inertial=*/true,
                            &current);
  } else {
    std::fill(current.map_points.begin(), current.map_points.end(), nullptr);
  }
  current.outliers.assign(current.size(), 0);
  // The IMU prediction stands: the matches are classified by the visual-inertial optimisation
  // after the local map search (ORB-SLAM3 runs a visual-only optimisation here first; with the
  // IMU prediction it only costs time).
  return true;
}

bool MapTracker::Relocalise(TrackedFrames* frames) {
  const KeyFrameDatabase* database = atlas_->database();
  if (database == nullptr) return false;
  Frame& current = frames->current;
  const std::uint64_t seed = MixSeed(options_.seed, static_cast<std::uint64_t>(current.id()));
  const RelocalisationResult result =
      relocalisation_.Try(*database, atlas_->current_map(), *vocabulary_, *rig_, seed, &current);
  if (result.success) frames->last_reloc_frame_id = current.id();
  return result.success;
}

bool MapTracker::TrackLocalMap(TrackingState state, bool imu_ready, TrackedFrames* frames) {
  Frame& current = frames->current;
  // ORB-SLAM3's front end left an IMU-predicted frame without matches: the last frame's choose
  // its local map (as ORB-SLAM3's UpdateLocalKeyFrames once the IMU is initialised).
  const bool unmatched = options_.inertial_search == TrackingOptions::InertialSearch::kOrbSlam3 &&
                         std::none_of(current.map_points.begin(), current.map_points.end(),
                                      [](const MapPointPtr& mp) { return mp != nullptr; });
  const Frame* voters = unmatched ? &frames->last : nullptr;
  if (KeyFrame* best = local_map_.Update(&current, voters)) {
    KeyFramePtr reference = atlas_->current_map()->Share(best);
    if (!reference && best->map() != nullptr) reference = best->map()->Share(best);
    frames->reference_kf = reference;
    current.reference_kf = reference;
  }
  const bool lost = state == TrackingState::kRecentlyLost || state == TrackingState::kLost;
  double radius = options_.LocalSearchRadius(IsRgbd(rig_->sensor), frames->JustRelocalised(), lost);
  if (options_.inertial_search == TrackingOptions::InertialSearch::kOrbSlam3 &&
      IsInertial(rig_->sensor) && !frames->JustRelocalised() && !lost) {
    const MapImuStatus& imu = atlas_->current_map()->imu_status();
    radius = TrackingOptions::InertialLocalSearchRadius(imu.imu_initialized, imu.inertial_ba2_done);
  }
  local_map_.Search(&current, *rig_, radius);
  current.outliers.assign(current.size(), 0);
  OptimizePose(imu_ready, frames);
  // Stereo-inertial keeps its outliers' matches until the keyframe decision, as ORB-SLAM3 does
  // (it drops them here for plain stereo only): a new keyframe then carries them to its BA.
  const int inliers = CountLocalMapInliers(rig_->sensor == Sensor::kStereo, &current);
  frames->inliers = inliers;
  if (WithinASecondOfRelocalisation(*frames) && inliers < options_.min_inliers_after_reloc) {
    return false;
  }
  if (state == TrackingState::kRecentlyLost && inliers > 10) return true;
  return inliers >= options_.min_inliers;
}

bool MapTracker::WithinASecondOfRelocalisation(const TrackedFrames& frames) const {
  return frames.WithinFramesOfRelocalisation(static_cast<int>(rig_->fps + 0.5));
}

void MapTracker::OptimizePose(bool imu_ready, TrackedFrames* frames) const {
  if (!imu_ready || imu_ == nullptr || !frames->current.imu.state.valid) {
    pkslam::OptimizePose(&frames->current, options_.pose);
    return;
  }
  imu_->OptimizePose(frames->last, frames->last_kf.get(), *rig_, options_.pose, &frames->current);
}

}  // namespace pkslam
