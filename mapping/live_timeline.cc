#include "mapping/live_timeline.h"

#include <algorithm>
#include <chrono>

#include "core/util/cpu_time.h"

namespace pkslam {

// Fitted by evaluation/studies/coupling/fit_work_model.py to 1568 keyframes of six runs
// (60 s realistic replays of V1_02, V1_03 and V2_02, mono-inertial and stereo-inertial, CPU
// clock, 2 cores; 2026-11-28): a keyframe 0.66 ms, a fused projection 0.14 us, a scalar solver
// residual per iteration 0.29 us; triangulation keypoints got no weight of their own (they
// grow with the keyframe count). Totals per run: 0.96-1.02x the measured CPU seconds
// mono-inertial, 0.83-0.88x stereo-inertial; median error per keyframe 9-15%.
const WorkModel kReferenceWork{{6.593e-4, 0.0, 1.351e-7, 2.854e-7}};

std::optional<LiveClock> ParseLiveClock(std::string_view name) {
  if (name == "work") return LiveClock::kWork;
  if (name == "cpu") return LiveClock::kCpu;
  if (name == "wall") return LiveClock::kWall;
  return std::nullopt;
}

LiveTimeline::LiveTimeline(LiveEmulation settings, const WorkMeter* work, const WorkModel& prices)
    : settings_(settings), work_(work), prices_(prices) {}

double LiveTimeline::ClockSeconds() const {
  if (settings_.clock == LiveClock::kWork) return prices_.Seconds(work_->Snapshot());
  if (settings_.clock == LiveClock::kCpu && cpu_clock_) return pkslam::ClockSeconds(*cpu_clock_);
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void LiveTimeline::StartJob(std::int64_t keyframe_ns) {
  job_start_ns_ = std::max(keyframe_ns, free_ns_);
  job_clock_start_ = ClockSeconds();
}

std::int64_t LiveTimeline::ReachedNs() const {
  return job_start_ns_ + settings_.DataNs(ClockSeconds() - job_clock_start_);
}

bool LiveTimeline::AdvanceTracker(std::int64_t t_ns) {
  if (t_ns <= tracker_ns_) return false;
  tracker_ns_ = t_ns;
  return true;
}

double LiveTimeline::RecheckSeconds(std::int64_t t_ns, std::int64_t reached_ns) const {
  if (settings_.clock == LiveClock::kWork) return 0.002;
  return static_cast<double>(t_ns - reached_ns) * 1e-9 / settings_.pace;
}

}  // namespace pkslam
