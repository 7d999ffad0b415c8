// Bias accuracy of an inertial run: the keyframes' gyro and accelerometer bias estimates
// (RUN/keyframes_imu.csv, written by `pkslam run` for inertial sensors) against the biases in
// EuRoC-format ground truth (state_groundtruth_estimate0: the simulator writes its true,
// slowly walking biases there; real EuRoC has the Vicon-based estimates).
#pragma once

#include <filesystem>
#include <optional>

#include "io/trajectory.h"

namespace pkslam::bench {

struct BiasErrors {
  // Mean over the evaluated keyframes of 100 * |b_estimate - b_true| / |b_true|.
  double gyro_pct = 0.0;
  double accel_pct = 0.0;
  int keyframes = 0;  // keyframes evaluated
};

// Keyframes at least `after_s` seconds after the run's first keyframe whose map has its IMU
// initialised, each compared with the ground-truth pose nearest in time (within 50 ms).
// std::nullopt when the file does not exist (a non-inertial run), the ground truth has no
// biases, or no keyframe qualifies. Throws InputError (file and line) for a malformed file.
std::optional<BiasErrors> EvaluateBiases(const std::filesystem::path& keyframes_imu_csv,
                                         const Trajectory& ground_truth, double after_s);

}  // namespace pkslam::bench
