// CPU time of the calling thread and of the process, for speed statistics that do not depend
// on how busy a shared machine is (wall-clock milliseconds include time spent preempted or
// waiting on locks; CPU milliseconds do not); and the process's peak memory.
#pragma once

#include <pthread.h>
#include <sys/resource.h>
#include <time.h>

#include <optional>

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

// Milliseconds of CPU the whole process has used: stage timings of runs on a shared, loaded
// machine (wall-clock stage times would measure the other jobs; CPU time measures the work,
// counting the threads OpenCV parallelises a stage over).
inline double ProcessCpuMs() { return 1e3 * ProcessCpuSeconds(); }

// The calling thread's CPU clock, which other threads of the process may read with
// ClockSeconds (live emulation measures local mapping's work in its thread's CPU time, so a
// shared machine's load does not make the emulated machine slower); nullopt if unavailable.
inline std::optional<clockid_t> CallingThreadCpuClock() {
  clockid_t id{};
  if (pthread_getcpuclockid(pthread_self(), &id) != 0) return std::nullopt;
  return id;
}

// Seconds on `clock`; 0 if it cannot be read.
inline double ClockSeconds(clockid_t clock) {
  timespec ts{};
  if (clock_gettime(clock, &ts) != 0) return 0.0;
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Peak resident memory of this process in MiB (getrusage; ru_maxrss is in KiB on Linux).
inline double PeakMemoryMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

}  // namespace pkslam
