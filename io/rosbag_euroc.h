// ROS 1 bags <-> EuRoC ASL folders (`pkslam convert`, `pkslam run --bag`).
//
// Streams and the topics they have in the EuRoC and TUM-VI bags (BagTopics' defaults):
//   cam0, cam1  sensor_msgs/Image                /cam0/image_raw, /cam1/image_raw
//   imu0        sensor_msgs/Imu                  /imu0
//   vicon0      geometry_msgs/TransformStamped   /vicon/firefly_sbx/firefly_sbx (EuRoC V1, V2)
//   leica0      geometry_msgs/PointStamped       /leica/position (EuRoC machine hall)
//   mocap0      geometry_msgs/TransformStamped   /vrpn_client/raw_transform (TUM-VI)
// In the folder: mav0/<stream>/data.csv, cameras with data/<t_ns>.png (8-bit grey), the IMU as
// EuRoC's imu0 rows, the ground-truth streams as the raw vicon0 / leica0 (and TUM-VI's mocap0)
// rows of the ASL download: t_ns, p (3)[, q (w, x, y, z)]. EuRoC's
// state_groundtruth_estimate0 (a post-processed estimate with velocities and biases) has no
// bag topic and is neither read nor written. Times are the messages' header.stamp, exact to the
// nanosecond; values are written with every digit a double needs, so folder -> bag -> folder
// gives back the same images, values and times. A bag carries no calibration: sensor.yaml files
// come from a settings file (rosbag_euroc_sensors.h).
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>

#include "io/rosbag_reader.h"
#include "io/rosbag_writer.h"

namespace pkslam {

struct BagTopics {
  std::string cam0 = "/cam0/image_raw";
  std::string cam1 = "/cam1/image_raw";
  std::string imu = "/imu0";
  std::string vicon = "/vicon/firefly_sbx/firefly_sbx";
  std::string leica = "/leica/position";
  std::string mocap = "/vrpn_client/raw_transform";

  // Throws OptionError unless every topic is non-empty and starts with '/', and no two
  // streams share a topic.
  void Check() const;
};

// BagTopics with the overrides of `spec`, "cam0=/left,imu=/imu" (names: cam0, cam1, imu,
// vicon, leica, mocap; empty spec: the defaults). OptionError naming the bad item.
BagTopics ParseBagTopics(std::string_view spec);

struct BagToEurocOptions {
  BagTopics topics;
  // Streams that must be in the bag (cam0 always must): a stereo run needs cam1, an inertial
  // one the IMU. Missing ones are an InputError listing the bag's topics.
  bool require_cam1 = false;
  bool require_imu = false;
  // Streams written when the bag has them (a run converts only what its sensor reads).
  bool write_cam1 = true;
  bool write_imu = true;
  bool write_ground_truth = true;
  // Image files: "png" (EuRoC's), or "pgm" (uncompressed: nothing to encode or decode, about
  // 1.5x the bytes; what `run --bag` writes into its temporary folder).
  std::string image_format = "png";
  // PNG compression level, 0-9 (the decoded pixels are the same at every level).
  int png_compression = 3;
  // No progress line.
  bool quiet = false;
  BagReaderOptions reader;

  void Check() const;
};

struct EurocToBagOptions {
  BagTopics topics;
  BagWriterOptions writer;
  bool quiet = false;

  void Check() const;
};

// Rows written per stream ("cam0", "imu0", ...).
using StreamCounts = std::map<std::string, std::size_t>;

// Writes the bag's streams as the EuRoC folder OUT/mav0/... . OUT must be absent, empty or a
// folder pkslam made (it is cleared first; after an error it is removed). InputError (bag, byte
// offset) for a bad bag, a missing required topic, a topic of the wrong type, an unsupported image
// encoding, or two messages of one stream with the same stamp; OutputError when a file cannot be
// written.
StreamCounts ConvertBagToEuroc(const std::filesystem::path& bag, const std::filesystem::path& out,
                               const BagToEurocOptions& options);

// Writes the EuRoC folder `folder` (the sequence directory or its mav0/) as the bag `bag`:
// cam0 (required), cam1, imu0, vicon0, leica0, mocap0 when present, messages in time order.
// Image rows whose file is missing are skipped with a warning (as a run does).
StreamCounts ConvertEurocToBag(const std::filesystem::path& folder,
                               const std::filesystem::path& bag, const EurocToBagOptions& options);

}  // namespace pkslam
