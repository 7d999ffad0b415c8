#include "system/rig_factory.h"

#include <fmt/format.h>

#include "core/util/error.h"

namespace pkslam {

RigCalibration CalibrationFromSettings(const Settings& settings, Sensor sensor) {
  RigCalibration c;
  c.cameras.push_back(settings.camera1);
  c.body_from_cam0 = settings.body_from_cam0.value_or(SE3d());
  c.time_offset_s = settings.time_offset_s;
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
