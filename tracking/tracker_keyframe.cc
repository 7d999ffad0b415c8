// Keyframe decisions and creation, and map initialisation (tracking/map_starter.h).
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
  if (imu_) imu_->FillSelectorInput(current_, last_, *rig_, ImuReady(), &in);
  NoteLocalMapping(*mapping_, mapping_idle, &in);
  in.trace_wanted = decision_.tracing();
  return in;
}

void Tracker::CreateNewKeyFrame(const SelectorInput& input) {
  KeyFramePtr kf;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInsertKeyFrame);
    std::optional<ClosePointRule> close_points;
    if (!IsMonocular(rig_->sensor)) {
      close_points = ClosePointRule{rig_->th_depth, options_.new_keyframe_min_close_points};
    }
    kf = CreateKeyFrame(lock, atlas_, *vocabulary_, ImuAttacher(), last_kf_.get(), close_points,
                        &current_);
  }
  reference_kf_ = kf;
  current_.reference_kf = kf;
  last_kf_ = kf;
  if (!selector_->SnapshotAfterCreation()) {
    selector_->OnKeyFrameInserted(input);
  } else {
    // The frame as the keyframe holds it: the new close points in, outliers still in.
    auto lock = MapReader(*atlas_).Lock();
    const SelectorInput created = BuildSelectorInput(input.local_mapping_idle);
    lock.unlock();
    selector_->OnKeyFrameInserted(created);
  }
  mapping_->InsertKeyFrame(kf);
  if (options_.lockstep) mapping_->WaitUntilIdle();
}

void Tracker::StartMap() {
  StartedMap started = starter_.Offer(&current_, ImuAttacher(), &local_map_);
  if (started.refused) Reset();
  if (!started.started()) return;
  for (const KeyFramePtr& kf : started.keyframes) mapping_->InsertKeyFrame(kf);
  if (options_.lockstep) mapping_->WaitUntilIdle();
  last_kf_ = started.newest();
  reference_kf_ = started.newest();
  current_.reference_kf = started.newest();
  inliers_ = started.TrackedPoints();
  // The pair's first frame is the last one until Track ends with the current frame.
  if (started.first_of_pair) last_ = std::move(*started.first_of_pair);
  RestartSelector(current_, selector_.get());
  state_ = TrackingState::kOk;
}

AttachKeyFrame Tracker::ImuAttacher() {
  return [this](const MapWriteLock& lock, KeyFrame* kf, KeyFrame* previous, const Frame& frame) {
    AttachImu(lock, kf, previous, frame);
  };
}

}  // namespace pkslam
