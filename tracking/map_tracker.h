// The moves that place a frame in an initialised map, as the Tracker's state machine calls
// them: the motion model, the reference keyframe, the IMU prediction and relocalisation, then
// the local map (ORB-SLAM3's TrackWithMotionModel, TrackReferenceKeyFrame, PredictStateIMU,
// Relocalization, TrackLocalMap). Each returns whether the frame counts as tracked and leaves
// its pose and matches in TrackedFrames::current. Owns the local map and the relocalisation
// attempts. Tracking thread, Atlas lock held (shared): the moves read map points.
#pragma once

#include <memory>

#include "core/sensor/camera_rig.h"
#include "tracking/frame_records.h"
#include "tracking/inertial_tracking.h"
#include "tracking/local_map.h"
#include "tracking/relocaliser.h"
#include "tracking/tracked_frames.h"
#include "tracking/tracking_options.h"

namespace pkslam {

class Atlas;
class Vocabulary;

class MapTracker {
 public:
  // `options` is the Tracker's own (which outlives this part and switches localise_only between
  // frames); `imu` is the Tracker's inertial side, null for visual sensors.
  MapTracker(const Atlas* atlas, const Vocabulary* vocabulary, const TrackingOptions& options,
             std::shared_ptr<const CameraRig> rig, InertialTracking* imu);

  // A new calibration estimate: frames are placed with this rig from the next move on.
  void SetRig(std::shared_ptr<const CameraRig> rig) { rig_ = std::move(rig); }

  // Matches the reference keyframe through BoW, starting from the last frame's pose; tracked
  // with at least 10 map points after the optimisation. False without a live reference.
  bool TrackReferenceKeyFrame(TrackedFrames* frames) const;
  // Projects the last frame's points at the pose the motion model predicts; tracked with at
  // least 10 map points (localisation only on a stereo/RGB-D rig: or 20 matches counting
  // visual-odometry points). `last_record` is the last frame's record.
  bool TrackWithMotionModel(const FrameRecord& last_record, TrackedFrames* frames) const;
  // The IMU predicts the pose and the last frame's points are matched around it; the matches
  // are classified later by the local map's visual-inertial optimisation. False when the IMU
  // cannot predict (no preintegration from the last frame or keyframe).
  bool TrackWithImu(const FrameRecord& last_record, TrackedFrames* frames) const;
  // The IMU prediction alone (RECENTLY_LOST with an initialised IMU: the local map decides).
  bool PredictWithImu(TrackedFrames* frames) const;
  // Finds the current frame's pose by place recognition (relocaliser.h); a success is
  // remembered in TrackedFrames::last_reloc_frame_id.
  bool Relocalise(TrackedFrames* frames);
  // Searches the local map around the frame's pose and optimises it (visual-inertial when
  // `imu_ready`); the reference keyframe becomes the local keyframe sharing most points.
  // Tracked with enough inliers: more right after a relocalisation, fewer while `state` is
  // RECENTLY_LOST.
  bool TrackLocalMap(TrackingState state, bool imu_ready, TrackedFrames* frames);

  // The last frame's pose moves with its reference keyframe (`last_record`), which local BA may
  // have moved; localisation only (stereo/RGB-D), it gets visual-odometry points.
  void UpdateLastFrame(const FrameRecord& last_record, TrackedFrames* frames) const;

  LocalMap& local_map() { return local_map_; }
  int relocalisations() const { return relocalisation_.successes(); }

 private:
  // Visual pose optimisation, or visual-inertial once the map's IMU is initialised.
  void OptimizePose(bool imu_ready, TrackedFrames* frames) const;
  // A second of frames after a relocalisation (ORB-SLAM3's mnFramesToResetIMU / mMaxFrames):
  // the new pose must be confirmed by more inliers, and ORB-SLAM3's front end matches the last
  // frame again meanwhile.
  bool WithinASecondOfRelocalisation(const TrackedFrames& frames) const;

  const Atlas* atlas_;
  const Vocabulary* vocabulary_;
  const TrackingOptions& options_;
  std::shared_ptr<const CameraRig> rig_;
  InertialTracking* imu_;
  LocalMap local_map_;  // rebuilt every frame
  RelocalisationAttempts relocalisation_;
};

}  // namespace pkslam
