// The inertial side of tracking (ORB-SLAM3's IMU paths of Tracking), owned by the Tracker for
// inertial rigs and used by the tracking thread only: the IMU samples and each frame's
// preintegration since the last frame, the IMU prediction of a frame's pose, its
// visual-inertial pose optimisation against the last frame (with the prior from that frame's
// own optimisation) or the last keyframe (after the map changed), a new keyframe's inertial
// state and chain link, and the interval the keyframe selector sees.
//
// The Tracker keeps the state machine and its own poses (it carries them across world changes
// that Follow reports). Calls that read keyframes or the map need the Atlas lock (shared);
// Attach takes the write lock as a parameter.
#pragma once

#include <cstdint>
#include <optional>

#include "core/imu/imu_types.h"
#include "core/sensor/camera_rig.h"
#include "keyframe/keyframe_selector.h"
#include "map_model/frame.h"
#include "map_model/map_ids.h"
#include "tracking/frame_records.h"
#include "tracking/imu_buffer.h"
#include "tracking/inertial_pose_optimizer.h"
#include "tracking/pose_optimizer.h"
#include "tracking/tracked_frames.h"
#include "tracking/world_change_cursor.h"

namespace pkslam {

class MapWriteLock;

class InertialTracking {
 public:
  explicit InertialTracking(const ImuNoise& noise, double gravity_magnitude = 9.81)
      : samples_(noise), gravity_magnitude_(gravity_magnitude) {}

  // The samples (Add, SetAxisErrors, SetNoise).
  ImuBuffer& samples() { return samples_; }
  const ImuBuffer& samples() const { return samples_; }

  // The preintegration from the previous frame to `current`, linearised at `bias` (the caller's
  // best estimate: the last frame's, else the last keyframe's), stored in current->imu with
  // the bias; then drops the samples no anchor older than `oldest_anchor_ns` needs.
  void Preintegrate(const ImuBias& bias, std::int64_t oldest_anchor_ns, Frame* current);

  // Follows `map`'s world-change log (Atlas lock held). After a new map or any change the next
  // prediction and optimisation start from the last keyframe; the Tracker carries its own
  // frames and records across what is returned.
  WorldChangesSeen Follow(const Map& map);
  // Follow, and what tracking keeps moves with what it passed (Atlas lock held): with
  // `correct_current`, a current frame tracked before a single rotation / rescale of the world
  // is carried across it; a rescaled map (monocular-inertial initialisation) rescales the
  // records' poses relative to its keyframes and the motion model.
  void FollowMap(const Map& map, bool correct_current, TrackedFrames* frames,
                 FrameRecords* records);
  // Preintegrate for frames->current at `bias`, keeping the samples the oldest anchor still
  // needs: the last keyframe, or `pair_first` (a monocular map's first frame, while starting).
  void PreintegrateCurrent(const ImuBias& bias, const Frame* pair_first, TrackedFrames* frames);

  // Predicts `current`'s pose, velocity and bias: from `last` along current's preintegration,
  // or from `last_keyframe` (after a map change, or when the last frame has no state). False
  // when neither has what it needs. Atlas lock held.
  bool Predict(const Frame& last, const KeyFrame* last_keyframe, const CameraRig& rig,
               Frame* current) const;

  // Visual-inertial optimisation of `current` (its state must be valid) against the last
  // frame, when its own optimisation left a prior, or else the last keyframe; a visual one
  // when neither anchor has a state. Atlas lock held.
  void OptimizePose(const Frame& last, const KeyFrame* last_keyframe, const CameraRig& rig,
                    const PoseOptimizerOptions& options, Frame* current);

  // A new keyframe made from `frame` takes its inertial state and joins the chain after
  // `previous` (same map, not retired) with the preintegration between them; without an
  // estimated state it starts from previous's bias.
  void Attach(const MapWriteLock& lock, const Frame& frame, KeyFrame* previous,
              KeyFrame* keyframe) const;

  // The interval since the last frame as the keyframe selector sees it; with the world's
  // orientation of the last body (an IMU-initialised map) also the body's own acceleration in
  // the world. nullopt without a preintegration.
  std::optional<SelectorImuInterval> IntervalSinceLastFrame(
      const Frame& current, const std::optional<SO3d>& world_from_last_body) const;

  // The same into the selector's input: with the last body's world orientation once the map's
  // IMU is initialised (`map_ready`) and the last frame has a pose.
  void FillSelectorInput(const Frame& current, const Frame& last, const CameraRig& rig,
                         bool map_ready, SelectorInput* in) const;

  // The bias tracking integrates with: the last frame's estimate, else the last keyframe's
  // (may be null), else zero. Atlas lock held (shared).
  static ImuBias IntegrationBias(const Frame& last, const KeyFrame* last_keyframe);

  // `frame` was tracked in the world before `change` (a rotation and rescale of the map):
  // its pose and velocity move into the new world.
  static void CarryAcross(const WorldChange& change, Frame* frame);

  double gravity_magnitude() const { return gravity_magnitude_; }

 private:
  ImuBuffer samples_;
  std::int64_t last_frame_t_ns_ = -1;
  WorldChangeCursor world_;
  // Predict and optimise against the last keyframe (true after the map changed under us)
  // instead of the last frame.
  bool from_keyframe_ = true;
  // Marginal information of the last frame's state (its inertial optimisation), and the
  // frame it belongs to.
  std::optional<InertialInformation> last_frame_information_;
  FrameId information_frame_id_ = kInvalidId;
  // Gravity in the (gravity-aligned) world of an initialised map.
  double gravity_magnitude_ = 9.81;
};

}  // namespace pkslam
