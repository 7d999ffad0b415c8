#include "tracking/selector_snapshot.h"

#include "core/util/error.h"
#include "map_model/keyframe.h"
#include "map_model/map.h"
#include "map_model/map_point.h"
#include "map_model/mapping_backend.h"

namespace pkslam {
namespace {

void CountClosePoints(const Frame& frame, double th_depth, SelectorInput* in) {
  for (int i = 0; i < frame.size(); ++i) {
    const float d = frame.depth()[i];
    if (d <= 0 || d >= th_depth) continue;
    if (frame.map_points[i] && !frame.outliers[i]) {
      ++in->tracked_close;
    } else {
      ++in->untracked_close;
    }
  }
}

void AddTrackedPoints(const Frame& frame, const KeyFrame* last_keyframe, bool outliers,
                      SelectorInput* in) {
  const auto& kps = frame.keypoints_undistorted();
  for (int i = 0; i < frame.size(); ++i) {
    const auto& mp = frame.map_points[i];
    if (!mp || (frame.outliers[i] && !outliers) || mp->IsBad()) continue;
    SelectorPoint p;
    p.id = mp->id();
    p.position_world = mp->position();
    p.uv = Eigen::Vector2d(kps[i].pt.x, kps[i].pt.y);
    p.keypoint_index = i;
    p.in_last_keyframe =
        last_keyframe != nullptr && !last_keyframe->IsBad() && mp->IsInKeyFrame(last_keyframe);
    p.outlier = frame.outliers[i] != 0;
    p.descriptor = &frame.descriptors()[i];
    p.map_point_descriptor = &mp->descriptor();
    in->points.push_back(p);
  }
}

}  // namespace

SelectorInput SnapshotTrackedFrame(const TrackedFrameView& view, const KeyframeSelector& selector) {
  PKSLAM_CHECK(view.rig != nullptr && view.map != nullptr && view.frame != nullptr,
               "SnapshotTrackedFrame needs a rig, a map and a frame");
  const CameraRig& rig = *view.rig;
  const Frame& frame = *view.frame;
  SelectorInput in;
  in.sensor = rig.sensor;
  in.frame_id = frame.id();
  in.t_ns = frame.t_ns();
  in.fps = rig.fps;
  in.image_width = rig.camera.width();
  in.image_height = rig.camera.height();
  in.fx = rig.fx;
  in.fy = rig.fy;
  in.cx = rig.cx;
  in.cy = rig.cy;
  in.bounds = rig.bounds;
  in.camera_from_world = frame.camera_from_world();
  in.inliers = view.inliers;
  in.recently_lost = view.recently_lost;
  in.keyframes_in_map = view.map->NumKeyFrames();
  in.imu_initialized = view.map->imu_status().imu_initialized;
  if (view.reference != nullptr) {
    in.reference_tracked_points =
        view.reference->TrackedMapPoints(in.keyframes_in_map <= 2 ? 2 : 3);
  }
  if (view.last_keyframe != nullptr) {
    in.last_keyframe_id = view.last_keyframe->id();
    in.last_keyframe_frame_id = view.last_keyframe->frame_id();
    in.last_keyframe_t_ns = view.last_keyframe->t_ns();
    in.last_keyframe_camera_from_world = view.last_keyframe->camera_from_world();
  }
  in.last_relocalisation_frame_id = view.last_relocalisation_frame_id;
  if (!IsMonocular(rig.sensor)) CountClosePoints(frame, rig.th_depth, &in);
  if (selector.NeedsTrackedPoints()) {
    AddTrackedPoints(frame, view.last_keyframe, selector.NeedsOutliers(), &in);
  }
  return in;
}

void NoteLocalMapping(const MappingBackend& mapping, bool idle, SelectorInput* in) {
  in->local_mapping_stopped = mapping.IsStoppedOrStopRequested();
  in->local_mapping_idle = idle;
  in->local_mapping_initializing = mapping.IsInitializingImu();
  in->local_mapping_queue = mapping.QueueSize();
}

void RestartSelector(const Frame& frame, KeyframeSelector* selector) {
  selector->Reset();
  SelectorInput input;
  input.frame_id = frame.id();
  input.t_ns = frame.t_ns();
  selector->OnKeyFrameInserted(input);
}

}  // namespace pkslam
