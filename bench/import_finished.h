// Resuming a study from the results it recorded (`pkslam bench --resume-from results.csv`).
//
// A long study keeps its collected results.csv in the repository; its run folders live on a
// machine that may not survive between sittings. Importing turns each recorded row back into the
// finished run the bench skips, so the next sitting executes only what is missing and the final
// collection holds every run, each with the provenance of the build that made it.
#pragma once

#include <filesystem>
#include <vector>

#include "bench/matrix.h"

namespace pkslam::bench {

struct ImportCounts {
  int imported = 0;  // rows written as finished runs
  int present = 0;   // rows whose run already has a result of its own here (left as they are)
  int other = 0;     // rows that are not runs of the selection (other configurations, sensors)
};

// For each row of `results_csv` whose run id is one of `runs` and which has no result in
// OUT/runs/<id>/ yet, writes that run's result.csv (the row, its index set to the run's) and an
// `imported` marker. Throws InputError naming the file when it cannot be read and when a row's
// dataset, sensor or configuration contradicts the run of the same id (a results file of
// another suite). The imported runs have no trajectory: --reevaluate leaves them as recorded.
ImportCounts ImportFinished(const std::filesystem::path& results_csv,
                            const std::vector<RunSpec>& runs, const std::filesystem::path& out);

// True when the run's result was imported rather than measured here.
bool IsImported(const std::filesystem::path& run_dir);

}  // namespace pkslam::bench
