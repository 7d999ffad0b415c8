// Progress line for long work (simulation, runs, sweeps, training, fusion).
// Prints "label  [#####.....]  42% 123/290  12.3/s  ETA 0:14" to stderr, redrawn in place
// when stderr is a terminal and as plain lines otherwise (logs stay readable): one per 5% step,
// and for slow work (a bench's runs take minutes) also one per finished item once a minute has
// passed since the last line, so a log of a study never goes quiet for long.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace pkslam {

namespace progress_detail {
// Plain (non-terminal) output: is a line due for an item finished now?
bool PlainLineDue(int percent, int last_percent_printed, double seconds_since_last_line);
// "12.3/s" for fast work, "2:05 each" when an item takes more than ten seconds.
std::string FormatRate(double items_per_second);
}  // namespace progress_detail

class Progress {
 public:
  // total == 0 means unknown (shows count and rate only). quiet disables all output.
  Progress(std::string label, std::size_t total, bool quiet = false);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Advance by n and redraw if due. Not thread-safe: call from one thread.
  void Add(std::size_t n = 1);
  // Set an extra text shown after the bar (e.g. "ATE 0.012 m").
  void SetSuffix(std::string suffix);
  // Final redraw and newline (idempotent; the destructor calls it).
  void Finish();

  std::size_t done() const { return done_; }

 private:
  void Draw(bool force);

  std::string label_;
  std::string suffix_;
  std::size_t total_ = 0;
  std::size_t done_ = 0;
  bool quiet_ = false;
  bool tty_ = false;
  bool finished_ = false;
  int last_percent_printed_ = -1;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace pkslam
