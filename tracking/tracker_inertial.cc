// The Tracker's inertial steps: the state machine's side of tracking/inertial_tracking.h
// (which bias to integrate with, which frames to carry across a world change, when the map's
// IMU is ready), with IMU-only prediction while vision is weak (RECENTLY_LOST).
#include <algorithm>
#include <mutex>
#include <shared_mutex>

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "tracking/frame_tracking.h"
#include "tracking/tracker.h"

namespace pkslam {

void Tracker::AddImu(const std::vector<ImuMeasurement>& samples) {
  PKSLAM_CHECK(imu_ != nullptr, "IMU samples given to a {} tracker", SensorName(rig_->sensor));
  imu_->samples().Add(samples);
}

void Tracker::SetGyroScale(const Eigen::Vector3d& k) {
  if (imu_) imu_->samples().SetGyroScale(k);
}

bool Tracker::ImuReady() const {
  // Localisation only tracks visually: the frames' velocities and biases are not estimated
  // (no keyframes to anchor them), so an inertial prior would pull the pose off.
  return imu_ != nullptr && !options_.localise_only &&
         atlas_->current_map()->imu_status().imu_initialized;
}

void Tracker::PreintegrateImu() {
  ImuBias bias;
  {
    auto lock = MapReader(*atlas_).Lock();
    SyncWithInertialMapLocked(/*correct_current=*/false);
    bias = InertialTracking::IntegrationBias(last_, last_kf_.get());
  }
  // Keep what the oldest anchor still needs.
  std::int64_t anchor = current_.t_ns();
  if (last_kf_) anchor = std::min(anchor, last_kf_->t_ns());
  if (const Frame* first = starter_.pair_first()) anchor = std::min(anchor, first->t_ns());
  imu_->Preintegrate(bias, anchor, &current_);
}

void Tracker::SyncWithInertialMapLocked(bool correct_current) {
  const Map* map = atlas_->current_map();
  const WorldChangesSeen seen = imu_->Follow(*map);
  if (!seen.ForgetsLastFrame()) return;
  // Local mapping rotated / rescaled the map after the current frame was tracked: its pose is
  // in the old world (WorldChangesSeen::single_transform).
  if (correct_current && current_.HasPose() && seen.single_transform) {
    InertialTracking::CarryAcross(*seen.single_transform, &current_);
  }
  if (seen.scale_ratio) {
    // Monocular-inertial initialisation rescaled the map: what tracking keeps relative to its
    // keyframes scales with it.
    const double ratio = *seen.scale_ratio;
    records_.Rescale(map, ratio);
    if (velocity_) velocity_->translation() *= ratio;
  }
}

bool Tracker::PredictWithImu() { return imu_->Predict(last_, last_kf_.get(), *rig_, &current_); }

bool Tracker::TrackWithImu() {
  UpdateLastFrame();
  if (!PredictWithImu()) return false;
  MatchLastFramePredicted(last_, options_, IsMonocular(rig_->sensor), &current_);
  current_.outliers.assign(current_.size(), 0);
  // The IMU prediction stands: the matches are classified by the visual-inertial optimisation
  // after the local map search (ORB-SLAM3 runs a visual-only optimisation here first; with the
  // IMU prediction it only costs time).
  return true;
}

void Tracker::OptimizeCurrentPose() {
  if (!ImuReady() || !current_.imu.state.valid) {
    OptimizePose(&current_, options_.pose);
    return;
  }
  imu_->OptimizePose(last_, last_kf_.get(), *rig_, options_.pose, &current_);
}

void Tracker::AttachImu(const MapWriteLock& lock, KeyFrame* kf, KeyFrame* previous,
                        const Frame& frame) {
  if (!imu_) return;
  // A world change between tracking and keyframe creation: the keyframe takes the corrected
  // pose (current_ is `frame` except at monocular initialisation, which precedes any change).
  if (&frame == &current_) {
    SyncWithInertialMapLocked(true);
    kf->SetPose(current_.camera_from_world());
  }
  imu_->Attach(lock, frame, previous, kf);
}

}  // namespace pkslam
