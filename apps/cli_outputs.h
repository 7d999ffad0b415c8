// Before a command writes anything: none of its outputs (--out, --save-map) is one of its
// inputs or lies inside an input folder (docs/robustness.md "Outputs").
#pragma once

#include <CLI/CLI.hpp>

namespace pkslam::apps {

// Checks the subcommand the parser reached; throws OptionError naming both flags.
void CheckOutputsAgainstInputs(CLI::App& app);

}  // namespace pkslam::apps
