// Calibrations of real cameras for tests and benchmarks (values from the EuRoC sensor.yaml files
// of V1_01_easy and the TUM-VI calibration), so camera tests run without the shared data.
#pragma once

#include <Eigen/Core>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"

namespace pkslam::testing {

inline CameraModel EurocCam0() {
  return CameraModel::Pinhole(752, 480, 458.654, 457.296, 367.215, 248.375,
                              {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05});
}

inline CameraModel EurocCam1() {
  return CameraModel::Pinhole(752, 480, 457.587, 456.134, 379.999, 255.238,
                              {-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05});
}

// TUM-VI-like equidistant fisheye.
inline CameraModel TumViKb8() {
  return CameraModel::KannalaBrandt8(512, 512, 190.98, 190.98, 254.93, 256.89,
                                     {0.00348, 0.000715, -0.00205, 0.000203});
}

// T_BS of EuRoC cam0 / cam1: body_from_cam.
inline SE3d EurocBodyFromCam0() {
  Eigen::Matrix4d m;
  m << 0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,  //
      0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,       //
      -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,   //
      0.0, 0.0, 0.0, 1.0;
  return SE3d(m);
}

inline SE3d EurocBodyFromCam1() {
  Eigen::Matrix4d m;
  m << 0.0125552670891, -0.999755099723, 0.0182237714554, -0.0198435579556,  //
      0.999598781151, 0.0130119051815, 0.0251588363115, 0.0453689425024,     //
      -0.0253898008918, 0.0179005838253, 0.999517347078, 0.00786212447038,   //
      0.0, 0.0, 0.0, 1.0;
  return SE3d(m);
}

// right_from_left = inv(T_BS_cam1) * T_BS_cam0.
inline SE3d EurocCam1FromCam0() { return EurocBodyFromCam1().Inverse() * EurocBodyFromCam0(); }

}  // namespace pkslam::testing
