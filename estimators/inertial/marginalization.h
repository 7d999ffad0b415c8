// Marginalisation prior of the local inertial bundle adjustment
// (estimators/inertial/inertial_bundle.h; collected and applied by
// map_model/estimation/inertial_bundle_collect.h).
//
// After each local window solve the window's anchor (the keyframe just before the free
// keyframes) is marginalised out of the factors that touch it: its own prior (if it had one), the
// inertial edge and bias random walks to the next chain keyframe, and its reprojection factors
// with the map points held fixed at their estimates (conditioning on the points instead of
// marginalising them keeps the prior 15-D: no fill-in over points other threads keep
// optimising). Linearised at the solution, these factors give a Gaussian
//   E(dx) = 1/2 dx^T H dx + b^T dx,   dx = [anchor (15); next (15)] in tangent coordinates,
// and the Schur complement onto the next keyframe,
//   H' = H_nn - H_na H_aa^+ H_an,   b' = b_n - H_na H_aa^+ b_a,
// symmetrised and clamped to positive semi-definite, is the next keyframe's prior
// (core/imu/inertial_state.h InertialStatePrior), stored as a mean x_lin [+] (-H'^+ b') and the
// information H' for InertialStatePriorError (imu/imu_factors.h).
//
// Approximations: the prior is linearised once (at the solve that made it) and never
// re-linearised; the marginalised keyframe's observations may still enter later windows as a
// fixed visual-only keyframe constraining the points, so that information is counted twice
// (once through the prior, with the points taken as exact).
//
// The prior of keyframe k summarises only factors of keyframes older than k, so a later window
// whose anchor is k may use it whatever happened to the keyframes after k. It is dropped when its
// keyframe is culled (mapping/inertial_culling.h) and ignored once anything moved the map as a
// whole (map_model/estimation/inertial_prior_stamp.h PriorIsValid).
#pragma once

#include <Eigen/Core>

#include "core/imu/inertial_state.h"

namespace pkslam {

// Gaussian (H, b) over [marginalised (m); kept] variables: the Schur complement onto the kept
// ones. H_mm is inverted through its eigen-decomposition, eigenvalues below
// `relative_threshold` * the largest treated as zero (unobservable directions carry nothing).
void MarginalizeLeading(const Eigen::MatrixXd& information, const Eigen::VectorXd& gradient,
                        int marginalized, Eigen::MatrixXd* kept_information,
                        Eigen::VectorXd* kept_gradient, double relative_threshold = 1e-12);

// Symmetrises and clamps the eigenvalues to >= 0.
Eigen::MatrixXd ProjectToPsd(const Eigen::MatrixXd& matrix);

// The prior of a 15-D state linearised at (state, bias) with information H and gradient b (the
// tangent order of InertialStatePriorError): mean = lin [+] (-H^+ b), where [+] moves the pose
// as p + R rho, R Exp(phi). The map stamps are left at their defaults (StampPrior).
InertialStatePrior MakeInertialStatePrior(const NavState& state, const ImuBias& bias,
                                          const Eigen::Matrix<double, 15, 15>& information,
                                          const Eigen::Matrix<double, 15, 1>& gradient);

}  // namespace pkslam
