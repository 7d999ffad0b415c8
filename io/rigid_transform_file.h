// A rigid transform in a small text file (the camera-body extrinsic a run writes beside its
// trajectories), and moving a trajectory to another rigidly attached sensor.
//
// Format: '#' comment lines, then four rows of four numbers (the row-major 4x4 matrix, metres).
// Used to compare monocular runs with body-frame ground truth: their maps have no metric scale,
// so the metric lever arm cannot be applied to the estimate; the ground truth is moved into the
// camera instead (pkslam eval --body-from-camera, the bench).
#pragma once

#include <filesystem>
#include <Eigen/Core>
#include <optional>
#include <string>
#include <string_view>

#include "core/geometry/se3.h"
#include "io/trajectory.h"

namespace pkslam {

// Throws pkslam::Error when the file cannot be written.
void WriteRigidTransform(const SE3d& transform, const std::filesystem::path& file,
                         std::string_view comment);
// Throws InputError (file and line) for a missing file, a row without four numbers, a wrong
// row count, a last row other than 0 0 0 1 or a rotation block that is not a rotation (1e-6).
SE3d ReadRigidTransform(const std::filesystem::path& file);

// What keeps a 4x4 matrix from being a rigid transform, or nothing: a value that is not finite,
// a last row other than 0 0 0 1, or a rotation block that is not a rotation (1e-6). The file
// reader and the library's pose arguments share it.
struct RigidTransformProblem {
  std::string what;
  bool in_last_row = false;
};
std::optional<RigidTransformProblem> FindRigidTransformProblem(const Eigen::Matrix4d& m);

// world_from_b = world_from_a * a_from_b for every pose; per-pose extras are dropped (the
// velocity of another point of the body differs).
Trajectory ChangeSensorFrame(const Trajectory& world_from_a, const SE3d& a_from_b);

// A run's trajectory and the ground truth it is compared with, in the same sensor frame.
struct RunAndGroundTruth {
  Trajectory ground_truth;
  Trajectory estimate;
  std::filesystem::path estimate_file;
};
// Body (EuRoC) ground truth is compared with RUN/trajectory_body.txt, except for visual-only
// monocular runs: their camera trajectory.txt is compared with the ground truth moved into
// the camera through RUN/body_from_camera.txt. `monocular`: the run's sensor when the caller
// knows it (a monocular run of an older version without the extrinsic file keeps its body
// trajectory); std::nullopt: a run without trajectory_body.txt is taken as monocular. Camera
// (TUM) ground truth is compared with RUN/trajectory.txt. Throws InputError for missing or
// malformed files.
RunAndGroundTruth ReadRunAndGroundTruth(const std::filesystem::path& run_dir,
                                        const std::filesystem::path& gt_file,
                                        std::optional<bool> monocular);

}  // namespace pkslam
