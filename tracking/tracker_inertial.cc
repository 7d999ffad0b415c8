// Visual-inertial tracking (ORB-SLAM3's IMU paths of Tracking): preintegration between frames,
// IMU prediction of the pose, visual-inertial pose optimisation against the last frame (with
// the prior from its own optimisation) or the last keyframe (fixed, after the map changed),
// IMU-only prediction while vision is weak (RECENTLY_LOST), and the IMU data handed to
// keyframes and to the keyframe selector.
#include <algorithm>
#include <mutex>
#include <shared_mutex>

#include "core/util/error.h"
#include "core/util/log.h"
#include "imu/preintegration.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "tracking/frame_tracking.h"
#include "tracking/tracker.h"

namespace pkslam {
namespace {

SE3d WorldFromBody(const SE3d& camera_from_world, const CameraRig& rig) {
  return camera_from_world.Inverse() * rig.body_from_camera.Inverse();
}

std::string V(const Eigen::Vector3d& v) {
  return fmt::format("({:.3f} {:.3f} {:.3f})", v.x(), v.y(), v.z());
}

SE3d CameraFromWorld(const SE3d& world_from_body, const CameraRig& rig) {
  return (world_from_body * rig.body_from_camera).Inverse();
}

}  // namespace

void Tracker::AddImu(const std::vector<ImuMeasurement>& samples) {
  PKSLAM_CHECK(imu_ != nullptr, "IMU samples given to a {} tracker", SensorName(rig_->sensor));
  imu_->samples.Add(samples);
}

void Tracker::SetGyroScale(const Eigen::Vector3d& k) {
  if (imu_) imu_->samples.SetGyroScale(k);
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
  current_.imu.state.bias = bias;
  if (imu_->last_frame_t_ns >= 0) {
    current_.imu.from_last_frame =
        imu_->samples.Between(imu_->last_frame_t_ns, current_.t_ns(), bias);
  }
  imu_->last_frame_t_ns = current_.t_ns();
  // Keep what the oldest anchor still needs.
  std::int64_t anchor = current_.t_ns();
  if (last_kf_) anchor = std::min(anchor, last_kf_->t_ns());
  if (two_view_.started()) anchor = std::min(anchor, two_view_.first().t_ns());
  imu_->samples.KeepFrom(anchor);
}

void Tracker::SyncWithInertialMap() {
  auto lock = MapReader(*atlas_).Lock();
  SyncWithInertialMapLocked(false);
}

void Tracker::SyncWithInertialMapLocked(bool correct_current) {
  const Map* map = atlas_->current_map();
  const WorldChangesSeen seen = imu_->world.Follow(*map);
  if (!seen.ForgetsLastFrame()) return;
  // A new map, or every change re-estimated the keyframes' states: predict from the last
  // keyframe.
  imu_->from_keyframe = true;
  imu_->last_frame_information.reset();
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
    for (FrameRecord& r : records_) {
      if (r.reference && r.reference->map() == map) r.camera_from_reference.translation() *= ratio;
    }
    if (velocity_) velocity_->translation() *= ratio;
  }
}

