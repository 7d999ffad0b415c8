#include "tracking/keyframe_inserter.h"

#include <mutex>
#include <shared_mutex>

#include "core/bow/vocabulary.h"
#include "core/util/error.h"
#include "map_model/atlas.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "tracking/selector_snapshot.h"

namespace pkslam {

KeyFrameInserter::KeyFrameInserter(Atlas* atlas, const Vocabulary* vocabulary,
                                   KeyframeSelector* selector, MappingBackend* mapping,
                                   const TrackingOptions& options, bool monocular)
    : atlas_(atlas),
      vocabulary_(vocabulary),
      selector_(selector),
      mapping_(mapping),
      options_(options),
      decision_(monocular, StarvingRule{options.starving_inliers, options.starving_ratio}) {
  PKSLAM_CHECK(
      atlas_ != nullptr && vocabulary_ != nullptr && selector_ != nullptr && mapping_ != nullptr,
      "keyframe insertion needs an atlas, a vocabulary, a selector and local mapping");
}

SelectorInput KeyFrameInserter::Snapshot(const KeyFrameContext& context,
                                         const TrackedFrames& frames, bool mapping_idle) const {
  TrackedFrameView view;
  view.rig = context.rig;
  view.map = atlas_->current_map();
  view.frame = &frames.current;
  view.inliers = frames.inliers;
  view.recently_lost = context.recently_lost;
  view.reference = frames.reference_kf.get();
  view.last_keyframe = frames.last_kf.get();
  view.last_relocalisation_frame_id = frames.last_reloc_frame_id;
  SelectorInput in = SnapshotTrackedFrame(view, *selector_);
  if (context.imu != nullptr) {
    context.imu->FillSelectorInput(frames.current, frames.last, *context.rig, context.imu_ready(),
                                   &in);
  }
  NoteLocalMapping(*mapping_, mapping_idle, &in);
  in.trace_wanted = decision_.tracing();
  return in;
}

SelectorInput KeyFrameInserter::Decide(const KeyFrameContext& context, const TrackedFrames& frames,
                                       bool mapping_idle, bool* declined_queue_full) {
  SelectorInput in = Snapshot(context, frames, mapping_idle);
  // Taken once per decision (a keyframe's second input, SnapshotAfterCreation, has none).
  in.slow_motion_before_refinement = mapping_->TakeSlowMotionFlag();
  decision_.Decide(
      *selector_, in, frames.inliers, [this] { return mapping_->QueueFull(); },
      declined_queue_full);
  decided_frame_ = in.frame_id;
  return in;
}

KeyFramePtr KeyFrameInserter::Insert(const KeyFrameContext& context, const SelectorInput& input,
                                     TrackedFrames* frames) {
  KeyFramePtr kf;
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kInsertKeyFrame);
    std::optional<ClosePointRule> close_points;
    if (!IsMonocular(context.rig->sensor)) {
      close_points = ClosePointRule{context.rig->th_depth, options_.new_keyframe_min_close_points};
    }
    kf = CreateKeyFrame(lock, atlas_, *vocabulary_, context.attach, frames->last_kf.get(),
                        close_points, &frames->current);
  }
  frames->reference_kf = kf;
  frames->current.reference_kf = kf;
  frames->last_kf = kf;
  if (!selector_->SnapshotAfterCreation()) {
    selector_->OnKeyFrameInserted(input);
  } else {
    // The frame as the keyframe holds it: the new close points in, outliers still in.
    auto lock = MapReader(*atlas_).Lock();
    const SelectorInput created = Snapshot(context, *frames, input.local_mapping_idle);
    lock.unlock();
    selector_->OnKeyFrameInserted(created);
  }
  mapping_->InsertKeyFrame(kf);
  if (options_.lockstep) mapping_->WaitUntilIdle();
  return kf;
}

}  // namespace pkslam
