#include "system/rig_factory.h"

#include <fmt/format.h>

#include "core/util/error.h"

namespace pkslam {

RigCalibration CalibrationFromSettings(const Settings& settings, Sensor sensor) {
  RigCalibration c;
  c.cameras.push_back(settings.camera1);
  c.body_from_cam0 = settings.body_from_cam0.value_or(SE3d());
  c.time_offset_s = settings.time_offset_s;
  c.gyro_scale = settings.gyro_scale;
  c.accel_axes = settings.accel_axes;
  if (IsStereo(sensor) && settings.IsStereo()) {
    if (settings.rectified_stereo) {
      c.cameras.push_back(settings.camera1);
      c.cam1_from_cam0 = SE3d(SO3d(), Eigen::Vector3d(-settings.BaselineM(), 0.0, 0.0));
    } else {
      c.cameras.push_back(*settings.camera2);
      c.cam1_from_cam0 = *settings.right_from_left;
    }
  }
  return c;
}

Settings SettingsWithCalibration(Settings settings, const RigCalibration& calibration) {
  settings.camera1 = calibration.cameras.at(0);
  if (settings.body_from_cam0) settings.body_from_cam0 = calibration.body_from_cam0;
  settings.time_offset_s = settings.imu ? calibration.time_offset_s : 0.0;
  settings.gyro_scale = settings.imu ? calibration.gyro_scale : Eigen::Vector3d::Zero();
  settings.accel_axes = settings.imu ? calibration.accel_axes : Eigen::Matrix3d::Zero();
  if (calibration.stereo() && settings.IsStereo()) {
    const bool still_rectified =
        settings.rectified_stereo && !calibration.cameras[1].HasDistortion() &&
        SameCalibration(calibration.cameras[0], calibration.cameras[1]) &&
        calibration.cam1_from_cam0.so3().Log().norm() == 0.0 &&
        calibration.cam1_from_cam0.translation().y() == 0.0 &&
        calibration.cam1_from_cam0.translation().z() == 0.0;
    if (still_rectified) {
      settings.stereo_baseline_m = -calibration.cam1_from_cam0.translation().x();
    } else {
      settings.rectified_stereo = false;
      settings.stereo_baseline_m.reset();
      settings.camera2 = calibration.cameras[1];
      settings.right_from_left = calibration.cam1_from_cam0;
    }
  }
  return settings;
}

RigShape ShapeFromSettings(const Settings& settings, Sensor sensor) {
  RigShape shape;
  shape.sensor = sensor;
  shape.fps = settings.fps > 0 ? settings.fps : 20.0;
  shape.pyramid = ScalePyramid(settings.orb.n_levels, settings.orb.scale_factor);
  shape.th_depth_baselines = settings.th_depth;
  if (IsInertial(sensor)) shape.imu = settings.imu;
  shape.rectified_input = settings.rectified_stereo;
  if (settings.depth_map_factor) shape.depth_factor = *settings.depth_map_factor;
  shape.depth_noise_k = settings.depth_noise_k;
  // The virtual baseline only scales the close/far split and the virtual right coordinate;
  // ORB-SLAM's TUM settings use about 8 cm.
  shape.virtual_baseline = settings.stereo_baseline_m.value_or(0.08);
  return shape;
}

RigSetup MakeRig(const Settings& settings, Sensor sensor) {
  settings.Check();
  if (IsInertial(sensor) && (!settings.imu || !settings.body_from_cam0)) {
    throw OptionError(
        fmt::format("sensor {} needs IMU calibration (IMU.* keys)", SensorName(sensor)));
  }
  if (IsStereo(sensor) && !settings.IsStereo()) {
    throw OptionError(
        "stereo sensor needs a stereo calibration (Camera2.* and Stereo.T_c1_c2, "
        "or Camera.type Rectified with Stereo.b)");
  }
  if (IsRgbd(sensor) && !settings.depth_map_factor) {
    throw OptionError("RGB-D sensor needs RGBD.DepthMapFactor in the settings");
  }
  return BuildRig(CalibrationFromSettings(settings, sensor), ShapeFromSettings(settings, sensor));
}

}  // namespace pkslam
