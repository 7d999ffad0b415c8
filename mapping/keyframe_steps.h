// Local mapping's work on one keyframe (ORB-SLAM3's LocalMapping::Run body, without the
// thread): admit the keyframe and its points, cull the recent points that did not hold,
// triangulate new points with the covisible keyframes, fuse duplicates with the neighbours, run
// local bundle adjustment (visual-inertial once the map's IMU is initialised) and cull redundant
// keyframes. Each step is a part tested beside its own file; this class keeps their order and
// the rules that skip the later ones when a newer keyframe waits.
//
// LocalMapper owns one and drives it from the mapping thread (or inline without a thread); the
// map is read under the shared Atlas lock and written under short exclusive locks (MapEditor).
// The hooks connect it to the thread: the queue, the stop request, live emulation's pacing.
#pragma once

#include <atomic>
#include <functional>
#include <memory>

#include "core/sensor/camera_rig.h"
#include "core/util/work_meter.h"
#include "map_model/atlas.h"
#include "map_model/map_ids.h"
#include "mapping/local_mapping_options.h"
#include "mapping/recent_points.h"

namespace pkslam {

struct KeyFrameStepHooks {
  // A newer keyframe waits in the queue: triangulation stops early, and fusion, local BA and
  // keyframe culling are left to it.
  std::function<bool()> keyframe_waiting;
  // Loop closing asked local mapping to stop: local BA and culling are left out.
  std::function<bool()> stopping;
  // Called before each step that changes the map or asks whether a keyframe waits (live
  // emulation on the work clock holds mapping back to tracking's data time there, and applies
  // a due calibration adjustment).
  std::function<void()> step_boundary;
  // Called before a result computed from the map is written back over the states it read
  // (pacing only: the result was computed with the present calibration).
  std::function<void()> pace;
  // Local mapping's BA interrupt (a newer keyframe) and work meter (live emulation); may be null.
  const std::atomic<bool>* abort = nullptr;
  WorkMeter* work = nullptr;
};

// What the steps did to the map, for LocalMappingStats.
struct KeyFrameStepReport {
  int points_culled = 0;
  int points_created = 0;
  int keyframes_culled = 0;
  // Local BA: wall and CPU time (0 when it did not run), aborted by a newer keyframe, and for an
  // inertial one whether its anchor carried a marginalisation prior.
  double ba_ms = 0;
  double ba_cpu_ms = 0;
  bool ba_aborted = false;
  bool inertial_ba = false;
  bool inertial_ba_with_prior = false;
};

class KeyFrameSteps {
 public:
  // `atlas` outlives the steps.
  KeyFrameSteps(Atlas* atlas, std::shared_ptr<const CameraRig> rig,
                const LocalMappingOptions& options, KeyFrameStepHooks hooks);
  KeyFrameSteps(const KeyFrameSteps&) = delete;
  KeyFrameSteps& operator=(const KeyFrameSteps&) = delete;

  KeyFrameStepReport Run(const KeyFramePtr& kf);
  // The queue was dropped (a reset): the recent points are no longer watched.
  void ForgetRecentPoints() { recent_points_.Clear(); }

 private:
  void Admit(const KeyFramePtr& kf);
  int CullRecentPoints(const KeyFramePtr& kf);
  int CreateNewPoints(const KeyFramePtr& kf);
  void Fuse(const KeyFramePtr& kf);
  // Local BA; the report's BA fields.
  void AdjustLocalMap(const KeyFramePtr& kf, KeyFrameStepReport* report);
  // Visual local BA; true when it was aborted.
  bool LocalBundleAdjustment(const KeyFramePtr& kf);
  // Local inertial BA once the map's IMU is initialised; false if it did not apply (then the
  // visual local BA runs).
  bool LocalInertialBundleAdjustment(const KeyFramePtr& kf, KeyFrameStepReport* report);
  int CullKeyFrames(const KeyFramePtr& kf);

  Atlas* atlas_;
  std::shared_ptr<const CameraRig> rig_;
  const LocalMappingOptions options_;
  KeyFrameStepHooks hooks_;
  // Points created recently, checked by CullRecentPoints (the mapping thread's).
  RecentPoints recent_points_;
};

}  // namespace pkslam
