// The run matrix of a suite: datasets x sensors x selector configurations (the suite's
// selectors, then one configuration per sweep value) x runs.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bench/suite.h"

namespace pkslam::bench {

// One `pkslam run` of the matrix.
struct RunSpec {
  int index = 0;         // position in the matrix (tables and results.csv keep this order)
  std::string id;        // unique, filesystem-safe: DATASET/SENSOR/CONFIG/seedN
  std::string dataset;   // DatasetSpec::name
  std::string sensor;    // passed through to pkslam run --sensor
  std::string config;    // selector label, plus @PARAM=VALUE for sweep points
  std::string selector;  // selector factory name
  std::map<std::string, double> params;  // suite params, then selector params, then sweep
  std::vector<std::string> run_args;     // the configuration's further `pkslam run` options
  std::string sweep_param;               // empty unless a sweep point
  double sweep_value = 0.0;
  bool dense = false;  // build the run's dense cloud after it
  int run = 0;         // 0 .. runs-1
  std::uint64_t seed = 0;
  std::optional<SimRecipe> sim;  // with the seed of this run's rendering
  // A peer system's run: its command (placeholders not yet substituted, see PeerSpec);
  // empty for `pkslam run`.
  std::vector<std::string> peer_command;
};

// "a=1;b=0.5" (sorted by name; numbers in shortest round-trip form).
std::string FormatParams(const std::map<std::string, double>& params);
// Shortest text that reads back to the same double ("20", "0.35").
std::string FormatNumber(double value);

// Expands the suite in a fixed order: dataset, sensor, configuration, run.
std::vector<RunSpec> ExpandSuite(const Suite& suite);

// The runs of these sensors (all when `sensors` is empty), in their order: a study split over
// sittings, one sensor first (`pkslam bench --sensor`). Throws OptionError for a sensor the
// suite does not run.
std::vector<RunSpec> SelectSensors(const std::vector<RunSpec>& runs,
                                   const std::vector<std::string>& sensors);

// The runs of these configurations (all when `configs` is empty), in their order: a study in
// passes, e.g. its peers alone on the machine, then pkslam's runs two at a time (`pkslam bench
// --config`). A name is a configuration's label, or `peers` (every peer) or `pkslam` (every
// selector configuration) unless a configuration has that label. Throws OptionError for a name
// that selects nothing.
std::vector<RunSpec> SelectConfigs(const std::vector<RunSpec>& runs,
                                   const std::vector<std::string>& configs);

// The runs grouped by rendering (`rendering_of` names a run's rendering; a run without one ranks
// first), the renderings ordered by the lowest run number among their runs, then by where their
// first run stands; matrix order within a group. A study pruned as it goes (`--prune-cache`)
// and stopped after a sitting thus holds run 1 of every dataset before run 2 of any: a balanced
// partial design, where the plain matrix order would finish all runs of the first datasets.
std::vector<const RunSpec*> RenderingOrder(
    std::vector<const RunSpec*> runs,
    const std::function<std::optional<std::string>(const RunSpec&)>& rendering_of);

// The dataset spec of a run (throws Error when absent).
const DatasetSpec& DatasetOf(const Suite& suite, const RunSpec& run);

}  // namespace pkslam::bench
