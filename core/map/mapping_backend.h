// What tracking needs from local mapping. Declared here (below both) so tracking/ and
// mapping/ stay peers: mapping/LocalMapper implements it; system/ wires them together.
#pragma once

#include "core/map/ids.h"

namespace pkslam {

class MappingBackend {
 public:
  virtual ~MappingBackend() = default;
  // Hands a new keyframe (already in the map) over for local mapping.
  virtual void InsertKeyFrame(const KeyFramePtr& kf) = 0;
  // Idle and willing to take keyframes now.
  virtual bool AcceptsKeyFrames() const = 0;
  // Paused by loop closing (or asked to pause).
  virtual bool IsStoppedOrStopRequested() const = 0;
  // Running IMU initialisation.
  virtual bool IsInitializingImu() const = 0;
  virtual int QueueSize() const = 0;
  // Asks a running local bundle adjustment to stop early.
  virtual void InterruptBundleAdjustment() = 0;
  // Deterministic mode: blocks until every queued keyframe is processed (and handed on).
  virtual void WaitUntilIdle() = 0;
  // Map reset by tracking: drop queued keyframes (called with no Atlas lock held).
  virtual void ResetQueue() = 0;
};

}  // namespace pkslam
