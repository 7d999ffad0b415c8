// What `pkslam info DATASET` reports: layout detection (EuRoC ASL or TUM RGB-D), and per
// stream (cameras, depth, IMU, ground truth) counts, nominal and measured rates, time span,
// gaps and missing files; as readable text or JSON.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "io/dataset_common.h"

namespace pkslam {

enum class DatasetLayout { kEuroc, kTumRgbd };

// Throws InputError(dir) when dir is missing or has neither layout.
DatasetLayout DetectDatasetLayout(const std::filesystem::path& dir);
std::string DatasetLayoutName(DatasetLayout layout);  // "EuRoC ASL" / "TUM RGB-D"

struct StreamSummary {
  std::string name;             // cam0, cam1, imu0, groundtruth, rgb, depth
  std::string description;      // sensor details, e.g. "camera 752x480 pinhole radial-tangential"
  std::size_t listed = 0;       // rows in the list file
  std::size_t count = 0;        // usable samples (listed minus missing files)
  double nominal_rate_hz = 0;   // 0 = unknown
  double measured_rate_hz = 0;  // (count - 1) / span
  std::int64_t first_ns = 0;
  std::int64_t last_ns = 0;
  double gap_threshold_periods = 0;  // what counted as a gap
  std::vector<TimeGap> gaps;
  std::vector<std::string> missing_files;  // listed files that do not exist (relative paths)

  double SpanS() const { return static_cast<double>(last_ns - first_ns) * 1e-9; }
};

struct DatasetInfo {
  std::filesystem::path root;
  DatasetLayout layout = DatasetLayout::kEuroc;
  std::vector<StreamSummary> streams;       // cameras first, then IMU, then ground truth
  std::optional<std::size_t> stereo_pairs;  // EuRoC with cam1: exact timestamp matches
  std::optional<double> stereo_baseline_m;  // EuRoC with cam1: |T_BS1^-1 T_BS0| translation
  std::optional<std::size_t> rgbd_pairs;    // TUM: associated rgb/depth pairs
  double association_max_difference_s = 0;  // TUM association tolerance
  std::optional<double> depth_factor;       // TUM depth value per metre
  bool has_ground_truth = false;

  const StreamSummary* Find(const std::string& name) const;
  // Span of the first image stream (cam0 / rgb): the length of the sequence a run sees.
  double ImageDurationS() const;
  // From the earliest to the latest sample of any stream (IMU and ground truth included).
  double TotalDurationS() const;
};

// Reads the dataset (lists, IMU, ground truth; not the images) and summarises it.
// Throws InputError for bad input, like the readers.
DatasetInfo ComputeDatasetInfo(const std::filesystem::path& dir);

std::string FormatDatasetInfo(const DatasetInfo& info);  // multi-line, human readable
std::string DatasetInfoToJson(const DatasetInfo& info);  // one JSON object

// 29120 -> "29,120".
std::string GroupThousands(std::size_t n);

}  // namespace pkslam
