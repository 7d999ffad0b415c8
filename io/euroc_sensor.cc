#include "io/euroc_sensor.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "io/opencv_yaml.h"

namespace pkslam {
namespace {

double PositiveDouble(const OpenCvYamlFile& yaml, const std::string& key) {
  const double value = yaml.Double(key);
  if (!(value > 0)) yaml.Fail(key, fmt::format("must be positive, found {}", value));
  return value;
}

}  // namespace

EurocCameraSensor ReadEurocCameraSensor(const std::filesystem::path& sensor_yaml) {
  const OpenCvYamlFile yaml(sensor_yaml);
  EurocCameraSensor camera;
  camera.body_from_camera = SE3d(yaml.RigidTransform("T_BS"));
  camera.rate_hz = PositiveDouble(yaml, "rate_hz");
  const std::vector<double> resolution = yaml.DoubleSequence("resolution", 2);
  // Range first: converting a double beyond int (1e10) to int is undefined behaviour.
  const auto positive_int = [](double v) {
    return v >= 1 && v <= std::numeric_limits<int>::max() && v == std::floor(v);
  };
  if (!positive_int(resolution[0]) || !positive_int(resolution[1])) {
    yaml.Fail("resolution", "expected two positive integers [width, height]");
  }
  camera.width = static_cast<int>(resolution[0]);
  camera.height = static_cast<int>(resolution[1]);
  camera.camera_model = yaml.String("camera_model");
  if (camera.camera_model != "pinhole") {
    yaml.Fail("camera_model",
              fmt::format("unsupported model '{}' (expected pinhole)", camera.camera_model));
  }
  const std::vector<double> intrinsics = yaml.DoubleSequence("intrinsics", 4);
  for (int i = 0; i < 4; ++i) camera.intrinsics[i] = intrinsics[i];
  if (!(intrinsics[0] > 0 && intrinsics[1] > 0)) {
    yaml.Fail("intrinsics", "focal lengths fu, fv must be positive");
  }
  if (const auto shift = yaml.OptionalDouble("timeshift_cam_imu")) {
    if (!(std::abs(*shift) <= 1.0)) {
      yaml.Fail("timeshift_cam_imu", fmt::format("must be within [-1, 1] s, found {}", *shift));
    }
    camera.timeshift_cam_imu = *shift;
  }
  camera.distortion_model = yaml.String("distortion_model");
  camera.distortion_coefficients = yaml.DoubleSequence("distortion_coefficients");
  const std::size_t n = camera.distortion_coefficients.size();
  if (camera.distortion_model == "radial-tangential") {
    if (n != 4 && n != 5) {
      yaml.Fail("distortion_coefficients",
                fmt::format("radial-tangential needs 4 or 5 coefficients, found {}", n));
    }
  } else if (camera.distortion_model == "equidistant") {
    if (n != 4) {
      yaml.Fail("distortion_coefficients",
                fmt::format("equidistant needs 4 coefficients, found {}", n));
    }
  } else {
    yaml.Fail("distortion_model",
              fmt::format("unsupported model '{}' (expected radial-tangential or equidistant)",
                          camera.distortion_model));
  }
  return camera;
}

namespace {

// Shortest text that reads back to the same double, always spelled as a real.
std::string Real(double v) {
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

std::string Join(const std::vector<double>& values) {
  std::string s;
  for (std::size_t i = 0; i < values.size(); ++i) s += (i > 0 ? ", " : "") + Real(values[i]);
  return s;
}

}  // namespace

namespace {

// EuRoC's layout: T_BS rows continued under the opening bracket.
std::string TbsYaml(const SE3d& body_from_sensor) {
  const Eigen::Matrix4d m = body_from_sensor.Matrix();
  std::string t_bs = "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int r = 0; r < 4; ++r) {
    if (r > 0) t_bs += ",\n         ";
    for (int col = 0; col < 4; ++col) t_bs += (col > 0 ? ", " : "") + Real(m(r, col));
  }
  return t_bs + "]\n";
}

}  // namespace

EurocCameraSensor EurocCameraSensorOf(const CameraModel& camera, const SE3d& body_from_camera,
                                      double rate_hz, double timeshift_cam_imu) {
  EurocCameraSensor s;
  s.body_from_camera = body_from_camera;
  s.rate_hz = rate_hz;
  s.width = camera.width();
  s.height = camera.height();
  s.camera_model = "pinhole";
  s.intrinsics = {camera.fx(), camera.fy(), camera.cx(), camera.cy()};
  s.distortion_model =
      camera.type() == CameraType::kKannalaBrandt8 ? "equidistant" : "radial-tangential";
  s.distortion_coefficients = camera.distortion();
  s.timeshift_cam_imu = timeshift_cam_imu;
  return s;
}

EurocImuSensor EurocImuSensorOf(const ImuNoise& noise, const Eigen::Vector3d& gyroscope_scale_error,
                                const Eigen::Matrix3d& accelerometer_axis_errors) {
  EurocImuSensor imu;
  imu.rate_hz = noise.rate_hz;
  imu.gyroscope_noise_density = noise.gyro_noise_density;
  imu.gyroscope_random_walk = noise.gyro_random_walk;
  imu.accelerometer_noise_density = noise.accel_noise_density;
  imu.accelerometer_random_walk = noise.accel_random_walk;
  imu.gyroscope_scale_error = gyroscope_scale_error;
  imu.accelerometer_axis_errors = accelerometer_axis_errors;
  return imu;
}

std::string EurocImuSensorYaml(const EurocImuSensor& imu, const std::string& comment) {
  std::string text = fmt::format(
      "%YAML:1.0\n# General sensor definitions.\nsensor_type: imu\ncomment: {}\n\n"
      "# Sensor extrinsics wrt. the body-frame.\n{}\n"
      "rate_hz: {}\n\n# inertial sensor noise model parameters (static)\n"
      "gyroscope_noise_density: {}     # [ rad / s / sqrt(Hz) ]   ( gyro \"white noise\" )\n"
      "gyroscope_random_walk: {}       # [ rad / s^2 / sqrt(Hz) ] ( gyro bias diffusion )\n"
      "accelerometer_noise_density: {}  # [ m / s^2 / sqrt(Hz) ]   ( accel \"white noise\" )\n"
      "accelerometer_random_walk: {}    # [ m / s^3 / sqrt(Hz) ].  ( accel bias diffusion )\n",
      comment, TbsYaml(imu.body_from_imu), Real(imu.rate_hz), Real(imu.gyroscope_noise_density),
      Real(imu.gyroscope_random_walk), Real(imu.accelerometer_noise_density),
      Real(imu.accelerometer_random_walk));
  if (!imu.gyroscope_scale_error.isZero()) {
    text += fmt::format(
        "# pkslam: the gyroscope reads (1 + k) times the true rate about each axis\n"
        "gyroscope_scale_error: [{}, {}, {}]\n",
        Real(imu.gyroscope_scale_error.x()), Real(imu.gyroscope_scale_error.y()),
        Real(imu.gyroscope_scale_error.z()));
  }
  if (!imu.accelerometer_axis_errors.isZero()) {
    const Eigen::Matrix3d& e = imu.accelerometer_axis_errors;
    text += fmt::format(
        "# pkslam: the accelerometer reads (I + E) times the true specific force (E row-major)\n"
        "accelerometer_axis_errors: [{}, {}, {},\n"
        "                            {}, {}, {},\n"
        "                            {}, {}, {}]\n",
        Real(e(0, 0)), Real(e(0, 1)), Real(e(0, 2)), Real(e(1, 0)), Real(e(1, 1)), Real(e(1, 2)),
        Real(e(2, 0)), Real(e(2, 1)), Real(e(2, 2)));
  }
  return text + "\n";
}

std::string EurocCameraSensorYaml(const EurocCameraSensor& c, const std::string& comment) {
  const std::string t_bs = TbsYaml(c.body_from_camera);
  const std::vector<double> distortion =
      c.distortion_coefficients.empty() ? std::vector<double>{0.0, 0.0, 0.0, 0.0}
                                        : c.distortion_coefficients;
  std::string text = fmt::format(
      "%YAML:1.0\n# General sensor definitions.\nsensor_type: camera\ncomment: {}\n\n"
      "# Sensor extrinsics wrt. the body-frame.\n{}\n"
      "# Camera specific definitions.\nrate_hz: {}\nresolution: [{}, {}]\n"
      "camera_model: {}\nintrinsics: [{}, {}, {}, {}] #fu, fv, cu, cv\n"
      "distortion_model: {}\ndistortion_coefficients: [{}]\n",
      comment, t_bs, c.rate_hz, c.width, c.height, c.camera_model, Real(c.intrinsics[0]),
      Real(c.intrinsics[1]), Real(c.intrinsics[2]), Real(c.intrinsics[3]), c.distortion_model,
      Join(distortion));
  if (c.timeshift_cam_imu != 0.0) {
    text += fmt::format("# t_imu = t_cam + timeshift_cam_imu [s] (Kalibr's convention)\n"
                        "timeshift_cam_imu: {}\n",
                        Real(c.timeshift_cam_imu));
  }
  return text + "\n";
}

EurocImuSensor ReadEurocImuSensor(const std::filesystem::path& sensor_yaml) {
  const OpenCvYamlFile yaml(sensor_yaml);
  EurocImuSensor imu;
  imu.body_from_imu = SE3d(yaml.RigidTransform("T_BS"));
  imu.rate_hz = PositiveDouble(yaml, "rate_hz");
  imu.gyroscope_noise_density = PositiveDouble(yaml, "gyroscope_noise_density");
  imu.gyroscope_random_walk = PositiveDouble(yaml, "gyroscope_random_walk");
  imu.accelerometer_noise_density = PositiveDouble(yaml, "accelerometer_noise_density");
  imu.accelerometer_random_walk = PositiveDouble(yaml, "accelerometer_random_walk");
  if (yaml.Has("gyroscope_scale_error")) {
    const std::vector<double> k = yaml.DoubleSequence("gyroscope_scale_error", 3);
    for (int i = 0; i < 3; ++i) {
      if (!(std::abs(k[i]) <= 0.1)) {
        yaml.Fail("gyroscope_scale_error",
                  fmt::format("{} is not a scale-factor error (a fraction within [-0.1, 0.1])",
                              k[i]));
      }
      imu.gyroscope_scale_error[i] = k[i];
    }
  }
  if (yaml.Has("accelerometer_axis_errors")) {
    const std::vector<double> e = yaml.DoubleSequence("accelerometer_axis_errors", 9);
    for (int i = 0; i < 9; ++i) {
      if (!(std::abs(e[i]) <= 0.2)) {
        yaml.Fail("accelerometer_axis_errors",
                  fmt::format("{} is not an axis error (a scale fraction or a misalignment "
                              "angle in rad, within [-0.2, 0.2])",
                              e[i]));
      }
      imu.accelerometer_axis_errors(i / 3, i % 3) = e[i];
    }
  }
  return imu;
}

}  // namespace pkslam
