#include "core/util/progress.h"

#include <unistd.h>

#include <cstdio>

#include <fmt/format.h>

namespace pkslam {
namespace {

std::string FormatDuration(double seconds) {
  if (seconds < 0 || seconds > 1e7) return "--:--";
  const auto s = static_cast<long>(seconds + 0.5);
  if (s >= 3600) return fmt::format("{}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60);
  return fmt::format("{}:{:02}", s / 60, s % 60);
}

}  // namespace

namespace progress_detail {

bool PlainLineDue(int percent, int last_percent_printed, double seconds_since_last_line) {
  if (percent < 0) return false;  // unknown total: only forced lines
  if (percent / 5 != last_percent_printed / 5) return true;
  // Slow items: a line per item after a quiet minute (an ETA an hour out is worth updating).
  constexpr double kQuietSeconds = 60.0;
  return seconds_since_last_line >= kQuietSeconds;
}

std::string FormatRate(double items_per_second) {
  if (items_per_second > 0 && items_per_second < 0.1) {
    return FormatDuration(1.0 / items_per_second) + " each";
  }
  return fmt::format("{:.1f}/s", items_per_second);
}

}  // namespace progress_detail

Progress::Progress(std::string label, std::size_t total, bool quiet)
    : label_(std::move(label)),
      total_(total),
      quiet_(quiet),
      tty_(isatty(fileno(stderr)) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() { Finish(); }

void Progress::Add(std::size_t n) {
  done_ += n;
  Draw(false);
}

void Progress::SetSuffix(std::string suffix) { suffix_ = std::move(suffix); }

void Progress::Finish() {
  if (finished_) return;
  Draw(true);
  finished_ = true;
  if (!quiet_ && tty_) std::fputc('\n', stderr);
}

void Progress::Draw(bool force) {
  if (quiet_ || finished_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed > 0 ? static_cast<double>(done_) / elapsed : 0.0;
  const int percent =
      total_ > 0 ? static_cast<int>(100.0 * static_cast<double>(done_) / static_cast<double>(total_))
                 : -1;
  if (tty_) {
    if (!force && now - last_draw_ < std::chrono::milliseconds(100)) return;
  } else {
    // Plain logs: see progress_detail::PlainLineDue (and forced lines, e.g. the last one).
    const double quiet_s = std::chrono::duration<double>(now - last_draw_).count();
    if (!force && !progress_detail::PlainLineDue(percent, last_percent_printed_, quiet_s)) return;
  }
  last_draw_ = now;
  last_percent_printed_ = percent;
  std::string line;
  if (total_ > 0) {
    constexpr int kWidth = 30;
    const int filled = std::min(kWidth, percent * kWidth / 100);
    const double eta = rate > 0 ? static_cast<double>(total_ - std::min(done_, total_)) / rate : -1;
    line = fmt::format("{} [{}{}] {:3}% {}/{} {} ETA {}", label_, std::string(filled, '#'),
                       std::string(kWidth - filled, '.'), percent, done_, total_,
                       progress_detail::FormatRate(rate), FormatDuration(eta));
  } else {
    line = fmt::format("{} {} done {} elapsed {}", label_, done_, progress_detail::FormatRate(rate),
                       FormatDuration(elapsed));
  }
  if (!suffix_.empty()) line += "  " + suffix_;
  if (tty_) {
    std::fprintf(stderr, "\r\033[K%s", line.c_str());
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
  std::fflush(stderr);
}

}  // namespace pkslam
