// RGBD.DepthNoise (pkslam's key for the RGB-D depth noise model, core/sensor/camera_rig.h).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "core/util/error.h"
#include "io/settings.h"
#include "io/test_fixtures.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

const fs::path kTumFile = fs::path(PKSLAM_SOURCE_DIR) / "io" / "testdata" / "tum_fr1_rgbd.yaml";

std::string ReadText(const fs::path& file) {
  std::ifstream in(file);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST(SettingsRgbd, DepthNoiseIsOptionalAndRoundTrips) {
  const fs::path dir = testing::MakeTempDir("settings_rgbd");
  Settings s = ReadOrbSlam3Settings(kTumFile);
  EXPECT_FALSE(s.depth_noise_k.has_value());  // ORB-SLAM3's own files: the rig default
  s.depth_noise_k = 2.5e-3;
  WriteOrbSlam3Settings(s, dir / "out.yaml");
  EXPECT_THAT(ReadText(dir / "out.yaml"), ::testing::HasSubstr("RGBD.DepthNoise: "));
  const Settings back = ReadOrbSlam3Settings(dir / "out.yaml");
  ASSERT_TRUE(back.depth_noise_k.has_value());
  EXPECT_DOUBLE_EQ(*back.depth_noise_k, 2.5e-3);
  EXPECT_EQ(back.depth_map_factor, 5000.0);
  fs::remove_all(dir);
}

TEST(SettingsRgbd, NonPositiveDepthNoiseIsAnInputError) {
  const fs::path dir = testing::MakeTempDir("settings_rgbd");
  const fs::path file = dir / "bad.yaml";
  testing::WriteText(file, ReadText(kTumFile) + "RGBD.DepthNoise: -0.001\n");
  EXPECT_THROW(ReadOrbSlam3Settings(file), InputError);
  Settings s = ReadOrbSlam3Settings(kTumFile);
  s.depth_noise_k = 0.0;
  EXPECT_THROW(s.Check(), Error);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pkslam
