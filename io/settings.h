// Run settings: cameras, stereo rig, IMU, RGB-D depth scale, ORB extractor and keyframe
// selector parameters. Read from an ORB-SLAM3 v1.0 settings file unchanged (OpenCV
// FileStorage YAML), written back in the same format, or built from a EuRoC dataset's
// sensor.yaml files (io/settings_euroc.h).
//
// Frame conventions. Camera frames are optical (x right, y down, z forward); "left"/camera1
// is cam0, "right"/camera2 is cam1; body is the IMU frame.
//   right_from_left: p_right = right_from_left * p_left. ORB-SLAM3's Stereo.T_c1_c2 is
//     T_c1_c2 = camera1_from_camera2 = left_from_right = right_from_left^-1; its translation
//     is the right camera's centre in left coordinates (about +baseline along x).
//   body_from_cam0: p_body = body_from_cam0 * p_cam0; ORB-SLAM3's IMU.T_b_c1 as is, and
//     EuRoC cam0's T_BS.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"
#include "core/sensor/camera_rig.h"

namespace pkslam {

// Whether two camera models have the same type, size, intrinsics and distortion (exactly).
bool SameCalibration(const CameraModel& a, const CameraModel& b);

// ORBextractor.* (ORB-SLAM3's names); the defaults are its EuRoC stereo-inertial values.
struct OrbExtractorSettings {
  int n_features = 1200;      // ORBextractor.nFeatures: features per image
  double scale_factor = 1.2;  // ORBextractor.scaleFactor: pyramid scale between levels
  int n_levels = 8;           // ORBextractor.nLevels: pyramid levels
  int ini_th_fast = 20;       // ORBextractor.iniThFAST: FAST threshold
  int min_th_fast = 7;        // ORBextractor.minThFAST: fallback threshold in empty cells

  bool operator==(const OrbExtractorSettings&) const = default;
};

struct Settings {
  // Camera.type "Rectified": images are already rectified and undistorted; camera1 has no
  // distortion, there is no camera2, and the baseline is Stereo.b.
  bool rectified_stereo = false;
  // Camera1.*: the left or only camera, as calibrated (raw, possibly distorted), with
  // Camera.width/height. Pinhole (radial-tangential) or Kannala-Brandt 8 per Camera.type.
  CameraModel camera1;
  // Camera2.*: the right camera of an unrectified stereo rig (same type and size).
  std::optional<CameraModel> camera2;
  double fps = 0;  // Camera.fps [Hz]
  // Camera.RGB: 1 = colour images are RGB ordered, 0 = BGR (ignored for grey images).
  // Optional, default 1.
  bool rgb_order = true;
  // Stereo extrinsic (see the frame conventions above). Set for unrectified stereo
  // (from Stereo.T_c1_c2) and for rectified stereo (identity rotation, -b along x).
  std::optional<SE3d> right_from_left;
  // Stereo.b [m]: baseline of a rectified pair (required with rectified_stereo), or the
  // virtual baseline of an RGB-D camera (sets bf and the close-depth threshold). Not with
  // camera2, whose baseline is |right_from_left.translation()|.
  std::optional<double> stereo_baseline_m;
  // Stereo.ThDepth: points closer than ThDepth baselines are "close". Optional, default 60.
  double th_depth = 60;
  // IMU.T_b_c1 (see the frame conventions above); set iff imu is set.
  std::optional<SE3d> body_from_cam0;
  // IMU.NoiseGyro -> gyro_noise_density, IMU.NoiseAcc -> accel_noise_density, IMU.GyroWalk
  // -> gyro_random_walk, IMU.AccWalk -> accel_random_walk, IMU.Frequency -> rate_hz.
  std::optional<ImuNoise> imu;
  // IMU.TimeOffset [s] (pkslam; optional, default 0): the image stamped t was taken at IMU time
  // t + time_offset_s (Kalibr's timeshift_cam_imu). ORB-SLAM3 has no such key and ignores it.
  double time_offset_s = 0.0;
  // IMU.GyroScaleX/Y/Z (pkslam; optional, default 0): the gyroscope's per-axis scale-factor error
  // (fraction: it reads 1 + k times the true rate). ORB-SLAM3 has no such keys and ignores them.
  Eigen::Vector3d gyro_scale = Eigen::Vector3d::Zero();
  // IMU.AccelAxes (pkslam; optional, default 0): a 3x3 !!opencv-matrix E, the accelerometer's
  // axis errors (scale factors on the diagonal, misalignment in rad off it: it reads (I + E) times
  // the true specific force). ORB-SLAM3 has no such key and ignores it.
  Eigen::Matrix3d accel_axes = Eigen::Matrix3d::Zero();
  // RGBD.DepthMapFactor: depth image value per metre (TUM: 5000). Optional.
  std::optional<double> depth_map_factor;
  // RGBD.DepthNoise (pkslam): k of the depth noise sigma_z = k z^2 [1/m]; optional, default
  // Kinect v1 (core/sensor/camera_rig.h).
  std::optional<double> depth_noise_k;
  OrbExtractorSettings orb;                // ORBextractor.*: optional, defaults above
  std::map<std::string, double> keyframe;  // Keyframe.<name>: selector parameters, free-form

  bool IsStereo() const { return right_from_left.has_value(); }
  // Stereo baseline [m] (Stereo.b, or |translation| of right_from_left); 0 if not stereo.
  double BaselineM() const;
  // baseline * camera1.fx [px*m] (ORB-SLAM3's bf; after rectification use the rectified fx).
  double Bf() const;

  // Throws OptionError naming the offending field.
  void Check() const;
};

// Reads an ORB-SLAM3 v1.0 settings file (File.version "1.0"). Required: File.version,
// Camera.type (PinHole | KannalaBrandt8 | Rectified), Camera1.fx/fy/cx/cy, Camera.width,
// Camera.height, Camera.fps; PinHole distortion Camera1.k1, k2, p1, p2 (all or none; k3
// optional); KannalaBrandt8 Camera1.k1..k4; Camera2.* and Stereo.T_c1_c2 together (stereo);
// Stereo.b for Rectified (optional otherwise: RGB-D virtual baseline); if any IMU.* key is
// present: IMU.NoiseGyro, NoiseAcc, GyroWalk, AccWalk, Frequency, T_b_c1. Optional keys
// default as documented on Settings. Unknown keys (Viewer.*, System.*, ...) are ignored;
// Camera.newWidth/newHeight (resizing) is rejected. Throws InputError naming the file, the
// key and its line.
Settings ReadOrbSlam3Settings(const std::filesystem::path& file);

// Writes `settings` (after Check()) in the same format. Matrices are written with dt: f, as
// ORB-SLAM3 reads them as float (pkslam's IMU.AccelAxes with dt: d), but with every double
// digit, so reading the file back here gives the same values. Throws Error if the file cannot
// be written.
void WriteOrbSlam3Settings(const Settings& settings, const std::filesystem::path& file);

}  // namespace pkslam
