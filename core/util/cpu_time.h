// CPU time of the calling thread and of the process, for speed statistics that do not depend
// on how busy a shared machine is (wall-clock milliseconds include time spent preempted or
// waiting on locks; CPU milliseconds do not).
#pragma once

#include <time.h>

namespace pkslam {

// Seconds of CPU the calling thread has used (CLOCK_THREAD_CPUTIME_ID); 0 if unavailable.
inline double ThreadCpuSeconds() {
  timespec ts{};
  if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0.0;
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Seconds of CPU the whole process has used, all threads (CLOCK_PROCESS_CPUTIME_ID).
inline double ProcessCpuSeconds() {
  timespec ts{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return 0.0;
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace pkslam
