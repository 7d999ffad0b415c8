#include "system/run_bag.h"

#include <fmt/format.h>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/output_guard.h"
#include "io/rosbag_euroc_sensors.h"
#include "io/settings.h"

namespace pkslam {

namespace fs = std::filesystem;

// Why a temporary folder rather than reading the bag into memory: the run on a bag must be the
// run on its converted folder, frame for frame and byte for byte under --deterministic. Running
// RunDataset itself on the converted streams makes that true by construction (the same reader,
// input checks, stereo pairing, IMU feeding and image prefetching), where an in-memory path
// would be a second copy of RunDataset's EuRoC branch (EurocDataset loads its images lazily
// from files) bound to drift from the first. The cost is writing the images once, uncompressed
// (PGM: nothing to encode, and less to decode than the PNGs of a folder): an 8 s stereo-inertial
// replay ran in 5.7 s from an lz4 bag, 5.5 s from its folder (docs/bags.md).
RunSummary RunBag(const RunOptions& options, const fs::path& bag, const BagTopics& topics,
                  const RunControl& control) {
  const Sensor sensor = options.system.sensor;
  if (!options.settings) {
    throw OptionError(
        fmt::format("{}: pass --settings (an ORB-SLAM3 settings file: a bag holds "
                    "no calibration)",
                    bag.string()));
  }
  if (IsRgbd(sensor)) {
    throw OptionError(
        fmt::format("{}: sensor {} needs depth images; a bag's EuRoC streams are "
                    "mono, stereo and IMU",
                    bag.string(), SensorName(sensor)));
  }
  CheckOutputIsNotInput(options.out, "--out", bag, "--bag");
  const Settings settings = ReadOrbSlam3Settings(*options.settings);  // errors before converting

  BagToEurocOptions convert;
  convert.topics = topics;
  convert.require_cam1 = convert.write_cam1 = IsStereo(sensor);
  convert.require_imu = convert.write_imu = IsInertial(sensor);
  convert.write_ground_truth = false;
  convert.image_format = "pgm";
  convert.quiet = options.quiet;
  const fs::path folder = options.out / (bag.stem().string() + ".euroc.tmp");
  CheckOwnedDirectory(folder);  // a folder of that name that pkslam did not make stays
  struct Cleanup {
    fs::path dir;
    ~Cleanup() {
      std::error_code ec;
      fs::remove_all(dir, ec);
    }
  } cleanup{folder};
  PKSLAM_LOG_INFO("{}: converting {} to the EuRoC folder {} (removed after the run)", bag.string(),
                  IsStereo(sensor) ? "the stereo pair" : "cam0", folder.string());
  ConvertBagToEuroc(bag, folder, convert);
  WriteEurocSensorFiles(settings, folder / "mav0", options.settings->string());

  RunOptions run = options;
  run.dataset = folder;
  return RunDataset(run, control);
}

}  // namespace pkslam
