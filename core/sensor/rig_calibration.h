// The calibration of a camera rig, as a calibration file states it and as online calibration
// (docs/calibration.md) re-estimates it, and the CameraRig tracking works with, built from it.
//
// A RigCalibration holds the physical cameras (before rectification), their extrinsics and the
// camera-IMU time offset: the quantities a calibration file gets wrong. Everything tracking
// derives from them (the rectified camera, bf, body_from_camera of the rectified camera, the
// remap tables) is rebuilt by BuildRig, so a new estimate gives a new RigSetup. A RigShape holds
// what no calibration changes (sensor, rate, ORB pyramid, IMU noise, RGB-D depth scale).
//
// Keypoint measurements move between two setups of one rig through the physical pixels
// (RigWarp): a stereo keypoint found in an image rectified with one estimate is unrectified with
// it and rectified with the next; a monocular keypoint keeps its raw pixel and is undistorted
// with the new camera.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/camera/fisheye_undistortion.h"
#include "core/camera/stereo_rectification.h"
#include "core/geometry/se3.h"
#include "core/imu/imu_types.h"
#include "core/sensor/camera_rig.h"
#include "core/sensor/scale_pyramid.h"
#include "core/sensor/sensor.h"

namespace pkslam {

struct RigCalibration {
  // cam0 and, for a stereo rig, cam1, as they take the images SLAM reads: distorted pinholes, or
  // two identical ideal pinholes for an already rectified pair.
  std::vector<CameraModel> cameras;
  // p_body = body_from_cam0 * p_cam0 (the IMU frame; identity without an IMU).
  SE3d body_from_cam0;
  // Stereo: p_cam1 = cam1_from_cam0 * p_cam0 (ORB-SLAM3's Stereo.T_c1_c2 inverted).
  SE3d cam1_from_cam0;
  // Camera-IMU time offset (s): the image stamped t was taken at IMU time t + time_offset_s
  // (Kalibr's timeshift_cam_imu convention: t_imu = t_cam + shift).
  double time_offset_s = 0.0;
  // The gyroscope's per-axis scale-factor error (fraction): it reads (1 + gyro_scale) times the
  // true rate about each IMU axis, so its samples are divided by 1 + gyro_scale before they are
  // integrated. Calibration files do not state it (0); online calibration estimates it.
  Eigen::Vector3d gyro_scale = Eigen::Vector3d::Zero();
  // The accelerometer's axis errors E (scale factors on the diagonal, axis misalignment off it,
  // small angles in rad): it reads (I + E) times the true specific force in the IMU frame, so its
  // samples are multiplied by (I + E)^-1 before they are integrated and the accelerometer bias
  // lives in the corrected axes. Calibration files do not state it (0); online calibration
  // estimates it.
  Eigen::Matrix3d accel_axes = Eigen::Matrix3d::Zero();

