// Stage timing for the RGB-D pipelines: CPU time of the process (all its threads), in ms.
// The machines these runs share are loaded, so wall-clock stage times would measure the other
// jobs; CPU time measures the work (on an idle machine the single-threaded stages take the
// same wall time; stages OpenCV parallelises internally count the work of all its threads).
#pragma once

#include <ctime>

namespace pkslam::rgbd {

inline double ProcessCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

}  // namespace pkslam::rgbd
