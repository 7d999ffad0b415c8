#include "sim/euroc_writer.h"

#include <fmt/format.h>

#include <opencv2/imgcodecs.hpp>

#include "core/util/error.h"
#include "io/euroc_sensor.h"

namespace pkslam::sim {

CameraRig EurocCam0() {
  CameraRig c;
  c.name = "cam0";
  c.camera = CameraModel::Pinhole(752, 480, 458.654, 457.296, 367.215, 248.375,
                                  {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05});
  Eigen::Matrix4d t;
  t << 0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,  //
      0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,       //
      -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,   //
      0.0, 0.0, 0.0, 1.0;
  c.body_from_camera = SE3d(t);
  return c;
}

CameraRig EurocCam1() {
  CameraRig c;
  c.name = "cam1";
  c.camera = CameraModel::Pinhole(752, 480, 457.587, 456.134, 379.999, 255.238,
                                  {-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05});
  Eigen::Matrix4d t;
  t << 0.0125552670891, -0.999755099723, 0.0182237714554, -0.0198435579556,  //
      0.999598781151, 0.0130119051815, 0.0251588363115, 0.0453689425024,     //
      -0.0253898008918, 0.0179005838253, 0.999517347078, 0.00786212447038,   //
      0.0, 0.0, 0.0, 1.0;
  c.body_from_camera = SE3d(t);
  return c;
}

// TUM-VI's 512x512 fisheye pair as its published calibration gives it (the numbers ORB-SLAM3's
// TUM-VI settings carry): Kannala-Brandt intrinsics, IMU.T_b_c1 and Stereo.T_c1_c2.
std::vector<CameraRig> TumViRig() {
  CameraRig left;
  left.name = "cam0";
  left.camera = CameraModel::KannalaBrandt8(512, 512, 190.97847715128717, 190.9733070521226,
                                            254.93170605935475, 256.8974428996504,
                                            {0.0034823894022493434, 0.0007150348452162257,
                                             -0.0020532361418706202, 0.00020293673591811182});
  Eigen::Matrix4d body_from_cam0;
  body_from_cam0 << -0.9995250378696743, 0.0075019185074052044, -0.02989013031643309,
      0.045574835649698026,                                                                    //
      0.029615343885863205, -0.03439736061393144, -0.998969345370175, -0.071161801837997044,   //
      -0.008522328211654736, -0.9993800792498829, 0.03415885127385616, -0.044681254117144367,  //
      0.0, 0.0, 0.0, 1.0;
  left.body_from_camera = SE3d(SO3d::FitToMatrix(body_from_cam0.topLeftCorner<3, 3>()),
                               body_from_cam0.topRightCorner<3, 1>());
  CameraRig right;
  right.name = "cam1";
  right.camera = CameraModel::KannalaBrandt8(
      512, 512, 190.44236969414825, 190.4344384721956, 252.59949716835982, 254.91723064636983,
      {0.0034003170790442797, 0.001766278153469831, -0.00266312569781606, 0.0003299517423931039});
  Eigen::Matrix4d cam0_from_cam1;
  cam0_from_cam1 << 0.999999445773493, 0.000791687752817, 0.000694034010224, 0.101063427414194,
      -0.000823363992158, 0.998899461915674, 0.046895490788700, 0.001946204678584,   //
      -0.000656143613644, -0.046896036240590, 0.998899560146304, 0.001015350132563,  //
      0.0, 0.0, 0.0, 1.0;
  right.body_from_camera =
      left.body_from_camera * SE3d(SO3d::FitToMatrix(cam0_from_cam1.topLeftCorner<3, 3>()),
                                   cam0_from_cam1.topRightCorner<3, 1>());
  return {left, right};
}

std::vector<CameraRig> StereoRig(const std::string& camera) {
  if (camera == "euroc") return {EurocCam0(), EurocCam1()};
  if (camera == "tumvi") return TumViRig();
  CameraRig left = EurocCam0();
  CameraRig right = EurocCam1();
  double baseline_m = 0;
  if (camera == "kitti") {
    left.camera = CameraModel::Pinhole(1241, 376, 718.856, 718.856, 607.1928, 185.2157);
    baseline_m = 0.537;
  } else if (camera == "vga") {
    left.camera = CameraModel::Pinhole(640, 480, 525.0, 525.0, 319.5, 239.5);
    baseline_m = 0.11;
  } else {
    throw OptionError(fmt::format("unknown --camera '{}' (euroc|kitti|vga|tumvi)", camera));
  }
  right.camera = left.camera;
  // A rectified pair: the right camera sits `baseline_m` along the left camera's x axis.
  right.body_from_camera =
      left.body_from_camera * SE3d(SO3d(), Eigen::Vector3d(baseline_m, 0.0, 0.0));
  return {left, right};
}

int OrbFeaturesFor(const std::string& camera) {
  if (camera == "kitti") return 2000;
  if (camera == "vga") return 1000;
  if (camera == "tumvi") return 1000;  // ORB-SLAM3's TUM-VI settings
  return 1200;
}

std::string FormatDouble(double v) {
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

namespace {

std::ofstream OpenOut(const std::filesystem::path& file) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(fmt::format("cannot write {}", file.string()));
  return out;
}

void WriteText(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out = OpenOut(file);
  out << text;
  if (!out) throw Error(fmt::format("cannot write {}", file.string()));
}

std::string MatrixYaml(const Eigen::Matrix4d& m) {
  // EuRoC's layout: rows continued under the opening bracket.
  std::string s = "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int r = 0; r < 4; ++r) {
    if (r > 0) s += ",\n         ";
    for (int c = 0; c < 4; ++c) {
      s += (c > 0 ? ", " : "") + FormatDouble(m(r, c));
    }
  }
  return s + "]\n";
}

std::string CameraYaml(const CameraRig& c) {
  return EurocCameraSensorYaml(
      EurocCameraSensorOf(c.camera, c.body_from_camera, c.rate_hz),
      fmt::format("pkslam simulated {} (EuRoC VI-Sensor geometry)", c.name));
}

std::string ImuYaml(const ImuOptions& imu) {
  return fmt::format(
      "%YAML:1.0\n#Default imu sensor yaml file\nsensor_type: imu\n"
      "comment: pkslam simulated IMU (ADIS16448 noise model)\n\n"
      "# Sensor extrinsics wrt. the body-frame.\n{}rate_hz: {}\n\n"
      "# inertial sensor noise model parameters (static)\n"
      "gyroscope_noise_density: {:.4e}     # [ rad / s / sqrt(Hz) ]   ( gyro \"white noise\" )\n"
      "gyroscope_random_walk: {:.4e}       # [ rad / s^2 / sqrt(Hz) ] ( gyro bias diffusion )\n"
      "accelerometer_noise_density: {:.4e}  # [ m / s^2 / sqrt(Hz) ]   ( accel \"white noise\" )\n"
      "accelerometer_random_walk: {:.4e}    # [ m / s^3 / sqrt(Hz) ].  ( accel bias diffusion "
      ")\n\n",
      MatrixYaml(Eigen::Matrix4d::Identity()), fmt::format("{}", imu.rate_hz),
      imu.gyro_noise_density, imu.gyro_random_walk, imu.accel_noise_density, imu.accel_random_walk);
}

constexpr const char* kGroundTruthHeader =
    "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], "
    "q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], "
    "b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], "
    "b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";

std::string GroundTruthLine(const GroundTruthRow& r) {
  const Eigen::Vector3d& p = r.world_from_body.translation();
  Eigen::Quaterniond q = r.world_from_body.quaternion();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // EuRoC keeps w >= 0
  return fmt::format(
      "{},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9e},{:.9e},"
      "{:.9e},{:.9e},{:.9e},{:.9e}\n",
      r.t_ns, p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), r.velocity_world.x(),
      r.velocity_world.y(), r.velocity_world.z(), r.gyro_bias.x(), r.gyro_bias.y(), r.gyro_bias.z(),
      r.accel_bias.x(), r.accel_bias.y(), r.accel_bias.z());
}

