// The tracking thread's logic (runs in the caller's thread, as in ORB-SLAM3): builds a Frame
// from the images, initialises a map, tracks the camera against the last frame / reference
// keyframe and the local map, asks the KeyframeSelector for keyframes and hands them to local
// mapping. It keeps the state machine; the work is done by its parts (tracking/README.md:
// frame_records.h, map_starter.h, map_tracker.h (frame_tracking.h, local_map.h, relocaliser.h),
// localisation_tracking.h, keyframe_inserter.h (selector_snapshot.h, keyframe_decision.h,
// keyframe_points.h), inertial_tracking.h). Owns its frames; touches the map model only under the
// Atlas mutex.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/sensor/rig_calibration.h"
#include "keyframe/keyframe_selector.h"
#include "map_model/atlas.h"
#include "map_model/frame.h"
#include "map_model/map_editor.h"
#include "map_model/mapping_backend.h"
#include "tracking/frame_builder.h"
#include "tracking/frame_records.h"
#include "tracking/inertial_tracking.h"
#include "tracking/keyframe_inserter.h"
#include "tracking/localisation_tracking.h"
#include "tracking/map_starter.h"
#include "tracking/map_tracker.h"
#include "tracking/tracked_frames.h"
#include "tracking/tracking_options.h"

namespace pkslam {

class Vocabulary;

struct TrackResult {
  TrackingState state = TrackingState::kNotInitialized;
  std::optional<SE3d> camera_from_world;
  bool new_keyframe = false;
  int inliers = 0;
  std::string keyframe_reason;
  // The selector decided on this frame (it was tracked); the trace's criterion* entries that
  // held (PKS: criterion1 = D_c > Th, criterion2 = ECOG > |COG|).
  bool selector_decided = false;
  std::vector<std::string> criteria_held;
  // The selector wanted a keyframe but local mapping's queue was full (MappingBackend::QueueFull).
  bool keyframe_declined_queue_full = false;
};

class Tracker {
 public:
  Tracker(Atlas* atlas, const Vocabulary* vocabulary, std::shared_ptr<const CameraRig> rig,
          std::unique_ptr<KeyframeSelector> selector, MappingBackend* mapping,
          TrackingOptions options, OrbOptions orb_options);
  ~Tracker();
  Tracker(const Tracker&) = delete;
  Tracker& operator=(const Tracker&) = delete;

  // Rectified stereo pair (grey).
  TrackResult TrackStereo(const cv::Mat& left, const cv::Mat& right, std::int64_t t_ns);
  // Registered RGB-D pair: grey (or colour) image and depth (CV_16U raw or CV_32F metres).
  TrackResult TrackRgbd(const cv::Mat& image, const cv::Mat& depth, std::int64_t t_ns);
  TrackResult TrackMonocular(const cv::Mat& image, std::int64_t t_ns);
  // Inertial sensors: IMU samples (time-ordered, after those already given) covering at least
  // up to the next frame's time. Throws Error on out-of-order samples.
  void AddImu(const std::vector<ImuMeasurement>& samples);

  TrackingState state() const { return state_; }
  const std::vector<FrameRecord>& records() const { return records_.all(); }
  const KeyframeSelector& selector() const { return *selector_; }
  // Keyframe-decision traces (one per tracked frame), for --trace.
  using TraceRow = KeyFrameTraceRow;
  const std::vector<TraceRow>& trace() const { return inserter_.trace(); }
  void EnableTrace(bool on) { inserter_.EnableTrace(on); }
  // Record every frame's matched map points in its FrameRecord (for --frame-tracks).
  void EnableFrameTracks(bool on) { records_.EnableObservations(on); }
  // Localisation only (TrackingOptions::localise_only) on a map loaded into the Atlas: the
  // next frame is relocalised against the current map (tracking/tracker_localisation.cc).
  void StartLocalisation();
  int relocalisations() const { return map_tracker_.relocalisations(); }
  // Localisation mode switched at run time (the library's SetLocalisationMode, as ORB-SLAM3's
  // ActivateLocalizationMode): from the next frame on, tracking only against the current map,
  // no keyframes, visual tracking (ImuReady() is false while on). Tracking thread, between
  // frames.
  void SetLocaliseOnly(bool on) {
    options_.localise_only = on;
    localisation_.Restart();
  }
  bool localise_only() const { return options_.localise_only; }
  // The last frame's pose inliers (map point id, undistorted left-image pixel); empty when it
  // was not tracked. Tracking thread.
  std::vector<FrameRecord::Observation> LastFrameInliers() const;

