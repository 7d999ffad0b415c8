#include "sim/realism_draw.h"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "core/geometry/se3.h"
#include "sim/random.h"

namespace pkslam::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Vector3d Normal3(Rng* rng, double sigma) {
  // One draw per statement: argument evaluation order is unspecified in C++.
  const double x = rng->Normal();
  const double y = rng->Normal();
  const double z = rng->Normal();
  return sigma * Eigen::Vector3d(x, y, z);
}

// Scale factors on the diagonal, axis non-orthogonality off it.
Eigen::Matrix3d AxisErrors(Rng* rng, double scale_pct, double misalignment_deg) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      m(i, j) +=
          i == j ? 0.01 * scale_pct * rng->Normal() : misalignment_deg * kDeg * rng->Normal();
    }
  }
  return m;
}

std::string Vector(const Eigen::VectorXd& v) {
  std::string s = "[";
  for (Eigen::Index i = 0; i < v.size(); ++i) s += (i > 0 ? ", " : "") + FormatDouble(v[i]);
  return s + "]";
}

std::string Matrix(const Eigen::Matrix3d& m) {
  return fmt::format("[{}, {}, {}]", Vector(m.row(0).transpose()), Vector(m.row(1).transpose()),
                     Vector(m.row(2).transpose()));
}

}  // namespace

RealismDraw DrawRealism(const RealismOptions& options, const std::vector<CameraRig>& true_cameras,
                        std::uint64_t sequence_seed) {
  options.Check();
  RealismDraw d;
  d.written_cameras = true_cameras;
  d.intrinsic_errors.resize(true_cameras.size());
  if (options.On(RealismSource::kCalibration) && !true_cameras.empty()) {
    const CalibrationErrorOptions& c = options.calibration;
    Rng rng(DeriveSeed(options.device_seed, 0x43414C4942));  // "CALIB"
    // fx fy cx cy k1 k2 p1 p2: one common draw, then each camera's own part.
    const std::array<double, 8> sigma = {c.focal_px,           c.focal_px,  c.principal_point_px,
                                         c.principal_point_px, c.k1,        c.k2,
                                         c.tangential,         c.tangential};
    std::array<double, 8> common{};
    for (int i = 0; i < 8; ++i) common[i] = sigma[i] * rng.Normal();
    for (std::size_t k = 0; k < true_cameras.size(); ++k) {
      const CameraModel& cam = true_cameras[k].camera;
      std::array<double, 8> delta{};
      for (int i = 0; i < 8; ++i) {
        delta[i] = common[i] + c.per_camera_fraction * sigma[i] * rng.Normal();
      }
      CameraCalibrationError& e = d.intrinsic_errors[k];
      e.dfx = delta[0];
      e.dfy = delta[1];
      e.dcx = delta[2];
      e.dcy = delta[3];
      std::vector<double> dist = cam.distortion();
      if (dist.empty()) dist.assign(4, 0.0);
      for (std::size_t i = 0; i < dist.size(); ++i) {
        const double de = i < 4 ? delta[4 + i] : 0.0;
        e.ddistortion.push_back(de);
        dist[i] += de;
      }
      d.written_cameras[k].camera =
          CameraModel::Pinhole(cam.width(), cam.height(), cam.fx() + e.dfx, cam.fy() + e.dfy,
                               cam.cx() + e.dcx, cam.cy() + e.dcy, dist);
    }
    d.rig_error.head<3>() = Normal3(&rng, 1e-3 * c.imu_translation_mm);
    d.rig_error.tail<3>() = Normal3(&rng, c.imu_rotation_deg * kDeg);
    d.stereo_error.head<3>() = Normal3(&rng, 1e-3 * c.stereo_translation_mm);
    d.stereo_error.tail<3>() = Normal3(&rng, c.stereo_rotation_deg * kDeg);
    const SE3d body_from_cam0 = true_cameras[0].body_from_camera;
    const SE3d written_body_from_cam0 = SE3d::Exp(d.rig_error) * body_from_cam0;
    d.written_cameras[0].body_from_camera = written_body_from_cam0;
    for (std::size_t k = 1; k < true_cameras.size(); ++k) {
      const SE3d cam0_from_camk = body_from_cam0.Inverse() * true_cameras[k].body_from_camera;
      d.written_cameras[k].body_from_camera =
          written_body_from_cam0 * cam0_from_camk * SE3d::Exp(d.stereo_error);
    }
  }
  if (options.On(RealismSource::kImu)) {
    const ImuErrorOptions& i = options.imu;
    Rng rng(DeriveSeed(options.device_seed, 0x494D5541584553));  // "IMUAXES"
    d.imu_errors.gyro_matrix = AxisErrors(&rng, i.gyro_scale_pct, i.gyro_misalignment_deg);
    d.imu_errors.accel_matrix = AxisErrors(&rng, i.accel_scale_pct, i.accel_misalignment_deg);
    const double g_sigma = i.gyro_g_sensitivity_dps_per_g * kDeg / 9.81;  // rad/s per m/s^2
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) d.imu_errors.gyro_g_sensitivity(r, c) = g_sigma * rng.Normal();
    }
    d.imu_errors.gyro_quantum = i.gyro_quantum_rad_s;
    d.imu_errors.accel_quantum = i.accel_quantum_m_s2;
    // Turn-on biases differ from flight to flight: drawn from the sequence seed.
    Rng bias_rng(DeriveSeed(sequence_seed, 0x4249415345));  // "BIASE"
    d.gyro_bias = Normal3(&bias_rng, i.gyro_bias_rad_s);
    d.accel_bias = Normal3(&bias_rng, i.accel_bias_m_s2);
  }
  if (options.On(RealismSource::kTiming)) {
    d.camera_imu_offset_ms = options.timing.camera_imu_offset_ms;
  }
  return d;
}

