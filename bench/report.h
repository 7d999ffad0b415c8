// The outputs of a benchmark made from run results: results.csv, summary.csv, report.md and
// report.html with the plots bench/plots.py draws into OUT/plots/.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/results.h"
#include "bench/summary.h"

namespace pkslam::bench {

struct ReportOptions {
  std::filesystem::path out;  // OUT: where the report goes
  // Folders holding the run folders (plot data); empty: OUT/runs.
  std::vector<std::filesystem::path> run_roots;
  std::string title = "pkslam bench";                 // report heading (the suite name)
  std::filesystem::path python = "/usr/bin/python3";  // with matplotlib + numpy
  std::filesystem::path plots_script;                 // empty: DefaultPlotsScript()
  bool plots = true;                                  // false: tables only
};

// bench/plots.py of the source tree this binary belongs to.
std::filesystem::path DefaultPlotsScript();

struct ReportFiles {
  std::vector<std::filesystem::path> pngs;
  std::string plot_error;  // why plots are missing, when they are
};

// Writes OUT/results.csv, OUT/summary.csv, OUT/report.md, OUT/report.html (and OUT/plots/).
// Results are sorted by run index. Returns the PNGs drawn.
ReportFiles WriteReport(std::vector<RunResult> results, const ReportOptions& options);

// Results of every finished run folder below DIR/runs (result.csv files), sorted by index;
// several folders are merged (a run id found twice keeps the later folder's row). An entry that
// is a file is a recorded collection (a results.csv): its rows join in the same way.
std::vector<RunResult> CollectResults(const std::vector<std::filesystem::path>& dirs);

// Renders tables as HTML (exposed for tests).
std::string HtmlTable(const Table& table);

}  // namespace pkslam::bench
