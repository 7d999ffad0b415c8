// Trajectory files: reading (with format auto-detection), writing, and simple measures.
//
// Formats (one pose per line, '#' lines are comments, blank lines are ignored):
//   tum       `t x y z qx qy qz qw`, t in seconds (decimal), fields separated by spaces, tabs or
//             commas. The TUM RGB-D benchmark and evo format.
//   euroc     `t,x,y,z,qw,qx,qy,qz[,vx,vy,vz,bwx,bwy,bwz,bax,bay,baz]`, comma separated, t in
//             integer nanoseconds, quaternion w first; the 17-column form is EuRoC's
//             state_groundtruth_estimate0/data.csv (velocity in the world frame, gyro bias
//             rad/s, accelerometer bias m/s^2).
//   orbslam3  ORB-SLAM3's f_*.txt / kf_*.txt: TUM column order but t in nanoseconds (ORB-SLAM3
//             prints them as e.g. `1403715274302142976.000000`).
// Auto-detection looks at the first data line (and the comments before it): a header naming
// EuRoC's columns (p_RS_R_x, q_RS_w) or 17 columns means euroc; otherwise 8 columns with a
// timestamp >= 1e12 means nanoseconds (euroc when comma separated, orbslam3 otherwise) and a
// smaller timestamp means tum (seconds). Nanosecond files whose clock starts near zero are
// therefore read as seconds: pass the format explicitly for those.
//
// Timestamps are converted from their decimal text to int64 nanoseconds exactly (no detour
// through double): "1403715524.907143" -> 1403715524907143000. Digits beyond the nanosecond
// are rounded half away from zero.
//
// Poses are world_from_<sensor> (the sensor is whatever the file describes: the IMU body for
// EuRoC ground truth, the camera for TUM RGB-D ground truth and visual-only estimates).
// Quaternions are normalised on read; a warning is logged when any was far from unit norm.
//
// Errors: pkslam::InputError naming the file and line for a missing or empty file, a line that
// is not numbers or has the wrong number of columns, a NaN/inf value, a zero quaternion,
// a timestamp earlier than the one before it (the line that breaks the order) and a format
// that cannot be detected. A timestamp equal to the previous one is an error too with
// DuplicateTimestamps::kError; by default (kKeepFirst) the later line is dropped with a warning,
// because real ground truth has them (TUM fr2_desk repeats 1311868229.5760 with two different
// poses) and evo, whose nearest-time search takes the first of equal stamps, evaluates such
// files as if the later line were absent.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

#include "core/geometry/se3.h"

namespace pkslam {

struct StampedPose {
  std::int64_t t_ns = 0;
  SE3d pose;  // world_from_sensor
};

// Per-pose extras carried by EuRoC ground truth (state_groundtruth_estimate0).
struct GroundTruthExtras {
  Eigen::Vector3d velocity_world = Eigen::Vector3d::Zero();  // m/s, in the world frame
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();       // rad/s
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();      // m/s^2
};

struct Trajectory {
  std::vector<StampedPose> poses;  // strictly increasing t_ns
  // Empty, or exactly one entry per pose (only EuRoC 17-column files fill it).
  std::vector<GroundTruthExtras> extras;
  // The file the trajectory was read from (for messages); empty when built in memory.
  std::filesystem::path source;

  std::size_t size() const { return poses.size(); }
  bool empty() const { return poses.empty(); }
  bool has_extras() const { return !extras.empty() && extras.size() == poses.size(); }
  std::vector<std::int64_t> Timestamps() const;
};

enum class TrajectoryFormat { kAuto, kTum, kEuroc, kOrbSlam3 };

// "auto", "tum", "euroc", "orbslam3" (case-sensitive); throws OptionError otherwise.
TrajectoryFormat ParseTrajectoryFormat(std::string_view name);
std::string_view TrajectoryFormatName(TrajectoryFormat format);

// The format of an existing file, by the rules above. Throws InputError when the file is
// missing, has no data line, or matches no format.
TrajectoryFormat DetectTrajectoryFormat(const std::filesystem::path& file);

// What to do with a line whose timestamp equals the previous line's.
enum class DuplicateTimestamps {
  kKeepFirst,  // drop the later line, warn once per file with the count and the first line
  kKeepAll,    // keep every line (stamps then only non-decreasing), warn once likewise: evo
               // evaluates each pose of an estimate, repeated stamps included
  kError,      // throw InputError naming the line
};

// Reads a trajectory; kAuto detects the format. Throws InputError (see above).
Trajectory ReadTrajectory(const std::filesystem::path& file,
                          TrajectoryFormat format = TrajectoryFormat::kAuto,
                          DuplicateTimestamps duplicates = DuplicateTimestamps::kKeepFirst);

// A dataset folder's ground truth: EuRoC's mav0/state_groundtruth_estimate0/data.csv, TUM-VI's
// mav0/mocap0/data.csv or TUM RGB-D's groundtruth.txt (nullopt when it has none).
std::optional<std::filesystem::path> FindDatasetGroundTruth(const std::filesystem::path& dataset);

// Writers (kAuto is not allowed). tum: seconds with exactly 9 decimals, so nanosecond
// timestamps survive a write/read round trip; positions and quaternions with 9 decimals.
// euroc: integer nanoseconds, 17 columns when the trajectory has extras, 8 otherwise.
// orbslam3: integer nanoseconds in TUM column order. Written atomically (core/util/
// output_file.h); throw OutputError naming the file when it cannot be written.
void WriteTrajectory(const Trajectory& trajectory, const std::filesystem::path& file,
                     TrajectoryFormat format);
void WriteTrajectoryTum(const Trajectory& trajectory, const std::filesystem::path& file);
// One pose line of the tum format (with its newline), and the header line the writer puts
// first; for writers that append pose by pose.
std::string FormatTumLine(const StampedPose& pose);
inline constexpr const char* kTumHeader = "# timestamp[s] tx ty tz qx qy qz qw\n";
void WriteTrajectoryEuroc(const Trajectory& trajectory, const std::filesystem::path& file);

// Sum of distances between consecutive positions (m).
double PathLengthMeters(const Trajectory& trajectory);
// Time from the first to the last pose (s); 0 for fewer than two poses.
double DurationSeconds(const Trajectory& trajectory);

// Exact decimal-to-integer conversion: the number in `text` (optional sign, digits with an
// optional '.', optional exponent e/E) times 10^decimal_shift, rounded half away from zero.
// decimal_shift = 9 turns seconds into nanoseconds, 0 reads nanoseconds. nullopt when `text`
// is not such a number or the result does not fit in int64.
std::optional<std::int64_t> ParseDecimalAsInt64(std::string_view text, int decimal_shift);

}  // namespace pkslam
