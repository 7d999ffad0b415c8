// `pkslam bench` driver: executes a suite's pending runs with N at a time (progress bar with
// ETA), and writes scale-out job lists (GNU parallel, Slurm) instead when asked.
#pragma once

#include <atomic>
#include <filesystem>
#include <string>
#include <vector>

#include "bench/executor.h"

namespace pkslam::bench {

struct BenchCounts {
  int total = 0;     // runs in the (filtered) matrix
  int skipped = 0;   // already finished
  int executed = 0;  // run now
  int failed = 0;    // of all finished runs, the failed ones
  bool cancelled = false;
};

// Runs of the matrix whose id is in `only` (all when empty). Throws OptionError for an id
// that is not in the matrix.
std::vector<RunSpec> SelectRuns(const std::vector<RunSpec>& runs,
                                const std::vector<std::string>& only);

// Renders the simulator recipes the pending runs need, then executes the pending runs,
// options.jobs at a time. Returns the results of every selected run that has one.
std::vector<RunResult> RunSuite(const Suite& suite, const std::vector<RunSpec>& runs,
                                const HarnessOptions& options, BenchCounts* counts,
                                const std::atomic<bool>* cancel = nullptr);

struct EmittedJobs {
  int jobs = 0;  // commands written (pending runs)
  std::filesystem::path jobs_file;
  std::filesystem::path parallel_script;
  std::filesystem::path slurm_script;
};

// Writes into options.out: jobs.txt (one `pkslam bench ... --run-id ID` command per pending
// run, for GNU parallel), run_parallel.sh (JOBS=n, optional SSHLOGINFILE=file), slurm.sh (an
// array job over jobs.txt) and bench.yaml (title), so that `pkslam bench --collect OUT`
// reports the results from OUT/runs.
EmittedJobs EmitJobs(const Suite& suite, const std::vector<RunSpec>& runs,
                     const HarnessOptions& options);

// OUT/bench.yaml: the title (suite name) and suite file, read back by --collect.
void WriteBenchInfo(const std::filesystem::path& out, const Suite& suite);
std::string ReadBenchTitle(const std::filesystem::path& out, const std::string& fallback);

}  // namespace pkslam::bench
