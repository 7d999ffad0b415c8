// Fuzz target: the OpenCV-YAML settings readers (io/settings.h ReadOrbSlam3Settings on an
// ORB-SLAM3 v1.0 settings file; io/euroc_sensor.h on an EuRoC sensor.yaml), all through
// io/opencv_yaml.h and cv::FileStorage. The input is the YAML file. Bad input must end in
// InputError (file, key, line); anything else, cv::Exception included, is a finding. Every key
// is also read with each typed accessor of io/opencv_yaml.h; a RigidTransform it returns must
// be one, and an accepted sensor.yaml must have a finite T_BS. (ReadOrbSlam3Settings checks
// what it accepts itself, with Settings::Check.)
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/util/error.h"
#include "fuzz/fuzz_support.h"
#include "io/euroc_sensor.h"
#include "io/opencv_yaml.h"
#include "io/settings.h"

namespace {

bool Finite(const pkslam::SE3d& t) {
  return t.translation().allFinite() && t.quaternion().coeffs().allFinite();
}

// One typed read of a key; a wrong type is an InputError.
template <typename F>
void Accessed(F read) {
  try {
    read();
  } catch (const pkslam::InputError& e) {
    pkslam::fuzz::Rejected(e);
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  pkslam::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pkslam;
  const auto yaml = fuzz::WriteScratchFile("settings.yaml", data, size);
  try {
    ReadOrbSlam3Settings(yaml);
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
  // Typed access to every key, as the readers use it (io/opencv_yaml.h).
  try {
    const OpenCvYamlFile file(yaml);
    for (const std::string& key : file.Keys()) {
      file.LineOf(key);
      file.IsString(key);
      Accessed([&] { file.OptionalDouble(key); });
      Accessed([&] { file.OptionalInt(key); });
      Accessed([&] { file.OptionalString(key); });
      Accessed([&] { file.DoubleSequence(key); });
      Accessed([&] {
        const Eigen::Matrix4d m = file.RigidTransform(key);
        const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
        if (!m.allFinite() || !((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() <= 1e-4)) {
          fuzz::Finding("RigidTransform accepted a matrix that is not a rigid transform");
        }
      });
    }
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
  // What the sensor readers accept is validated: a rigid, finite T_BS above all.
  try {
    const EurocCameraSensor camera = ReadEurocCameraSensor(yaml);
    if (!Finite(camera.body_from_camera)) fuzz::Finding("camera sensor.yaml: non-finite T_BS");
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
  try {
    const EurocImuSensor imu = ReadEurocImuSensor(yaml);
    if (!Finite(imu.body_from_imu)) fuzz::Finding("imu sensor.yaml: non-finite T_BS");
  } catch (const InputError& e) {
    fuzz::Rejected(e);
  }
  return 0;
}
