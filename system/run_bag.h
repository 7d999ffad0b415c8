// `pkslam run --bag FILE`: SLAM over a ROS 1 bag (io/rosbag_reader.h), the run of the EuRoC
// folder `pkslam convert --bag FILE` makes. Needs --settings (a bag holds no calibration).
#pragma once

#include <filesystem>

#include "io/rosbag_euroc.h"
#include "system/run_dataset.h"

namespace pkslam {

// The streams the sensor reads (cam0, cam1 for stereo, the IMU for inertial sensors) are
// converted into a temporary EuRoC folder OUT/<bag name>.euroc.tmp, with sensor.yaml files from
// options.settings, and RunDataset runs on it; the folder is removed afterwards (also after an
// error; a process killed while converting leaves it, and the next run into OUT clears it).
// options.dataset is ignored (stats.json's "dataset" names the temporary folder). InputError
// for a bad bag or missing topics, OptionError without --settings or for an RGB-D sensor.
RunSummary RunBag(const RunOptions& options, const std::filesystem::path& bag,
                  const BagTopics& topics, const RunControl& control = {});

}  // namespace pkslam
