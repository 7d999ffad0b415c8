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

}  // namespace pkslam
