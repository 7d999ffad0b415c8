#include "io/kalibr_files.h"

#include <gtest/gtest.h>

#include "core/util/error.h"
#include "io/test_fixtures.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

EurocCameraSensor Fisheye(double x) {
  EurocCameraSensor c;
  c.body_from_camera =
      SE3d(SO3d::Exp(Eigen::Vector3d(0.1, -1.5, 0.2)), Eigen::Vector3d(x, 0.01, -0.02));
  c.width = 512;
  c.height = 512;
  c.camera_model = "pinhole";
  c.intrinsics = {190.97847715128717, 190.9733070521226, 254.93170605935475, 256.8974428996504};
  c.distortion_model = "equidistant";
  c.distortion_coefficients = {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202,
                               0.00020293673591811182};
  return c;
}

TEST(KalibrFiles, CamchainAndImuRoundTrip) {
  const fs::path dir = testing::MakeTempDir("kalibr");
  const std::vector<EurocCameraSensor> cameras = {Fisheye(0.0), Fisheye(0.1)};
  WriteKalibrCamchain(cameras, dir / "camchain.yaml");
  const std::vector<EurocCameraSensor> back = ReadKalibrCamchain(dir / "camchain.yaml");
  ASSERT_EQ(back.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(back[k].intrinsics, cameras[k].intrinsics);
    EXPECT_EQ(back[k].distortion_coefficients, cameras[k].distortion_coefficients);
    EXPECT_EQ(back[k].distortion_model, "equidistant");
    EXPECT_EQ(back[k].width, 512);
    EXPECT_LT(
        (back[k].body_from_camera.translation() - cameras[k].body_from_camera.translation()).norm(),
        1e-12);
  }
  EurocImuSensor imu;
  imu.gyroscope_noise_density = 0.00016;
  imu.accelerometer_noise_density = 0.0028;
  imu.gyroscope_random_walk = 0.000022;
  imu.accelerometer_random_walk = 0.00086;
  imu.rate_hz = 200;
  WriteKalibrImu(imu, dir / "imu_config.yaml");
  const EurocImuSensor imu_back = ReadKalibrImu(dir / "imu_config.yaml");
  EXPECT_EQ(imu_back.gyroscope_noise_density, 0.00016);
  EXPECT_EQ(imu_back.accelerometer_random_walk, 0.00086);
  EXPECT_EQ(imu_back.rate_hz, 200);
  // Found beside a TUM-VI folder's mav0 (in dso/).
  fs::create_directories(dir / "seq" / "mav0");
  fs::create_directories(dir / "seq" / "dso");
  fs::copy_file(dir / "camchain.yaml", dir / "seq" / "dso" / "camchain.yaml");
  EXPECT_EQ(FindKalibrCamchain(dir / "seq" / "mav0"), dir / "seq" / "dso" / "camchain.yaml");
  EXPECT_FALSE(FindKalibrImu(dir / "seq" / "mav0").has_value());
  fs::remove_all(dir);
}

TEST(KalibrFiles, BadFilesNameFileAndLine) {
  const fs::path dir = testing::MakeTempDir("kalibr_bad");
  testing::WriteText(dir / "a.yaml", "cam0:\n  camera_model: pinhole\n");
  try {
    ReadKalibrCamchain(dir / "a.yaml");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'T_cam_imu' missing"), std::string::npos) << e.what();
  }
  testing::WriteText(dir / "b.yaml",
                     "cam0:\n  T_cam_imu:\n  - [1, 0, 0, 0]\n  - [0, 1, 0, 0]\n  - [0, 0, 1, 0]\n"
                     "  - [0, 0, 0, 1]\n  camera_model: omni\n");
  EXPECT_THROW(ReadKalibrCamchain(dir / "b.yaml"), InputError);
  testing::WriteText(dir / "c.yaml", "accelerometer_noise_density: [oops\n");
  EXPECT_THROW(ReadKalibrImu(dir / "c.yaml"), InputError);
  EXPECT_THROW(ReadKalibrImu(dir / "missing.yaml"), InputError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pkslam
