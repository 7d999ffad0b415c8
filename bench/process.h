// Child processes and inter-process locks for the benchmark harness (POSIX).
#pragma once

#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

namespace pkslam::bench {

struct ProcessResult {
  int exit_code = -1;  // exit status, or -1 when killed by a signal
  int signal = 0;      // the terminating signal, if any
  bool timed_out = false;
  double wall_s = 0.0;
  bool ok() const { return exit_code == 0 && !timed_out; }
  std::string Describe() const;  // "exit 1", "killed by signal 9", "timed out after 12.0 s"
};

// Runs argv[0] (a path) with stdout and stderr appended to `log`. Kills the child (SIGTERM,
// then SIGKILL after 5 s) when it outlives timeout_s or when `cancel` becomes true. Throws
// Error when the program cannot be started.
ProcessResult RunProcess(const std::vector<std::string>& argv, const std::filesystem::path& log,
                         double timeout_s, const std::atomic<bool>* cancel = nullptr);

// Shell-quotes one argument ('...' when needed) and a whole command line.
std::string ShellQuote(const std::string& arg);
std::string ShellCommand(const std::vector<std::string>& argv);

// An exclusive advisory lock (flock) on a file, held for the object's lifetime; blocks until
// acquired. Serialises work between processes (parallel jobs rendering one simulator recipe).
class FileLock {
 public:
  explicit FileLock(const std::filesystem::path& file);
  ~FileLock();
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace pkslam::bench
