// The trajectories of a `pkslam view` page aligned to the ground truth (issue 41): the run's
// own, further runs, and bare trajectory files (another system's estimate, such as ORB-SLAM3's
// f_*.txt). Each is aligned to the ground truth the way `pkslam eval` and the bench align a run
// (SE(3), or Sim(3) for visual-only monocular runs and when asked for bare files), so all sit
// in the ground truth's world and share the page.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "core/geometry/sim3.h"
#include "evaluation/alignment.h"
#include "io/trajectory.h"
#include "viewer/view_data.h"

namespace pkslam {

// An estimate in the ground truth's world, every pose with its ATE (evo's: associate by time,
// align, translation error; -1 for a pose without a partner in the ground truth).
struct AlignedEstimate {
  std::vector<ViewPose> poses;
  Sim3d world_from_map;  // the alignment: the ground truth's world from the estimate's
  double ate_rmse_m = -1;
};

// Throws InputError naming the estimate's file when it cannot be aligned (no pose pairs in
// time, too few of them); a near-constant rotation between the two is allowed (the page
// draws, it does not judge the frame).
AlignedEstimate AlignToGroundTruth(const Trajectory& ground_truth, const Trajectory& estimate,
                                   AlignmentMethod method);

// The name of a run folder (its last component, also for "run/" or ".").
std::string RunFolderName(const std::filesystem::path& run);

// RUN/keyframes.txt moved into the shown world (reasons left empty); none without the file.
std::vector<ViewKeyframe> ReadRunKeyframes(const std::filesystem::path& run,
                                           const Sim3d& world_from_map);

// A further run against the ground truth file, as LoadViewData takes the first run: camera
// poses (trajectory.txt) against the ground truth moved into its camera, aligned by SE(3), or
// Sim(3) for a visual-only monocular run; with its keyframes. InputError for a missing folder.
ViewTrack LoadRunTrack(const std::filesystem::path& run,
                       const std::filesystem::path& ground_truth_file);

// A bare trajectory file moved into the sensor frame the first run is compared in
// (`shown_in_camera`), with `first_run`'s body_from_camera.txt when its frame differs, and
// aligned to `ground_truth` (already in that frame) by `method`. InputError naming the file
// when it is missing or unreadable, or the extrinsic it needs is absent.
ViewTrack LoadTrajectoryTrack(const ViewTrajectoryFile& file, const Trajectory& ground_truth,
                              bool shown_in_camera, const std::filesystem::path& first_run,
                              AlignmentMethod method);

}  // namespace pkslam
