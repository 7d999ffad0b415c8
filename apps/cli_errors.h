// Usage errors the pkslam way: one line `pkslam: error: ...`, exit 1 (docs/robustness.md), a
// "did you mean" for a mistyped subcommand, flag or value, instead of CLI11's own texts and
// exit codes (105-109).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace pkslam::apps {

// Prints the error (help and --version go to CLI11 unchanged, exit 0) and returns the exit
// code. `argv` is searched for the unknown words behind an "arguments were not expected" error.
int ReportParseError(CLI::App& app, const CLI::ParseError& error, int argc, char** argv);

// The subcommand the parser reached: the last parsed one, nested subcommands followed (the app
// itself when none was given).
CLI::App* DeepestSubcommand(CLI::App& app);

// The values of every `--sensor` option ("mono" ... "rgbd-inertial").
std::vector<std::string> SensorNames();

// A check for an option whose value is one of `values`: the error lists them and suggests the
// nearest ("--sensor: 'stero' is not one of mono, stereo, ... (did you mean 'stereo'?)").
// `why` (optional) follows the list: why other values are not offered.
CLI::Validator OneOf(std::vector<std::string> values, std::string why = "");

}  // namespace pkslam::apps
