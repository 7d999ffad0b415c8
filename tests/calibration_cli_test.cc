// End-to-end: online calibration (docs/calibration.md). A replay whose calibration files carry
// the realism preset's errors (calibration and timing sources on, the others off so it renders
// fast) is run with --calibrate online and off; what the run reports (stats.json "calibration",
// OUT/calibration/) is read back as a user would, fed back to pkslam, and `pkslam calibrate`
// writes its report.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/euroc_sensor.h"
#include "io/json_file.h"
#include "io/settings.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::RunPkslam;

// The replay every test of this file reads, and one online run of it (with a saved map):
// `Prepare` makes both. Under CTest it runs once as the fixture CalibrationCli.prepare
// (tests/CMakeLists.txt) into $PKSLAM_CALIBRATION_CLI_DIR and the tests share it; run directly,
// without that variable, each test process prepares its own copy in a scratch directory.
constexpr const char* kSharedDirVariable = "PKSLAM_CALIBRATION_CLI_DIR";

// `pkslam run` stereo-inertial of DIR/seq into OUT.
testing::CommandResult RunReplay(const fs::path& dir, const fs::path& out,
                                 const std::string& extra) {
  return RunPkslam(
      fmt::format("--log-level info run --dataset '{}' --sensor stereo-inertial --out '{}' --quiet "
                  "--deterministic {}",
                  (dir / "seq").string(), out.string(), extra));
}

// The online run's arguments (its map goes to DIR/online.map).
std::string OnlineArguments(const fs::path& map) {
  return fmt::format("--calibrate online --save-map '{}'", map.string());
}

// Renders DIR/seq and runs it online into DIR/online (output in DIR/online.log); "" when done,
// else what failed.
std::string Prepare(const fs::path& dir, const fs::path& shared) {
  const auto sim = RunPkslam(fmt::format(
      "--log-level warn simulate --out '{}' --trajectory '{}' --start 3 --duration 22 "
      "--quality fast --quiet --no-cloud --realism euroc --realism-off "
      "appearance,motion,imu,ground-truth",
      (dir / "seq").string(), (shared / "euroc/groundtruth/V1_02_medium.txt").string()));
  if (sim.exit_code != 0) return sim.output;
  const auto online = RunReplay(dir, dir / "online", OnlineArguments(dir / "online.map"));
  std::ofstream(dir / "online.log") << online.output;
  if (online.exit_code != 0) return online.output;
  std::ofstream(dir / "prepared") << "ok\n";
  return "";
}

TEST(CalibrationCliFixture, Prepare) {
  const char* shared_dir = std::getenv(kSharedDirVariable);
  if (shared_dir == nullptr) GTEST_SKIP() << kSharedDirVariable << " not set (CTest sets it)";
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  fs::remove_all(shared_dir);
  fs::create_directories(shared_dir);
  const std::string failure = Prepare(shared_dir, shared);
  EXPECT_EQ(failure, "");
}

class CalibrationCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto shared = testing::SharedDataDir();
    if (!shared) return;
    dir_ = new fs::path(testing::MakeTempDir("calibration_cli"));
    const char* shared_dir = std::getenv(kSharedDirVariable);
    if (shared_dir != nullptr && fs::exists(fs::path(shared_dir) / "prepared")) {
      prepared_ = new fs::path(shared_dir);
      return;
    }
    prepared_ = new fs::path(*dir_);
    const std::string failure = Prepare(*prepared_, *shared);
    if (!failure.empty()) ADD_FAILURE() << failure;
  }
  static void TearDownTestSuite() {
    delete dir_;
    delete prepared_;
    dir_ = prepared_ = nullptr;
  }
  void SetUp() override {
    PKSLAM_REQUIRE_SHARED_DATA(shared);
    ASSERT_TRUE(fs::exists(*prepared_ / "prepared"));
  }
  static fs::path Seq() { return *prepared_ / "seq"; }
  // The prepared online run: its folder, its saved map and what it printed.
  static fs::path Online() { return *prepared_ / "online"; }
  static fs::path OnlineMap() { return *prepared_ / "online.map"; }
  static std::string OnlineOutput() { return testing::ReadFileBytes(*prepared_ / "online.log"); }
  // This process's outputs.
  static fs::path Dir() { return *dir_; }
  // `pkslam run` stereo-inertial into Dir()/name.
  static testing::CommandResult Run(const std::string& name, const std::string& extra) {
    return RunReplay(*prepared_, Dir() / name, extra);
  }

  static fs::path* dir_;
  static fs::path* prepared_;
};

