// Live emulation's data clock: where local mapping's work would fall in the data time of the
// frames if the run were live on the emulated machine (offline runs, LocalMapper::EmulateLive).
//
// A keyframe's processing (a "job") starts at its data stamp, or when the previous job ended if
// that was later, and spans its measured work times the playback pace. Tracking asks whether
// mapping is still busy at a frame's time (LocalMapper::AcceptsKeyFramesAt); on the work clock
// mapping also waits until tracking has reached the data time its work got to
// (LocalMapper::PaceToTracker), so each frame sees the map a live run would show it.
//
// LiveEmulation is the settings (fixed before the mapping thread starts, read without a lock).
// LiveTimeline is the state; it is not thread-safe: LocalMapper keeps it under its mutex.
#pragma once

#include <time.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>

#include "core/util/work_meter.h"

namespace pkslam {

// How live emulation measures local mapping's work on a keyframe.
enum class LiveClock {
  // Units of work priced by kReferenceWork (core/util/work_meter.h): the same emulated machine
  // on every machine, loaded or not, fast or slow.
  kWork,
  // The mapping thread's CPU time: this machine, however loaded it is.
  kCpu,
  // Wall time: this machine under its present load.
  kWall,
};
// "work", "cpu" or "wall"; nullopt for anything else.
std::optional<LiveClock> ParseLiveClock(std::string_view name);

// The work clock's prices: CPU seconds per unit of work of local mapping on the machine the
// defaults were tuned on (2 cores, 2026-11; fitted to per-keyframe CPU times by
// evaluation/studies/coupling/fit_work_model.py, docs/speed.md "One core or two").
extern const WorkModel kReferenceWork;

struct LiveEmulation {
  bool on = false;
  // Playback speed of the emulated live run (2: frames arrive twice as fast as their
  // timestamps say, so mapping's work spans twice as much data time).
  double pace = 1.0;
  LiveClock clock = LiveClock::kWork;

  // Paced emulation: the work clock, the only one that gives every machine the same result.
  bool paced() const { return on && clock == LiveClock::kWork; }
  // Data-clock nanoseconds spanned by `seconds` on the emulation clock.
  std::int64_t DataNs(double seconds) const {
    return static_cast<std::int64_t>(seconds * pace * 1e9);
  }
};

class LiveTimeline {
 public:
  // `work` (not owned, outlives the timeline) is read by the work clock, priced by `prices`.
  LiveTimeline(LiveEmulation settings, const WorkMeter* work,
               const WorkModel& prices = kReferenceWork);

  const LiveEmulation& settings() const { return settings_; }
  // The CPU clock to read (the mapping thread's own, set by that thread); without one the CPU
  // clock reads wall time.
  void SetCpuClock(std::optional<clockid_t> clock) { cpu_clock_ = clock; }
  // Seconds on the emulation clock: priced work, the CPU clock, or wall time.
  double ClockSeconds() const;

  // A keyframe stamped `keyframe_ns` is taken for processing.
  void StartJob(std::int64_t keyframe_ns);
  // The data time the current job's work has reached.
  std::int64_t ReachedNs() const;
  // The current job is done: the next one starts no earlier than where it reached.
  void EndJob() { free_ns_ = ReachedNs(); }
  // The queue was dropped (a reset): the next job starts at its own stamp.
  void Reset() { free_ns_ = std::numeric_limits<std::int64_t>::min(); }
  // True when the last job had ended by `t_ns`.
  bool FreeBy(std::int64_t t_ns) const { return free_ns_ <= t_ns; }

  // Tracking has processed every frame up to `t_ns` (the time only grows); true if it grew.
  bool AdvanceTracker(std::int64_t t_ns);
  // True while tracking has not reached `ns` yet.
  bool TrackerBefore(std::int64_t ns) const { return tracker_ns_ < ns; }
  // How long tracking, at `t_ns`, waits before asking again when the job has reached only
  // `reached_ns`: work is counted and its meter wakes the waiter, so only a short bound on a
  // missed wake-up; the CPU and wall clocks cannot run faster than real time, so the data time
  // still to go.
  double RecheckSeconds(std::int64_t t_ns, std::int64_t reached_ns) const;

 private:
  LiveEmulation settings_;
  const WorkMeter* work_;
  WorkModel prices_;
  std::optional<clockid_t> cpu_clock_;
  // Data time at which the last finished job ended.
  std::int64_t free_ns_ = std::numeric_limits<std::int64_t>::min();
  // The current job's data-clock start and emulation-clock start.
  std::int64_t job_start_ns_ = 0;
  double job_clock_start_ = 0;
  // The data time of the frame tracking processes (every earlier one done).
  std::int64_t tracker_ns_ = std::numeric_limits<std::int64_t>::min();
};

}  // namespace pkslam
