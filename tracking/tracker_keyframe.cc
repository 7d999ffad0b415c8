// Keyframe decisions and creation, and monocular map initialisation.
#include <algorithm>
#include <mutex>
#include <shared_mutex>

#include "core/bow/vocabulary.h"
#include "core/util/log.h"
#include "map_model/estimation/bundle_collect.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"
#include "tracking/keyframe_points.h"
#include "tracking/tracker.h"
#include "tracking/two_view_initializer.h"

namespace pkslam {

SelectorInput Tracker::BuildSelectorInput(bool mapping_idle) const {
  SelectorInput in;
  const CameraRig& rig = *rig_;
  const Map* map = atlas_->current_map();
  in.sensor = rig.sensor;
  in.frame_id = current_.id();
  in.t_ns = current_.t_ns();
  in.fps = rig.fps;
  in.image_width = rig.camera.width();
  in.image_height = rig.camera.height();
  in.fx = rig.fx;
  in.fy = rig.fy;
  in.cx = rig.cx;
  in.cy = rig.cy;
  in.bounds = rig.bounds;
  in.camera_from_world = current_.camera_from_world();
  in.inliers = inliers_;
  in.recently_lost = state_ == TrackingState::kRecentlyLost;
  in.keyframes_in_map = map->NumKeyFrames();
  in.imu_initialized = map->imu_status().imu_initialized;
  if (reference_kf_) {
    in.reference_tracked_points = reference_kf_->TrackedMapPoints(in.keyframes_in_map <= 2 ? 2 : 3);
  }
  if (last_kf_) {
    in.last_keyframe_id = last_kf_->id();
    in.last_keyframe_frame_id = last_kf_->frame_id();
    in.last_keyframe_t_ns = last_kf_->t_ns();
    in.last_keyframe_camera_from_world = last_kf_->camera_from_world();
  }
  in.last_relocalisation_frame_id = last_reloc_frame_id_;
  FillImuSelectorInput(&in);
  in.local_mapping_stopped = mapping_->IsStoppedOrStopRequested();
  in.local_mapping_idle = mapping_idle;
  in.trace_wanted = trace_enabled_;
  in.local_mapping_initializing = mapping_->IsInitializingImu();
  in.local_mapping_queue = mapping_->QueueSize();

  if (!IsMonocular(rig.sensor)) {
    for (int i = 0; i < current_.size(); ++i) {
      const float d = current_.depth()[i];
      if (d <= 0 || d >= rig.th_depth) continue;
      if (current_.map_points[i] && !current_.outliers[i]) {
        ++in.tracked_close;
      } else {
        ++in.untracked_close;
      }
    }
  }
  if (selector_->NeedsTrackedPoints()) {
    const bool outliers = selector_->NeedsOutliers();
    const auto& kps = current_.keypoints_undistorted();
    for (int i = 0; i < current_.size(); ++i) {
      const auto& mp = current_.map_points[i];
      if (!mp || (current_.outliers[i] && !outliers) || mp->IsBad()) continue;
      SelectorPoint p;
      p.id = mp->id();
      p.position_world = mp->position();
      p.uv = Eigen::Vector2d(kps[i].pt.x, kps[i].pt.y);
      p.keypoint_index = i;
      p.in_last_keyframe = last_kf_ && !last_kf_->IsBad() && mp->IsInKeyFrame(last_kf_.get());
      p.outlier = current_.outliers[i] != 0;
      p.descriptor = &current_.descriptors()[i];
      p.map_point_descriptor = &mp->descriptor();
      in.points.push_back(p);
    }
  }
  return in;
}

void Tracker::CreateNewKeyFrame(const SelectorInput& input) {
  KeyFramePtr kf;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInsertKeyFrame);
    Map* map = atlas_->current_map();
    current_.ComputeBoW(*vocabulary_);
    kf = std::make_shared<KeyFrame>(atlas_->NextKeyFrameId(), current_, map);
    map->AddKeyFrame(kf);
    AttachImu(lock, kf.get(), last_kf_.get(), current_);
    if (!IsMonocular(rig_->sensor)) {
      const ClosePointRule rule{rig_->th_depth, options_.new_keyframe_min_close_points};
      AddClosePoints(lock, atlas_, kf.get(), rule, &current_);
    }
  }
  reference_kf_ = kf;
  current_.reference_kf = kf;
  last_kf_ = kf;
  if (selector_->SnapshotAfterCreation()) {
    // The frame as the keyframe holds it: the new close points in, outliers still in.
    SelectorInput created;
    {
      auto lock = MapReader(*atlas_).Lock();
      created = BuildSelectorInput(input.local_mapping_idle);
    }
    selector_->OnKeyFrameInserted(created);
  } else {
    selector_->OnKeyFrameInserted(input);
  }
  mapping_->InsertKeyFrame(kf);
  if (options_.lockstep) mapping_->WaitUntilIdle();
}

