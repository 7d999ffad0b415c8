// WriteOrbSlam3Settings: the ORB-SLAM3 v1.0 settings format as text. cv::FileStorage cannot
// write it (its emitter rejects '.' in key names), so the YAML is produced here.
#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <string>

#include "core/util/error.h"
#include "io/settings.h"

namespace pkslam {
namespace {

// Shortest text that reads back to the same double, always spelled as a YAML real (ORB-SLAM3
// rejects an integer where it expects a float).
std::string Real(double value) {
  std::string text = fmt::format("{}", value);
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

class Writer {
 public:
  void Comment(const std::string& text) { out_ += "# " + text + "\n"; }
  void Blank() { out_ += "\n"; }
  void RealKey(const std::string& key, double value) { out_ += key + ": " + Real(value) + "\n"; }
  void IntKey(const std::string& key, int value) { out_ += fmt::format("{}: {}\n", key, value); }
  void StringKey(const std::string& key, const std::string& value) {
    out_ += fmt::format("{}: \"{}\"\n", key, value);
  }
  // dt: f because ORB-SLAM3 reads these matrices as CV_32F; the digits are full double ones.
  void Transform(const std::string& key, const SE3d& transform) {
    MatrixKey(key, transform.Matrix(), "f");
  }
  // Rows continued under the opening bracket; `dt` is OpenCV's type letter.
  void MatrixKey(const std::string& key, const Eigen::MatrixXd& m, const char* dt) {
    out_ += fmt::format("{}: !!opencv-matrix\n  rows: {}\n  cols: {}\n  dt: {}\n  data: [", key,
                        m.rows(), m.cols(), dt);
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      for (Eigen::Index c = 0; c < m.cols(); ++c) {
        out_ += Real(m(r, c));
        if (c + 1 < m.cols()) out_ += ", ";
      }
      if (r + 1 < m.rows()) out_ += ",\n         ";
    }
    out_ += "]\n";
  }
  const std::string& text() const { return out_; }

 private:
  std::string out_;
};

void WriteCamera(const CameraModel& camera, const std::string& prefix, Writer* w) {
  w->RealKey(prefix + ".fx", camera.fx());
  w->RealKey(prefix + ".fy", camera.fy());
  w->RealKey(prefix + ".cx", camera.cx());
  w->RealKey(prefix + ".cy", camera.cy());
  const auto& d = camera.distortion();
  if (camera.type() == CameraType::kKannalaBrandt8) {
    for (int i = 0; i < 4; ++i) w->RealKey(fmt::format("{}.k{}", prefix, i + 1), d[i]);
  } else if (!d.empty()) {
    w->RealKey(prefix + ".k1", d[0]);
    w->RealKey(prefix + ".k2", d[1]);
    w->RealKey(prefix + ".p1", d[2]);
    w->RealKey(prefix + ".p2", d[3]);
    if (d.size() == 5) w->RealKey(prefix + ".k3", d[4]);
  }
  w->Blank();
}

bool ValidKeyName(const std::string& name) {
  if (name.empty()) return false;
  for (char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '.') return false;
  }
  return true;
}

}  // namespace