constexpr const char* kGroundTruthYaml =
    "%YAML:1.0\n# General sensor definitions.\nsensor_type: visual-inertial\n"
    "comment: pkslam simulator ground truth (the exact spline trajectory of the body/IMU "
    "frame, true IMU biases).\n\n"
    "# Sensor extrinsics wrt. the body-frame. This is the transformation of the\n"
    "# tracking prima to the body frame.\nT_BS:\n  cols: 4\n  rows: 4\n"
    "  data: [1.0, 0.0, 0.0, 0.0,\n         0.0, 1.0, 0.0, 0.0,\n"
    "         0.0, 0.0, 1.0, 0.0,\n         0.0, 0.0, 0.0, 1.0]\n";

}  // namespace

void WritePng(const std::filesystem::path& file, const cv::Mat& image, int compression) {
  const std::vector<int> params{cv::IMWRITE_PNG_COMPRESSION, compression};
  if (!cv::imwrite(file.string(), image, params)) {
    throw Error(fmt::format("cannot write image {}", file.string()));
  }
}

EurocWriter::EurocWriter(const std::filesystem::path& dir, const std::vector<CameraRig>& cameras,
                         const ImuOptions& imu, bool write_imu)
    : dir_(dir) {
  const std::filesystem::path mav = dir / "mav0";
  std::error_code ec;
  for (const CameraRig& c : cameras) {
    std::filesystem::create_directories(mav / c.name / "data", ec);
    if (ec) throw Error(fmt::format("cannot create {}: {}", (mav / c.name).string(), ec.message()));
    WriteText(mav / c.name / "sensor.yaml", CameraYaml(c));
    camera_csv_.push_back(OpenOut(mav / c.name / "data.csv"));
    camera_csv_.back() << "#timestamp [ns],filename\n";
  }
  std::filesystem::create_directories(mav / "state_groundtruth_estimate0", ec);
  if (ec) throw Error(fmt::format("cannot create {}: {}", mav.string(), ec.message()));
  WriteText(mav / "body.yaml", "%YAML:1.0\ncomment: pkslam simulated MAV (body = IMU frame)\n");
  WriteText(mav / "state_groundtruth_estimate0" / "sensor.yaml", kGroundTruthYaml);
  gt_csv_ = OpenOut(mav / "state_groundtruth_estimate0" / "data.csv");
  gt_csv_ << kGroundTruthHeader;
  if (write_imu) {
    std::filesystem::create_directories(mav / "imu0", ec);
    if (ec) throw Error(fmt::format("cannot create {}: {}", mav.string(), ec.message()));
    WriteText(mav / "imu0" / "sensor.yaml", ImuYaml(imu));
    imu_csv_ = OpenOut(mav / "imu0" / "data.csv");
    imu_csv_ << "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
                "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  }
  timestamps_ = OpenOut(dir / "timestamps.txt");
}

void EurocWriter::WriteImage(int camera, std::int64_t t_ns, const cv::Mat& image) {
  WritePng(AddImage(camera, t_ns), image, kEurocPngCompression);
}

std::filesystem::path EurocWriter::AddImage(int camera, std::int64_t t_ns) {
  const std::string name = fmt::format("{}.png", t_ns);
  camera_csv_.at(camera) << t_ns << ',' << name << '\n';
  if (t_ns != last_timestamp_) {
    timestamps_ << t_ns << '\n';
    last_timestamp_ = t_ns;
  }
  return dir_ / "mav0" / fmt::format("cam{}", camera) / "data" / name;
}

void EurocWriter::WriteImu(const ImuSample& s) {
  imu_csv_ << s.t_ns;
  for (int i = 0; i < 3; ++i) imu_csv_ << ',' << FormatDouble(s.gyro[i]);
  for (int i = 0; i < 3; ++i) imu_csv_ << ',' << FormatDouble(s.accel[i]);
  imu_csv_ << '\n';
}

void EurocWriter::WriteGroundTruth(const GroundTruthRow& r) { gt_csv_ << GroundTruthLine(r); }

void EurocWriter::OpenTruth(const std::vector<CameraRig>& true_cameras,
                            const std::string& draw_yaml) {
  const std::filesystem::path truth = dir_ / "truth";
  std::error_code ec;
  std::filesystem::create_directories(truth, ec);
  if (ec) throw Error(fmt::format("cannot create {}: {}", truth.string(), ec.message()));
  for (const CameraRig& c : true_cameras) {
    WriteText(truth / (c.name + "_sensor.yaml"), CameraYaml(c));
  }
  WriteText(truth / "realism_draw.yaml", draw_yaml);
  exact_gt_csv_ = OpenOut(truth / "state_groundtruth_exact.csv");
  exact_gt_csv_ << kGroundTruthHeader;
  frame_times_ = OpenOut(truth / "frame_times.csv");
  frame_times_ << "#image timestamp [ns],mid-exposure time on the IMU clock [ns],exposure [s]\n";
}

void EurocWriter::WriteExactGroundTruth(const GroundTruthRow& r) {
  exact_gt_csv_ << GroundTruthLine(r);
}

void EurocWriter::WriteFrameTime(std::int64_t stamp_ns, std::int64_t exposure_mid_ns,
                                 double exposure_s) {
  frame_times_ << stamp_ns << ',' << exposure_mid_ns << ',' << FormatDouble(exposure_s) << '\n';
}

void EurocWriter::Close() {
  if (closed_) return;
  closed_ = true;
  for (auto& f : camera_csv_) f.close();
  bool ok = true;
  for (auto& f : camera_csv_) ok = ok && !f.fail();
  if (imu_csv_.is_open()) {
    imu_csv_.close();
    ok = ok && !imu_csv_.fail();
  }
  gt_csv_.close();
  timestamps_.close();
  ok = ok && !gt_csv_.fail() && !timestamps_.fail();
  for (std::ofstream* f : {&exact_gt_csv_, &frame_times_}) {
    if (f->is_open()) {
      f->close();
      ok = ok && !f->fail();
    }
  }
  if (!ok) throw Error(fmt::format("writing the EuRoC files under {} failed", dir_.string()));
}

EurocWriter::~EurocWriter() {
  try {
    Close();
  } catch (const Error&) {
    // Destructors must not throw; Close() reports errors to callers that call it.
  }
}

}  // namespace pkslam::sim
