// The realism preset end to end through RunSimulation: what SLAM reads (sensor.yaml,
// settings.yaml, ground truth, image timing) differs from the rendering truth (truth/) by
// exactly the configured amounts, and the same seed still gives identical bytes.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>

#include "io/settings.h"
#include "io/trajectory.h"
#include "sim/realism_draw.h"
#include "sim/simulator.h"
#include "tests/support/test_data.h"

namespace pkslam::sim {
namespace {

namespace fs = std::filesystem;

SimulationOptions EurocReplay(const fs::path& shared, const fs::path& out) {
  SimulationOptions o;
  o.output_dir = out;
  o.trajectory = shared / "euroc/groundtruth/V1_02_medium.txt";
  o.start_s = 20.0;
  o.duration_s = 0.5;
  o.quality = Quality::kFast;
  o.quiet = true;
  o.write_cloud = false;
  o.realism = MakeRealism(RealismPreset::kEuroc);
  o.scene = DefaultScene(o.realism, o.trajectory);
  ApplyAppearance(o.realism.appearance, &o);
  return o;
}

std::vector<double> Intrinsics(const fs::path& sensor_yaml) {
  cv::FileStorage f(sensor_yaml.string(), cv::FileStorage::READ);
  std::vector<double> v;
  f["intrinsics"] >> v;
  std::vector<double> d;
  f["distortion_coefficients"] >> d;
  v.insert(v.end(), d.begin(), d.end());
  return v;
}

TEST(RealismSimulation, WhatSlamReadsDiffersFromTheTruthByTheConfiguredErrors) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path out = testing::MakeTempDir("realism_sim") / "seq";
  SimulationOptions o = EurocReplay(shared, out);
  // Exact checks: no ground-truth noise or jitter, an offset of one IMU period.
  SetRealismParameter(&o.realism, "ground_truth.position_noise_mm=0");
  SetRealismParameter(&o.realism, "ground_truth.rotation_noise_deg=0");
  SetRealismParameter(&o.realism, "ground_truth.time_offset_ms=5");
  SetRealismParameter(&o.realism, "timing.jitter_ms=0");
  SetRealismParameter(&o.realism, "timing.camera_imu_offset_ms=3");
  EXPECT_EQ(o.scene, "euroc_vicon_room");
  RunSimulation(o);

  // Calibration: sensor.yaml = truth + the drawn errors; settings.yaml says the same.
  const RealismDraw draw = DrawRealism(o.realism, {EurocCam0(), EurocCam1()}, o.seed);
  for (int cam = 0; cam < 2; ++cam) {
    const auto written = Intrinsics(out / "mav0" / fmt::format("cam{}", cam) / "sensor.yaml");
    const auto truth = Intrinsics(out / "truth" / fmt::format("cam{}_sensor.yaml", cam));
    ASSERT_EQ(written.size(), 8u);
    ASSERT_EQ(truth.size(), 8u);
    const CameraCalibrationError& e = draw.intrinsic_errors[cam];
    EXPECT_NEAR(written[0] - truth[0], e.dfx, 1e-9);
    EXPECT_NEAR(written[3] - truth[3], e.dcy, 1e-9);
    EXPECT_NEAR(written[4] - truth[4], e.ddistortion[0], 1e-12);
    EXPECT_GT(std::abs(written[0] - truth[0]), 1e-3);
  }
  const Settings settings = ReadOrbSlam3Settings(out / "settings.yaml");
  EXPECT_NEAR(settings.camera1.fx(), draw.written_cameras[0].camera.fx(), 1e-9);
  ASSERT_TRUE(settings.body_from_cam0.has_value());
  EXPECT_TRUE(settings.body_from_cam0->Matrix().isApprox(
      draw.written_cameras[0].body_from_camera.Matrix(), 1e-9));

  // Ground truth: the row stamped t holds the exact state at t + 5 ms.
  const Trajectory written = ReadTrajectory(out / "mav0/state_groundtruth_estimate0/data.csv");
  const Trajectory exact = ReadTrajectory(out / "truth/state_groundtruth_exact.csv");
  ASSERT_EQ(written.poses.size(), exact.poses.size());
  double moved = 0.0;
  for (std::size_t i = 0; i + 1 < written.poses.size(); ++i) {
    ASSERT_EQ(written.poses[i].t_ns, exact.poses[i].t_ns);
    EXPECT_LT((written.poses[i].pose.translation() - exact.poses[i + 1].pose.translation()).norm(),
              1e-8);
    moved += (written.poses[i].pose.translation() - exact.poses[i].pose.translation()).norm();
  }
  EXPECT_GT(moved / static_cast<double>(written.poses.size()), 1e-4);  // it is not the truth

