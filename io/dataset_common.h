// Types shared by the dataset readers: image lists with their missing files and time gaps,
// IMU samples, and lazy image loading that turns unreadable files into InputError.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "core/imu/imu_types.h"

namespace pkslam {

// One image of a sequence: its timestamp and the absolute path of its file.
struct ImageEntry {
  std::int64_t t_ns = 0;
  std::filesystem::path path;
};

// An interval between consecutive samples longer than the gap threshold.
struct TimeGap {
  std::int64_t begin_ns = 0;  // the sample before the gap
  std::int64_t end_ns = 0;    // the sample after the gap
  double periods = 0;         // (end - begin) / nominal period
};

// A list of images as the dataset describes it, after the up-front existence check.
struct ImageStream {
  std::string name;                            // "cam0", "cam1", "rgb", "depth"
  std::filesystem::path list_file;             // data.csv / rgb.txt the list came from
  double nominal_rate_hz = 0;                  // from the sensor description; 0 = unknown
  std::size_t listed = 0;                      // rows in the list file
  std::vector<ImageEntry> images;              // rows whose file exists, time-ordered
  std::vector<std::filesystem::path> missing;  // rows whose file does not exist
  std::vector<TimeGap> gaps;                   // between consecutive usable images
};

// One IMU reading, in the IMU sensor frame (the core type; readers and algorithms share it).
using ImuSample = ImuMeasurement;

// Gaps of a strictly increasing time series: intervals > max_periods * nominal period.
// nominal_period_ns <= 0 uses the median interval. Fewer than 2 samples: no gaps.
std::vector<TimeGap> FindTimeGaps(const std::vector<std::int64_t>& t_ns, double nominal_period_ns,
                                  double max_periods);

// The time base of a list against its sensor description: throws InputError naming `file` when
// the median interval between samples is more than 5x off the nominal period (nominal_rate_hz
// > 0; fewer than 3 samples are not checked). Stamps in microseconds where nanoseconds belong
// come out 1000x too fast, whole seconds read as nanoseconds 10^9x: the message says which unit
// the stamps look like. Without this check such data ran as "0.00 s of data".
// `rate_source` names where the nominal rate came from ("sensor.yaml", "Camera.fps").
void CheckTimeBase(const std::vector<std::int64_t>& t_ns, double nominal_rate_hz,
                   std::string_view rate_source, const std::filesystem::path& file,
                   std::string_view what);

// (n - 1) / (last - first) in Hz; 0 when fewer than 2 samples or zero span.
double MeasuredRateHz(std::int64_t first_ns, std::int64_t last_ns, std::size_t count);

// Splits `listed` into stream->images (file exists) and stream->missing, keeping order,
// and fills stream->gaps (intervals > frame_gap_periods nominal periods among usable images).
// Logs one warning with the count and the first few names when files are missing.
void FillImageStream(const std::vector<ImageEntry>& listed, double frame_gap_periods,
                     ImageStream* stream);

// Loads an image lazily. Throws InputError(path) if the file is missing or cannot be decoded.
cv::Mat LoadGreyImage(const std::filesystem::path& path);       // CV_8UC1
cv::Mat LoadColourImage(const std::filesystem::path& path);     // CV_8UC3, BGR
cv::Mat LoadUnchangedImage(const std::filesystem::path& path);  // as stored (e.g. CV_16UC1)

}  // namespace pkslam
