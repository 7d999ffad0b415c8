#include "tracking/frame_records.h"

#include "map_model/keyframe.h"
#include "map_model/map_point.h"

namespace pkslam {

const char* TrackingStateName(TrackingState s) {
  switch (s) {
    case TrackingState::kNotInitialized:
      return "NOT_INITIALIZED";
    case TrackingState::kOk:
      return "OK";
    case TrackingState::kRecentlyLost:
      return "RECENTLY_LOST";
    case TrackingState::kLost:
      return "LOST";
  }
  return "?";
}

std::vector<FrameRecord::Observation> InlierObservations(const Frame& frame) {
  std::vector<FrameRecord::Observation> out;
  const auto& keypoints = frame.keypoints_undistorted();
  for (std::size_t i = 0; i < frame.map_points.size() && i < keypoints.size(); ++i) {
    const MapPointPtr& mp = frame.map_points[i];
    if (!mp || (i < frame.outliers.size() && frame.outliers[i] != 0)) continue;
    out.push_back({mp->id(), keypoints[i].pt.x, keypoints[i].pt.y});
  }
  return out;
}

void FrameRecords::MoveCamera(const SE3d& new_from_old) {
  const SE3d old_from_new = new_from_old.Inverse();
  for (FrameRecord& r : records_) {
    r.camera_from_reference = new_from_old * r.camera_from_reference * old_from_new;
    if (r.camera_from_world_online) {
      r.camera_from_world_online = new_from_old * *r.camera_from_world_online;
    }
  }
}

void FrameRecords::Rescale(const Map* map, double ratio) {
  for (FrameRecord& r : records_) {
    if (r.reference && r.reference->map() == map) r.camera_from_reference.translation() *= ratio;
  }
}

void FrameRecords::Forget(const Map* map) {
  for (FrameRecord& r : records_) {
    if (r.reference && r.reference->map() == map) r.reference.reset();
  }
}

void FrameRecords::SetPose(const KeyFramePtr& reference, bool keyframe, Frame* frame,
                           FrameRecord* record) const {
  record->camera_from_world_online = frame->camera_from_world();
  if (keyframe && reference->t_ns() == frame->t_ns() && !reference->IsBad()) {
    // The frame is the keyframe's image, so it has the keyframe's pose. Local mapping may
    // already have moved it (lock-step runs map before the record is made: the
    // monocular-inertial initialisation rotates and rescales the world and then runs a full
    // BA, more than the tracker's world-change sync can carry the frame across; a frame 19 cm
    // off at the initialisation of a MH_01 replay).
    frame->SetPose(reference->camera_from_world());
  }
  record->reference = reference;
  record->camera_from_reference = frame->camera_from_world() * reference->world_from_camera();
  if (observations_enabled_) record->observations = InlierObservations(*frame);
}

}  // namespace pkslam
