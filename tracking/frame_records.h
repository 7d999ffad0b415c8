// What tracking keeps of every processed frame for the trajectory, and how it follows the map.
// A record holds the frame's pose relative to its reference keyframe (ORB-SLAM's
// mlRelativeFramePoses), so later map optimisation moves it along; what changes the relation
// itself (a new calibration moving the camera in the body, a monocular-inertial rescale, a
// reset dropping the map) is one operation here. Owned by the tracking thread; no lock.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "core/geometry/se3.h"
#include "map_model/frame.h"
#include "map_model/map_ids.h"

namespace pkslam {

class Map;

enum class TrackingState { kNotInitialized, kOk, kRecentlyLost, kLost };
const char* TrackingStateName(TrackingState s);

// One processed frame.
struct FrameRecord {
  std::int64_t t_ns = 0;
  FrameId frame_id = kInvalidId;
  TrackingState state = TrackingState::kNotInitialized;
  KeyFramePtr reference;  // null when the frame has no pose
  SE3d camera_from_reference;
  // The pose as tracking estimated it then, in the world of that moment (later map
  // optimisation does not move it): what a live user saw; inertial runs write it out.
  std::optional<SE3d> camera_from_world_online;
  bool keyframe = false;
  // Localisation only: the pose came from visual odometry against the previous frame, not
  // from the loaded map's points (tracking/localisation_tracking.h).
  bool visual_odometry = false;
  // Wall time from image to pose: building the frame (ORB extraction, stereo matching) and
  // tracking it, as ORB-SLAM3's examples time Track*(); live-emulation waits excluded.
  double tracking_ms = 0;
  // CPU time of the tracking thread: building the frame (ORB, stereo matching) and tracking it
  // (the wall-clock tracking_ms also counts waits for the Atlas lock and preemption).
  double build_cpu_ms = 0;
  double tracking_cpu_ms = 0;
  int inliers = 0;
  // With FrameRecords::EnableObservations: the frame's pose inliers, as (map point id,
  // undistorted pixel): `pkslam run --frame-tracks` writes them as a tracks file
  // (io/track_file.h).
  struct Observation {
    MapPointId point = kInvalidId;
    float u = 0, v = 0;
  };
  std::vector<Observation> observations;
};

// The pose inliers of a tracked frame: every keypoint with a map point that is not an outlier.
std::vector<FrameRecord::Observation> InlierObservations(const Frame& frame);

class FrameRecords {
 public:
  // Whether records keep their frame's pose inliers (--frame-tracks).
  void EnableObservations(bool on) { observations_enabled_ = on; }
  bool observations_enabled() const { return observations_enabled_; }

  void Add(FrameRecord record) { records_.push_back(std::move(record)); }
  const std::vector<FrameRecord>& all() const { return records_; }
  bool empty() const { return records_.empty(); }
  const FrameRecord& back() const { return records_.back(); }
  FrameRecord& back() { return records_.back(); }

  // The pose of a tracked `frame` into its `record`: the online pose, the pose relative to
  // `reference` (alive), and with EnableObservations its inliers. A frame that became
  // `reference` (`keyframe`: made a keyframe at its time) takes the keyframe's pose first.
  // Atlas lock held (shared).
  void SetPose(const KeyFramePtr& reference, bool keyframe, Frame* frame,
               FrameRecord* record) const;

  // A new calibration moved the tracking camera in the body by new_from_old (the body keeps
  // its place): relative poses and the online poses move with it.
  void MoveCamera(const SE3d& new_from_old);
  // `map` was rescaled by `ratio` (monocular-inertial initialisation): the translations of the
  // records relative to its keyframes scale with it; other maps' records stay.
  void Rescale(const Map* map, double ratio);
  // `map` was dropped (a reset): its frames lose their reference and so end up without a pose.
  void Forget(const Map* map);

 private:
  std::vector<FrameRecord> records_;
  bool observations_enabled_ = false;
};

}  // namespace pkslam
