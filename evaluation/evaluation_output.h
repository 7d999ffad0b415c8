// Files of one evaluation for people and plots (`pkslam eval --save-aligned / --save-errors /
// --plot`), as evo's --save_results and rpg_trajectory_evaluation's saved_results hold them:
//   LABEL_aligned.tum    the matched estimate poses after alignment (TUM: t x y z qx qy qz qw)
//   LABEL_poses.csv      per matched pose: time, truth and aligned estimate (position, roll /
//                        pitch / yaw in deg), the ATE translation and rotation error, and the
//                        distance travelled along the truth
//   LABEL_rpe.csv        per RPE pair: start and end time, translation and rotation error
//   LABEL_segments.csv   per segment pair: length, start and end time, translation (m, %),
//                        rotation (deg, deg/m), yaw and gravity errors (segment_error.h)
// Times are the estimate's stamps in seconds. Roll, pitch and yaw decompose world_from_sensor
// as Rz(yaw) Ry(pitch) Rx(roll) (evo's rpy plot).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "evaluation/evaluate.h"
#include "io/trajectory.h"

namespace pkslam {

// A file-name-safe label for an estimate: its file's stem, or its folder's name when the stem is
// a generic one (trajectory, trajectory_body, f_dataset-..., CameraTrajectory...).
std::string EstimateLabel(const std::filesystem::path& estimate_file);

// Labels for several estimates, made unique by appending _2, _3 ... to repeats.
std::vector<std::string> UniqueLabels(const std::vector<std::filesystem::path>& estimate_files);

// The aligned estimate as a trajectory (the estimate's stamps; repeated stamps from evo
// association are written once).
Trajectory AlignedEstimate(const Trajectory& est, const EvaluationResult& result);

// Writes the files above into `dir` (created); throws OutputError naming a file it cannot write.
void WriteAlignedEstimate(const std::filesystem::path& dir, const std::string& label,
                          const Trajectory& est, const EvaluationResult& result);
void WriteErrorFiles(const std::filesystem::path& dir, const std::string& label,
                     const Trajectory& est, const EvaluationResult& result);

// Only LABEL_segments.csv's content, into `file` (nothing when the result has no segments).
void WriteSegmentErrorsCsv(const std::filesystem::path& file, const Trajectory& est,
                           const EvaluationResult& result);

// Several estimates against one truth, one line each: pairs, scale, ATE rmse / mean / median /
// max, ATE rotation rmse, RPE translation and rotation rmse.
std::string FormatComparisonTable(const std::vector<std::string>& labels,
                                  const std::vector<EvaluationResult>& results);

}  // namespace pkslam
