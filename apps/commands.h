// Each pkslam subcommand lives in its own cmd_*.cc and registers itself on the CLI11 app.
// A command's callback throws on error; main() prints one line and exits non-zero.
#pragma once

#include <CLI/CLI.hpp>

namespace pkslam::apps {

void RegisterEvalCommand(CLI::App& app);
void RegisterInfoCommand(CLI::App& app);
void RegisterRunCommand(CLI::App& app);
void RegisterVocabCommand(CLI::App& app);
void RegisterDenseCommand(CLI::App& app);
void RegisterCloudCompareCommand(CLI::App& app);
void RegisterExportColmapCommand(CLI::App& app);
void RegisterRgbdOdometryCommand(CLI::App& app);
void RegisterPlanarCommand(CLI::App& app);
void RegisterSimulateCommand(CLI::App& app);
void RegisterBenchCommand(CLI::App& app);

}  // namespace pkslam::apps
