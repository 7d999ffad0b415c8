// pkslam map info FILE | pkslam map roundtrip FILE --dataset SEQ: inspect a map file
// (`pkslam run --save-map`), and prove that loading it restores everything it holds (load into
// a new system, save again, compare the bytes).
#include <chrono>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include "apps/cli_errors.h"
#include "apps/commands.h"
#include "core/sensor/sensor.h"
#include "core/util/error.h"
#include "io/euroc_dataset.h"
#include "io/settings.h"
#include "io/settings_euroc.h"
#include "map_model/storage/map_file.h"
#include "system/run_dataset.h"
#include "system/slam_system.h"

namespace pkslam::apps {
namespace {

struct MapArgs {
  std::string file;
  std::string dataset;
  std::string sensor = "stereo-inertial";
  std::string settings;
  std::string vocabulary;
  std::string out;
};

void RunInfo(const MapArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const AtlasRecord record = ReadMapFile(args.file);
  const double read_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  int keyframes = 0;
  int points = 0;
  std::cout << fmt::format("{}: map file version {}, {:.1f} MB, read in {:.2f} s\n", args.file,
                           kMapFileVersion, std::filesystem::file_size(args.file) / 1e6, read_s);
  std::cout << fmt::format("camera     {} ({}), bf {:.4f}\n", record.camera.model,
                           SensorName(static_cast<Sensor>(record.camera.sensor)), record.camera.bf);
  std::cout << fmt::format("vocabulary fingerprint {:016x}\n", record.vocabulary_fingerprint);
  for (const MapRecord& m : record.maps) {
    std::cout << fmt::format("map {}{}: {} keyframes, {} points, IMU {}\n", m.id,
                             m.id == record.current_map ? " (current)" : "", m.keyframes.size(),
                             m.points.size(),
                             m.imu_initialized ? "initialised" : "not initialised");
    keyframes += static_cast<int>(m.keyframes.size());
    points += static_cast<int>(m.points.size());
  }
  std::cout << fmt::format("total      {} map(s), {} keyframes, {} points\n", record.maps.size(),
                           keyframes, points);
}

std::string ReadBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void RunRoundTrip(const MapArgs& args) {
  const auto sensor = ParseSensor(args.sensor);
  if (!sensor) throw OptionError(fmt::format("--sensor: unknown sensor '{}'", args.sensor));
  Settings settings;
  if (!args.settings.empty()) {
    settings = ReadOrbSlam3Settings(args.settings);
  } else {
    settings = SettingsFromEuroc(EurocDataset::Open(args.dataset));
  }
  const std::filesystem::path vocabulary_path =
      args.vocabulary.empty() ? DefaultVocabularyPath() : std::filesystem::path(args.vocabulary);
  auto vocabulary = std::make_shared<const Vocabulary>(Vocabulary::Load(vocabulary_path));
  SystemOptions options;
  options.sensor = *sensor;
  options.tracking.localise_only = true;  // keeps the loaded current map current, adds nothing
  options.no_loop = true;
  SlamSystem system(settings, vocabulary, options);
  const SlamSystem::MapFileInfo loaded = system.LoadMap(args.file);
  system.Shutdown();
  const std::filesystem::path out = args.out.empty()
                                        ? std::filesystem::path(args.file + ".roundtrip")
                                        : std::filesystem::path(args.out);
  system.SaveMap(out);
  const bool same = ReadBytes(out) == ReadBytes(args.file);
  std::cout << fmt::format(
      "{} map(s), {} keyframes, {} points loaded in {:.2f} s; saved again "
      "to {}{}: {}\n",
      loaded.maps, loaded.keyframes, loaded.map_points, loaded.seconds, out.string(),
      args.out.empty() ? " (a new file beside the input; --out chooses another)" : "",
      same ? "byte-identical" : "DIFFERENT");
  if (!same) throw CommandExit{1, "map round trip changed the file"};
}

}  // namespace

void RegisterMapCommand(CLI::App& app) {
  auto args = std::make_shared<MapArgs>();
  auto* cmd = app.add_subcommand("map", "Inspect and check map files (pkslam run --save-map)");
  cmd->require_subcommand(1);
  auto* info = cmd->add_subcommand("info", "Counts, camera, vocabulary and size of a map file");
  info->add_option("FILE", args->file, "Map file")->required();
  info->callback([args] { RunInfo(*args); });
  auto* roundtrip = cmd->add_subcommand(
      "roundtrip",
      "Load a map file into a new system and save it again: the bytes must be identical (every "
      "keyframe, point, link and state restored); exits 1 otherwise");
  roundtrip->add_option("FILE", args->file, "Map file")->required();
  roundtrip->add_option("--dataset", args->dataset,
                        "EuRoC dataset whose sensor.yaml files give the camera (or --settings)");
  roundtrip->add_option("--settings", args->settings, "ORB-SLAM3 settings file");
  roundtrip->add_option("--sensor", args->sensor, "Sensor the map was built with")
      ->check(OneOf(SensorNames()))
      ->capture_default_str();
  roundtrip->add_option("--vocabulary", args->vocabulary, "ORB vocabulary (default: shipped)");
  roundtrip->add_option("--out", args->out, "Where to write the re-saved map (FILE.roundtrip)");
  roundtrip->callback([args] {
    if (args->dataset.empty() && args->settings.empty()) {
      throw OptionError("map roundtrip: give --dataset or --settings (the camera)");
    }
    RunRoundTrip(*args);
  });
}

}  // namespace pkslam::apps
