// One row of results.csv per run, and the CSV files that hold them. Each finished run folder
// holds its row as result.csv (the resumability marker and what --collect merges).
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "bench/matrix.h"

namespace pkslam::bench {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What made a run (empty in files written before it), so statistics never pool different
// builds unknowingly (bench/bench_statistics.py). A re-evaluation keeps it whole.
struct RunProvenance {
  std::string pkslam_commit;  // the commit of the pkslam that ran it (peers: that evaluated it)
  std::string executable;     // ExecutableId of that pkslam executable
  std::string peer_build;     // peers: the first line of the run folder's peer_build.txt
  int cores = 0;              // hardware threads of the machine
  int jobs = 0;               // runs the bench executed at once
  std::string finished_utc;   // when the run finished (ISO 8601, UTC)
};

struct RunResult {
  int index = 0;
  std::string run_id;
  std::string dataset;
  std::string sensor;
  std::string config;
  std::string selector;
  std::string params;  // FormatParams
  std::string sweep_param;
  double sweep_value = kNaN;
  std::uint64_t seed = 0;
  std::string baseline;       // the suite's baseline configuration
  bool ok = false;            // run and evaluation succeeded
  std::string error;          // why not, when !ok
  std::string alignment;      // "se3" or "sim3": the one ate_m uses (sim3 for monocular)
  double ate_m = kNaN;        // primary ATE RMSE (m)
  double ate_se3_m = kNaN;    // ATE RMSE after SE(3) alignment (m)
  double ate_sim3_m = kNaN;   // ATE RMSE after Sim(3) alignment (m)
  double scale = kNaN;        // the Sim(3) alignment's scale
  double rpe_trans_m = kNaN;  // RPE translation RMSE over pose pairs rpe_delta_m apart
  double rpe_rot_deg = kNaN;
  double coverage = kNaN;  // fraction of ground-truth poses with an associated estimate
  int frames = 0;
  int keyframes = 0;
  int map_points = 0;
  int lost_frames = 0;
  double wall_s = kNaN;
  double median_tracking_ms = kNaN;
  // Optional trailing columns (results.csv files written before they existed still read).
  // Points of the run's dense cloud (runs with `dense`; empty otherwise).
  double dense_points = kNaN;
  // Inertial runs on ground truth with biases: mean relative bias error (%) of the keyframes
  // from 15 s after the first one (bias_evaluation.h); empty otherwise.
  double gyro_bias_err_pct = kNaN;
  double accel_bias_err_pct = kNaN;
  // Speed, from the run's stats.json (empty when it lacks them: older pkslam runs, peers).
  double realtime_factor = kNaN;    // sequence duration / wall time (> 1: faster than real time)
  double p95_tracking_ms = kNaN;    // 95th percentile of the per-frame tracking times
  double mapping_ms_per_kf = kNaN;  // median local mapping time per keyframe
  double cpu_s = kNaN;              // CPU time of the whole process (every thread)
  double peak_memory_mib = kNaN;    // peak resident memory
  double sequence_s = kNaN;         // duration of the sequence the run processed
  double mapping_cpu_s = kNaN;      // CPU time of local mapping (equal-budget comparisons)
  double degraded = kNaN;           // 1: the run warned about degraded input (stats.json)
  // Keyframes per creating rule, "reason=count" separated by spaces (stats.json
  // keyframe_reasons; empty for peers and older runs).
  std::string keyframe_reasons;
  // 1: the run's own signals call its estimate suspect (stats.json "estimate", or for runs
  // written before it, a loss for good in loop_closing.new_map_or_reset_times_s); NaN: unknown.
  double suspect = kNaN;
  // Keyframes created (culled ones too): stats.json keyframes_created; peers that count them.
  double keyframes_created = kNaN;
  RunProvenance provenance;
};

// The headline alignment of a run: `suite_choice` when "se3"/"sim3"; for "auto" "sim3" for
// monocular sensors (scale unobservable) and "se3" otherwise.
std::string PrimaryAlignment(const std::string& sensor, const std::string& suite_choice);

// A result with the run's identity filled in (not yet measured).
RunResult ResultSkeleton(const RunSpec& run, const Suite& suite);

std::vector<std::string> ResultColumns();
std::string ResultCsvHeader();
std::string ResultCsvRow(const RunResult& r);

// Writes header + rows (atomically: temp file then rename).
void WriteResultsCsv(const std::filesystem::path& file, const std::vector<RunResult>& results);
// Throws InputError(file, line) for a malformed file (wrong columns, bad numbers).
std::vector<RunResult> ReadResultsCsv(const std::filesystem::path& file);

// CSV field splitting with RFC 4180 quotes (exposed for tests).
std::vector<std::string> SplitCsvLine(const std::string& line);
std::string CsvField(const std::string& text);

}  // namespace pkslam::bench
