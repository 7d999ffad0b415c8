#include "sim/settings_writer.h"

#include <fmt/format.h>

#include <fstream>
#include <string>

#include "core/util/error.h"

namespace pkslam::sim {
namespace {

std::string OpencvMatrix(const std::string& key, const Eigen::Matrix4d& m) {
  std::string s = key + ": !!opencv-matrix\n  rows: 4\n  cols: 4\n  dt: f\n  data: [";
  for (int r = 0; r < 4; ++r) {
    if (r > 0) s += ",\n         ";
    for (int c = 0; c < 4; ++c) s += (c > 0 ? ", " : "") + FormatDouble(m(r, c));
  }
  return s + "]\n";
}

std::string CameraBlock(int index, const CameraModel& cam) {
  std::string s = fmt::format(
      "Camera{0}.fx: {1}\nCamera{0}.fy: {2}\nCamera{0}.cx: {3}\n"
      "Camera{0}.cy: {4}\n",
      index, FormatDouble(cam.fx()), FormatDouble(cam.fy()), FormatDouble(cam.cx()),
      FormatDouble(cam.cy()));
  const auto& d = cam.distortion();
  const char* names[] = {"k1", "k2", "p1", "p2", "k3"};
  for (std::size_t i = 0; i < d.size() && i < 5; ++i) {
    s += fmt::format("Camera{}.{}: {}\n", index, names[i], FormatDouble(d[i]));
  }
  return s + "\n";
}

void Write(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << text;
  if (!out) throw Error(fmt::format("cannot write {}", file.string()));
}

constexpr const char* kOrb =
    "ORBextractor.nFeatures: 1200\nORBextractor.scaleFactor: 1.2\nORBextractor.nLevels: 8\n"
    "ORBextractor.iniThFAST: 20\nORBextractor.minThFAST: 7\n\n"
    "Viewer.KeyFrameSize: 0.05\nViewer.KeyFrameLineWidth: 1.0\nViewer.GraphLineWidth: 0.9\n"
    "Viewer.PointSize: 2.0\nViewer.CameraSize: 0.08\nViewer.CameraLineWidth: 3.0\n"
    "Viewer.ViewpointX: 0.0\nViewer.ViewpointY: -0.7\nViewer.ViewpointZ: -1.8\n"
    "Viewer.ViewpointF: 500.0\n";

}  // namespace

void WriteStereoSettings(const std::filesystem::path& file, const CameraRig& left,
                         const CameraRig& right, const ImuOptions* imu) {
  std::string s =
      "%YAML:1.0\n\n# Written by pkslam simulate.\nFile.version: \"1.0\"\n\n"
      "Camera.type: \"PinHole\"\n\n";
  s += CameraBlock(1, left.camera);
  s += CameraBlock(2, right.camera);
  s += fmt::format("Camera.width: {}\nCamera.height: {}\nCamera.fps: {}\nCamera.RGB: 1\n\n",
                   left.camera.width(), left.camera.height(),
                   static_cast<int>(std::lround(left.rate_hz)));
  s += "Stereo.ThDepth: 60.0\n";
  const SE3d left_from_right = left.body_from_camera.Inverse() * right.body_from_camera;
  s += OpencvMatrix("Stereo.T_c1_c2", left_from_right.Matrix()) + "\n";
  if (imu != nullptr) {
    s += OpencvMatrix("IMU.T_b_c1", left.body_from_camera.Matrix());
    s += fmt::format(
        "IMU.InsertKFsWhenLost: 0\nIMU.NoiseGyro: {}\nIMU.NoiseAcc: {}\nIMU.GyroWalk: {}\n"
        "IMU.AccWalk: {}\nIMU.Frequency: {}\n\n",
        FormatDouble(imu->gyro_noise_density), FormatDouble(imu->accel_noise_density),
        FormatDouble(imu->gyro_random_walk), FormatDouble(imu->accel_random_walk),
        FormatDouble(imu->rate_hz));
  }
  Write(file, s + kOrb);
}

void WriteRgbdSettings(const std::filesystem::path& file, const CameraRig& camera,
                       double depth_factor) {
  std::string s =
      "%YAML:1.0\n\n# Written by pkslam simulate.\nFile.version: \"1.0\"\n\n"
      "Camera.type: \"PinHole\"\n\n";
  s += CameraBlock(1, camera.camera);
  s += fmt::format("Camera.width: {}\nCamera.height: {}\nCamera.fps: {}\nCamera.RGB: 1\n\n",
                   camera.camera.width(), camera.camera.height(),
                   static_cast<int>(std::lround(camera.rate_hz)));
  s += fmt::format("Stereo.ThDepth: 40.0\nStereo.b: 0.07\nRGBD.DepthMapFactor: {}\n\n",
                   FormatDouble(depth_factor));
  Write(file, s + kOrb);
}

}  // namespace pkslam::sim