  // Drops the current map (a reset) and starts again from NOT_INITIALIZED.
  void Reset();
  // The camera-IMU time offset the caller shifted the next frames' stamps by (recorded in their
  // FrameImu / KeyFrameImu for the calibration BA).
  void SetTimeOffset(double seconds) { time_offset_s_ = seconds; }
  // The IMU's axis errors (RigCalibration::gyro_scale, accel_axes): samples are corrected for
  // them as they are integrated (ImuBuffer::SetAxisErrors).
  void SetImuAxisErrors(const Eigen::Vector3d& gyro_scale, const Eigen::Matrix3d& accel_axes);
  // A new calibration estimate (online calibration) moved the map's keyframes to `setup`'s rig:
  // frames are built with it from now on, and what tracking keeps of earlier frames (the last
  // frame, the monocular initialisation frame, the motion model, the records' poses relative to
  // their keyframes) moves with the keyframes, the body keeping its place.
  void SetRig(const RigSetup& setup, const RigSetup& old_setup);

 private:
  TrackResult Track(Frame frame);
  // An initialised map, not localisation only: tracks the frame by the IMU, the motion model,
  // the reference keyframe or relocalisation, then against the local map, and moves the state
  // machine (OK / RECENTLY_LOST / LOST). Atlas lock held (shared).
  bool TrackInMap();
  // The tracked frame's keyframe decision (selector, a starving monocular map, backpressure),
  // traced when asked. Returns the selector's input. Atlas lock held (shared).
  SelectorInput DecideKeyFrame(bool mapping_idle, TrackResult* result);
  // Carries out the decision (interrupting local BA, creating the keyframe) after the lock is
  // released. Returns whether a keyframe was created.
  bool ActOnDecision(const SelectorInput& selector_input, TrackResult* result);
  // Map initialisation (tracking/map_starter.h): a new map's keyframes go to local mapping, the
  // selector starts over from the newest, tracking is OK; a refused one is reset.
  void StartMap();
  // AttachImu as the callback of the map's keyframe makers.
  AttachKeyFrame ImuAttacher();
  // Localisation only (localisation_ chooses between map_tracker_'s moves); sets state_ (kOk
  // or kLost). Atlas lock held (shared).
  bool TrackLocalisationOnly();
  // What the keyframe inserter reads of this frame's tracking.
  KeyFrameContext KeyFrameContextNow();
  void HandleLost();
  // Back to NOT_INITIALIZED on the current (new or cleared) map.
  void StartOver();
  void RecordFrame(bool keyframe, double ms, double cpu_ms);

  // --- inertial sensors (tracking/tracker_inertial.cc; the work: tracking/inertial_tracking.h) ---
  bool ImuReady() const;  // the current map's IMU is initialised (Atlas lock held)
  void PreintegrateImu();
  // Follows the map's world changes (Atlas lock held); `correct_current` carries the current
  // frame's pose and velocity across a world change (rotation / rescale) made since it was
  // tracked.
  void SyncWithInertialMapLocked(bool correct_current);
  // Tracking's keyframe joins the map's inertial chain after `previous` (map write lock held).
  void AttachImu(const MapWriteLock& lock, KeyFrame* kf, KeyFrame* previous, const Frame& frame);

  Atlas* atlas_;
  const Vocabulary* vocabulary_;
  std::shared_ptr<const CameraRig> rig_;
  std::unique_ptr<KeyframeSelector> selector_;
  MappingBackend* mapping_;
  TrackingOptions options_;
  FrameBuilder builder_;
  MapStarter starter_;  // while NOT_INITIALIZED

  TrackingState state_ = TrackingState::kNotInitialized;
  TrackedFrames frames_;  // the current and last frames, the motion model (tracked_frames.h)
  // CPU and wall ms building the frame being tracked (for its FrameRecord).
  double build_cpu_ms_ = 0;
  double build_ms_ = 0;
  std::int64_t lost_since_t_ns_ = 0;
  // Localisation only: map or visual odometry (tracking/localisation_tracking.h).
  LocalisationTracking localisation_;

  FrameRecords records_;  // the trajectory (frame_records.h)
  double time_offset_s_ = 0.0;
  // The selector's decision with tracking's overrides, its trace, and the new keyframes
  // (keyframe_inserter.h).
  KeyFrameInserter inserter_;
  std::unique_ptr<InertialTracking> imu_;  // inertial sensors only
  // The moves that place a frame in the map, with the local map (map_tracker.h); after imu_,
  // which it uses.
  MapTracker map_tracker_;
};

}  // namespace pkslam
