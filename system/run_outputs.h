// Writes a run's output files (see run_dataset.h for the list).
#pragma once

#include "system/run_dataset.h"

namespace pkslam {

// Fills the map/keyframe/timing fields of `summary` and writes every output file.
void WriteRunOutputs(const SlamSystem& system, const RunOptions& options, RunSummary* summary);

// Peak resident memory of this process in MiB (getrusage).
double PeakMemoryMiB();

}  // namespace pkslam
