// ORB-SLAM3 v1.0's keyframe rule (Tracking::NeedNewKeyFrame), see
// ../shared/docs/ORBSLAM3_FACTS.md "Keyframe decision"; with `no_keyframe_while_imu_initialises`
// the rule of v0.3, the revision the PKS authors' code derives from.
#pragma once

#include "keyframe/keyframe_selector.h"

namespace pkslam {

struct OrbSlam3SelectorOptions {
  // Minimum frames between keyframes (ORB-SLAM's mMinFrames).
  int min_frames = 0;
  // Frames after which a keyframe is due; <= 0 means the camera fps (mMaxFrames).
  int max_frames = 0;
  // Inertial, IMU not initialised: a keyframe every this many seconds.
  double imu_uninitialised_interval_s = 0.25;
  // Inertial: a keyframe at least every this many seconds (c3).
  double inertial_interval_s = 0.5;
  // Close-point rule: insert when tracked close < this and untracked close > the next.
  int close_tracked_max = 100;
  int close_untracked_min = 70;
  // ORB-SLAM3 v0.3 (and the PKS authors' code built on it) takes no keyframe while local
  // mapping initialises the IMU; v1.0 dropped that exit (and inserts then, as when idle).
  // Everything else of NeedNewKeyFrame is the same in the two revisions.
  bool no_keyframe_while_imu_initialises = false;

  void Check() const;
};

class OrbSlam3Selector : public KeyframeSelector {
 public:
  explicit OrbSlam3Selector(OrbSlam3SelectorOptions options = {});
  std::string_view name() const override { return "orbslam3"; }
  SelectorDecision Decide(const SelectorInput& input) override;

 private:
  OrbSlam3SelectorOptions options_;
};

// The decision ORB-SLAM3 takes once its conditions say "a keyframe is wanted": insert if
// local mapping is idle (or initialising IMU); else interrupt its BA and insert for
// non-monocular sensors when its queue is short. Shared by every selector that keeps
// ORB-SLAM3's safety exits (PKS included).
SelectorDecision AcceptIfMappingCanTakeIt(const SelectorInput& input, std::string reason);

}  // namespace pkslam
