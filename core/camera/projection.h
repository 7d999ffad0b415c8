// Templated projection functions for automatic differentiation (Ceres Jets) in bundle
// adjustment and calibration. They mirror CameraModel::Project exactly (same formulas, same
// parameter meaning) but know nothing about image bounds or validity limits beyond what each
// comment states. Intrinsics are plain doubles (fixed during BA); the point is of type T.
//
// Parameter layouts (CameraModel::Params() fills them):
//   ideal pinhole:      fx, fy, cx, cy
//   radial-tangential:  fx, fy, cx, cy, k1, k2, p1, p2, k3    (OpenCV's model)
//   Kannala-Brandt 8:   fx, fy, cx, cy, k1, k2, k3, k4        (OpenCV fisheye model)
#pragma once

#include <cmath>

namespace pkslam::projection {

// Points closer to the image plane than this (in the camera's z, metres) are not projected by
// the pinhole models: their pixels are meaningless and their derivatives explode.
inline constexpr double kMinDepth = 1e-6;

// Below this squared ratio (x^2 + y^2) / z^2 a KB8 point is treated as on the optical axis,
// where the model equals the pinhole to first order (avoids sqrt(0), whose Jet derivative is
// infinite). The neglected terms are ~1e-16 relative.
inline constexpr double kKbAxisRatioSq = 1e-16;

// Ideal pinhole (undistorted pixel coordinates, as ORB-SLAM's BA uses with undistorted
// keypoints). Returns false (uv untouched) when z <= kMinDepth.
template <typename T>
bool ProjectIdealPinhole(const double* params, const T* p_camera, T* uv) {
  if (!(p_camera[2] > T(kMinDepth))) return false;
  const T inv_z = T(1) / p_camera[2];
  uv[0] = params[0] * (p_camera[0] * inv_z) + params[2];
  uv[1] = params[1] * (p_camera[1] * inv_z) + params[3];
  return true;
}

// Pinhole with OpenCV's radial-tangential distortion (k1, k2, p1, p2, k3). Returns false when
// z <= kMinDepth. Unlike CameraModel::Project it does not reject points beyond the radius where
// the distortion polynomial folds back; keep such points out of the optimisation. The
// parameters may be Jets too (P = T: calibration, estimators/calibration).
template <typename P, typename T>
bool ProjectRadTan(const P* params, const T* p_camera, T* uv) {
  if (!(p_camera[2] > T(kMinDepth))) return false;
  const T inv_z = T(1) / p_camera[2];
  const T x = p_camera[0] * inv_z;
  const T y = p_camera[1] * inv_z;
  const P k1 = params[4], k2 = params[5], p1 = params[6], p2 = params[7], k3 = params[8];
  const T x2 = x * x;
  const T y2 = y * y;
  const T xy = x * y;
  const T r2 = x2 + y2;
  const T radial = T(1) + r2 * (k1 + r2 * (k2 + r2 * k3));
  const T xd = x * radial + T(2.0 * p1) * xy + p2 * (r2 + T(2) * x2);
  const T yd = y * radial + p1 * (r2 + T(2) * y2) + T(2.0 * p2) * xy;
  uv[0] = params[0] * xd + params[2];
  uv[1] = params[1] * yd + params[3];
  return true;
}

// Kannala-Brandt equidistant fisheye with four coefficients (OpenCV fisheye, ORB-SLAM3
// KannalaBrandt8): theta = atan2(sqrt(x^2 + y^2), z), theta_d = theta (1 + k1 theta^2 + ... +
// k4 theta^8), pixel = f * theta_d * (x, y) / sqrt(x^2 + y^2) + c. Works beyond 90 degrees
// (z <= 0). Returns false only for points on the optical axis behind the camera; the caller
// must keep points within the model's monotonic range (CameraModel::max_theta()).
template <typename T>
bool ProjectKannalaBrandt8(const double* params, const T* p_camera, T* uv) {
  using std::atan2;
  using std::sqrt;
  const T& x = p_camera[0];
  const T& y = p_camera[1];
  const T& z = p_camera[2];
  const T r2 = x * x + y * y;
  if (!(r2 > T(kKbAxisRatioSq) * z * z)) {  // also catches the origin
    if (!(z > T(0))) return false;
    const T inv_z = T(1) / z;
    uv[0] = params[0] * (x * inv_z) + params[2];
    uv[1] = params[1] * (y * inv_z) + params[3];
    return true;
  }
  const T r = sqrt(r2);
  const T theta = atan2(r, z);
  const T t2 = theta * theta;
  const T theta_d =
      theta * (T(1) + t2 * (params[4] + t2 * (params[5] + t2 * (params[6] + t2 * params[7]))));
  const T scale = theta_d / r;
  uv[0] = params[0] * (scale * x) + params[2];
  uv[1] = params[1] * (scale * y) + params[3];
  return true;
}

}  // namespace pkslam::projection
