#include "io/kalibr_files.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/euroc_dataset.h"
#include "io/rigid_transform_file.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

YAML::Node Load(const fs::path& file) {
  if (!fs::is_regular_file(file)) throw InputError(file, "file not found");
  try {
    return YAML::LoadFile(file.string());
  } catch (const YAML::Exception& e) {
    throw InputError(file, static_cast<std::size_t>(e.mark.line + 1), "YAML: " + e.msg);
  }
}

YAML::Node Require(const YAML::Node& node, const char* key, const fs::path& file) {
  const YAML::Node v = node[key];
  if (!v) {
    throw InputError(file, static_cast<std::size_t>(node.Mark().line + 1),
                     fmt::format("'{}' missing", key));
  }
  return v;
}

std::vector<double> Numbers(const YAML::Node& node, const char* key, std::size_t count,
                            const fs::path& file) {
  const YAML::Node v = Require(node, key, file);
  std::vector<double> out;
  try {
    for (const auto& x : v) out.push_back(x.as<double>());
  } catch (const YAML::Exception&) {
    throw InputError(file, static_cast<std::size_t>(v.Mark().line + 1),
                     fmt::format("'{}': not a list of numbers", key));
  }
  if (count != 0 && out.size() != count) {
    throw InputError(file, static_cast<std::size_t>(v.Mark().line + 1),
                     fmt::format("'{}': {} numbers, expected {}", key, out.size(), count));
  }
  return out;
}

double Number(const YAML::Node& node, const char* key, const fs::path& file) {
  const YAML::Node v = Require(node, key, file);
  try {
    return v.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(file, static_cast<std::size_t>(v.Mark().line + 1),
                     fmt::format("'{}': not a number", key));
  }
}

std::optional<fs::path> FirstExisting(const fs::path& mav0, const char* name) {
  for (const fs::path& dir : {mav0.parent_path() / "dso", mav0.parent_path(), mav0}) {
    if (fs::is_regular_file(dir / name)) return dir / name;
  }
  return std::nullopt;
}

std::string Row(const Eigen::Matrix4d& m, int r) {
  return fmt::format("  - [{}, {}, {}, {}]\n", m(r, 0), m(r, 1), m(r, 2), m(r, 3));
}

}  // namespace

std::vector<EurocCameraSensor> ReadKalibrCamchain(const fs::path& file) {
  const YAML::Node root = Load(file);
  std::vector<EurocCameraSensor> cameras;
  for (int k = 0;; ++k) {
    const YAML::Node cam = root[fmt::format("cam{}", k)];
    if (!cam) break;
    EurocCameraSensor c;
    const YAML::Node t = Require(cam, "T_cam_imu", file);
    Eigen::Matrix4d m;
    if (!t.IsSequence() || t.size() != 4) {
      throw InputError(file, static_cast<std::size_t>(t.Mark().line + 1),
                       "T_cam_imu: expected 4 rows of 4 numbers");
    }
    for (int r = 0; r < 4; ++r) {
      for (int col = 0; col < 4; ++col) m(r, col) = t[r][col].as<double>();
    }
    if (const auto problem = FindRigidTransformProblem(m)) {
      throw InputError(file, static_cast<std::size_t>(t.Mark().line + 1),
                       "T_cam_imu: " + problem->what);
    }
    c.body_from_camera = SE3d(m).Inverse();  // the IMU is the body
    c.camera_model = Require(cam, "camera_model", file).as<std::string>();
    if (c.camera_model != "pinhole") {
      throw InputError(file, static_cast<std::size_t>(cam.Mark().line + 1),
                       fmt::format("camera_model '{}': only pinhole is supported", c.camera_model));
    }
    const std::string model = Require(cam, "distortion_model", file).as<std::string>();
    if (model == "equidistant") {
      c.distortion_model = "equidistant";
      c.distortion_coefficients = Numbers(cam, "distortion_coeffs", 4, file);
    } else if (model == "radtan") {
      c.distortion_model = "radial-tangential";
      c.distortion_coefficients = Numbers(cam, "distortion_coeffs", 0, file);
    } else {
      throw InputError(
          file, static_cast<std::size_t>(cam.Mark().line + 1),
          fmt::format("distortion_model '{}' (expected equidistant or radtan)", model));
    }
    const std::vector<double> k4 = Numbers(cam, "intrinsics", 4, file);
    c.intrinsics = {k4[0], k4[1], k4[2], k4[3]};
    const std::vector<double> size = Numbers(cam, "resolution", 2, file);
    c.width = static_cast<int>(size[0]);
    c.height = static_cast<int>(size[1]);
    cameras.push_back(std::move(c));
  }
  if (cameras.empty()) throw InputError(file, "no cam0 entry");
  return cameras;
}