  bool stereo() const { return cameras.size() >= 2; }
  SE3d body_from_cam1() const { return body_from_cam0 * cam1_from_cam0.Inverse(); }
};

// The parts of a rig that calibration does not change.
struct RigShape {
  Sensor sensor = Sensor::kStereo;
  double fps = 20.0;
  ScalePyramid pyramid;
  // Close/far split in baselines (Stereo.ThDepth).
  double th_depth_baselines = 60.0;
  std::optional<ImuNoise> imu;
  // Stereo images arrive rectified (Camera.type Rectified): a calibration that is still the
  // ideal side-by-side pair needs no rectification.
  bool rectified_input = false;
  // RGB-D: depth image factor, depth noise k (CameraRig defaults when unset), virtual baseline.
  double depth_factor = 5000.0;
  std::optional<double> depth_noise_k;
  double virtual_baseline = 0.08;
};

struct RigSetup {
  std::shared_ptr<const CameraRig> rig;
  // Set when stereo images must be rectified before tracking.
  std::optional<StereoRectification> rectification;
  // Set when a monocular fisheye's images must be undistorted to a pinhole view before tracking.
  std::optional<FisheyeUndistortion> undistortion;
};

// Whether `estimate` can be a calibration of the rig `file` describes, not of another camera:
// same cameras and image sizes, focal lengths within 3%, principal points within 20 px,
// extrinsics within 3 deg and 3 cm, time offsets within 50 ms, gyro scale and accelerometer axis
// errors within 5% (several times the error of a bad calibration, far below the difference
// between two rigs). Throws OptionError naming the first difference.
void CheckSameRig(const RigCalibration& file, const RigCalibration& estimate);

// Throws OptionError for calibrations the pipeline cannot track with (an RGB-D fisheye, stereo
// without a second camera, a vertical or swapped stereo pair). A monocular fisheye is tracked in
// its pinhole view (FisheyeUndistortion), a fisheye pair rectified (StereoRectification).
RigSetup BuildRig(const RigCalibration& calibration, const RigShape& shape);

// Keypoint measurements of one setup expressed in another's image coordinates (same sensor):
// rectified stereo pixels through the physical ones; monocular / RGB-D keypoints by their raw
// pixel. All functions return nullopt when a pixel cannot be mapped (outside the models' range).
class RigWarp {
 public:
  RigWarp(const RigSetup& from, const RigSetup& to) : from_(from), to_(to) {}

  // A tracking-camera pixel of `from` (rectified left; monocular: undistorted) in `to`.
  std::optional<Eigen::Vector2d> Left(const Eigen::Vector2d& uv) const;
  // A right-image pixel of `from` (rectified right) in `to`.
  std::optional<Eigen::Vector2d> Right(const Eigen::Vector2d& uv) const;

 private:
  const RigSetup& from_;
  const RigSetup& to_;
};

// The physical (raw) pixel of a tracking-camera keypoint (rectified left / undistorted).
std::optional<Eigen::Vector2d> RawLeftPixel(const RigSetup& setup, const Eigen::Vector2d& uv);
// The physical pixel of a rectified right-image pixel (stereo).
std::optional<Eigen::Vector2d> RawRightPixel(const RigSetup& setup, const Eigen::Vector2d& uv);
// And back: a physical pixel in the setup's tracking-camera / right-image coordinates.
std::optional<Eigen::Vector2d> TrackingLeftPixel(const RigSetup& setup,
                                                 const Eigen::Vector2d& raw);
std::optional<Eigen::Vector2d> TrackingRightPixel(const RigSetup& setup,
                                                  const Eigen::Vector2d& raw);

// A keypoint's measurement in physical pixels with its whitening (calibration BA,
// estimators/calibration/calibration_bundle.h): the raw cam0 pixel of a tracking-camera keypoint
// and W_left = sqrt(inv_sigma2) * d(tracking pixel)/d(raw pixel), so W_left * (raw error) is the
// whitened error in the image the keypoint was measured in; for a stereo match (u_right >= 0) the
// raw cam1 pixel of (u_right, v) and w_right = sqrt(inv_sigma2) * d(u_right)/d(raw right pixel),
// the rectified right coordinate being the only part of it the matcher measured. Monocular
// keypoints are measured in the raw image: W_left = sqrt(inv_sigma2) * I (a fisheye's, found in
// its pinhole view, are whitened like rectified ones).
struct RawMeasurement {
  Eigen::Vector2d left = Eigen::Vector2d::Zero();
  Eigen::Matrix2d left_whitening = Eigen::Matrix2d::Identity();
  bool has_right = false;
  Eigen::Vector2d right = Eigen::Vector2d::Zero();
  Eigen::RowVector2d right_whitening = Eigen::RowVector2d::Zero();
};
// nullopt when a pixel cannot be unmapped. `raw_keypoint`: the keypoint as extracted (monocular
// pinhole: the raw pixel, used as is; unused when the setup rectifies or undistorts).
std::optional<RawMeasurement> MakeRawMeasurement(const RigSetup& setup, const Eigen::Vector2d& uv,
                                                 double u_right, double inv_sigma2,
                                                 const Eigen::Vector2d& raw_keypoint);

}  // namespace pkslam
