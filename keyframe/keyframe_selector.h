// Keyframe decisions as a pluggable policy. The tracker fills a SelectorInput snapshot for
// every tracked frame and asks the selector; the selector owns its own state (reference
// values, keyframe snapshots) and is reset on map reset / new map.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/features/descriptor.h"
#include "core/geometry/se3.h"
#include "core/sensor/camera_rig.h"
#include "core/sensor/sensor.h"
#include "core/util/ids.h"

namespace pkslam {

// One map point tracked in the current frame: an inlier of the pose optimisation, or an
// outlier when the selector NeedsOutliers().
struct SelectorPoint {
  MapPointId id = kInvalidId;
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // undistorted pixel in the current frame
  int keypoint_index = -1;
  bool in_last_keyframe = false;  // the point is observed by the last keyframe
  bool outlier = false;           // rejected by the pose optimisation
  // Valid during Decide / OnKeyFrameInserted only: the keypoint's descriptor and the map
  // point's distinctive one.
  const Descriptor* descriptor = nullptr;
  const Descriptor* map_point_descriptor = nullptr;
};

// IMU summary over an interval (from preintegration; body frame at the interval start).
struct SelectorImuInterval {
  double dt = 0;                                         // seconds
  Eigen::Vector3d mean_accel = Eigen::Vector3d::Zero();  // bias-corrected, rotated to start
  Eigen::Vector3d mean_gyro = Eigen::Vector3d::Zero();
  // Mean gravity-compensated specific force in the world frame (needs gravity estimate).
  std::optional<Eigen::Vector3d> mean_accel_world_no_gravity;
};

struct SelectorInput {
  Sensor sensor = Sensor::kStereo;
  FrameId frame_id = 0;
  std::int64_t t_ns = 0;
  double fps = 20.0;
  int image_width = 0;
  int image_height = 0;
  // Pinhole of the undistorted keypoint coordinates and the undistorted image's bounds
  // (selectors that project map points into the frame).
  double fx = 0, fy = 0, cx = 0, cy = 0;
  ImageBounds bounds;
  SE3d camera_from_world;

  // Tracking results of the current frame.
  int inliers = 0;                    // map-point matches surviving pose optimisation
  int tracked_close = 0;              // inliers with depth < th_depth (stereo/RGB-D)
  int untracked_close = 0;            // keypoints with depth < th_depth and no map point
  bool recently_lost = false;         // tracking state RECENTLY_LOST (IMU prediction)
  std::vector<SelectorPoint> points;  // filled only when the selector NeedsTrackedPoints()

  // Map and keyframe context.
  int keyframes_in_map = 0;
  int reference_tracked_points = 0;  // ORB-SLAM's nRefMatches (>= 3 obs, 2 if <= 2 KFs)
  KeyFrameId last_keyframe_id = kInvalidId;
  FrameId last_keyframe_frame_id = 0;
  std::int64_t last_keyframe_t_ns = 0;
  SE3d last_keyframe_camera_from_world;
  FrameId last_relocalisation_frame_id = -1000000;

  // Local mapping and mode.
  bool only_tracking = false;
  bool local_mapping_stopped = false;  // stopped or stop requested (loop closure)
  bool local_mapping_idle = true;      // accepts keyframes
  // keyframe_trace.csv is written (--trace): selectors whose trace is extra work fill it only
  // then.
  bool trace_wanted = false;
  bool local_mapping_initializing = false;  // IMU initialisation running
  // Local mapping saw the body barely move between its last keyframes while the inertial
  // refinement is pending (ORB-SLAM3 v0.3's mbBadImu2; consumed by this frame's decision).
  bool slow_motion_before_refinement = false;
  int local_mapping_queue = 0;
  bool imu_initialized = false;

  // IMU since the previous frame and since the last keyframe (inertial sensors only).
  std::optional<SelectorImuInterval> imu_since_last_frame;
  std::optional<SelectorImuInterval> imu_since_last_keyframe;

  int FramesSinceLastKeyFrame() const {
    return static_cast<int>(frame_id - last_keyframe_frame_id);
  }
  double SecondsSinceLastKeyFrame() const {
    return static_cast<double>(t_ns - last_keyframe_t_ns) * 1e-9;
  }
};

// Trace values of one decision (one row of keyframe_trace.csv). Keys are column names;
// selectors fill what they compute.
using SelectorTrace = std::map<std::string, double>;

struct SelectorDecision {
  bool insert = false;
  // Ask local mapping to interrupt its bundle adjustment (it is busy and we want a keyframe).
  bool interrupt_local_ba = false;
  // Refused only because local mapping is busy (with mapping idle it would insert); tracking
  // may still insert when its map is about to starve (TrackingOptions::starving_inliers).
  bool deferred_busy = false;
  // Short machine-readable reason, e.g. "c1a+c2", "imu-time", "busy", "no".
  std::string reason;
  SelectorTrace trace;

  static SelectorDecision No(std::string why) {
    SelectorDecision d;
    d.reason = std::move(why);
    return d;
  }
};

class KeyframeSelector {
 public:
  virtual ~KeyframeSelector() = default;
  virtual std::string_view name() const = 0;
  // Whether Decide needs SelectorInput::points (building them costs a little per frame).
  virtual bool NeedsTrackedPoints() const { return false; }
  // Whether SelectorInput::points also holds the pose optimisation's outliers (flagged).
  virtual bool NeedsOutliers() const { return false; }
  // Whether OnKeyFrameInserted wants the frame as it is after keyframe creation (with the new
  // stereo/RGB-D points) rather than the input its decision saw.
  virtual bool SnapshotAfterCreation() const { return false; }
  virtual SelectorDecision Decide(const SelectorInput& input) = 0;
  // Called after a keyframe was created from `input`'s frame (the selector may snapshot it).
  virtual void OnKeyFrameInserted(const SelectorInput& input) { (void)input; }
  // Map reset or new map: forget all state.
  virtual void Reset() {}
};

}  // namespace pkslam