fs::path* CalibrationCli::dir_ = nullptr;
fs::path* CalibrationCli::prepared_ = nullptr;

const YAML::Node* FindParameter(const YAML::Node& parameters, const std::string& name,
                                YAML::Node* storage) {
  for (const YAML::Node& p : parameters) {
    if (p["name"].as<std::string>() == name) {
      *storage = p;
      return storage;
    }
  }
  return nullptr;
}

TEST_F(CalibrationCli, OnlineRunReportsAndWritesTheEstimate) {
  const fs::path out = Online();
  const YAML::Node c = ReadJsonFile(out / "stats.json")["calibration"];
  ASSERT_TRUE(c.IsMap());
  EXPECT_EQ(c["mode"].as<std::string>(), "online");
  EXPECT_EQ(c["solved_in"].as<std::string>(), "step");  // --deterministic
  // Adjustments ran while mapping and at least one moved the map to its estimate.
  ASSERT_GE(c["history"].size(), 1u);
  bool applied = false;
  for (const YAML::Node& h : c["history"]) applied = applied || h["applied"].as<bool>();
  EXPECT_TRUE(applied);
  // The final estimate carries sigmas; the time offset (file 0, rendered +1 ms) was freed and
  // moved towards the truth, further than its sigma.
  EXPECT_TRUE(c["covariance"].as<bool>());
  // The final adjustment's wall time: a solve that includes its covariance, then the move.
  const YAML::Node timing = c["final_timing"];
  EXPECT_GT(timing["solve_ms"].as<double>(), 0.0);
  EXPECT_GT(timing["covariance_ms"].as<double>(), 0.0);
  EXPECT_LT(timing["covariance_ms"].as<double>(), timing["solve_ms"].as<double>());
  EXPECT_GT(timing["apply_ms"].as<double>(), 0.0);
  YAML::Node offset;
  ASSERT_NE(FindParameter(c["parameters"], "time_offset", &offset), nullptr);
  EXPECT_TRUE(offset["free"].as<bool>());
  EXPECT_EQ(offset["file"].as<double>(), 0.0);
  const double estimate_ms = offset["estimate"].as<double>();
  const double sigma_ms = offset["sigma"].as<double>();
  EXPECT_GT(sigma_ms, 0.0);
  EXPECT_LT(std::abs(estimate_ms - 1.0), 0.5) << estimate_ms;
  EXPECT_GT(estimate_ms, 3 * sigma_ms);
  // The free parameters' joint covariance, by name: its diagonal is their sigmas squared.
  const YAML::Node m = c["covariance_matrix"];
  ASSERT_GT(m["names"].size(), 1u);
  ASSERT_EQ(m["matrix"].size(), m["names"].size());
  for (std::size_t i = 0; i < m["names"].size(); ++i) {
    YAML::Node p;
    ASSERT_NE(FindParameter(c["parameters"], m["names"][i].as<std::string>(), &p), nullptr);
    EXPECT_TRUE(p["free"].as<bool>());
    ASSERT_EQ(m["matrix"][i].size(), m["names"].size());
    const double sigma = p["sigma"].as<double>();
    EXPECT_NEAR(std::sqrt(m["matrix"][i][i].as<double>()), sigma, 1e-6 * (1 + sigma));
  }
  // The estimate's files read back as EuRoC sensor files and as settings, with the same values.
  const EurocCameraSensor cam0 = ReadEurocCameraSensor(out / "calibration/cam0/sensor.yaml");
  EXPECT_NEAR(cam0.timeshift_cam_imu * 1e3, estimate_ms, 1e-9);
  const Settings settings = ReadOrbSlam3Settings(out / "calibration/settings.yaml");
  EXPECT_NEAR(settings.time_offset_s * 1e3, estimate_ms, 1e-9);
  YAML::Node fx;
  ASSERT_NE(FindParameter(c["parameters"], "cam0.fx", &fx), nullptr);
  EXPECT_DOUBLE_EQ(settings.camera1.fx(), fx["estimate"].as<double>());
  EXPECT_DOUBLE_EQ(cam0.intrinsics[0], fx["estimate"].as<double>());
  // The file's 1 ms is half a prior sigma: corrected, but below the warning's floor (a third
  // of the prior's sigma, 3 times: 2 ms), so no line claims the file is off (the rule and its
  // wording: system/calibration_outputs_test.cc; gross errors: docs/calibration.md).
  EXPECT_THAT(OnlineOutput(), ::testing::Not(HasSubstr("calibration: time_offset in")));
  // What is named is the stereo rig's disparity bias: the render's files make disparities 0.21
  // px too large (stereo depth 1.3% short at 3 m, evaluation/studies/calibration/
  // stereo_depth_error.py), which no single parameter shows at 3 sigma.
  ASSERT_EQ(c["warnings"].size(), 1u);
  const std::string bias = c["warnings"][0].as<std::string>();
  EXPECT_THAT(bias, HasSubstr("makes disparities"));
  EXPECT_THAT(bias, HasSubstr("px larger than the estimate does"));
  EXPECT_THAT(bias, HasSubstr("too short at 3 m"));
  EXPECT_THAT(OnlineOutput(), HasSubstr(bias));
}

