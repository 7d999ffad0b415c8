// Each pkslam subcommand lives in its own cmd_*.cc and registers itself on the CLI11 app.
// A command's callback throws on error; main() prints one line and exits non-zero.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace pkslam::apps {

// Exit codes (docs/run.md): 0 success, 1 error (bad input, failed write), 2 internal error,
// 3 finished on degraded input under --strict, 4 finished with a suspect estimate under --strict
// (system/estimate_health.h), 5 the run has no estimate (too few frames with a pose; --strict or
// not), 128 + signal when interrupted (outputs written).
inline constexpr int kExitDegraded = 3;
inline constexpr int kExitSuspect = 4;
inline constexpr int kExitNoEstimate = 5;

// Thrown by a command that finished its work but must exit with `code`; main() prints
// `message` (when not empty) as one line.
struct CommandExit {
  int code = 0;
  std::string message;
};

void RegisterEvalCommand(CLI::App& app);
void RegisterInfoCommand(CLI::App& app);
void RegisterRunCommand(CLI::App& app);
void RegisterCalibrateCommand(CLI::App& app);
void RegisterMapCommand(CLI::App& app);
void RegisterTracksCommand(CLI::App& app);
void RegisterViewCommand(CLI::App& app);
void RegisterVocabCommand(CLI::App& app);
void RegisterDenseCommand(CLI::App& app);
void RegisterCloudCompareCommand(CLI::App& app);
void RegisterExportColmapCommand(CLI::App& app);
void RegisterRgbdOdometryCommand(CLI::App& app);
void RegisterPlanarCommand(CLI::App& app);
void RegisterSimulateCommand(CLI::App& app);
void RegisterBenchCommand(CLI::App& app);
void RegisterSettingsCommand(CLI::App& app);
void RegisterConvertCommand(CLI::App& app);

}  // namespace pkslam::apps
