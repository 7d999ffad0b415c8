// What a run found wrong with its input without refusing it: frames it skipped, timestamp
// jumps, IMU gaps, frames tracked without IMU or depth. Each finding is logged as a warning
// and recorded, so that a degraded run says so in its summary line and in stats.json
// ("input" object, "degraded": true) instead of passing for a clean one.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "io/dataset_common.h"

namespace pkslam {

struct InputReport {
  int frames_skipped = 0;        // listed images not processed (no stereo partner / depth)
  int timestamp_jumps = 0;       // frame intervals beyond kJumpPeriods frame periods
  int imu_gaps = 0;              // IMU intervals beyond EurocOptions::imu_gap_periods
  int frames_without_imu = 0;    // inertial runs: frames whose interval holds no IMU sample
  int frames_without_depth = 0;  // RGB-D: depth images without one valid pixel
  std::vector<std::string> warnings;

  bool degraded() const { return !warnings.empty(); }
  // Logs `message` as a warning and records it.
  void Warn(std::string message);
};

// A frame interval longer than this many median frame periods is a timestamp jump.
inline constexpr double kJumpPeriods = 5.0;

struct TimestampJump {
  std::size_t frame = 0;   // the frame after the jump
  std::int64_t dt_ns = 0;  // its interval from the previous frame
};

// Frame intervals beyond `max_periods` median periods, in order.
std::vector<TimestampJump> FindTimestampJumps(const std::vector<std::int64_t>& frame_t_ns,
                                              double max_periods = kJumpPeriods);

// Frames an inertial run would track without IMU: frames i > 0 with no sample in
// (t[i-1], t[i] + lookahead]. `imu_t_ns` is sorted.
std::vector<std::size_t> FramesWithoutImu(const std::vector<std::int64_t>& frame_t_ns,
                                          const std::vector<std::int64_t>& imu_t_ns,
                                          std::int64_t lookahead_ns);

// "frames 3-7, 12, 40-41" for a sorted index list, at most `max_ranges` ranges then "...".
std::string FormatIndexRanges(const std::vector<std::size_t>& indices, std::size_t max_ranges = 5);

// FindTimestampJumps, reported to `report` in one warning naming `source`; returns the jumps.
std::vector<TimestampJump> ReportTimestampJumps(const std::vector<std::int64_t>& frame_t_ns,
                                                const std::string& source, InputReport* report);

// The IMU checks of an inertial run over frames `frame_t_ns`: at least two samples, units
// (CheckImuUnits), and every frame covered (FramesWithoutImu): throws InputError naming
// `imu_file`, or with `allow_gaps` records the uncovered frames as a warning.
void CheckImuForFrames(const std::vector<ImuSample>& imu, std::size_t imu_gaps,
                       const std::filesystem::path& imu_file,
                       const std::vector<std::int64_t>& frame_t_ns, std::int64_t lookahead_ns,
                       bool allow_gaps, InputReport* report);

// Throws InputError naming `file` when the samples look like another unit than rad/s and
// m/s^2: the median |accel| of a body in gravity is near 9.81 m/s^2 (near 1 when in g); a
// 90th percentile of |gyro| above 5 rad/s (290 deg/s) is a spin no MAV or hand-held
// recording keeps up (real EuRoC: 0.4-1.0 rad/s; deg/s data read as rad/s: 57 times more).
void CheckImuUnits(const std::vector<ImuSample>& samples, const std::filesystem::path& file);

}  // namespace pkslam
