#include "sim/realism.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/util/error.h"
#include "sim/realism_draw.h"

namespace pkslam::sim {
namespace {

TEST(Realism, IdealHasEverySourceOffEurocEveryOn) {
  const RealismOptions ideal = MakeRealism(RealismPreset::kIdeal);
  const RealismOptions euroc = MakeRealism(RealismPreset::kEuroc);
  for (RealismSource s : kRealismSources) {
    EXPECT_FALSE(ideal.On(s)) << RealismSourceName(s);
    EXPECT_TRUE(euroc.On(s)) << RealismSourceName(s);
    EXPECT_EQ(ParseRealismSource(RealismSourceName(s)), s);
  }
  EXPECT_NO_THROW(euroc.Check());
  // The report lists every size with a documented range and a reference; ideal reports zeros.
  const auto report = RealismReport(euroc);
  EXPECT_GE(report.size(), 30u);
  for (const RealismEntry& e : report) {
    EXPECT_FALSE(e.range.empty()) << e.name;
    EXPECT_FALSE(e.reference.empty()) << e.name;
  }
  for (const RealismEntry& e : RealismReport(ideal)) EXPECT_EQ(e.value, 0.0) << e.name;
  EXPECT_NE(FormatRealismReport(euroc).find("calibration.focal_px"), std::string::npos);
  EXPECT_EQ(ParseRealismPreset("euroc"), RealismPreset::kEuroc);
  EXPECT_THROW(ParseRealismPreset("real"), OptionError);
  EXPECT_THROW(ParseRealismSource("lighting"), OptionError);
}

TEST(Realism, ParametersAreSetByNameAndChecked) {
  RealismOptions r = MakeRealism(RealismPreset::kEuroc);
  SetRealismParameter(&r, "calibration.focal_px=2.5");
  EXPECT_EQ(r.calibration.focal_px, 2.5);
  SetRealismParameter(&r, "timing.camera_imu_offset_ms", -1.5);
  EXPECT_EQ(r.timing.camera_imu_offset_ms, -1.5);
  EXPECT_THROW(SetRealismParameter(&r, "calibration.colour=1"), OptionError);
  EXPECT_THROW(SetRealismParameter(&r, "calibration.focal_px=abc"), OptionError);
  EXPECT_THROW(SetRealismParameter(&r, "calibration.focal_px"), OptionError);
  EXPECT_THROW(SetRealismParameter(&r, "calibration.focal_px=-1"), OptionError);  // Check()
}

std::vector<CameraRig> Rig() { return {EurocCam0(), EurocCam1()}; }

TEST(Realism, RequestsResolveToAPresetWithSourcesOffAndSizesSet) {
  RealismRequest replay;
  replay.replay = true;
  EXPECT_EQ(ResolveRealism(replay).preset, RealismPreset::kEuroc);  // a replay's default
  RealismRequest random;
  EXPECT_EQ(ResolveRealism(random).preset, RealismPreset::kIdeal);
  RealismRequest rgbd = replay;
  rgbd.rgbd = true;
  EXPECT_EQ(ResolveRealism(rgbd).preset, RealismPreset::kIdeal);  // euroc models the VI-Sensor
  rgbd.preset = "euroc";
  EXPECT_THROW(ResolveRealism(rgbd), OptionError);
  RealismRequest euroc;
  euroc.preset = "euroc";
  euroc.off = {"calibration"};
  euroc.params = {"timing.camera_imu_offset_ms=2.5"};
  euroc.device_seed = 9;
  const RealismOptions r = ResolveRealism(euroc);
  EXPECT_FALSE(r.On(RealismSource::kCalibration));
  EXPECT_TRUE(r.On(RealismSource::kImu));
  EXPECT_EQ(r.timing.camera_imu_offset_ms, 2.5);
  EXPECT_EQ(r.device_seed, 9u);
  RealismRequest ideal_off;
  ideal_off.preset = "ideal";
  ideal_off.off = {"imu"};
  EXPECT_THROW(ResolveRealism(ideal_off), OptionError);
}

TEST(RealismDraw, IdealWritesTheTruth) {
  const RealismDraw d = DrawRealism(MakeRealism(RealismPreset::kIdeal), Rig(), 1);
  ASSERT_EQ(d.written_cameras.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(d.written_cameras[k].camera.fx(), Rig()[k].camera.fx());
    EXPECT_EQ(d.written_cameras[k].camera.distortion(), Rig()[k].camera.distortion());
    EXPECT_TRUE(d.written_cameras[k].body_from_camera.Matrix().isApprox(
        Rig()[k].body_from_camera.Matrix(), 0.0));
  }
  EXPECT_TRUE(d.imu_errors.IsIdeal());
  EXPECT_EQ(d.camera_imu_offset_ms, 0.0);
  EXPECT_TRUE(d.gyro_bias.isZero());
}

TEST(RealismDraw, WrittenCalibrationDiffersFromTruthByTheDrawnErrors) {
  const RealismOptions r = MakeRealism(RealismPreset::kEuroc);
  const std::vector<CameraRig> truth = Rig();
  const RealismDraw d = DrawRealism(r, truth, 7);
  for (std::size_t k = 0; k < 2; ++k) {
    const CameraModel& w = d.written_cameras[k].camera;
    const CameraModel& t = truth[k].camera;
    EXPECT_NEAR(w.fx() - t.fx(), d.intrinsic_errors[k].dfx, 1e-12);
    EXPECT_NEAR(w.cy() - t.cy(), d.intrinsic_errors[k].dcy, 1e-12);
    EXPECT_NE(w.fx(), t.fx());
    for (std::size_t i = 0; i < 4; ++i) {
      EXPECT_NEAR(w.distortion()[i] - t.distortion()[i], d.intrinsic_errors[k].ddistortion[i],
                  1e-15);
    }
  }
  // body_from_cam0 moved by the rig error; cam1 relative to cam0 by the stereo error only.
  const SE3d written0 = d.written_cameras[0].body_from_camera;
  EXPECT_TRUE((SE3d::Exp(d.rig_error) * truth[0].body_from_camera)
                  .Matrix()
                  .isApprox(written0.Matrix(), 1e-12));
  const SE3d true_01 = truth[0].body_from_camera.Inverse() * truth[1].body_from_camera;
  const SE3d written_01 = written0.Inverse() * d.written_cameras[1].body_from_camera;
  EXPECT_TRUE((true_01 * SE3d::Exp(d.stereo_error)).Matrix().isApprox(written_01.Matrix(), 1e-12));
  // The IMU's axis errors are drawn, scale factors on the diagonal.
  EXPECT_FALSE(d.imu_errors.IsIdeal());
  EXPECT_NE(d.imu_errors.gyro_matrix(0, 0), 1.0);
  EXPECT_EQ(d.camera_imu_offset_ms, r.timing.camera_imu_offset_ms);
}

TEST(RealismDraw, SizesFollowTheOptionsAndTheDeviceSeedFixesTheRig) {
  RealismOptions r = MakeRealism(RealismPreset::kEuroc);
  r.calibration.focal_px = 2.0;
  r.calibration.per_camera_fraction = 0.3;
  r.calibration.imu_rotation_deg = 0.2;
  double sum_dfx2 = 0.0;
  double sum_diff2 = 0.0;
  double sum_rot2 = 0.0;
  const int n = 400;
  for (int seed = 1; seed <= n; ++seed) {
    r.device_seed = static_cast<std::uint64_t>(seed);
    const RealismDraw d = DrawRealism(r, Rig(), 1);
    sum_dfx2 += d.intrinsic_errors[0].dfx * d.intrinsic_errors[0].dfx;
    const double diff = d.intrinsic_errors[1].dfx - d.intrinsic_errors[0].dfx;
    sum_diff2 += diff * diff;
    sum_rot2 += d.rig_error.tail<3>().squaredNorm() / 3.0;
  }
  // Each camera: common part plus its own (0.3 of the sigma); between the cameras only the own
  // parts differ.
  EXPECT_NEAR(std::sqrt(sum_dfx2 / n), 2.0 * std::sqrt(1.0 + 0.09), 0.2);
  EXPECT_NEAR(std::sqrt(sum_diff2 / n), 2.0 * 0.3 * std::sqrt(2.0), 0.08);
  EXPECT_NEAR(std::sqrt(sum_rot2 / n) * 180.0 / M_PI, 0.2, 0.02);
  // One device, several sequences: the same calibration, different turn-on biases.
  r.device_seed = 3;
  const RealismDraw a = DrawRealism(r, Rig(), 1);
  const RealismDraw b = DrawRealism(r, Rig(), 2);
  EXPECT_EQ(a.written_cameras[0].camera.fx(), b.written_cameras[0].camera.fx());
  EXPECT_TRUE(a.imu_errors.gyro_matrix.isApprox(b.imu_errors.gyro_matrix, 0.0));
  EXPECT_FALSE(a.gyro_bias.isApprox(b.gyro_bias));
}

TEST(RealismDraw, SwitchedOffSourcesDrawNothing) {
  RealismOptions r = MakeRealism(RealismPreset::kEuroc);
  r.enabled[static_cast<std::size_t>(RealismSource::kCalibration)] = false;
  r.enabled[static_cast<std::size_t>(RealismSource::kTiming)] = false;
  const RealismDraw d = DrawRealism(r, Rig(), 1);
  EXPECT_EQ(d.written_cameras[0].camera.fx(), Rig()[0].camera.fx());
  EXPECT_TRUE(d.rig_error.isZero());
  EXPECT_EQ(d.camera_imu_offset_ms, 0.0);
  EXPECT_FALSE(d.imu_errors.IsIdeal());  // imu stays on
  EXPECT_NE(RealismDrawYaml(d).find("rig_error"), std::string::npos);
}

}  // namespace
}  // namespace pkslam::sim
