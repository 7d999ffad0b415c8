#include "system/input_report.h"

#include <algorithm>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/quantile.h"

namespace pkslam {

void InputReport::Warn(std::string message) {
  PKSLAM_LOG_WARN("{}", message);
  warnings.push_back(std::move(message));
}

std::vector<TimestampJump> FindTimestampJumps(const std::vector<std::int64_t>& frame_t_ns,
                                              double max_periods) {
  std::vector<TimestampJump> jumps;
  if (frame_t_ns.size() < 2) return jumps;
  std::vector<double> dt;
  dt.reserve(frame_t_ns.size() - 1);
  for (std::size_t i = 1; i < frame_t_ns.size(); ++i) {
    dt.push_back(static_cast<double>(frame_t_ns[i] - frame_t_ns[i - 1]));
  }
  const double period = Quantile(dt, 0.5).value_or(0.0);
  for (std::size_t i = 1; i < frame_t_ns.size(); ++i) {
    const std::int64_t d = frame_t_ns[i] - frame_t_ns[i - 1];
    if (d <= 0 || (period > 0 && static_cast<double>(d) > max_periods * period)) {
      jumps.push_back({i, d});
    }
  }
  return jumps;
}

std::vector<std::size_t> FramesWithoutImu(const std::vector<std::int64_t>& frame_t_ns,
                                          const std::vector<std::int64_t>& imu_t_ns,
                                          std::int64_t lookahead_ns) {
  std::vector<std::size_t> frames;
  // The first frame integrates nothing; frame i > 0 needs the first sample after frame i-1 to
  // come no later than the lookahead past frame i.
  for (std::size_t i = 1; i < frame_t_ns.size(); ++i) {
    const auto it = std::upper_bound(imu_t_ns.begin(), imu_t_ns.end(), frame_t_ns[i - 1]);
    if (it == imu_t_ns.end() || *it > frame_t_ns[i] + lookahead_ns) frames.push_back(i);
  }
  return frames;
}

std::string FormatIndexRanges(const std::vector<std::size_t>& indices, std::size_t max_ranges) {
  std::string out;
  std::size_t ranges = 0;
  for (std::size_t i = 0; i < indices.size();) {
    std::size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    if (ranges == max_ranges) {
      out += ", ...";
      break;
    }
    if (!out.empty()) out += ", ";
    out += i == j ? fmt::format("{}", indices[i]) : fmt::format("{}-{}", indices[i], indices[j]);
    ++ranges;
    i = j + 1;
  }
  return out;
}

void CheckImuUnits(const std::vector<ImuSample>& samples, const std::filesystem::path& file) {
  if (samples.empty()) return;
  std::vector<double> accel;
  std::vector<double> gyro;
  accel.reserve(samples.size());
  gyro.reserve(samples.size());
  for (const ImuSample& s : samples) {
    accel.push_back(s.accel.norm());
    gyro.push_back(s.gyro.norm());
  }
  const double a = *Quantile(accel, 0.5);
  const double w = *Quantile(gyro, 0.9);
  constexpr double kGravity = 9.81;
  if (a < 0.5 * kGravity || a > 2.0 * kGravity) {
    const bool in_g = a > 0.5 && a < 2.0;
    throw InputError(file, fmt::format("median |accelerometer| is {:.3g}, not near gravity "
                                       "(9.81 m/s^2){}",
                                       a,
                                       in_g ? ": the data look like g, multiply by 9.81"
                                            : ": expected m/s^2 including gravity"));
  }
  if (w > 5.0) {
    throw InputError(file, fmt::format("|gyro| is above {:.3g} rad/s in 10% of the samples, a "
                                       "spin of {:.0f} deg/s: the data look like deg/s, "
                                       "expected rad/s",
                                       w, w * 180.0 / 3.141592653589793));
  }
}

std::vector<TimestampJump> ReportTimestampJumps(const std::vector<std::int64_t>& frame_t_ns,
                                                const std::string& source, InputReport* report) {
  std::vector<TimestampJump> jumps = FindTimestampJumps(frame_t_ns);
  report->timestamp_jumps = static_cast<int>(jumps.size());
  if (jumps.empty()) return jumps;
  constexpr std::size_t kListed = 5;
  std::string list;
  for (std::size_t i = 0; i < std::min(jumps.size(), kListed); ++i) {
    const TimestampJump& j = jumps[i];
    list += fmt::format("{}{:.3f} s after frame {} (t = {} ns)", i ? ", " : "",
                        1e-9 * static_cast<double>(j.dt_ns), j.frame - 1, frame_t_ns[j.frame - 1]);
  }
  report->Warn(fmt::format("{}: {} timestamp jump(s) beyond {} frame periods: {}{}", source,
                           jumps.size(), kJumpPeriods, list,
                           jumps.size() > kListed ? ", ..." : ""));
  return jumps;
}

void CheckImuForFrames(const std::vector<ImuSample>& imu, std::size_t imu_gaps,
                       const std::filesystem::path& imu_file,
                       const std::vector<std::int64_t>& frame_t_ns, std::int64_t lookahead_ns,
                       bool allow_gaps, InputReport* report) {
  if (imu.size() < 2) {
    throw InputError(imu_file,
                     "a single IMU sample: an inertial run needs IMU data over its frames");
  }
  CheckImuUnits(imu, imu_file);
  report->imu_gaps = static_cast<int>(imu_gaps);
  std::vector<std::int64_t> imu_t_ns;
  imu_t_ns.reserve(imu.size());
  for (const ImuSample& s : imu) imu_t_ns.push_back(s.t_ns);
  // An "inertial" run over frames the IMU does not cover is silently visual-only there.
  const std::vector<std::size_t> uncovered = FramesWithoutImu(frame_t_ns, imu_t_ns, lookahead_ns);
  report->frames_without_imu = static_cast<int>(uncovered.size());
  if (uncovered.empty()) return;
  const std::int64_t t0 = frame_t_ns.front();
  const std::string what = fmt::format(
      "{} of {} frames have no IMU sample since the previous frame (frames {}; the IMU covers "
      "{:.3f}..{:.3f} s of frames spanning 0..{:.3f} s)",
      uncovered.size(), frame_t_ns.size(), FormatIndexRanges(uncovered),
      1e-9 * static_cast<double>(imu.front().t_ns - t0),
      1e-9 * static_cast<double>(imu.back().t_ns - t0),
      1e-9 * static_cast<double>(frame_t_ns.back() - t0));
  if (!allow_gaps) {
    throw InputError(imu_file, what +
                                   ": an inertial run would track them without IMU; "
                                   "--allow-imu-gaps runs anyway");
  }
  report->Warn(fmt::format("{}: {}: tracked without IMU", imu_file.string(), what));
}

}  // namespace pkslam
