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
#include "tracking/tracker.h"

namespace pkslam {

void Tracker::AddImu(const std::vector<ImuMeasurement>& samples) {
  PKSLAM_CHECK(imu_ != nullptr, "IMU samples given to a {} tracker", SensorName(rig_->sensor));
  imu_->samples().Add(samples);
}

void Tracker::SetImuAxisErrors(const Eigen::Vector3d& gyro_scale,
                               const Eigen::Matrix3d& accel_axes) {
  if (imu_) imu_->samples().SetAxisErrors(gyro_scale, accel_axes);
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
    bias = InertialTracking::IntegrationBias(frames_.last, frames_.last_kf.get());
  }
  imu_->PreintegrateCurrent(bias, starter_.pair_first(), &frames_);
}

void Tracker::SyncWithInertialMapLocked(bool correct_current) {
  imu_->FollowMap(*atlas_->current_map(), correct_current, &frames_, &records_);
}

void Tracker::AttachImu(const MapWriteLock& lock, KeyFrame* kf, KeyFrame* previous,
                        const Frame& frame) {
  if (!imu_) return;
  // A world change between tracking and keyframe creation: the keyframe takes the corrected
  // pose (frames_.current is `frame` except at monocular initialisation, which precedes any
  // change).
  if (&frame == &frames_.current) {
    SyncWithInertialMapLocked(true);
    kf->SetPose(lock, frames_.current.camera_from_world());
  }
  imu_->Attach(lock, frame, previous, kf);
}

}  // namespace pkslam