bool Tracker::PredictWithImu() {
  const Eigen::Vector3d g(0, 0, -imu_->gravity_magnitude);
  NavState start;
  ImuBias bias;
  std::optional<PreintegratedImu> kf_pim;
  const PreintegratedImu* pim = nullptr;
  if (imu_->from_keyframe || !last_.imu.state.valid || !current_.imu.from_last_frame ||
      !last_.HasPose()) {
    if (!last_kf_ || last_kf_->IsBad() || !last_kf_->imu().state.valid) return false;
    start = {WorldFromBody(last_kf_->camera_from_world(), *rig_),
             last_kf_->imu().state.velocity_world};
    bias = last_kf_->imu().state.bias;
    kf_pim = imu_->samples.Between(last_kf_->t_ns(), current_.t_ns(), bias);
    if (!kf_pim) return false;
    pim = &*kf_pim;
  } else {
    start = {WorldFromBody(last_.camera_from_world(), *rig_), last_.imu.state.velocity_world};
    bias = last_.imu.state.bias;
    pim = &*current_.imu.from_last_frame;
  }
  const NavState predicted = PredictState(start, *pim, bias, g);
  PKSLAM_LOG_DEBUG("imu predict frame {} from {} dt {:.3f}: p {} -> {} v {} -> {}", current_.id(),
                   kf_pim ? "keyframe" : "frame", pim->dt, V(start.world_from_body.translation()),
                   V(predicted.world_from_body.translation()), V(start.velocity_world),
                   V(predicted.velocity_world));
  current_.SetPose(CameraFromWorld(predicted.world_from_body, *rig_));
  current_.imu.state.velocity_world = predicted.velocity_world;
  current_.imu.state.bias = bias;
  current_.imu.state.valid = true;
  return true;
}

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
  InertialPoseInput in;
  in.gravity_world = Eigen::Vector3d(0, 0, -imu_->gravity_magnitude);
  std::optional<PreintegratedImu> kf_pim;
  const bool use_last_frame = !imu_->from_keyframe && imu_->last_frame_information &&
                              imu_->information_frame_id == last_.id() && last_.imu.state.valid &&
                              current_.imu.from_last_frame && last_.HasPose();
  if (use_last_frame) {
    in.previous_state = {WorldFromBody(last_.camera_from_world(), *rig_),
                         last_.imu.state.velocity_world};
    in.previous_bias = last_.imu.state.bias;
    in.previous_information = *imu_->last_frame_information;
    in.preintegration = &*current_.imu.from_last_frame;
  } else {
    if (!last_kf_ || last_kf_->IsBad() || !last_kf_->imu().state.valid) {
      OptimizePose(&current_, options_.pose);
      return;
    }
    in.previous_state = {WorldFromBody(last_kf_->camera_from_world(), *rig_),
                         last_kf_->imu().state.velocity_world};
    in.previous_bias = last_kf_->imu().state.bias;
    kf_pim = imu_->samples.Between(last_kf_->t_ns(), current_.t_ns(), in.previous_bias);
    if (!kf_pim) {
      OptimizePose(&current_, options_.pose);
      return;
    }
    in.preintegration = &*kf_pim;
  }
  const SE3d before = current_.camera_from_world();
  const InertialPoseOutput out = OptimizeInertialPose(&current_, in, options_.pose);
  PKSLAM_LOG_DEBUG(
      "inertial pose frame {} ({}): inliers {}, moved {:.4f} m, v {}", current_.id(),
      use_last_frame ? "last frame" : "keyframe", out.inliers,
      (current_.camera_from_world().Inverse().translation() - before.Inverse().translation())
          .norm(),
      V(out.state.velocity_world));
  imu_->last_frame_information = out.information;
  imu_->information_frame_id = current_.id();
  imu_->from_keyframe = false;
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
  kf->mutable_imu(lock).state = frame.imu.state;
  if (previous == nullptr || previous->IsBad() || previous->map() != kf->map()) return;
  kf->map()->inertial_chain().Append(
      lock, previous, kf,
      imu_->samples.Between(previous->t_ns(), kf->t_ns(), previous->imu().state.bias));
  if (!kf->imu().state.valid) kf->mutable_imu(lock).state.bias = previous->imu().state.bias;
}

void Tracker::FillImuSelectorInput(SelectorInput* in) const {
  if (!imu_ || !current_.imu.from_last_frame) return;
  const PreintegratedImu& pim = *current_.imu.from_last_frame;
  SelectorImuInterval interval;
  interval.dt = pim.dt;
  interval.mean_accel = pim.average_accel;
  interval.mean_gyro = pim.average_gyro;
  if (ImuReady() && last_.HasPose()) {
    // Specific force in the world frame plus gravity: the body's own acceleration.
    const SO3d r_wb = WorldFromBody(last_.camera_from_world(), *rig_).so3();
    interval.mean_accel_world_no_gravity =
        r_wb * pim.average_accel + Eigen::Vector3d(0, 0, -imu_->gravity_magnitude);
  }
  in->imu_since_last_frame = interval;
}

}  // namespace pkslam
