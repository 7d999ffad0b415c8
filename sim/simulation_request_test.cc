#include "sim/simulation_request.h"

#include <gtest/gtest.h>

#include "core/util/error.h"
#include "sim/motion_generator.h"

namespace pkslam::sim {
namespace {

SimulationRequest Replay(const std::string& file) {
  SimulationRequest request;
  request.options.scene.clear();
  request.options.output_dir = "unused";
  request.options.trajectory = file;
  return request;
}

TEST(ResolveSimulation, AReplayGetsTheEurocPresetAndItsSceneByTheFileName) {
  const SimulationOptions hall = ResolveSimulation(Replay("MH_01_easy.txt"));
  EXPECT_EQ(hall.realism.preset, RealismPreset::kEuroc);
  EXPECT_EQ(hall.scene, hall.realism.appearance.machine_hall_scene);
  const SimulationOptions room = ResolveSimulation(Replay("V1_01_easy.txt"));
  EXPECT_EQ(room.scene, room.realism.appearance.vicon_scene);
  EXPECT_NE(room.scene, hall.scene);
  // The preset's appearance reaches the sensor model.
  EXPECT_EQ(room.sensor.read_noise_dn, room.realism.appearance.read_noise_dn);
  EXPECT_EQ(room.sensor.vignetting, room.realism.appearance.vignetting);
}

TEST(ResolveSimulation, RandomMotionIsIdealAndKeepsANamedScene) {
  SimulationRequest request;
  request.options.scene = "machine_hall";
  request.motion = "difficult";
  const SimulationOptions o = ResolveSimulation(request);
  EXPECT_EQ(o.realism.preset, RealismPreset::kIdeal);
  EXPECT_EQ(o.scene, "machine_hall");
  EXPECT_EQ(o.motion.level, MotionLevel::kDifficult);
}

TEST(ResolveSimulation, ValuesTheUserSetStayOverThePresetsAppearance) {
  SimulationRequest request = Replay("V1_01_easy.txt");
  request.options.sensor.read_noise_dn = 7.5;
  request.options.sensor.vignetting = 0.05;
  request.given.read_noise = true;  // vignetting was not given: the preset's wins
  const SimulationOptions o = ResolveSimulation(request);
  EXPECT_EQ(o.sensor.read_noise_dn, 7.5);
  EXPECT_EQ(o.sensor.vignetting, o.realism.appearance.vignetting);
  EXPECT_NE(o.sensor.vignetting, 0.05);
}

TEST(ResolveSimulation, ACameraBringsItsRateAndTumViItsImu) {
  SimulationRequest request;
  request.options.camera = "kitti";
  EXPECT_EQ(ResolveSimulation(request).camera_rate_hz, 10.0);
  request.options.camera = "tumvi";
  const SimulationOptions tumvi = ResolveSimulation(request);
  EXPECT_EQ(tumvi.camera_rate_hz, 20.0);
  EXPECT_EQ(tumvi.imu.rate_hz, 200.0);
  EXPECT_EQ(tumvi.imu.gyro_noise_density, 0.00016);
}

TEST(ResolveSimulation, SwitchesAndBiasesReachTheOptions) {
  SimulationRequest request;
  request.images = false;  // no images: no cloud either, whatever `cloud` says
  request.imu_noise = false;
  request.auto_exposure = false;
  request.blackout = std::make_pair(1.0, 2.0);
  request.gyro_bias = Eigen::Vector3d(0.01, 0, 0);
  const SimulationOptions o = ResolveSimulation(request);
  EXPECT_FALSE(o.write_images);
  EXPECT_FALSE(o.write_cloud);
  EXPECT_FALSE(o.imu.noise);
  EXPECT_FALSE(o.sensor.auto_exposure);
  EXPECT_EQ(o.blackout_begin_s, 1.0);
  EXPECT_EQ(o.blackout_end_s, 2.0);
  EXPECT_EQ(o.imu.initial_gyro_bias.x(), 0.01);
}

TEST(ResolveSimulation, BadValuesAreOptionErrorsNamingTheOption) {
  SimulationRequest request;
  request.motion = "wild";
  EXPECT_THROW(ResolveSimulation(request), OptionError);
  request.motion = "easy";
  request.quality = "ultra";
  EXPECT_THROW(ResolveSimulation(request), OptionError);
  request.quality = "fast";
  request.options.duration_s = 1.0;  // random motion rests its first 2 s
  try {
    ResolveSimulation(request);
    FAIL() << "no error for a random flight shorter than its rest";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("--duration"), std::string::npos) << e.what();
  }
  SimulationRequest off = Replay("V1_01_easy.txt");
  off.realism.off = {"sunshine"};
  EXPECT_THROW(ResolveSimulation(off), OptionError);
}

}  // namespace
}  // namespace pkslam::sim
