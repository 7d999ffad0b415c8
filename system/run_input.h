// What a run reads, opened once: the dataset's reader (EuRoC ASL, a KITTI odometry sequence as
// EuRoC image streams, or TUM RGB-D), the frames to process (--first-frame, --max-frames
// applied), the settings, and each frame's images as the tracker takes them. Opening checks
// what the sensor needs (an IMU, cam1, depth) and names the file when it is missing, so
// RunDataset (run_dataset.h) starts its frame loop on a dataset that can feed it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/sensor/sensor.h"
#include "io/euroc_dataset.h"
#include "io/settings.h"
#include "io/tum_rgbd_dataset.h"
#include "system/input_report.h"

namespace pkslam {

struct RunOptions;

// One input frame, however the dataset stores it.
struct DatasetFrame {
  std::int64_t t_ns = 0;
  std::size_t a = 0;  // left / rgb index
  std::size_t b = 0;  // right / depth index
};

// A frame's images, decoded.
struct LoadedImages {
  cv::Mat a;              // left / rgb
  cv::Mat b;              // right / depth (empty for monocular)
  bool no_depth = false;  // RGB-D: not one valid depth pixel (counted off the tracking thread)
};

struct RunInput {
  Sensor sensor = Sensor::kMonocular;
  std::optional<EurocDataset> euroc;  // EuRoC, or a KITTI sequence read as one
  std::optional<TumRgbdDataset> tum;
  std::vector<DatasetFrame> frames;  // in order, --first-frame and --max-frames applied
  Settings settings;

  std::vector<std::int64_t> FrameTimes() const;
  // Decodes frame k's images (both of a pair at once) and checks their size against the
  // calibration; throws InputError naming the image otherwise.
  LoadedImages Load(std::size_t k) const;
};

// Opens options.dataset for options.system.sensor; warnings (skipped frames) go to `report`.
// Throws InputError / OptionError naming what is missing or wrong.
RunInput OpenRunInput(const RunOptions& options, InputReport* report);

}  // namespace pkslam
