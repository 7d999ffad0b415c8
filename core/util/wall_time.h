// Wall-clock milliseconds for the timings runs report (stats.json, logs). CPU time, which a
// shared machine's load does not inflate, is core/util/cpu_time.h.
#pragma once

#include <chrono>

namespace pkslam {

// Milliseconds of the steady clock since `start`.
inline double WallMsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace pkslam
