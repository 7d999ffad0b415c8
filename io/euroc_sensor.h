// EuRoC ASL sensor descriptions (mav0/<sensor>/sensor.yaml). T_BS maps sensor coordinates to
// body (IMU) coordinates: p_body = T_BS * p_sensor, i.e. body_from_sensor.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"
#include "core/imu/imu_types.h"

namespace pkslam {

struct EurocCameraSensor {
  SE3d body_from_camera;                        // T_BS
  double rate_hz = 0;                           // rate_hz
  int width = 0;                                // resolution[0]
  int height = 0;                               // resolution[1]
  std::string camera_model;                     // "pinhole" (the only model EuRoC/TUM-VI use)
  std::array<double, 4> intrinsics{};           // fu, fv, cu, cv
  std::string distortion_model;                 // "radial-tangential" | "equidistant"
  std::vector<double> distortion_coefficients;  // radtan: k1 k2 p1 p2 [k3]; equidistant: k1..k4
  // Kalibr's camera-IMU time shift (t_imu = t_cam + shift, seconds): not in EuRoC's files
  // (0), written by pkslam's calibration estimates (OUT/calibration/cam0/sensor.yaml).
  double timeshift_cam_imu = 0;
};

struct EurocImuSensor {
  SE3d body_from_imu;                      // T_BS (identity on EuRoC: the IMU is the body)
  double rate_hz = 0;                      // rate_hz
  double gyroscope_noise_density = 0;      // [rad/s/sqrt(Hz)]
  double gyroscope_random_walk = 0;        // [rad/s^2/sqrt(Hz)]
  double accelerometer_noise_density = 0;  // [m/s^2/sqrt(Hz)]
  double accelerometer_random_walk = 0;    // [m/s^3/sqrt(Hz)]
  // pkslam's key gyroscope_scale_error (optional, not in EuRoC's files): the gyro reads
  // (1 + k) times the true rate per axis (written by pkslam's calibration estimates).
  Eigen::Vector3d gyroscope_scale_error = Eigen::Vector3d::Zero();
  // pkslam's key accelerometer_axis_errors (optional, not in EuRoC's files; 9 numbers,
  // row-major): the accelerometer reads (I + E) times the true specific force (scale factors on
  // the diagonal, misalignment angles in rad off it; written by pkslam's calibration estimates).
  Eigen::Matrix3d accelerometer_axis_errors = Eigen::Matrix3d::Zero();
};

// A camera's description from a camera model: pinhole, its intrinsics, "equidistant" for a
// Kannala-Brandt model and "radial-tangential" otherwise; timeshift_cam_imu as given.
EurocCameraSensor EurocCameraSensorOf(const CameraModel& camera, const SE3d& body_from_camera,
                                      double rate_hz, double timeshift_cam_imu = 0.0);
// An IMU at the body frame (T_BS identity, as EuRoC's) with `noise`'s densities and rate.
EurocImuSensor EurocImuSensorOf(
    const ImuNoise& noise, const Eigen::Vector3d& gyroscope_scale_error = Eigen::Vector3d::Zero(),
    const Eigen::Matrix3d& accelerometer_axis_errors = Eigen::Matrix3d::Zero());

// Parse and validate (positive rate and size, known models, coefficient counts, rigid T_BS).
// Throws InputError naming the file and key.
EurocCameraSensor ReadEurocCameraSensor(const std::filesystem::path& sensor_yaml);
EurocImuSensor ReadEurocImuSensor(const std::filesystem::path& sensor_yaml);

// A camera's sensor.yaml in EuRoC's layout (%YAML:1.0 header, T_BS rows under the bracket);
// timeshift_cam_imu only when not 0. Doubles are written with every digit.
std::string EurocCameraSensorYaml(const EurocCameraSensor& camera, const std::string& comment);
// An IMU's sensor.yaml in EuRoC's layout; gyroscope_scale_error and accelerometer_axis_errors
// only when not 0.
std::string EurocImuSensorYaml(const EurocImuSensor& imu, const std::string& comment);

}  // namespace pkslam