EurocImuSensor ReadKalibrImu(const fs::path& file) {
  const YAML::Node root = Load(file);
  EurocImuSensor imu;
  imu.accelerometer_noise_density = Number(root, "accelerometer_noise_density", file);
  imu.accelerometer_random_walk = Number(root, "accelerometer_random_walk", file);
  imu.gyroscope_noise_density = Number(root, "gyroscope_noise_density", file);
  imu.gyroscope_random_walk = Number(root, "gyroscope_random_walk", file);
  imu.rate_hz = Number(root, "update_rate", file);
  if (!(imu.rate_hz > 0)) throw InputError(file, "update_rate must be positive");
  return imu;
}

std::optional<fs::path> FindKalibrCamchain(const fs::path& mav0) {
  return FirstExisting(mav0, "camchain.yaml");
}

std::optional<fs::path> FindKalibrImu(const fs::path& mav0) {
  if (auto f = FirstExisting(mav0, "imu_config.yaml")) return f;
  return FirstExisting(mav0, "imu.yaml");
}

void WriteKalibrCamchain(const std::vector<EurocCameraSensor>& cameras, const fs::path& file) {
  OutputFile out(file);
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    const EurocCameraSensor& c = cameras[k];
    const Eigen::Matrix4d t = c.body_from_camera.Inverse().Matrix();
    out.stream() << fmt::format("cam{}:\n  T_cam_imu:\n", k);
    for (int r = 0; r < 4; ++r) out.stream() << "  " << Row(t, r);
    if (k > 0) {
      const Eigen::Matrix4d rel =
          (c.body_from_camera.Inverse() * cameras[k - 1].body_from_camera).Matrix();
      out.stream() << "  T_cn_cnm1:\n";
      for (int r = 0; r < 4; ++r) out.stream() << "  " << Row(rel, r);
    }
    const std::string model = c.distortion_model == "equidistant" ? "equidistant" : "radtan";
    out.stream() << fmt::format(
        "  camera_model: pinhole\n  distortion_coeffs: [{}]\n  distortion_model: {}\n"
        "  intrinsics: [{}, {}, {}, {}]\n  resolution: [{}, {}]\n  rostopic: /cam{}/image_raw\n",
        fmt::join(c.distortion_coefficients, ", "), model, c.intrinsics[0], c.intrinsics[1],
        c.intrinsics[2], c.intrinsics[3], c.width, c.height, k);
  }
  out.Commit();
}

void WriteKalibrImu(const EurocImuSensor& imu, const fs::path& file) {
  OutputFile out(file);
  out.stream() << fmt::format(
      "accelerometer_noise_density: {}\naccelerometer_random_walk: {}\n"
      "gyroscope_noise_density: {}\ngyroscope_random_walk: {}\nrostopic: /imu0\n"
      "update_rate: {}\n",
      imu.accelerometer_noise_density, imu.accelerometer_random_walk, imu.gyroscope_noise_density,
      imu.gyroscope_random_walk, imu.rate_hz);
  out.Commit();
}

void WriteTumViFiles(const fs::path& root) {
  const EurocDataset d = EurocDataset::Open(root);
  std::vector<EurocCameraSensor> cameras = {d.cam0_sensor()};
  if (d.has_cam1()) cameras.push_back(d.cam1_sensor());
  const fs::path dso = d.mav0().parent_path() / "dso";
  fs::create_directories(dso);
  WriteKalibrCamchain(cameras, dso / "camchain.yaml");
  if (d.has_imu()) WriteKalibrImu(d.imu_sensor(), dso / "imu_config.yaml");
  if (d.has_ground_truth()) {
    fs::create_directories(d.mav0() / "mocap0");
    OutputFile out(d.mav0() / "mocap0" / "data.csv");
    out.stream() << "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],"
                    "q_RS_y [],q_RS_z []\n";
    for (const EurocGroundTruthState& g : d.ground_truth()) {
      const Eigen::Vector3d p = g.world_from_body.translation();
      const Eigen::Quaterniond q = g.world_from_body.so3().quaternion();
      out.stream() << fmt::format("{},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f},{:.9f}\n", g.t_ns,
                                  p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
    }
    out.Commit();
  }
}

}  // namespace pkslam
