#include "tracking/inertial_tracking.h"

#include <fmt/format.h>

#include <algorithm>

#include "core/util/log.h"
#include "imu/preintegration.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_editor.h"
#include "map_model/world_transform.h"

namespace pkslam {
namespace {

SE3d WorldFromBody(const SE3d& camera_from_world, const CameraRig& rig) {
  return camera_from_world.Inverse() * rig.body_from_camera.Inverse();
}

SE3d CameraFromWorld(const SE3d& world_from_body, const CameraRig& rig) {
  return (world_from_body * rig.body_from_camera).Inverse();
}

std::string V(const Eigen::Vector3d& v) {
  return fmt::format("({:.3f} {:.3f} {:.3f})", v.x(), v.y(), v.z());
}

}  // namespace

void InertialTracking::Preintegrate(const ImuBias& bias, std::int64_t oldest_anchor_ns,
                                    Frame* current) {
  current->imu.state.bias = bias;
  if (last_frame_t_ns_ >= 0) {
    current->imu.from_last_frame = samples_.Between(last_frame_t_ns_, current->t_ns(), bias);
  }
  last_frame_t_ns_ = current->t_ns();
  samples_.KeepFrom(oldest_anchor_ns);
}

WorldChangesSeen InertialTracking::Follow(const Map& map) {
  const WorldChangesSeen seen = world_.Follow(map);
  if (seen.ForgetsLastFrame()) {
    from_keyframe_ = true;
    last_frame_information_.reset();
  }
  return seen;
}

void InertialTracking::FollowMap(const Map& map, bool correct_current, TrackedFrames* frames,
                                 FrameRecords* records) {
  const WorldChangesSeen seen = Follow(map);
  if (!seen.ForgetsLastFrame()) return;
  // Local mapping rotated / rescaled the map after the current frame was tracked: its pose is
  // in the old world (WorldChangesSeen::single_transform).
  if (correct_current && frames->current.HasPose() && seen.single_transform) {
    CarryAcross(*seen.single_transform, &frames->current);
  }
  if (seen.scale_ratio) {
    // Monocular-inertial initialisation rescaled the map: what tracking keeps relative to its
    // keyframes scales with it.
    const double ratio = *seen.scale_ratio;
    records->Rescale(&map, ratio);
    if (frames->velocity) frames->velocity->translation() *= ratio;
  }
}

void InertialTracking::PreintegrateCurrent(const ImuBias& bias, const Frame* pair_first,
                                           TrackedFrames* frames) {
  std::int64_t anchor = frames->current.t_ns();
  if (frames->last_kf) anchor = std::min(anchor, frames->last_kf->t_ns());
  if (pair_first != nullptr) anchor = std::min(anchor, pair_first->t_ns());
  Preintegrate(bias, anchor, &frames->current);
}

bool InertialTracking::Predict(const Frame& last, const KeyFrame* last_keyframe,
                               const CameraRig& rig, Frame* current) const {
  const Eigen::Vector3d g(0, 0, -gravity_magnitude_);
  NavState start;
  ImuBias bias;
  std::optional<PreintegratedImu> kf_pim;
  const PreintegratedImu* pim = nullptr;
  if (from_keyframe_ || !last.imu.state.valid || !current->imu.from_last_frame || !last.HasPose()) {
    if (last_keyframe == nullptr || last_keyframe->IsBad() || !last_keyframe->imu().state.valid) {
      return false;
    }
    start = {WorldFromBody(last_keyframe->camera_from_world(), rig),
             last_keyframe->imu().state.velocity_world};
    bias = last_keyframe->imu().state.bias;
    kf_pim = samples_.Between(last_keyframe->t_ns(), current->t_ns(), bias);
    if (!kf_pim) return false;
    pim = &*kf_pim;
  } else {
    start = {WorldFromBody(last.camera_from_world(), rig), last.imu.state.velocity_world};
    bias = last.imu.state.bias;
    pim = &*current->imu.from_last_frame;
  }
  const NavState predicted = PredictState(start, *pim, bias, g);
  PKSLAM_LOG_DEBUG("imu predict frame {} from {} dt {:.3f}: p {} -> {} v {} -> {}", current->id(),
                   kf_pim ? "keyframe" : "frame", pim->dt, V(start.world_from_body.translation()),
                   V(predicted.world_from_body.translation()), V(start.velocity_world),
                   V(predicted.velocity_world));
  current->SetPose(CameraFromWorld(predicted.world_from_body, rig));
  current->imu.state.velocity_world = predicted.velocity_world;
  current->imu.state.bias = bias;
  current->imu.state.valid = true;
  return true;
}

void InertialTracking::OptimizePose(const Frame& last, const KeyFrame* last_keyframe,
                                    const CameraRig& rig, const PoseOptimizerOptions& options,
                                    Frame* current) {
  InertialPoseInput in;
  in.gravity_world = Eigen::Vector3d(0, 0, -gravity_magnitude_);
  std::optional<PreintegratedImu> kf_pim;
  const bool use_last_frame = !from_keyframe_ && last_frame_information_ &&
                              information_frame_id_ == last.id() && last.imu.state.valid &&
                              current->imu.from_last_frame && last.HasPose();
  if (use_last_frame) {
    in.previous_state = {WorldFromBody(last.camera_from_world(), rig),
                         last.imu.state.velocity_world};
    in.previous_bias = last.imu.state.bias;
    in.previous_information = *last_frame_information_;
    in.preintegration = &*current->imu.from_last_frame;
  } else {
    if (last_keyframe == nullptr || last_keyframe->IsBad() || !last_keyframe->imu().state.valid) {
      pkslam::OptimizePose(current, options);
      return;
    }
    in.previous_state = {WorldFromBody(last_keyframe->camera_from_world(), rig),
                         last_keyframe->imu().state.velocity_world};
    in.previous_bias = last_keyframe->imu().state.bias;
    kf_pim = samples_.Between(last_keyframe->t_ns(), current->t_ns(), in.previous_bias);
    if (!kf_pim) {
      pkslam::OptimizePose(current, options);
      return;
    }
    in.preintegration = &*kf_pim;
  }
  const SE3d before = current->camera_from_world();
  const InertialPoseOutput out = OptimizeInertialPose(current, in, options);
  PKSLAM_LOG_DEBUG(
      "inertial pose frame {} ({}): inliers {}, moved {:.4f} m, v {}", current->id(),
      use_last_frame ? "last frame" : "keyframe", out.inliers,
      (current->camera_from_world().Inverse().translation() - before.Inverse().translation())
          .norm(),
      V(out.state.velocity_world));
  last_frame_information_ = out.information;
  information_frame_id_ = current->id();
  from_keyframe_ = false;
}

void InertialTracking::Attach(const MapWriteLock& lock, const Frame& frame, KeyFrame* previous,
                              KeyFrame* keyframe) const {
  keyframe->mutable_imu(lock).state = frame.imu.state;
  if (previous == nullptr || previous->IsBad() || previous->map() != keyframe->map()) return;
  keyframe->map()->inertial_chain().Append(
      lock, previous, keyframe,
      samples_.Between(previous->t_ns(), keyframe->t_ns(), previous->imu().state.bias));
  if (!keyframe->imu().state.valid) {
    keyframe->mutable_imu(lock).state.bias = previous->imu().state.bias;
  }
}

std::optional<SelectorImuInterval> InertialTracking::IntervalSinceLastFrame(
    const Frame& current, const std::optional<SO3d>& world_from_last_body) const {
  if (!current.imu.from_last_frame) return std::nullopt;
  const PreintegratedImu& pim = *current.imu.from_last_frame;
  SelectorImuInterval interval;
  interval.dt = pim.dt;
  interval.mean_accel = pim.average_accel;
  interval.mean_gyro = pim.average_gyro;
  if (world_from_last_body) {
    // Specific force in the world frame plus gravity: the body's own acceleration.
    interval.mean_accel_world_no_gravity =
        *world_from_last_body * pim.average_accel + Eigen::Vector3d(0, 0, -gravity_magnitude_);
  }
  return interval;
}

void InertialTracking::FillSelectorInput(const Frame& current, const Frame& last,
                                         const CameraRig& rig, bool map_ready,
                                         SelectorInput* in) const {
  std::optional<SO3d> world_from_last_body;
  if (map_ready && last.HasPose()) {
    world_from_last_body =
        (last.camera_from_world().Inverse() * rig.body_from_camera.Inverse()).so3();
  }
  if (auto interval = IntervalSinceLastFrame(current, world_from_last_body)) {
    in->imu_since_last_frame = *interval;
  }
}

ImuBias InertialTracking::IntegrationBias(const Frame& last, const KeyFrame* last_keyframe) {
  if (last.imu.state.valid) return last.imu.state.bias;
  if (last_keyframe != nullptr) return last_keyframe->imu().state.bias;
  return ImuBias();
}

void InertialTracking::CarryAcross(const WorldChange& change, Frame* frame) {
  frame->SetPose(CameraFromMovedWorld(frame->camera_from_world(), change.rotation, change.scale));
  frame->imu.state.velocity_world =
      VelocityInMovedWorld(frame->imu.state.velocity_world, change.rotation, change.scale);
}

}  // namespace pkslam
