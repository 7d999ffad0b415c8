// Kalibr's calibration files, as TUM-VI ships them beside its EuRoC-layout folders
// (dso/camchain.yaml, dso/imu_config.yaml) in place of EuRoC's sensor.yaml files:
//   camchain.yaml   camN: {T_cam_imu: 4x4 rows, camera_model: pinhole, distortion_model:
//                   equidistant | radtan, distortion_coeffs, intrinsics [fu, fv, pu, pv],
//                   resolution [w, h], (T_cn_cnm1, cam_overlaps, rostopic)}
//   imu.yaml        {accelerometer_noise_density, accelerometer_random_walk,
//                   gyroscope_noise_density, gyroscope_random_walk, update_rate}
// read into the sensors the EuRoC reader uses (the body is the IMU: T_BS = T_cam_imu^-1), and
// written from them.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "io/euroc_sensor.h"

namespace pkslam {

// camN entries in order (cam0, cam1, ...); rate_hz is left 0 (Kalibr does not record it).
// Throws InputError naming the file (and line) for a missing key, a wrong count, an unknown
// model or a T_cam_imu that is not rigid.
std::vector<EurocCameraSensor> ReadKalibrCamchain(const std::filesystem::path& camchain_yaml);
EurocImuSensor ReadKalibrImu(const std::filesystem::path& imu_yaml);

// The camchain.yaml and imu.yaml next to a TUM-VI folder (ROOT/dso/, ROOT/, ROOT/mav0/), if any.
std::optional<std::filesystem::path> FindKalibrCamchain(const std::filesystem::path& mav0);
std::optional<std::filesystem::path> FindKalibrImu(const std::filesystem::path& mav0);

void WriteKalibrCamchain(const std::vector<EurocCameraSensor>& cameras,
                         const std::filesystem::path& file);
void WriteKalibrImu(const EurocImuSensor& imu, const std::filesystem::path& file);

// TUM-VI's extra files for an EuRoC folder (`pkslam simulate --camera tumvi`): ROOT/dso/
// camchain.yaml and imu_config.yaml from the sensor.yaml files, and mav0/mocap0/data.csv (time,
// position, quaternion w x y z) from the ground truth; with them the folder reads as TUM-VI's
// also once the sensor.yaml files are gone.
void WriteTumViFiles(const std::filesystem::path& root);

}  // namespace pkslam