void Tracker::MonocularInitialization() {
  constexpr int kMinFeatures = 100;
  if (!init_frame_) {
    if (current_.size() <= kMinFeatures) return;
    init_frame_ = current_;
    init_prev_matched_.clear();
    for (const auto& kp : current_.keypoints_undistorted()) init_prev_matched_.push_back(kp.pt);
    init_matches_.assign(current_.size(), -1);
    return;
  }
  if (current_.size() <= kMinFeatures) {
    init_frame_.reset();
    return;
  }
  const OrbMatcher matcher(0.9, true);
  const int n = matcher.SearchForInitialization(*init_frame_, current_, &init_prev_matched_,
                                                &init_matches_, 100);
  if (n < kMinFeatures) {
    init_frame_.reset();
    return;
  }
  TwoViewOptions two_view;
  two_view.seed = MixSeed(options_.seed, static_cast<std::uint64_t>(current_.id()));
  const auto reconstruction = ReconstructTwoView(*init_frame_, current_, init_matches_, two_view);
  if (!reconstruction) return;
  for (std::size_t i = 0; i < init_matches_.size(); ++i) {
    if (init_matches_[i] >= 0 && !reconstruction->triangulated[i]) init_matches_[i] = -1;
  }
  CreateInitialMapMonocular(*reconstruction);
}

void Tracker::CreateInitialMapMonocular(const TwoViewResult& reconstruction) {
  KeyFramePtr kf_init;
  KeyFramePtr kf_current;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInitialise);
    Map* map = atlas_->current_map();
    init_frame_->SetPose(SE3d());
    current_.SetPose(reconstruction.camera2_from_camera1);
    init_frame_->ComputeBoW(*vocabulary_);
    current_.ComputeBoW(*vocabulary_);
    kf_init = std::make_shared<KeyFrame>(atlas_->NextKeyFrameId(), *init_frame_, map);
    kf_current = std::make_shared<KeyFrame>(atlas_->NextKeyFrameId(), current_, map);
    map->AddKeyFrame(kf_init);
    map->AddKeyFrame(kf_current);
    AttachImu(lock, kf_init.get(), nullptr, *init_frame_);
    AttachImu(lock, kf_current.get(), kf_init.get(), current_);
    for (std::size_t i = 0; i < init_matches_.size(); ++i) {
      const int j = init_matches_[i];
      if (j < 0) continue;
      auto mp = std::make_shared<MapPoint>(atlas_->NextMapPointId(), reconstruction.points[i],
                                           kf_current.get(), map);
      kf_init->AddMapPoint(mp, static_cast<int>(i));
      kf_current->AddMapPoint(mp, j);
      mp->AddObservation(kf_init.get(), static_cast<int>(i));
      mp->AddObservation(kf_current.get(), j);
      mp->ComputeDistinctiveDescriptor();
      mp->UpdateNormalAndDepth();
      current_.map_points[j] = mp;
      current_.outliers[j] = 0;
      map->AddMapPoint(mp);
    }
    kf_init->UpdateConnections();
    kf_current->UpdateConnections();
  }
  // Refine both views and all points before fixing the scale.
  {
    BundleProblem problem;
    {
      auto lock = MapReader(*atlas_).Lock();
      problem = CollectGlobalBundle(*atlas_->current_map());
    }
    BundleAdjustmentOptions ba;
    ba.iterations_first = 20;
    ba.iterations_second = 0;
    const BundleResult result = SolveBundle(problem, ba);
    auto lock = MapEditor(atlas_).Write(MapEdit::kInitialise);
    ApplyBundle(atlas_->current_map(), problem, result);
  }
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInitialise);
    const double median_depth = kf_init->SceneDepthQuantile(0.5);
    if (median_depth <= 0 || kf_current->TrackedMapPoints(1) < 50) {
      lock.unlock();
      PKSLAM_LOG_WARN("monocular initialisation rejected (median depth {:.3f}); retrying",
                      median_depth);
      Reset();
      return;
    }
    // The map's unit becomes the initial median scene depth.
    const double scale = 1.0 / median_depth;
    SE3d tcw = kf_current->camera_from_world();
    tcw.translation() *= scale;
    kf_current->SetPose(tcw);
    for (const auto& mp : kf_init->map_points()) {
      if (mp && !mp->IsBad()) {
        mp->SetPosition(mp->position() * scale);
        mp->UpdateNormalAndDepth();
      }
    }
    current_.SetPose(tcw);
    local_map_.Reset({kf_current.get(), kf_init.get()}, kf_init->GoodMapPoints());
    PKSLAM_LOG_INFO("new map {} initialised from two views with {} points",
                    atlas_->current_map()->id(), atlas_->current_map()->NumMapPoints());
  }
  mapping_->InsertKeyFrame(kf_init);
  mapping_->InsertKeyFrame(kf_current);
  if (options_.lockstep) mapping_->WaitUntilIdle();
  last_kf_ = kf_current;
  reference_kf_ = kf_current;
  current_.reference_kf = kf_current;
  inliers_ = kf_current->TrackedMapPoints(1);
  last_ = *init_frame_;  // replaced by the current frame at the end of Track
  init_frame_.reset();
  selector_->Reset();
  SelectorInput input;
  input.frame_id = current_.id();
  input.t_ns = current_.t_ns();
  selector_->OnKeyFrameInserted(input);
  state_ = TrackingState::kOk;
}

}  // namespace pkslam
