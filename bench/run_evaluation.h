// Measures one finished `pkslam run` output folder against ground truth: ATE after SE(3) and
// Sim(3) alignment, RPE, counts and timings from stats.json. Also writes the small CSV files
// the plots read, so a run folder is self-contained (--collect works on copies of it):
//   plot_trajectory.csv  t_s, ground truth x y z, estimate x y z aligned by the primary alignment
//   plot_keyframes.csv   t_s, keyframe x y z (the estimate's frame: body or camera), aligned alike
#pragma once

#include <filesystem>
#include <optional>

#include "bench/results.h"

namespace pkslam::bench {

struct RunFiles {
  std::filesystem::path run_dir;                      // pkslam run --out
  std::filesystem::path dataset;                      // the dataset the run read
  std::optional<std::filesystem::path> ground_truth;  // override (default: found in dataset)
  double rpe_delta_m = 1.0;
};

// The ground truth of a dataset: mav0/state_groundtruth_estimate0/data.csv (EuRoC, body
// frame) or groundtruth.txt (TUM RGB-D, camera frame). Throws InputError when neither exists.
std::filesystem::path FindGroundTruth(const std::filesystem::path& dataset);

// Fills the measured fields of `result` (ok=true on success). Throws InputError when a file
// is missing or malformed or the trajectory cannot be aligned (too few associated poses).
void EvaluateRun(const RunFiles& files, RunResult* result);

}  // namespace pkslam::bench
