// Least-squares fits of the simulator's splines to sampled poses (motion-capture ground
// truth): smoothing splines, so millimetre-level capture noise does not turn into large
// accelerations or angular rates when the fit is differentiated for the IMU.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/geometry/so3.h"
#include "sim/bspline.h"

namespace pkslam::sim {

// Minimises sum_k |p(t_k) - p_k|^2 + lambda * integral |p'''(t)|^2 dt. lambda comes from a
// cutoff frequency: for samples at rate rho the fit is a low-pass with gain 1/2 at cutoff_hz
// (lambda = rho / (2 pi cutoff)^6); cutoff_hz <= 0 disables the jerk penalty.
// Throws Error when there are fewer samples than control points.
PositionSpline6 FitPositionSpline(const std::vector<std::int64_t>& t_ns,
                                  const std::vector<Eigen::Vector3d>& positions,
                                  const KnotGrid& grid, double cutoff_hz);

// Nonlinear least squares (Ceres) of sum_k |Log(R_k^-1 R(t_k))|^2 plus a penalty on the
// second differences of the control rotations (angular acceleration), scaled like the
// position fit by cutoff_hz (<= 0 disables it). Initialised from the nearest samples.
RotationSpline4 FitRotationSpline(const std::vector<std::int64_t>& t_ns,
                                  const std::vector<SO3d>& rotations, const KnotGrid& grid,
                                  double cutoff_hz);

// Control rotations so that a spline starts from the given rotations at the control points'
// nominal times: a cheap initialisation (also used by the random motion generator).
std::vector<SO3d> NearestSampleControls(const std::vector<std::int64_t>& t_ns,
                                        const std::vector<SO3d>& rotations, const KnotGrid& grid);

}  // namespace pkslam::sim
