#include "bench/import_finished.h"

#include <fmt/format.h>

#include <fstream>
#include <map>

#include "bench/executor.h"
#include "bench/results.h"
#include "core/util/error.h"

namespace pkslam::bench {

namespace fs = std::filesystem;

namespace {

constexpr const char* kMarker = "imported";

void CheckSameRun(const fs::path& file, const RunResult& row, const RunSpec& run) {
  if (row.dataset == run.dataset && row.sensor == run.sensor && row.config == run.config) return;
  throw InputError(file, fmt::format("run {} is {} / {} / {} here but {} / {} / {} in the suite: "
                                     "a results file of another suite?",
                                     row.run_id, row.dataset, row.sensor, row.config, run.dataset,
                                     run.sensor, run.config));
}

}  // namespace

ImportCounts ImportFinished(const fs::path& results_csv, const std::vector<RunSpec>& runs,
                            const fs::path& out) {
  std::map<std::string, const RunSpec*> by_id;
  for (const auto& r : runs) by_id[r.id] = &r;
  ImportCounts counts;
  for (RunResult row : ReadResultsCsv(results_csv)) {
    const auto it = by_id.find(row.run_id);
    if (it == by_id.end()) {
      ++counts.other;
      continue;
    }
    const RunSpec& run = *it->second;
    CheckSameRun(results_csv, row, run);
    const fs::path run_dir = RunDir(out, run);
    if (ReadFinished(run_dir)) {
      ++counts.present;  // measured (or imported) here already: that result stands
      continue;
    }
    row.index = run.index;
    fs::remove_all(run_dir);  // what an interrupted run left
    fs::create_directories(run_dir);
    WriteResultsCsv(run_dir / "result.csv", {row});
    std::ofstream(run_dir / kMarker) << results_csv.filename().string() << '\n';
    ++counts.imported;
  }
  return counts;
}

bool IsImported(const fs::path& run_dir) { return fs::exists(run_dir / kMarker); }

}  // namespace pkslam::bench
