// The concrete errors of one simulated rig and sequence, drawn from RealismOptions: the
// calibration SLAM will read (cameras as written to sensor.yaml / settings.yaml), the IMU's
// axis errors and initial biases, and the camera-IMU time offset. Device errors come from
// RealismOptions::device_seed, the initial IMU biases from the sequence seed.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/euroc_writer.h"
#include "sim/imu_simulator.h"
#include "sim/realism.h"

namespace pkslam::sim {

struct CameraCalibrationError {
  double dfx = 0, dfy = 0, dcx = 0, dcy = 0;  // pixels
  std::vector<double> ddistortion;            // k1, k2, p1, p2
};

struct RealismDraw {
  std::vector<CameraRig> written_cameras;                // the calibration SLAM reads
  std::vector<CameraCalibrationError> intrinsic_errors;  // per camera (written - true)
  Eigen::Matrix<double, 6, 1> rig_error = Eigen::Matrix<double, 6, 1>::Zero();  // [t m; rot rad]
  Eigen::Matrix<double, 6, 1> stereo_error = Eigen::Matrix<double, 6, 1>::Zero();
  ImuSensorErrors imu_errors;
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();   // initial, added to ImuOptions'
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();  // initial, added to ImuOptions'
  double camera_imu_offset_ms = 0.0;
};

// true_cameras: cam0 first; further cameras keep their pose relative to cam0 except for the
// stereo error, which moves them (all alike) relative to cam0.
//   written body_from_cam0 = Exp(rig_error) * true body_from_cam0
//   written cam0_from_camK = true cam0_from_camK * Exp(stereo_error)
RealismDraw DrawRealism(const RealismOptions& options, const std::vector<CameraRig>& true_cameras,
                        std::uint64_t sequence_seed);

// YAML text of the drawn values (written beside the sequence for diagnostics).
std::string RealismDrawYaml(const RealismDraw& draw);

}  // namespace pkslam::sim
