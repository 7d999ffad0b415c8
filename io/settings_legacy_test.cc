#include "io/settings_legacy.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>

#include "core/util/error.h"
#include "io/settings.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kLegacyTestData = fs::path(PKSLAM_SOURCE_DIR) / "io" / "testdata";

void ExpectSameCameras(const Settings& a, const Settings& b) {
  EXPECT_TRUE(SameCalibration(a.camera1, b.camera1))
      << a.camera1.ToString() << " vs " << b.camera1.ToString();
  ASSERT_EQ(a.camera2.has_value(), b.camera2.has_value());
  if (a.camera2) {
    EXPECT_TRUE(SameCalibration(*a.camera2, *b.camera2));
  }
  EXPECT_EQ(a.fps, b.fps);
  EXPECT_EQ(a.th_depth, b.th_depth);
  EXPECT_EQ(a.orb, b.orb);
}

// ORB-SLAM2's stereo file holds the rectification, not the extrinsic: the extrinsic it implies
// is the v1.0 file's to float precision of the rectification (1e-9 m, 1e-9 rad here).
TEST(LegacySettings, Orbslam2StereoReadsAsTheV1File) {
  const Settings legacy = ReadOrbSlam3Settings(kLegacyTestData / "orbslam2_euroc_stereo.yaml");
  const Settings v1 = ReadOrbSlam3Settings(kLegacyTestData / "euroc_stereo_inertial.yaml");
  ExpectSameCameras(legacy, v1);
  ASSERT_TRUE(legacy.right_from_left);
  const SE3d diff = *legacy.right_from_left * v1.right_from_left->Inverse();
  EXPECT_LT(diff.translation().norm(), 1e-9);
  EXPECT_LT(diff.so3().Angle(), 1e-9);
  EXPECT_FALSE(legacy.rectified_stereo);
  EXPECT_FALSE(legacy.imu);
}

TEST(LegacySettings, Orbslam3V04MonoInertialReadsAsTheV1File) {
  const Settings legacy = ReadOrbSlam3Settings(kLegacyTestData / "orbslam3_v04_euroc_mono_inertial.yaml");
  const Settings v1 = ReadOrbSlam3Settings(kLegacyTestData / "euroc_stereo_inertial.yaml");
  EXPECT_TRUE(SameCalibration(legacy.camera1, v1.camera1));
  EXPECT_FALSE(legacy.camera2);
  ASSERT_TRUE(legacy.body_from_cam0 && legacy.imu);
  EXPECT_TRUE(legacy.body_from_cam0->Matrix().isApprox(v1.body_from_cam0->Matrix(), 1e-12));
  EXPECT_EQ(legacy.imu->gyro_noise_density, v1.imu->gyro_noise_density);
  EXPECT_EQ(legacy.imu->accel_random_walk, v1.imu->accel_random_walk);
  EXPECT_EQ(legacy.imu->rate_hz, v1.imu->rate_hz);
}

TEST(LegacySettings, Orbslam2RgbdReadsAsTheV1File) {
  const Settings legacy = ReadOrbSlam3Settings(kLegacyTestData / "orbslam2_tum_fr1_rgbd.yaml");
  const Settings v1 = ReadOrbSlam3Settings(kLegacyTestData / "tum_fr1_rgbd.yaml");
  ExpectSameCameras(legacy, v1);
  EXPECT_EQ(legacy.depth_map_factor, v1.depth_map_factor);
  ASSERT_TRUE(legacy.stereo_baseline_m);
  EXPECT_NEAR(*legacy.stereo_baseline_m, 0.07, 1e-9);
  EXPECT_FALSE(legacy.IsStereo());
}

// Written back as v1.0 (`pkslam settings convert`) and read again: the same settings.
TEST(LegacySettings, ConvertedFileReadsTheSame) {
  const fs::path dir = testing::MakeTempDir("settings_legacy_convert");
  for (const char* name : {"orbslam2_euroc_stereo.yaml", "orbslam3_v04_euroc_mono_inertial.yaml",
                           "orbslam2_tum_fr1_rgbd.yaml"}) {
    const Settings legacy = ReadOrbSlam3Settings(kLegacyTestData / name);
    WriteOrbSlam3Settings(legacy, dir / name);
    const Settings again = ReadOrbSlam3Settings(dir / name);
    ExpectSameCameras(again, legacy);
    EXPECT_EQ(again.right_from_left.has_value(), legacy.right_from_left.has_value()) << name;
    EXPECT_EQ(again.imu.has_value(), legacy.imu.has_value()) << name;
  }
}

std::string ReadLegacyError(const fs::path& file) {
  try {
    ReadOrbSlam3Settings(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(LegacySettings, MissingKeysGetAHint) {
  const fs::path dir = testing::MakeTempDir("settings_legacy_hints");
  std::stringstream text;
  text << std::ifstream(kLegacyTestData / "orbslam2_tum_fr1_rgbd.yaml").rdbuf();
  const std::string no_size =
      std::regex_replace(text.str(), std::regex("Camera\\.(width|height): [0-9]+\n"), "");
  std::ofstream(dir / "no_size.yaml") << no_size;
  EXPECT_THAT(ReadLegacyError(dir / "no_size.yaml"), HasSubstr("add Camera.width and Camera.height"));
  std::ofstream(dir / "no_version.yaml") << "%YAML:1.0\nCamera1.fx: 500\n";
  EXPECT_THAT(ReadLegacyError(dir / "no_version.yaml"), HasSubstr("pkslam settings convert"));
  std::ofstream(dir / "no_tbc.yaml") << "%YAML:1.0\nCamera.fx: 458\nCamera.fy: 457\nCamera.cx: "
                                        "367\nCamera.cy: 248\nCamera.width: 752\nCamera.height: "
                                        "480\nCamera.fps: 20\nIMU.NoiseGyro: 1e-4\nIMU.NoiseAcc: "
                                        "2e-3\nIMU.GyroWalk: 2e-5\nIMU.AccWalk: 3e-3\n"
                                        "IMU.Frequency: 200\n";
  EXPECT_THAT(ReadLegacyError(dir / "no_tbc.yaml"), HasSubstr("Tbc"));
}

}  // namespace
}  // namespace pkslam
