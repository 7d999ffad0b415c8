// Aggregates run results per (dataset, sensor, configuration): mean +- std over the runs that
// succeeded, and the ATE change against the baseline configuration, in one sign convention
// shared by every table, plot and sentence of the report (bench_statistics.py too):
// 100 * (ATE - ATE_baseline) / ATE_baseline, negative = lower error (more accurate).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "bench/results.h"

namespace pkslam::bench {

// Mean and sample standard deviation (n - 1; 0 for one value) of the finite values.
struct MeanStd {
  int n = 0;
  double mean = kNaN;
  double std = kNaN;
};
MeanStd ComputeMeanStd(const std::vector<double>& values);

// Speed of a configuration: medians over its successful runs (robust to one run slowed by a
// busy machine). NaN where no run measured it.
struct SpeedMedians {
  double realtime_factor = kNaN;  // sequence duration / wall time
  double tracking_ms = kNaN;      // of the runs' median tracking times
  double p95_tracking_ms = kNaN;
  double mapping_ms_per_kf = kNaN;
  double cpu_s = kNaN;
  double peak_memory_mib = kNaN;
};

struct GroupSummary {
  int order = 0;  // smallest run index of the group (tables keep the matrix order)
  std::string dataset;
  std::string sensor;
  std::string config;
  std::string selector;
  std::string sweep_param;
  double sweep_value = kNaN;
  std::string baseline;
  std::string alignment;
  int runs = 0;
  int ok = 0;
  MeanStd ate_m;
  MeanStd ate_se3_m;
  MeanStd ate_sim3_m;
  MeanStd scale;
  MeanStd rpe_trans_m;
  MeanStd keyframes;
  MeanStd map_points;
  MeanStd lost_frames;
  MeanStd coverage;  // fraction of frames with a pose in the evaluated trajectory
  MeanStd wall_s;
  MeanStd median_tracking_ms;
  MeanStd dense_points;       // runs with dense clouds
  MeanStd gyro_bias_err_pct;  // inertial runs (bias_evaluation.h)
  MeanStd accel_bias_err_pct;
  double ate_median_m = kNaN;
  SpeedMedians speed;
  // ATE change (%) against the baseline group of the same dataset and sensor; negative = lower.
  double ate_change_pct = kNaN;
  // Sweep points with dense clouds: the PKS paper's Eq. 13 criterion, mean density and mean
  // ATE each min-max normalised over the sweep's values, density_n - ATE_n (the paper picks
  // the value with the largest score).
  double sweep_score = kNaN;
};

// Groups in matrix order (by their first run's index).
std::vector<GroupSummary> Summarize(const std::vector<RunResult>& results);

// summary.csv: one row per group (the numbers --collect must reproduce).
void WriteSummaryCsv(const std::filesystem::path& file, const std::vector<GroupSummary>& groups);

// "0.0123 ± 0.0012" (or "—" without values); "0.0123 (1 run)", and "0.0123 (3 identical runs)"
// when the runs gave the same value (deterministic runs: a spread of zero is not a measured one).
std::string FormatMeanStd(const MeanStd& m, int decimals);

// A table: header row and body rows of cells (rendered to Markdown or HTML by report.cc).
struct Table {
  std::string title;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

// Headline: one table per sensor, rows = datasets, columns = the non-sweep configurations,
// cells = ATE mean ± std [m] and the ATE change against the baseline, flagged "[cov N%]" when
// the evaluated trajectory covers less than kLowCoverage of the frames (an ATE over a short piece
// is not comparable); summary rows as the paper's (mean ATE and its change, the mean of the
// per-sequence changes, on how many sequences the ATE is lower).
inline constexpr double kLowCoverage = 0.9;
std::vector<Table> HeadlineTables(const std::vector<GroupSummary>& groups);
// Keyframes, map points, lost frames and timings per group.
Table DetailTable(const std::vector<GroupSummary>& groups);
// One table per swept parameter: value -> ATE and keyframes per dataset and sensor.
std::vector<Table> SweepTables(const std::vector<GroupSummary>& groups);
// Inertial runs: gyro and accelerometer bias errors (%) per group (no rows when none).
Table BiasTable(const std::vector<GroupSummary>& groups);
// Speed per group: ok/runs, then the SpeedMedians; for each peer configuration of the suite
// (selector "peer") a column with the ratio of realtime factors group / peer on the same dataset
// and sensor. No rows when no group has a realtime factor (runs from before it was measured).
Table SpeedTable(const std::vector<GroupSummary>& groups);
// Failed runs with their error (empty table when none).
Table FailureTable(const std::vector<RunResult>& results);
// Which rule created the keyframes (results.csv keyframe_reasons): one row per sensor and
// configuration (sweeps left out), one column per rule, cells = keyframes per run naming that
// rule (a "forced+imu" keyframe counts for both; suffixes such as ";busy" are dropped) and its
// share of all rule mentions. No rows when no run recorded its reasons (peers, older runs).
Table ReasonTable(const std::vector<RunResult>& results);

std::string MarkdownTable(const Table& table);

}  // namespace pkslam::bench
