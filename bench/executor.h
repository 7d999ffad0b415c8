// Executes runs of a suite as child processes of the pkslam executable:
//   `pkslam simulate` renders each simulator recipe once into the cache (a file lock makes
//   concurrent jobs - threads or separate processes - wait for one rendering), then
//   `pkslam run` writes OUT/runs/<run id>/, which is evaluated in-process and gets its
//   result.csv (one results.csv row). A folder with result.csv is finished and is skipped.
#pragma once

#include <atomic>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench/matrix.h"
#include "bench/results.h"
#include "bench/suite.h"

namespace pkslam::bench {

struct HarnessOptions {
  std::filesystem::path pkslam;  // the pkslam executable the child processes run
  // The pkslam executable that renders the simulated datasets (empty: `pkslam`). A study run in
  // passes by different builds of pkslam renders with one build throughout, so its renderings
  // keep their cache keys and every pass replays the same images.
  std::filesystem::path simulator;
  std::filesystem::path out;     // OUT: runs/, results.csv, summary, report
  std::filesystem::path cache;   // simulator renderings (shared between suites)
  int jobs = 1;                  // runs executed at once
  bool quiet = false;            // no progress bars
  bool retry_failed = false;     // re-execute runs whose result.csv says failed
  bool reevaluate = false;       // measure finished runs again (new evaluation code or truth)
  // Render each simulator recipe just before its first pending run, execute the runs of one
  // recipe together (run 1 of every dataset before run 2 of any: RenderingOrder), and delete
  // the rendering when its last pending run finished: disk holds
  // about `jobs` renderings at a time (a study with per-run render seeds of full EuRoC replays
  // would otherwise need ~2 GB per run).
  bool prune_cache = false;
  // Recorded results (results.csv of an earlier collection) whose runs count as finished
  // (ImportFinished): a study resumes on a machine that no longer has its run folders.
  std::vector<std::filesystem::path> resume_from;
  // Part of every cache key (ExecutableId of Simulator()): a rebuilt simulator may render the
  // same command line differently, so its renders are never mistaken for an older build's.
  std::string simulator_id;
  // The commit of `pkslam` (BuildCommit of that build) and its ExecutableId, recorded in every
  // result with the machine's cores, `jobs` and the time (results.h RunProvenance).
  std::string pkslam_commit;
  std::string executable_id;

  const std::filesystem::path& Simulator() const { return simulator.empty() ? pkslam : simulator; }
  void Check() const;
};

// OUT/runs/<run id>.
std::filesystem::path RunDir(const std::filesystem::path& out, const RunSpec& run);

// The cache folder of a recipe: CACHE/<dataset>-seed<S>-<hash of the recipe and simulator_id>.
std::filesystem::path SimCacheDir(const HarnessOptions& options, const std::string& dataset,
                                  const SimRecipe& recipe);
// A content hash of an executable (hex); throws Error naming the file when it cannot be read.
std::string ExecutableId(const std::filesystem::path& executable);
// The `pkslam simulate` command line of a recipe (without the executable).
std::vector<std::string> SimulateArguments(const SimRecipe& recipe,
                                           const std::filesystem::path& out_dir);
// Renders the recipe unless cached; returns its folder. Throws Error when the simulator fails
// (its log is CACHE/<name>.log).
std::filesystem::path EnsureSimulated(const HarnessOptions& options, const std::string& dataset,
                                      const SimRecipe& recipe,
                                      const std::atomic<bool>* cancel = nullptr);

// The dataset folder a run reads (rendering it first for simulator recipes).
std::filesystem::path PrepareDataset(const Suite& suite, const RunSpec& run,
                                     const HarnessOptions& options,
                                     const std::atomic<bool>* cancel = nullptr);

// The dataset's settings file with {dataset} replaced by `dataset` (nullopt: none given).
std::optional<std::filesystem::path> SettingsFile(const DatasetSpec& d,
                                                  const std::filesystem::path& dataset);

// The `pkslam run` command line (without the executable).
std::vector<std::string> RunArguments(const Suite& suite, const RunSpec& run,
                                      const std::filesystem::path& dataset,
                                      const std::filesystem::path& run_dir);

// The `pkslam dense` command line of a run with `dense` (without the executable).
std::vector<std::string> DenseArguments(const Suite& suite, const RunSpec& run,
                                        const std::filesystem::path& dataset,
                                        const std::filesystem::path& run_dir);

// Measures a finished, successful run again from its folder (ATE, RPE, biases, plot files)
// without running SLAM; keeps its dense cloud count. Returns the new result (written to
// result.csv), or std::nullopt when the run is not finished or failed.
std::optional<RunResult> ReevaluateRun(const Suite& suite, const RunSpec& run,
                                       const HarnessOptions& options);

// The recorded result of a finished run, if its folder has a readable result.csv.
std::optional<RunResult> ReadFinished(const std::filesystem::path& run_dir);
// Whether a run still has to be executed (no result, failed and retry_failed, or finished
// without the dense cloud its suite now asks for - then only the cloud is built).
bool NeedsExecution(const HarnessOptions& options, const RunSpec& run);

// Renders (if needed), runs and evaluates one run; writes its result.csv. Failures of the run
// or its evaluation are recorded in the result (ok=false), not thrown; a cancelled run is not
// recorded (it will run again on resume) and returns nullopt.
std::optional<RunResult> ExecuteRun(const Suite& suite, const RunSpec& run,
                                    const HarnessOptions& options,
                                    const std::atomic<bool>* cancel = nullptr);

}  // namespace pkslam::bench
