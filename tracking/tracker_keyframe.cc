// Keyframe decisions and creation, and map initialisation (its parts: tracking/map_initializer.h).
#include <algorithm>
#include <mutex>
#include <shared_mutex>

#include "core/bow/vocabulary.h"
#include "core/util/log.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"
#include "tracking/keyframe_points.h"
#include "tracking/map_initializer.h"
#include "tracking/selector_snapshot.h"
#include "tracking/tracker.h"

namespace pkslam {

SelectorInput Tracker::BuildSelectorInput(bool mapping_idle) const {
  TrackedFrameView view;
  view.rig = rig_.get();
  view.map = atlas_->current_map();
  view.frame = &current_;
  view.inliers = inliers_;
  view.recently_lost = state_ == TrackingState::kRecentlyLost;
  view.reference = reference_kf_.get();
  view.last_keyframe = last_kf_.get();
  view.last_relocalisation_frame_id = last_reloc_frame_id_;
  SelectorInput in = SnapshotTrackedFrame(view, *selector_);
  FillImuSelectorInput(&in);
  in.local_mapping_stopped = mapping_->IsStoppedOrStopRequested();
  in.local_mapping_idle = mapping_idle;
  in.trace_wanted = decision_.tracing();
  in.local_mapping_initializing = mapping_->IsInitializingImu();
  in.local_mapping_queue = mapping_->QueueSize();
  return in;
}

void Tracker::CreateNewKeyFrame(const SelectorInput& input) {
  KeyFramePtr kf;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInsertKeyFrame);
    Map* map = atlas_->current_map();
    current_.ComputeBoW(*vocabulary_);
    kf = std::make_shared<KeyFrame>(atlas_->NextKeyFrameId(), current_, map);
    map->AddKeyFrame(lock, kf);
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
  const auto reconstruction =
      two_view_.Offer(current_, MixSeed(options_.seed, static_cast<std::uint64_t>(current_.id())));
  if (reconstruction) CreateInitialMapMonocular(*reconstruction);
}

void Tracker::CreateInitialMapMonocular(const TwoViewResult& reconstruction) {
  TwoViewKeyFrames map;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInitialise);
    map = CreateTwoViewMap(lock, atlas_, *vocabulary_, AttachKeyFrameFunction(), reconstruction,
                           two_view_.matches(), &two_view_.first(), &current_);
  }
  // Refine both views and all points before fixing the scale.
  RefineTwoViewMap(atlas_);
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInitialise);
    const TwoViewScaling scaling =
        NormaliseTwoViewScale(lock, map, kMinTwoViewMapPoints, &current_);
    if (!scaling.accepted) {
      lock.unlock();
      PKSLAM_LOG_WARN("monocular initialisation rejected (median depth {:.3f}); retrying",
                      scaling.median_depth);
      Reset();
      return;
    }
    local_map_.Reset({map.second.get(), map.first.get()}, map.first->GoodMapPoints());
    PKSLAM_LOG_INFO("new map {} initialised from two views with {} points",
                    atlas_->current_map()->id(), atlas_->current_map()->NumMapPoints());
  }
  mapping_->InsertKeyFrame(map.first);
  mapping_->InsertKeyFrame(map.second);
  if (options_.lockstep) mapping_->WaitUntilIdle();
  last_kf_ = map.second;
  reference_kf_ = map.second;
  current_.reference_kf = map.second;
  inliers_ = map.second->TrackedMapPoints(1);
  last_ = two_view_.first();  // replaced by the current frame at the end of Track
  two_view_.Reset();
  BeginTrackingNewMap();
}

AttachKeyFrame Tracker::AttachKeyFrameFunction() {
  return [this](const MapWriteLock& lock, KeyFrame* kf, KeyFrame* previous, const Frame& frame) {
    AttachImu(lock, kf, previous, frame);
  };
}

void Tracker::BeginTrackingNewMap() {
  selector_->Reset();
  SelectorInput input;
  input.frame_id = current_.id();
  input.t_ns = current_.t_ns();
  selector_->OnKeyFrameInserted(input);
  state_ = TrackingState::kOk;
}

}  // namespace pkslam
