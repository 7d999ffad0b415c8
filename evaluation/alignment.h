// Aligning an estimated trajectory to the reference before measuring absolute errors.
//
// All methods return ref_from_est, the transform T minimising sum_i |p_ref_i - T p_est_i|^2
// over associated positions, within the method's family:
//   se3     rotation + translation (Umeyama 1991 without scale), evo's `--align`;
//   sim3    rotation + translation + scale (Umeyama with scale), evo's `--align --correct_scale`;
//   posyaw  translation + rotation about the reference's z axis only (4-DoF; the directions
//           a visual-inertial system cannot observe, with gravity along z), the closed form of
//           Zhang & Scaramuzza's rpg_trajectory_evaluation using all poses;
//   none    identity.
// Umeyama's rotation includes the determinant fix (a reflection is never returned).
#pragma once

#include <Eigen/Core>
#include <string_view>
#include <vector>

#include "core/geometry/sim3.h"

namespace pkslam {

enum class AlignmentMethod { kNone, kSE3, kSim3, kPosYaw };

// "none", "se3", "sim3", "posyaw"; throws OptionError otherwise.
AlignmentMethod ParseAlignmentMethod(std::string_view name);
std::string_view AlignmentMethodName(AlignmentMethod method);

// The fewest point pairs a method needs (se3/sim3: 3, posyaw: 2, none: 0).
std::size_t MinimumAlignmentPairs(AlignmentMethod method);

// ref_from_est by `method`. est and ref have equal sizes >= MinimumAlignmentPairs(method);
// sim3 also needs the estimate's points not all equal (the scale is undefined otherwise).
// Violations throw pkslam::Error.
Sim3d AlignPositions(const std::vector<Eigen::Vector3d>& est,
                     const std::vector<Eigen::Vector3d>& ref, AlignmentMethod method);

// Least-squares similarity (with_scale) or rigid transform ref_from_est (Umeyama 1991).
Sim3d UmeyamaAlignment(const std::vector<Eigen::Vector3d>& est,
                       const std::vector<Eigen::Vector3d>& ref, bool with_scale);

// Least-squares translation + yaw (rotation about z) ref_from_est, scale 1.
Sim3d PositionYawAlignment(const std::vector<Eigen::Vector3d>& est,
                           const std::vector<Eigen::Vector3d>& ref);

}  // namespace pkslam
