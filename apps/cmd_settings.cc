// pkslam settings convert OLD --out NEW: an ORB-SLAM2 / ORB-SLAM3 <= 0.4 (or v1.0) settings file
// written in the ORB-SLAM3 v1.0 format (io/settings_legacy.h says what maps to what).
#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <string>

#include "apps/commands.h"
#include "io/settings.h"

namespace pkslam::apps {
namespace {

struct SettingsArgs {
  std::string file;
  std::string out;
};

void RunConvert(const SettingsArgs& args) {
  const Settings settings = ReadOrbSlam3Settings(args.file);
  WriteOrbSlam3Settings(settings, args.out);
  std::cout << fmt::format("{} -> {} (ORB-SLAM3 v1.0: Camera.type {}, {}{})\n", args.file,
                           args.out,
                           settings.rectified_stereo ? "Rectified"
                           : settings.camera1.type() == CameraType::kKannalaBrandt8
                               ? "KannalaBrandt8"
                               : "PinHole",
                           settings.camera2      ? "two cameras and Stereo.T_c1_c2"
                           : settings.IsStereo() ? "a rectified stereo pair"
                                                 : "one camera",
                           settings.imu ? ", IMU" : "");
}

}  // namespace

void RegisterSettingsCommand(CLI::App& app) {
  auto args = std::make_shared<SettingsArgs>();
  auto* cmd = app.add_subcommand("settings", "Settings files: convert older ORB-SLAM formats");
  cmd->require_subcommand(1);
  auto* convert = cmd->add_subcommand(
      "convert",
      "Write an ORB-SLAM2 or ORB-SLAM3 <= 0.4 settings file (Camera.fx, LEFT.K, Tlr, Tbc) in "
      "the ORB-SLAM3 v1.0 format (pkslam run reads the old files too, with a warning)");
  convert->add_option("FILE", args->file, "Settings file to convert")->required();
  convert->add_option("--out", args->out, "The v1.0 file to write")->required();
  convert->callback([args] { RunConvert(*args); });
}

}  // namespace pkslam::apps
