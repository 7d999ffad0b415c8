// Writes a run's output files (see run_dataset.h for the list).
#pragma once

#include "system/run_dataset.h"

namespace pkslam {

// The trajectory-so-far, appended frame by frame while a run goes (online poses as tracking
// estimated them); removed when the run's outputs are complete. A run killed with SIGKILL or
// by a crash leaves it, readable by `pkslam eval`.
inline constexpr const char* kPartialTrajectory = "trajectory.txt.partial";

// Writes trajectory.txt (and trajectory_body.txt); returns the number of poses. Called first
// by WriteRunOutputs, and before the shutdown of an interrupted run.
int WriteTrajectoryOutputs(const SlamSystem& system, const RunOptions& options);

// Fills the map/keyframe/timing fields of `summary` and writes every output file.
void WriteRunOutputs(const SlamSystem& system, const RunOptions& options, RunSummary* summary);

// Removes the files an earlier run may have left in `out` (a re-run into the same folder left
// e.g. a stereo run's trajectory_body.txt beside a monocular run's outputs, or a trace from an
// earlier --trace run). Throws Error naming the file when one cannot be removed.
void RemoveRunOutputs(const std::filesystem::path& out);

}  // namespace pkslam
