// Local mapping's whole-map inertial work at each keyframe of an inertial map (ORB-SLAM3's
// LocalMapping::Run IMU part; the stages are described in mapping/inertial_mapping.h): the IMU
// initialisation, the two visual-inertial refinements (VIBA1, VIBA2) when due, each followed
// by a full visual-inertial BA, and afterwards gravity refinement
// (estimators/inertial/gravity_gauge.h). The gathers and write-backs are
// map_model/estimation/{inertial_init,inertial_bundle,gravity_refinement}_*.h.
//
// Threads: owned by LocalMapper and driven by its mapping thread (Step). Tracking reads the
// two flags (atomics); the stats are guarded by `mutex_`.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "core/imu/imu_types.h"
#include "core/sensor/sensor.h"
#include "core/util/annotated_mutex.h"
#include "core/util/work_meter.h"
#include "map_model/atlas.h"
#include "mapping/inertial_mapping.h"
#include "mapping/inertial_motion_clock.h"

namespace pkslam {

// The map's keyframe chain right after one IMU initialisation stage (its full visual-inertial
// BA included), for evaluation against ground truth (scale, gravity, biases per stage).
struct ImuStageSnapshot {
  std::int64_t t_ns = 0;  // the keyframe that triggered the stage
  int stage = 0;          // 0 initialisation, 1 VIBA1, 2 VIBA2
  double scale = 1.0;     // the scale the inertial-only step applied
  ImuBias bias;
  std::vector<std::pair<std::int64_t, SE3d>> world_from_body;  // chain keyframes, oldest first
};

// One gravity refinement (estimators/inertial/gravity_gauge.h).
struct GravityRefinementStat {
  std::int64_t t_ns = 0;       // the keyframe that triggered it
  int keyframes = 0;           // chain keyframes in the BA
  double observability = 0;    // TiltObservability of the chain
  double tilt_change_rad = 0;  // how far gravity moved, seen from the first keyframe
  double ms = 0;
};

struct InertialStagesStats {
  std::vector<ImuStageSnapshot> imu_stages;
  std::vector<GravityRefinementStat> gravity_refinements;
  int gravity_refinements_dropped = 0;  // results dropped: the map moved meanwhile
};

// What the stages ask of local mapping, at the moment they need it.
struct InertialStageHooks {
  // A keyframe waits in local mapping's queue: gravity refinement leaves it the thread.
  std::function<bool()> keyframe_queued;
  // A calibration adjustment solves in its own thread: the refinements, which move every state
  // of the map, wait for it to end (its result would find its map moved).
  std::function<bool()> calibration_running;
  // Local mapping's BA interrupt (a new keyframe) and work meter (live emulation); may be null.
  const std::atomic<bool>* abort = nullptr;
  WorkMeter* work = nullptr;
};

class InertialStages {
 public:
  // `solver_threads`: the solvers' Ceres threads (local BA's).
  InertialStages(Atlas* atlas, Sensor sensor, InertialMappingOptions options, int solver_threads,
                 InertialStageHooks hooks);
  InertialStages(const InertialStages&) = delete;
  InertialStages& operator=(const InertialStages&) = delete;

  // Mapping thread, at each keyframe of an inertial map: the stage that is due, if any.
  void Step(const KeyFramePtr& kf);

  // An initialisation stage is running (MappingBackend::IsInitializingImu).
  bool initializing() const { return initializing_.load(); }
  // ORB-SLAM3 v0.3's slow-motion flag, raised by Step and taken by tracking
  // (MappingBackend::TakeSlowMotionFlag).
  bool TakeSlowMotionFlag() { return slow_motion_.exchange(false); }

  InertialStagesStats stats() const;

 private:
  // One initialisation stage (0: the first, 1: VIBA1, 2: VIBA2) with the given bias prior
  // informations; false when the chain is not ready or the solve failed.
  bool Initialize(const KeyFramePtr& kf, double gyro_prior, double accel_prior, int stage);
  // The full visual-inertial BA (shared biases) after a stage, over the chain ending at kf.
  void FullBundleAdjustment(const KeyFramePtr& kf, double gyro_prior, double accel_prior);
  // Gravity refinement when due (InertialMappingOptions::gravity_refinement).
  void RefineGravity(const KeyFramePtr& kf);

  Atlas* atlas_;
  Sensor sensor_;
  InertialMappingOptions options_;
  int solver_threads_;
  InertialStageHooks hooks_;

  // The mapping thread's: the motion time and ORB-SLAM3 v0.3's mTinit of the current map.
  InertialMotionClock motion_clock_;
  std::atomic<bool> initializing_{false};
  std::atomic<bool> slow_motion_{false};

  mutable Mutex mutex_;
  InertialStagesStats stats_ PKSLAM_GUARDED_BY(mutex_);
};

}  // namespace pkslam
