// What the keyframe inserter reads of the Tracker (tracking/keyframe_inserter.h), and map
// initialisation (tracking/map_starter.h).
#include "map_model/keyframe.h"
#include "tracking/selector_snapshot.h"
#include "tracking/tracker.h"

namespace pkslam {

KeyFrameContext Tracker::KeyFrameContextNow() {
  KeyFrameContext context;
  context.rig = rig_.get();
  context.recently_lost = state_ == TrackingState::kRecentlyLost;
  context.imu = imu_.get();
  context.imu_ready = [this] { return ImuReady(); };
  context.attach = ImuAttacher();
  return context;
}

void Tracker::StartMap() {
  StartedMap started = starter_.Offer(&frames_.current, ImuAttacher(), &map_tracker_.local_map());
  if (started.refused) Reset();
  if (!started.started()) return;
  for (const KeyFramePtr& kf : started.keyframes) mapping_->InsertKeyFrame(kf);
  if (options_.lockstep) mapping_->WaitUntilIdle();
  frames_.last_kf = started.newest();
  frames_.reference_kf = started.newest();
  frames_.current.reference_kf = started.newest();
  frames_.inliers = started.TrackedPoints();
  // The pair's first frame is the last one until Track ends with the current frame.
  if (started.first_of_pair) frames_.last = std::move(*started.first_of_pair);
  RestartSelector(frames_.current, selector_.get());
  state_ = TrackingState::kOk;
}

AttachKeyFrame Tracker::ImuAttacher() {
  return [this](const MapWriteLock& lock, KeyFrame* kf, KeyFrame* previous, const Frame& frame) {
    AttachImu(lock, kf, previous, frame);
  };
}

}  // namespace pkslam