std::string RealismDrawYaml(const RealismDraw& d) {
  std::string s =
      "# Errors drawn for this sequence (written calibration minus the rendering truth).\n";
  s += "cameras:\n";
  for (std::size_t k = 0; k < d.intrinsic_errors.size(); ++k) {
    const CameraCalibrationError& e = d.intrinsic_errors[k];
    s += fmt::format("  - {{name: {}, dfx: {}, dfy: {}, dcx: {}, dcy: {}, ddistortion: {}}}\n",
                     d.written_cameras[k].name, FormatDouble(e.dfx), FormatDouble(e.dfy),
                     FormatDouble(e.dcx), FormatDouble(e.dcy),
                     Vector(Eigen::Map<const Eigen::VectorXd>(
                         e.ddistortion.data(), static_cast<Eigen::Index>(e.ddistortion.size()))));
  }
  s += "# body_from_cam0 written = Exp(rig_error) * true; [translation m, rotation rad]\n";
  s += "rig_error: " + Vector(d.rig_error) + "\n";
  s += "# cam0_from_cam1 written = true * Exp(stereo_error)\n";
  s += "stereo_error: " + Vector(d.stereo_error) + "\n";
  s += "imu_gyro_matrix: " + Matrix(d.imu_errors.gyro_matrix) + "\n";
  s += "imu_accel_matrix: " + Matrix(d.imu_errors.accel_matrix) + "\n";
  s += "imu_gyro_g_sensitivity: " + Matrix(d.imu_errors.gyro_g_sensitivity) + "\n";
  s += "imu_gyro_quantum: " + FormatDouble(d.imu_errors.gyro_quantum) + "\n";
  s += "imu_accel_quantum: " + FormatDouble(d.imu_errors.accel_quantum) + "\n";
  s += "initial_gyro_bias_added: " + Vector(d.gyro_bias) + "\n";
  s += "initial_accel_bias_added: " + Vector(d.accel_bias) + "\n";
  s += "camera_imu_offset_ms: " + FormatDouble(d.camera_imu_offset_ms) + "\n";
  return s;
}

}  // namespace pkslam::sim
