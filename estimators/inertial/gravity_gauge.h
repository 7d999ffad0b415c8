// Gravity-direction refinement of an inertial map, once its keyframes have turned about gravity
// (an addition to ORB-SLAM3, which fixes gravity after its second visual-inertial BA).
//
// Why: a horizontal accelerometer bias and a tilt of gravity are indistinguishable while the
// body keeps its heading. A tilt d of the world adds R_bw (g x d) to the specific force seen in
// the body frame: a constant, exactly what a bias adds. EuRoC's MAV flies its first seconds
// sideways at a nearly fixed heading (MH_01: within 160-171 deg for its first 45 s), so the
// staged initialisation (inertial_mapping.h) can end with gravity a few mrad off and the bias
// absorbing it (simulated MH_01 replay: 5.7 mrad, body-y bias 0.05 m/s^2 low for the whole
// 182 s run). Local BA cannot undo it: its fixed keyframes hold the world. Once the headings
// spread, a full visual-inertial BA whose gauge fixes only the first keyframe's position and
// yaw (the four unobservable directions of visual-inertial SLAM) leaves roll and pitch of the
// whole map free and re-estimates gravity, with per-keyframe biases joined by random walks.
#pragma once

#include <vector>

#include "core/geometry/so3.h"
#include "core/imu/imu_types.h"
#include "core/imu/inertial_state.h"

namespace pkslam {

// How well keyframes with these orientations separate a tilt of gravity from a constant
// accelerometer bias, in [0, 1]. The bias that mimics a horizontal tilt d at keyframe i is
// G_i d with G_i = R_bw_i [e_z]x (restricted to horizontal d, per unit gravity); a constant bias
// mimics d at every keyframe iff G_i d is the same for all of them. Returned: the smallest
// eigenvalue of (1/N) sum_i (G_i - mean G)^T (G_i - mean G). A fixed heading gives 0; headings
// turning about gravity give 1 - R^2, R the mean resultant length of the headings (spread
// uniformly over 65 deg: 0.10, over 120 deg: 0.32, all around: 1). 0 for fewer than 2.
double TiltObservability(const std::vector<SO3d>& world_from_body);

// The gauge of a full visual-inertial BA with free roll and pitch: a prior on `state`'s position
// and on its yaw (rotation about world z) with `information`, nothing on the rest (tangent order
// of InertialStatePriorError: [rho, phi, v, b_g, b_a]).
InertialStatePrior PositionYawPrior(const NavState& state, const ImuBias& bias, double information);

}  // namespace pkslam
