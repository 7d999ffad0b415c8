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
  SyncWithInertialMap();
  // The bias tracking integrates with: the last frame's estimate, else the last keyframe's.
  ImuBias bias;
  {
    auto lock = MapReader(*atlas_).Lock();
    if (last_.imu.state.valid) {
      bias = last_.imu.state.bias;
    } else if (last_kf_) {
      bias = last_kf_->imu().state.bias;
    }
  }
  // Keep what the oldest anchor still needs.
  std::int64_t anchor = current_.t_ns();
  if (last_kf_) anchor = std::min(anchor, last_kf_->t_ns());
  if (two_view_.started()) anchor = std::min(anchor, two_view_.first().t_ns());
  imu_->Preintegrate(bias, anchor, &current_);
}

void Tracker::SyncWithInertialMap() {
  auto lock = MapReader(*atlas_).Lock();
  SyncWithInertialMapLocked(false);
}

void Tracker::SyncWithInertialMapLocked(bool correct_current) {
  const Map* map = atlas_->current_map();
  const WorldChangesSeen seen = imu_->Follow(*map);
  if (!seen.ForgetsLastFrame()) return;
  // Local mapping rotated / rescaled the map after the current frame was tracked: its pose is
  // in the old world (WorldChangesSeen::single_transform).
  if (correct_current && current_.HasPose() && seen.single_transform) {
    const WorldChange& transform = *seen.single_transform;
    const SE3d& tcw = current_.camera_from_world();
    current_.SetPose(
        SE3d(tcw.so3() * transform.rotation.Inverse(), transform.scale * tcw.translation()));
    current_.imu.state.velocity_world =
        transform.scale * (transform.rotation * current_.imu.state.velocity_world);
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
  const bool mono = IsMonocular(rig_->sensor);
  const double th = mono ? options_.motion_model_radius_mono : options_.motion_model_radius_stereo;
  MatchLastFrame(last_, th, mono, options_.min_matches_motion_model, &current_);
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

void Tracker::FillImuSelectorInput(SelectorInput* in) const {
  if (!imu_) return;
  std::optional<SO3d> world_from_last_body;
  if (ImuReady() && last_.HasPose()) {
    world_from_last_body =
        (last_.camera_from_world().Inverse() * rig_->body_from_camera.Inverse()).so3();
  }
  if (auto interval = imu_->IntervalSinceLastFrame(current_, world_from_last_body)) {
    in->imu_since_last_frame = *interval;
  }
}

}  // namespace pkslam
