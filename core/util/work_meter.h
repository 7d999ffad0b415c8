// Counts of the work a thread has done, by kind, as a clock that does not depend on the machine.
//
// Live emulation (mapping/local_mapper.h) needs to know how long local mapping's work on a
// keyframe would take on "the" machine. Measured in CPU seconds, that time halves on a machine
// twice as fast, and the offline result moved with it (issue 37: a monocular-inertial replay
// diverged on a slower machine where it tracked on this one). Counted in units of work
// (keyframes taken, triangulation searches, fused points, solver residual evaluations) and
// priced by a fixed model, the emulated time is the same on every machine for the same map.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>

namespace pkslam {

enum class WorkKind : std::size_t {
  kKeyFrame = 0,           // a keyframe taken for processing (the fixed part of its cost)
  kTriangulationPair = 1,  // keypoints of both keyframes of a triangulation search, summed
  kFuseProjection = 2,     // map points projected into a keyframe by a fusion
  kSolverResidual = 3,     // scalar residuals evaluated by a solver, per iteration
};
inline constexpr std::size_t kNumWorkKinds = 4;

using WorkCounts = std::array<std::int64_t, kNumWorkKinds>;

// Written by the thread that does the work (and by solver callbacks on it), read by others:
// every count is an atomic of its own, so a reader sees each count at some moment of the run;
// counts only grow.
// The pacer (optional, set before the work starts and never changed while it runs) is what
// Pace() calls: the working thread calls Pace() where it holds no lock (solver callbacks after
// each iteration), so live emulation can hold local mapping back to tracking's data time.
class WorkMeter {
 public:
  void SetPacer(std::function<void()> pacer) { pacer_ = std::move(pacer); }
  void Pace() const {
    if (pacer_) pacer_();
  }
  void Add(WorkKind kind, std::int64_t units) {
    counts_[static_cast<std::size_t>(kind)].fetch_add(units, std::memory_order_relaxed);
  }
  WorkCounts Snapshot() const {
    WorkCounts out{};
    for (std::size_t k = 0; k < kNumWorkKinds; ++k) {
      out[k] = counts_[k].load(std::memory_order_relaxed);
    }
    return out;
  }

 private:
  std::array<std::atomic<std::int64_t>, kNumWorkKinds> counts_{};
  std::function<void()> pacer_;
};

// Seconds a reference machine spends on each unit of work of each kind (a linear model, fitted
// to measured CPU time; the fit and its machine are documented where the model is used).
struct WorkModel {
  std::array<double, kNumWorkKinds> seconds_per_unit{};

  double Seconds(const WorkCounts& counts) const {
    double s = 0;
    for (std::size_t k = 0; k < kNumWorkKinds; ++k) {
      s += seconds_per_unit[k] * static_cast<double>(counts[k]);
    }
    return s;
  }
};

inline WorkCounts operator-(const WorkCounts& a, const WorkCounts& b) {
  WorkCounts out{};
  for (std::size_t k = 0; k < kNumWorkKinds; ++k) out[k] = a[k] - b[k];
  return out;
}

}  // namespace pkslam
