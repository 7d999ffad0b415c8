#include "system/rig_factory.h"

#include <fmt/format.h>

#include "core/util/error.h"

namespace pkslam {

RigSetup MakeRig(const Settings& settings, Sensor sensor) {
  settings.Check();
  RigSetup setup;
  auto rig = std::make_shared<CameraRig>();
  rig->sensor = sensor;
  rig->fps = settings.fps > 0 ? settings.fps : 20.0;
  rig->pyramid = ScalePyramid(settings.orb.n_levels, settings.orb.scale_factor);
  const SE3d body_from_cam0 = settings.body_from_cam0.value_or(SE3d());

  if (IsInertial(sensor)) {
    if (!settings.imu || !settings.body_from_cam0) {
      throw OptionError(
          fmt::format("sensor {} needs IMU calibration (IMU.* keys)", SensorName(sensor)));
    }
    rig->imu = settings.imu;
  }

  if (IsStereo(sensor)) {
    if (!settings.IsStereo()) {
      throw OptionError(
          "stereo sensor needs a stereo calibration (Camera2.* and Stereo.T_c1_c2, "
          "or Camera.type Rectified with Stereo.b)");
    }
    if (settings.rectified_stereo) {
      rig->camera = settings.camera1;
      rig->baseline = settings.BaselineM();
      rig->body_from_camera = body_from_cam0;
    } else {
      setup.rectification.emplace(settings.camera1, *settings.camera2, *settings.right_from_left);
      rig->camera = setup.rectification->rectified_camera();
      rig->baseline = setup.rectification->baseline();
      rig->body_from_camera = setup.rectification->BodyFromRectLeft(body_from_cam0);
    }
  } else {
    rig->camera = settings.camera1;
    rig->body_from_camera = body_from_cam0;
    if (IsRgbd(sensor)) {
      if (!settings.depth_map_factor) {
        throw OptionError("RGB-D sensor needs RGBD.DepthMapFactor in the settings");
      }
      rig->depth_factor = *settings.depth_map_factor;
      if (settings.depth_noise_k) rig->depth_noise_k = *settings.depth_noise_k;
      // The virtual baseline only scales the close/far split and the virtual right
      // coordinate; ORB-SLAM's TUM settings use about 8 cm.
      rig->baseline = settings.stereo_baseline_m.value_or(0.08);
    }
  }
  if (rig->camera.type() != CameraType::kPinhole) {
    // Tracking, matching and BA work on undistorted keypoints of an ideal pinhole; a fisheye
    // image cannot be undistorted to one beyond 90 degrees.
    throw OptionError(
        "the SLAM pipeline supports pinhole (radial-tangential) cameras; "
        "Kannala-Brandt fisheye is supported by the camera model only");
  }
  rig->UpdateDerived();
  rig->bf = rig->fx * rig->baseline;
  rig->th_depth = settings.th_depth * rig->baseline;
  setup.rig = std::move(rig);
  return setup;
}

}  // namespace pkslam
