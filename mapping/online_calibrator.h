// Online calibration's schedule and thread (docs/calibration.md "When"): local mapping's part
// that decides when a calibration bundle adjustment of the whole map is due, gathers it in the
// keyframe step, solves it there or in a thread of its own, and applies the result like a
// global BA. The policy (what is observable, what is implausible) is calibration_refinement.h;
// the gather and write-back are map_model/estimation/calibration_{collect,apply}.h.
//
// Threads: owned by LocalMapper and driven by its mapping thread (Step, ApplyDue, Stop); the
// calibration thread only solves (and, unpaced, applies under the map's write lock). The
// history and the retry span are guarded by `mutex_`; the rest is the mapping thread's.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/sensor/camera_rig.h"
#include "core/sensor/rig_calibration.h"
#include "core/util/annotated_mutex.h"
#include "core/util/work_meter.h"
#include "map_model/atlas.h"
#include "mapping/calibration_refinement.h"

namespace pkslam {

// Where local mapping's work has got to on the data clock (live emulation on the work clock),
// read under local mapping's lock.
struct LiveDataPosition {
  std::int64_t reached_ns = 0;
  bool stopping = false;  // a stop, finish or reset is requested
};

// What the calibrator reads of local mapping's live emulation. Unpaced (no live emulation on
// the work clock) the thread's result is applied as soon as it is solved.
struct CalibrationPacing {
  bool paced = false;
  std::function<LiveDataPosition()> position;  // paced only
  // Data-clock nanoseconds that this much work spans on the reference machine.
  std::function<std::int64_t(const WorkCounts& work)> data_ns;
};

class OnlineCalibrator {
 public:
  // `solver_threads`: the adjustment's Ceres threads (local BA's).
  OnlineCalibrator(Atlas* atlas, Sensor sensor, OnlineCalibrationOptions options,
                   int solver_threads);
  ~OnlineCalibrator();
  OnlineCalibrator(const OnlineCalibrator&) = delete;
  OnlineCalibrator& operator=(const OnlineCalibrator&) = delete;

  // The calibration file's values (the prior) and the rest of the rig, to build rigs of new
  // estimates; before the first Step.
  void SetPrior(RigCalibration file, RigShape shape);
  void SetPacing(CalibrationPacing pacing);

  // Mapping thread, in kf's keyframe step: starts an adjustment of kf's map when due. It waits
  // for a later keyframe when one is queued (`keyframe_queued`) or the previous adjustment is
  // still outstanding. `in_step`: solve it here, interrupted by `step_abort` (after
  // options.min_iterations) and counted on `step_work` (may be nullptr); otherwise in the
  // calibration thread.
  void Step(const KeyFramePtr& kf, bool keyframe_queued, bool in_step,
            const std::atomic<bool>* step_abort, WorkMeter* step_work);
  // Mapping thread, at its step boundaries (paced only): applies the adjustment solving in the
  // calibration thread once local mapping's data time has passed the data time it started at
  // plus its solve's work on the reference machine (waiting for the solve if this machine is
  // slower), so where it lands does not depend on this machine's speed.
  void ApplyDue();
  // Whether an adjustment started and has not ended (paced: not yet applied or dropped).
  bool Outstanding() const;
  // Whether the calibration thread is solving or applying (the whole-map inertial steps wait).
  bool Running() const { return running_.load(); }
  // Interrupts a solve in the calibration thread (its result would be discarded anyway).
  void Interrupt() { abort_.store(true); }
  // Interrupts the calibration thread, waits for it, and drops a paced result not yet applied.
  void Stop();

  // Every adjustment so far, in the order they ended (stats.json "calibration.history").
  std::vector<CalibrationRefinementStat> history() const;

 private:
  // One adjustment: gathered in the keyframe step, then solved and applied.
  struct Job {
    KeyFramePtr kf;  // the keyframe that triggered it
    CalibrationBundleProblem problem;
    CalibrationRefinementStat stat;
    RigSetup setup;        // the rig it was gathered with
    int change_index = 0;  // its map's change index then
  };
  // A solved adjustment waiting to be applied.
  struct Solved {
    Job job;
    CalibrationBundleResult result;
    RigSetup next;  // the rig of the estimate (built outside the map lock)
    std::chrono::steady_clock::time_point start;
  };
  // Gathers kf's map when an adjustment is due; nullopt when none is.
  std::optional<Job> Gather(const KeyFramePtr& kf);
  void StartThread(Job job);
  // Solves `job`; nullopt when there is nothing to apply (the history says why).
  std::optional<Solved> Solve(Job job, const std::atomic<bool>* abort, WorkMeter* work);
  // Applies a solved adjustment unless the map or the rig was replaced meanwhile.
  void Apply(Solved solved);
  // Adds an adjustment's record with its note and its wall time since `start`.
  void Record(CalibrationRefinementStat stat, std::string note,
              std::chrono::steady_clock::time_point start);
  void Join();

  Atlas* atlas_;
  Sensor sensor_;
  OnlineCalibrationOptions options_;
  int solver_threads_;
  // Set before the first Step, read-only afterwards.
  RigCalibration prior_;
  RigShape shape_;
  CalibrationPacing pacing_;

  mutable Mutex mutex_;
  std::vector<CalibrationRefinementStat> history_ PKSLAM_GUARDED_BY(mutex_);
  // Set when an adjustment was not applied because the map moved meanwhile: the span at which
  // the next keyframe tries again.
  std::optional<double> retry_s_ PKSLAM_GUARDED_BY(mutex_);

  // The mapping thread's: the map the schedule follows and the span (s) at which its next
  // adjustment is due.
  const Map* map_ = nullptr;
  double due_s_ = 0;
  // The calibration thread, one adjustment at a time, started and joined by the mapping thread.
  // `running_` is true from its start until its job has ended; `abort_` interrupts its solve.
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::atomic<bool> abort_{false};
  // Paced: the thread only solves, counting on `work_`, and hands the result over through
  // `solved_`; the mapping thread applies it (ApplyDue).
  WorkMeter work_;
  std::future<std::optional<Solved>> solved_;
  bool pending_ = false;       // a paced job started, not yet applied or dropped
  std::int64_t start_ns_ = 0;  // the data time it started at
  WorkCounts work_start_{};    // work_ then
};

}  // namespace pkslam