void WriteOrbSlam3Settings(const Settings& s, const std::filesystem::path& file) {
  s.Check();
  Writer w;
  w.Comment("ORB-SLAM3 v1.0 settings, written by pkslam.");
  w.Comment(
      "Stereo.T_c1_c2 = camera1_from_camera2 (p_c1 = T * p_c2); IMU.T_b_c1 = body_from_camera1.");
  w.Blank();
  w.StringKey("File.version", "1.0");
  w.Blank();
  const bool kb = s.camera1.type() == CameraType::kKannalaBrandt8;
  w.StringKey("Camera.type", s.rectified_stereo ? "Rectified" : kb ? "KannalaBrandt8" : "PinHole");
  w.Blank();
  WriteCamera(s.camera1, "Camera1", &w);
  if (s.camera2) WriteCamera(*s.camera2, "Camera2", &w);
  w.IntKey("Camera.width", s.camera1.width());
  w.IntKey("Camera.height", s.camera1.height());
  // Range first: converting a double beyond int to int is undefined behaviour.
  if (s.fps <= 1e6 && s.fps == std::floor(s.fps)) {
    w.IntKey("Camera.fps", static_cast<int>(s.fps));  // ORB-SLAM3 reads fps as an integer
  } else {
    w.RealKey("Camera.fps", s.fps);
  }
  w.Comment("Colour order of the images (0: BGR, 1: RGB; ignored for grey images)");
  w.IntKey("Camera.RGB", s.rgb_order ? 1 : 0);
  w.Blank();
  if (s.stereo_baseline_m) w.RealKey("Stereo.b", *s.stereo_baseline_m);
  if (s.camera2) w.Transform("Stereo.T_c1_c2", s.right_from_left->Inverse());
  w.Comment("Close/far point threshold in baselines");
  w.RealKey("Stereo.ThDepth", s.th_depth);
  w.Blank();
  if (s.imu) {
    w.Transform("IMU.T_b_c1", *s.body_from_cam0);
    w.RealKey("IMU.NoiseGyro", s.imu->gyro_noise_density);
    w.RealKey("IMU.NoiseAcc", s.imu->accel_noise_density);
    w.RealKey("IMU.GyroWalk", s.imu->gyro_random_walk);
    w.RealKey("IMU.AccWalk", s.imu->accel_random_walk);
    w.RealKey("IMU.Frequency", s.imu->rate_hz);
    if (s.time_offset_s != 0.0) {
      w.Comment("pkslam: the image stamped t was taken at IMU time t + TimeOffset (s)");
      w.RealKey("IMU.TimeOffset", s.time_offset_s);
    }
    if (!s.gyro_scale.isZero()) {
      w.Comment("pkslam: the gyroscope reads (1 + GyroScale) times the true rate, per IMU axis");
      w.RealKey("IMU.GyroScaleX", s.gyro_scale.x());
      w.RealKey("IMU.GyroScaleY", s.gyro_scale.y());
      w.RealKey("IMU.GyroScaleZ", s.gyro_scale.z());
    }
    if (!s.accel_axes.isZero()) {
      w.Comment("pkslam: the accelerometer reads (I + AccelAxes) times the true specific force");
      w.MatrixKey("IMU.AccelAxes", s.accel_axes, "d");  // pkslam's: ORB-SLAM3 does not read it
    }
    w.Blank();
  }
  if (s.depth_noise_k) {
    w.Comment("Depth noise sigma_z = DepthNoise * z^2 (m)");
    w.RealKey("RGBD.DepthNoise", *s.depth_noise_k);
  }
  if (s.depth_map_factor) {
    w.RealKey("RGBD.DepthMapFactor", *s.depth_map_factor);
    w.Blank();
  }
  w.IntKey("ORBextractor.nFeatures", s.orb.n_features);
  w.RealKey("ORBextractor.scaleFactor", s.orb.scale_factor);
  w.IntKey("ORBextractor.nLevels", s.orb.n_levels);
  w.IntKey("ORBextractor.iniThFAST", s.orb.ini_th_fast);
  w.IntKey("ORBextractor.minThFAST", s.orb.min_th_fast);
  if (!s.keyframe.empty()) {
    w.Blank();
    w.Comment("Keyframe selector parameters (pkslam; ORB-SLAM3 ignores them)");
    for (const auto& [name, value] : s.keyframe) {
      if (!ValidKeyName(name)) {
        throw OptionError(fmt::format("keyframe parameter name '{}' is not a valid key", name));
      }
      w.RealKey("Keyframe." + name, value);
    }
  }

  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(fmt::format("{}: cannot open for writing", file.string()));
  out << "%YAML:1.0\n\n" << w.text();
  out.close();
  if (!out) throw Error(fmt::format("{}: write failed", file.string()));
}

}  // namespace pkslam