TEST_F(CalibrationCli, DeterministicOnlineRunsAreIdentical) {
  const auto run = Run("again", OnlineArguments(Dir() / "again.map"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(testing::ReadFileBytes(Online() / "trajectory.txt"),
            testing::ReadFileBytes(Dir() / "again/trajectory.txt"));
  EXPECT_EQ(testing::ReadFileBytes(Online() / "calibration/settings.yaml"),
            testing::ReadFileBytes(Dir() / "again/calibration/settings.yaml"));
  EXPECT_EQ(testing::ReadFileBytes(OnlineMap()), testing::ReadFileBytes(Dir() / "again.map"));
}

TEST_F(CalibrationCli, AdjustmentsInTheirOwnThreadAreAppliedAndReported) {
  // Without --deterministic, which keeps them in local mapping's step: an offline run's default
  // is the thread, paced by the live emulation (its results applied by local mapping).
  const auto run = RunPkslam(
      fmt::format("--log-level info run --dataset '{}' --sensor stereo-inertial --out '{}' --quiet "
                  "--calibrate online",
                  Seq().string(), (Dir() / "thread").string()));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const YAML::Node c = ReadJsonFile(Dir() / "thread/stats.json")["calibration"];
  EXPECT_EQ(c["solved_in"].as<std::string>(), "thread");
  int applied = 0;
  for (const YAML::Node& h : c["history"]) applied += h["applied"].as<bool>() ? 1 : 0;
  EXPECT_GE(applied, 1) << run.output;
  EXPECT_TRUE(c["covariance"].as<bool>());
}

TEST_F(CalibrationCli, OffReportsTheFileAndWritesItBack) {
  const auto run = Run("off", "");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const YAML::Node c = ReadJsonFile(Dir() / "off/stats.json")["calibration"];
  EXPECT_EQ(c["mode"].as<std::string>(), "off");
  EXPECT_EQ(c["history"].size(), 0u);
  EXPECT_EQ(c["final_timing"]["solve_ms"].as<double>(), 0.0);
  for (const YAML::Node& p : c["parameters"]) {
    EXPECT_FALSE(p["free"].as<bool>());
    // Extrinsic entries are Log(estimate * file^-1): zero up to rounding.
    EXPECT_NEAR(p["file"].as<double>(), p["estimate"].as<double>(), 1e-9)
        << p["name"].as<std::string>();
  }
  // The written file is the dataset's calibration.
  const EurocCameraSensor written =
      ReadEurocCameraSensor(Dir() / "off/calibration/cam1/sensor.yaml");
  const EurocCameraSensor dataset = ReadEurocCameraSensor(Seq() / "mav0/cam1/sensor.yaml");
  EXPECT_EQ(written.intrinsics, dataset.intrinsics);
  EXPECT_EQ(written.distortion_coefficients, dataset.distortion_coefficients);
  EXPECT_LT((written.body_from_camera.Inverse() * dataset.body_from_camera).Log().norm(), 1e-12);
}

TEST_F(CalibrationCli, FreedomFlagsReachTheAdjustment) {
  // One flag that frees a group held by default and one that holds a group freed by default
  // (apps/calibration_flags.cc registers both from one table).
  const auto run =
      Run("freedom", "--calibrate online --calibrate-lever-arm --calibrate-hold-gyro-scale");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const YAML::Node c = ReadJsonFile(Dir() / "freedom/stats.json")["calibration"];
  YAML::Node p;
  ASSERT_NE(FindParameter(c["parameters"], "imu.tx", &p), nullptr);
  EXPECT_TRUE(p["free"].as<bool>());
  EXPECT_FALSE(c["frozen"]["imu_translation"].IsDefined());
  ASSERT_NE(FindParameter(c["parameters"], "gyro.sy", &p), nullptr);
  EXPECT_FALSE(p["free"].as<bool>());
  EXPECT_THAT(c["frozen"]["gyro_scale"].as<std::string>(),
              HasSubstr("--calibrate-hold-gyro-scale"));
}

TEST_F(CalibrationCli, TheEstimateFedBackRunsAndAMapCarriesItsCalibration) {
  const auto fed_back =
      Run("fed_back",
          fmt::format("--settings '{}'", (Online() / "calibration/settings.yaml").string()));
  EXPECT_EQ(fed_back.exit_code, 0) << fed_back.output;
  // A later session with the file's calibration loads the map and continues in its estimate.
  const auto loaded =
      Run("loaded", fmt::format("--load-map '{}' --max-frames 60", OnlineMap().string()));
  ASSERT_EQ(loaded.exit_code, 0) << loaded.output;
  const YAML::Node c = ReadJsonFile(Dir() / "loaded/stats.json")["calibration"];
  YAML::Node offset;
  ASSERT_NE(FindParameter(c["parameters"], "time_offset", &offset), nullptr);
  const YAML::Node saved = ReadJsonFile(Online() / "stats.json")["calibration"];
  YAML::Node saved_offset;
  ASSERT_NE(FindParameter(saved["parameters"], "time_offset", &saved_offset), nullptr);
  EXPECT_DOUBLE_EQ(offset["estimate"].as<double>(), saved_offset["estimate"].as<double>());
}

TEST_F(CalibrationCli, CalibrateWritesFilesAndAReport) {
  const fs::path out = Dir() / "calibrate";
  const auto r = RunPkslam(fmt::format(
      "--log-level warn calibrate --dataset '{}' --sensor stereo-inertial --out '{}' --quiet "
      "--deterministic --no-verify",
      Seq().string(), out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(out / "calibration/cam0/sensor.yaml"));
  EXPECT_TRUE(fs::exists(out / "calibration/settings.yaml"));
  const std::string report = testing::ReadFileBytes(out / "report.md");
  EXPECT_THAT(report, HasSubstr("| time_offset | ms |"));
  EXPECT_THAT(r.output, HasSubstr("parameters estimated"));
}

TEST(CalibrationCliOptions, RejectsAnUnknownModeAndMonocularCalibrate) {
  const auto bad = RunPkslam("run --dataset nowhere --calibrate sometimes");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_THAT(bad.output, HasSubstr("--calibrate"));
  const auto where = RunPkslam("run --dataset nowhere --calibrate online --calibrate-thread both");
  EXPECT_NE(where.exit_code, 0);
  EXPECT_THAT(where.output, HasSubstr("--calibrate-thread"));
  const auto mono = RunPkslam("calibrate --dataset nowhere --sensor mono");
  EXPECT_NE(mono.exit_code, 0);
  EXPECT_THAT(mono.output, HasSubstr("stereo rig or an IMU"));
}

}  // namespace
}  // namespace pkslam
