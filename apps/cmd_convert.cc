// pkslam convert: ROS 1 bags <-> EuRoC folders (io/rosbag_euroc.h, docs/bags.md).
//   convert --bag FILE --out DIR [--topics ...] [--sensor S] [--settings FILE]
//   convert --folder DIR --out FILE.bag [--compression none|bz2|lz4] [--topics ...]
#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "apps/cli_errors.h"
#include "apps/commands.h"
#include "core/sensor/sensor.h"
#include "core/util/error.h"
#include "core/util/output_guard.h"
#include "io/rosbag_euroc.h"
#include "io/rosbag_euroc_sensors.h"
#include "io/settings.h"

namespace pkslam::apps {
namespace {

struct ConvertArgs {
  std::string bag;
  std::string folder;
  std::string out;
  std::string topics;
  std::optional<std::string> sensor;
  std::string settings;
  std::string compression = "none";
  bool quiet = false;
};

std::string Counts(const StreamCounts& counts) {
  std::string out;
  for (const auto& [stream, n] : counts)
    out += fmt::format("{}{} {}", out.empty() ? "" : ", ", stream, n);
  return out;
}

void BagToFolder(const ConvertArgs& args) {
  BagToEurocOptions options;
  options.topics = ParseBagTopics(args.topics);
  options.quiet = args.quiet;
  if (args.sensor) {
    // --sensor was checked against SensorNames().
    const Sensor sensor = *ParseSensor(*args.sensor);
    if (IsRgbd(sensor)) {
      throw OptionError(
          fmt::format("--sensor {}: a bag's EuRoC streams have no depth images", *args.sensor));
    }
    options.require_cam1 = options.write_cam1 = IsStereo(sensor);
    options.require_imu = options.write_imu = IsInertial(sensor);
  }
  CheckOutputIsNotInput(args.out, "--out", args.bag, "--bag");
  std::optional<Settings> settings;
  if (!args.settings.empty()) settings = ReadOrbSlam3Settings(args.settings);
  const StreamCounts counts = ConvertBagToEuroc(args.bag, args.out, options);
  const std::filesystem::path mav0 = std::filesystem::path(args.out) / "mav0";
  if (settings) WriteEurocSensorFiles(*settings, mav0, args.settings);
  fmt::print("{} -> {}: {}\n", args.bag, mav0.string(), Counts(counts));
  if (!settings) {
    fmt::print(
        "no sensor.yaml files (a bag holds no calibration): convert with --settings FILE "
        "to write them, or copy them from the dataset's ASL download; `pkslam run --dataset` "
        "needs them\n");
  }
}

void FolderToBag(const ConvertArgs& args) {
  EurocToBagOptions options;
  options.topics = ParseBagTopics(args.topics);
  options.quiet = args.quiet;
  // --compression was checked against the three names.
  options.writer.compression = *ParseBagCompression(args.compression);
  CheckOutputIsNotInput(args.out, "--out", args.folder, "--folder");
  const StreamCounts counts = ConvertEurocToBag(args.folder, args.out, options);
  std::error_code ec;
  const auto file_size = std::filesystem::file_size(args.out, ec);
  const double bytes = ec ? 0.0 : static_cast<double>(file_size);
  const std::string size =
      bytes < 1e6 ? fmt::format("{:.1f} kB", bytes / 1e3) : fmt::format("{:.1f} MB", bytes / 1e6);
  fmt::print("{} -> {} ({} chunks, {}): {}\n", args.folder, args.out, args.compression, size,
             Counts(counts));
}

}  // namespace

void RegisterConvertCommand(CLI::App& app) {
  auto args = std::make_shared<ConvertArgs>();
  auto* cmd = app.add_subcommand(
      "convert",
      "Convert a ROS 1 bag (EuRoC, TUM-VI) to a EuRoC folder, or a EuRoC folder to a bag");
  cmd->add_option("--bag", args->bag,
                  "The bag to read (format 2.0; only read) into the EuRoC folder --out");
  cmd->add_option("--folder", args->folder, "The EuRoC folder to write as the bag --out");
  cmd->add_option("--out", args->out, "The folder (--bag) or bag file (--folder) to write")
      ->required();
  cmd->add_option("--topics", args->topics,
                  "Topics of the streams, e.g. cam0=/cam0/image_raw,cam1=/cam1/image_raw,"
                  "imu=/imu0 (also vicon, leica, mocap; defaults: EuRoC's and TUM-VI's names)");
  cmd->add_option("--sensor", args->sensor,
                  "--bag: convert the streams this sensor reads (cam0; cam1 for stereo; the IMU "
                  "for inertial sensors), which must be in the bag (default: every stream found)")
      ->check(OneOf(SensorNames()));
  cmd->add_option("--settings", args->settings,
                  "--bag: ORB-SLAM3 settings file whose calibration becomes the folder's "
                  "sensor.yaml files (a bag holds none)");
  cmd->add_option("--compression", args->compression, "--folder: chunk compression of the bag")
      ->check(OneOf({"none", "bz2", "lz4"}))
      ->capture_default_str();
  cmd->add_flag("--quiet", args->quiet, "No progress line");
  cmd->callback([args, cmd] {
    if (args->bag.empty() == args->folder.empty()) {
      throw OptionError(
          "give exactly one input: --bag FILE (to a folder) or --folder DIR (to a bag)");
    }
    if (!args->bag.empty()) {
      if (cmd->count("--compression") > 0) {
        throw OptionError("--compression goes with --folder (a bag is written)");
      }
      BagToFolder(*args);
    } else {
      if (args->sensor || !args->settings.empty()) {
        throw OptionError("--sensor and --settings go with --bag (a folder is written)");
      }
      FolderToBag(*args);
    }
  });
}

}  // namespace pkslam::apps
