// What tracking needs from local mapping. Declared here (below both) so tracking/ and
// mapping/ stay peers: mapping/LocalMapper implements it; system/ wires them together.
#pragma once

#include <cstdint>

#include "map_model/map_ids.h"

namespace pkslam {

class MappingBackend {
 public:
  virtual ~MappingBackend() = default;
  // Hands a new keyframe (already in the map) over for local mapping. Waits while the queue is
  // full (QueueFull), so call it holding no map lock.
  virtual void InsertKeyFrame(const KeyFramePtr& kf) = 0;
  // Idle and willing to take keyframes now.
  virtual bool AcceptsKeyFrames() const = 0;
  // Paused by loop closing (or asked to pause).
  virtual bool IsStoppedOrStopRequested() const = 0;
  // Running IMU initialisation.
  virtual bool IsInitializingImu() const = 0;
  virtual int QueueSize() const = 0;
  // The queue holds its bound (LocalMappingOptions::max_queued_keyframes): tracking declines
  // keyframes meanwhile; InsertKeyFrame would wait for room (backpressure).
  virtual bool QueueFull() const = 0;
  // Returns and clears the flag local mapping raises when, before the second inertial
  // refinement and within its first 10 s of motion, the body moved less than 10 cm over its
  // last two keyframe steps (ORB-SLAM3 v0.3's mbBadImu2, which pks-released obeys).
  virtual bool TakeSlowMotionFlag() { return false; }
  // Asks a running local bundle adjustment to stop early.
  virtual void InterruptBundleAdjustment() = 0;
  // Deterministic mode: blocks until every queued keyframe is processed (and handed on).
  virtual void WaitUntilIdle() = 0;
  // Whether local mapping takes keyframes for a frame at data time `t_ns`. Without live
  // emulation this is AcceptsKeyFrames(). With it (offline runs, EmulateLive), local mapping
  // is idle at t_ns only if its work, laid out on the data clock (a keyframe's processing
  // starts at its timestamp or when the previous one ends, and lasts its wall time), ended
  // by t_ns; the call blocks while that cannot be known yet (mapping is still working on a
  // keyframe whose data-clock span has not yet reached t_ns). Tracking thereby sees mapping
  // as a live run at real-time pace would, without sleeping when mapping is idle.
  virtual bool AcceptsKeyFramesAt(std::int64_t t_ns) = 0;
  // Tracking is about to process the frame at data time `t_ns`: every earlier frame is done
  // (called for every frame, before any map access; never blocks). Live emulation on the work
  // clock holds local mapping's map changes back until tracking has reached their data time.
  virtual void NoteFrameTime(std::int64_t /*t_ns*/) {}
  // Whether AcceptsKeyFramesAt emulates a live run (else it is AcceptsKeyFrames()).
  virtual bool EmulatesLive() const = 0;
  // Map reset by tracking: drop queued keyframes (called with no Atlas lock held).
  virtual void ResetQueue() = 0;
};

}  // namespace pkslam
