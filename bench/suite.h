// Benchmark suites: which datasets, sensors, keyframe selectors, parameter sweeps and how many
// runs `pkslam bench` executes. A suite is a YAML file (see bench/suites/*.yaml and
// docs/bench.md):
//
//   name: smoke                 # shown in the report
//   runs: 10                    # runs per configuration (distinct seeds seed, seed+1, ...)
//   seed: 1
//   deterministic: false        # pass --deterministic to every `pkslam run`
//   trace: true                 # pass --trace (keyframe_trace.csv: the viewer colours each
//                               # keyframe by the rule that made it); false to skip the file
//   baseline: orbslam3          # selector label relative improvements are measured against
//   alignment: auto             # headline ATE: se3 | sim3 | auto (sim3 for mono sensors)
//   sensors: [stereo, mono]     # passed through to `pkslam run --sensor`
//   selectors: [orbslam3, pks, {name: pks, label: pks-strict, params: {tau: 0.3}},
//               {name: orbslam3, label: online, args: [--calibrate, online]}]
//   params: {name: value}       # overrides for every run (pkslam run --param)
//   dense: false                # build a dense cloud of every run (pkslam dense)
//   sweeps: [{selector: pks, param: delta, values: [10, 20, 30, 40], datasets: [V101],
//             dense: true}]     # dense clouds for the sweep's runs (the paper's Eq. 13)
//   peers:                      # other SLAM systems run on the same datasets (peer_import.h)
//     - {label: orbslam3-peer, command: [bash, "{suite_dir}/../peer/run_peer.sh", "{dataset}",
//        "{sensor}", "{out}"]}
//   datasets:
//     - {name: MH_01_easy, path: ${EUROC_ROOT}/MH_01_easy}         # real data on disk
//     - {name: sim_V102, sim: {trajectory: ..., start: 20, duration: 10, args: [...]},
//        settings: "{dataset}/settings.yaml"}  # the rendering's own settings (DatasetSpec)
//
// Paths may use ${VAR} and ${VAR:-default}; relative paths are relative to the suite file.
// Every error is an InputError naming the suite file and the line of the offending node.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace pkslam::bench {

// A simulator recipe: the arguments of one `pkslam simulate` call (rendered once, cached).
struct SimRecipe {
  std::filesystem::path trajectory;  // replay this ground truth; empty: random motion
  std::string motion;                // random motion level when no trajectory
  double start_s = 0.0;
  double duration_s = 0.0;
  std::string scene;    // empty: the simulator's default
  std::string quality;  // empty: the simulator's default
  std::uint64_t seed = 1;
  // true: run k of a configuration replays its own rendering with seed + k (noise
  // realisations vary per run); false: every run uses one rendering with `seed`.
  bool seed_per_run = false;
  std::vector<std::string> extra_args;  // further `pkslam simulate` options, verbatim
};

struct DatasetSpec {
  std::string name;
  std::optional<std::filesystem::path> path;  // real (or pre-rendered) dataset
  std::optional<SimRecipe> sim;               // exactly one of path / sim
  // Ground truth; default: mav0/state_groundtruth_estimate0/data.csv (EuRoC layout) or
  // groundtruth.txt (TUM RGB-D layout) inside the dataset.
  std::optional<std::filesystem::path> ground_truth;
  // pkslam run --settings. "{dataset}" in it stands for the dataset folder the run reads (a
  // simulator recipe's rendering in the cache: "{dataset}/settings.yaml" is the settings file
  // `pkslam simulate` wrote); such a path is not resolved against the suite's folder.
  std::optional<std::filesystem::path> settings;
  std::vector<std::string> sensors;  // empty: the suite's sensors
  int max_frames = 0;                // pkslam run --max-frames (0: all)
};

// Stands for the dataset folder in DatasetSpec::settings (and in peer commands).
inline constexpr const char* kDatasetPlaceholder = "{dataset}";

// One selector configuration (a column of the summary tables).
struct SelectorSpec {
  std::string name;   // selector_factory name (orbslam3, pks, ...)
  std::string label;  // unique label in tables; default: the name
  std::map<std::string, double> params;
  // Further `pkslam run` options of this configuration, verbatim (e.g. [--calibrate, online]).
  std::vector<std::string> args;
};

// One parameter swept over values for one selector; each value is its own configuration.
struct SweepSpec {
  std::string selector;  // a selector label of the suite (or a selector name)
  std::string param;
  std::vector<double> values;
  std::vector<std::string> datasets;  // only on these datasets (empty: all)
  // Build each sweep run's dense cloud: its point count is the density of the PKS paper's
  // Eq. 13 (delta = argmax of normalised density - normalised ATE).
  bool dense = false;
};

// Another SLAM system, run as a command on each dataset and sensor of the suite (`runs` times,
// the repeats differing only in thread timing). The command's words may use {dataset} (the
// dataset folder), {sensor}, {out} (the run folder), {seed} and {suite_dir} (the suite file's
// folder); the program writes the peer output contract of peer_import.h into {out}.
struct PeerSpec {
  std::string label;  // its column in the tables (unique among selectors and peers)
  std::vector<std::string> command;
  // The sensors it runs (empty: every sensor of the suite); others are skipped, not failed
  // (the ORB-SLAM3 peer has no RGB-D mode).
  std::vector<std::string> sensors;
  std::size_t line = 0;  // in the suite file (messages)
};

struct Suite {
  std::filesystem::path file;  // where it was read from (for messages)
  std::string name;
  int runs = 10;
  std::uint64_t seed = 1;
  bool deterministic = false;
  bool trace = true;
  bool dense = false;  // a dense cloud for every run (`pkslam dense` after `pkslam run`)
  std::string baseline = "orbslam3";
  double timeout_s = 3600.0;  // per run; a run that takes longer is killed and marked failed
  double rpe_delta_m = 1.0;   // RPE pose-pair distance in metres
  // Alignment of the headline ATE: se3 | sim3 (the PKS paper's) | auto (sim3 for monocular
  // sensors, se3 otherwise). Both are always measured and in results.csv.
  std::string alignment = "auto";
  std::vector<std::string> sensors;
  std::vector<SelectorSpec> selectors;
  std::vector<PeerSpec> peers;
  std::map<std::string, double> params;
  std::vector<SweepSpec> sweeps;
  std::vector<DatasetSpec> datasets;
};

// Expands ${VAR} / ${VAR:-default} from the environment; throws InputError(file, line) for an
// unset variable without default or an unterminated ${.
std::string ExpandEnvironment(const std::string& text, const std::filesystem::path& file,
                              std::size_t line);

// Reads and validates a suite. Throws InputError naming the file and line.
Suite ReadSuite(const std::filesystem::path& file);
// The same from text (file only names the source in messages; relative paths resolve
// against its directory).
Suite ParseSuite(const std::string& text, const std::filesystem::path& file);

// Before a bench starts its runs: every peer's program can be started (a path exists and is
// executable; a bare name is on PATH) and every file it names beside the suite
// ("{suite_dir}/...") exists. Throws InputError naming the suite file and the peer's line, so
// a mistyped path stops a study at once, not as failed runs hours in. `peers`: the labels
// checked (those with runs to do).
void CheckPeerCommands(const Suite& suite, const std::set<std::string>& peers);

}  // namespace pkslam::bench
