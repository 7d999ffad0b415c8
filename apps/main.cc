// pkslam: one executable, one subcommand per capability (see README.md).
#include <CLI/CLI.hpp>
#include <exception>
#include <filesystem>
#include <iostream>

#include "apps/cli_errors.h"
#include "apps/cli_outputs.h"
#include "apps/commands.h"
#include "core/util/build_info.h"
#include "core/util/error.h"
#include "core/util/log.h"

int main(int argc, char** argv) {
  CLI::App app{"pkslam: keyframe SLAM with photogrammetric keyframe selection (PKS)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", pkslam::BuildDescription());
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace|debug|info|warn|error|off")
      ->capture_default_str();
  // Runs once parsing is complete, before the subcommand's callback: nothing is written yet.
  app.parse_complete_callback([&app, &log_level] {
    pkslam::SetLogLevel(log_level);
    pkslam::apps::CheckOutputsAgainstInputs(app);
  });

  pkslam::apps::RegisterEvalCommand(app);
  pkslam::apps::RegisterInfoCommand(app);
  pkslam::apps::RegisterRunCommand(app);
  pkslam::apps::RegisterCalibrateCommand(app);
  pkslam::apps::RegisterMapCommand(app);
  pkslam::apps::RegisterTracksCommand(app);
  pkslam::apps::RegisterViewCommand(app);
  pkslam::apps::RegisterVocabCommand(app);
  pkslam::apps::RegisterDenseCommand(app);
  pkslam::apps::RegisterCloudCompareCommand(app);
  pkslam::apps::RegisterExportColmapCommand(app);
  pkslam::apps::RegisterRgbdOdometryCommand(app);
  pkslam::apps::RegisterPlanarCommand(app);
  pkslam::apps::RegisterSimulateCommand(app);
  pkslam::apps::RegisterBenchCommand(app);
  pkslam::apps::RegisterSettingsCommand(app);
  pkslam::apps::RegisterConvertCommand(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return pkslam::apps::ReportParseError(app, e, argc, argv);
  } catch (const pkslam::apps::CommandExit& e) {
    if (!e.message.empty()) std::cerr << "pkslam: " << e.message << '\n';
    return e.code;
  } catch (const pkslam::Error& e) {
    std::cerr << "pkslam: error: " << e.what() << '\n';
    return 1;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path that cannot be created or read (an unwritable --out): the user's to fix, and
    // the message names the path.
    std::cerr << "pkslam: error: " << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "pkslam: error: " << e.what() << '\n';
    return 2;
  }
  return 0;
}