  // Timing: every image was exposed 3 ms after its stamp (IMU clock).
  std::ifstream times(out / "truth/frame_times.csv");
  std::string line;
  std::getline(times, line);
  int rows = 0;
  while (std::getline(times, line)) {
    long long stamp = 0;
    long long mid = 0;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lld,%lld", &stamp, &mid), 2) << line;
    EXPECT_EQ(mid - stamp, 3'000'000) << line;
    ++rows;
  }
  EXPECT_EQ(rows, 11);
  EXPECT_NE(testing::ReadFileBytes(out / "sim.yaml").find("preset: euroc"), std::string::npos);
}

TEST(RealismSimulation, SameSeedSameBytes) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path root = testing::MakeTempDir("realism_bytes");
  RunSimulation(EurocReplay(shared, root / "a"));
  RunSimulation(EurocReplay(shared, root / "b"));
  int files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(root / "a")) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), root / "a");
    if (rel == "sim.yaml") continue;  // names its output folder
    ASSERT_EQ(testing::ReadFileBytes(entry.path()), testing::ReadFileBytes(root / "b" / rel))
        << rel;
    ++files;
  }
  EXPECT_GE(files, 38);  // 2 x 11 images, lists, IMU, ground truths, truth/ files, settings
}

TEST(RealismSimulation, GainFlickerChangesEachFrameOfItsCameraOnly) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path root = testing::MakeTempDir("realism_flicker");
  SimulationOptions steady = EurocReplay(shared, root / "steady");
  SetRealismParameter(&steady.realism, "appearance.cam1_gain_flicker_percent", 0.0);
  ApplyAppearance(steady.realism.appearance, &steady);
  RunSimulation(steady);
  SimulationOptions o = EurocReplay(shared, root / "flicker");
  SetRealismParameter(&o.realism, "appearance.cam1_gain_flicker_percent", 5.0);
  ApplyAppearance(o.realism.appearance, &o);
  RunSimulation(o);
  std::vector<double> ratios;
  for (const auto& entry : fs::directory_iterator(root / "steady/mav0/cam1/data")) {
    const fs::path name = entry.path().filename();
    // cam0 (and with it the auto exposure, which meters cam0) does not see cam1's flicker.
    EXPECT_EQ(testing::ReadFileBytes(root / "steady/mav0/cam0/data" / name),
              testing::ReadFileBytes(root / "flicker/mav0/cam0/data" / name));
    const cv::Mat a = cv::imread(entry.path().string(), cv::IMREAD_GRAYSCALE);
    const cv::Mat b = cv::imread((root / "flicker/mav0/cam1/data" / name).string(),
                                 cv::IMREAD_GRAYSCALE);
    ratios.push_back(cv::mean(b)[0] / cv::mean(a)[0]);
  }
  ASSERT_GE(ratios.size(), 10u);
  double mean = 0.0;
  for (double r : ratios) mean += r / static_cast<double>(ratios.size());
  double var = 0.0;
  for (double r : ratios) var += (r - mean) * (r - mean) / static_cast<double>(ratios.size() - 1);
  // 5% per frame (saturated pixels and rounding take a little of it).
  EXPECT_GT(std::sqrt(var), 0.02);
  EXPECT_LT(std::sqrt(var), 0.08);
  EXPECT_NEAR(mean, 1.0, 0.05);
}

TEST(RealismSimulation, IdealWritesTheEurocCalibrationAndNoTruthFolder) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path out = testing::MakeTempDir("realism_ideal") / "seq";
  SimulationOptions o = EurocReplay(shared, out);
  o.realism = MakeRealism(RealismPreset::kIdeal);
  o.scene = DefaultScene(o.realism, o.trajectory);
  EXPECT_EQ(o.scene, "vicon_room");
  RunSimulation(o);
  EXPECT_FALSE(fs::exists(out / "truth"));
  const auto written = Intrinsics(out / "mav0/cam0/sensor.yaml");
  EXPECT_DOUBLE_EQ(written[0], 458.654);
}

}  // namespace
}  // namespace pkslam::sim
