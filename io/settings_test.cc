#include "io/settings.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/core/persistence.hpp>
#include <regex>
#include <string>
#include <tuple>
#include <vector>

#include "core/util/error.h"
#include "io/euroc_sensor.h"
#include "io/settings_euroc.h"
#include "io/test_fixtures.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kTestData = fs::path(PKSLAM_SOURCE_DIR) / "io" / "testdata";

void ExpectTransformNear(const std::optional<SE3d>& a, const std::optional<SE3d>& b, double tol,
                         const char* what) {
  ASSERT_EQ(a.has_value(), b.has_value()) << what;
  if (!a) return;
  EXPECT_TRUE(a->Matrix().isApprox(b->Matrix(), tol)) << what << "\n"
                                                      << a->Matrix() << "\nvs\n"
                                                      << b->Matrix();
}

void ExpectSettingsNear(const Settings& a, const Settings& b, double tol) {
  EXPECT_EQ(a.rectified_stereo, b.rectified_stereo);
  EXPECT_TRUE(SameCalibration(a.camera1, b.camera1))
      << a.camera1.ToString() << " vs " << b.camera1.ToString();
  ASSERT_EQ(a.camera2.has_value(), b.camera2.has_value());
  if (a.camera2) {
    EXPECT_TRUE(SameCalibration(*a.camera2, *b.camera2))
        << a.camera2->ToString() << " vs " << b.camera2->ToString();
  }
  EXPECT_EQ(a.fps, b.fps);
  EXPECT_EQ(a.rgb_order, b.rgb_order);
  EXPECT_EQ(a.stereo_baseline_m, b.stereo_baseline_m);
  EXPECT_EQ(a.th_depth, b.th_depth);
  ExpectTransformNear(a.right_from_left, b.right_from_left, tol, "right_from_left");
  ExpectTransformNear(a.body_from_cam0, b.body_from_cam0, tol, "body_from_cam0");
  ASSERT_EQ(a.imu.has_value(), b.imu.has_value());
  if (a.imu) {
    EXPECT_EQ(a.imu->gyro_noise_density, b.imu->gyro_noise_density);
    EXPECT_EQ(a.imu->accel_noise_density, b.imu->accel_noise_density);
    EXPECT_EQ(a.imu->gyro_random_walk, b.imu->gyro_random_walk);
    EXPECT_EQ(a.imu->accel_random_walk, b.imu->accel_random_walk);
    EXPECT_EQ(a.imu->rate_hz, b.imu->rate_hz);
  }
  EXPECT_EQ(a.depth_map_factor, b.depth_map_factor);
  EXPECT_EQ(a.orb, b.orb);
  EXPECT_EQ(a.keyframe, b.keyframe);
}

TEST(Settings, ReadsEurocStereoInertialFile) {
  const Settings s = ReadOrbSlam3Settings(kTestData / "euroc_stereo_inertial.yaml");
  EXPECT_EQ(s.camera1.type(), CameraType::kPinhole);
  EXPECT_EQ(s.camera1.width(), 752);
  EXPECT_EQ(s.camera1.height(), 480);
  EXPECT_DOUBLE_EQ(s.camera1.fx(), 458.654);
  EXPECT_EQ(s.camera1.distortion(),
            (std::vector<double>{-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05}));
  ASSERT_TRUE(s.camera2.has_value());
  EXPECT_DOUBLE_EQ(s.camera2->cy(), 255.238);
  EXPECT_EQ(s.fps, 20);
  EXPECT_TRUE(s.IsStereo());
  // Stereo.T_c1_c2 is left_from_right: the right camera is +0.110 m along left x, so a point
  // in left coordinates has x about 0.110 m smaller in right coordinates.
  EXPECT_NEAR(s.right_from_left->translation().x(), -0.110, 0.001);
  EXPECT_NEAR(s.BaselineM(), 0.110078, 1e-6);
  EXPECT_NEAR(s.Bf(), 0.110078 * 458.654, 1e-3);
  EXPECT_EQ(s.th_depth, 60);
  ASSERT_TRUE(s.body_from_cam0.has_value());
  EXPECT_NEAR(s.body_from_cam0->translation().y(), -0.064676986768, 1e-12);
  ASSERT_TRUE(s.imu.has_value());
  EXPECT_EQ(s.imu->gyro_noise_density, 1.6968e-04);
  EXPECT_EQ(s.imu->accel_random_walk, 3.0e-3);
  EXPECT_EQ(s.imu->rate_hz, 200);
  EXPECT_TRUE(s.gyro_scale.isZero());  // pkslam's keys, absent
  EXPECT_TRUE(s.accel_axes.isZero());
  EXPECT_FALSE(s.depth_map_factor.has_value());
  EXPECT_EQ(s.orb, OrbExtractorSettings{});
  EXPECT_TRUE(s.keyframe.empty());
}

TEST(Settings, ReadsTumFr1RgbdFile) {
  const Settings s = ReadOrbSlam3Settings(kTestData / "tum_fr1_rgbd.yaml");
  EXPECT_EQ(s.camera1.distortion().size(), 5u);
  EXPECT_DOUBLE_EQ(s.camera1.distortion()[4], 1.163314);
  EXPECT_FALSE(s.camera2.has_value());
  EXPECT_FALSE(s.IsStereo());
  EXPECT_EQ(s.depth_map_factor, 5000.0);
  EXPECT_NEAR(s.Bf(), 0.07 * 517.306408, 1e-9);
  EXPECT_EQ(s.th_depth, 40);
  EXPECT_EQ(s.orb.n_features, 1000);
  EXPECT_FALSE(s.imu.has_value());
  EXPECT_EQ(s.fps, 30);
}

TEST(Settings, FromEurocSensorYamlEqualsAuthoredFile) {
  const fs::path root = testing::MakeTempDir("settings_euroc");
  testing::EurocFixture().Write(root);  // sensor.yaml files as in the real dataset
  const Settings from_dataset = SettingsFromEuroc(EurocDataset::Open(root));
  const Settings from_file = ReadOrbSlam3Settings(kTestData / "euroc_stereo_inertial.yaml");
  ExpectSettingsNear(from_dataset, from_file, 1e-12);
  fs::remove_all(root);
}

TEST(Settings, FromRealEurocSliceEqualsAuthoredFile) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const Settings from_dataset =
      SettingsFromEuroc(EurocDataset::Open(shared / "euroc" / "V1_01_easy_static"));
  ExpectSettingsNear(from_dataset, ReadOrbSlam3Settings(kTestData / "euroc_stereo_inertial.yaml"),
                     1e-12);
}

// pkslam's keys in imu0/sensor.yaml (written by a run's calibration estimates) reach the
// settings; out-of-range or misshapen values name the key.
TEST(Settings, FromEurocReadsTheImuScaleAndAxisErrors) {
  const fs::path root = testing::MakeTempDir("settings_euroc_imu");
  testing::EurocFixture().Write(root);
  const fs::path yaml = root / "mav0" / "imu0" / "sensor.yaml";
  const Eigen::Vector3d gyro_scale(0.001, -0.0048, 0.0);
  Eigen::Matrix3d accel_axes;
  accel_axes << 0.0021, 1.3e-3, -0.4e-3,  //
      -0.9e-3, -0.0017, 2.2e-3,           //
      0.0, 1.0 / 3.0 * 1e-3, 0.0005;
  const ImuNoise noise{1.6968e-04, 2.0e-3, 1.9393e-05, 3.0e-3, 200};
  const std::string text =
      EurocImuSensorYaml(EurocImuSensorOf(noise, gyro_scale, accel_axes), "imu0");
  EXPECT_THAT(text, HasSubstr("# pkslam: the accelerometer reads (I + E) times the true specific "
                              "force (E row-major)\naccelerometer_axis_errors: [0.0021, 0.0013, "));
  testing::WriteText(yaml, text);
  const Settings s = SettingsFromEuroc(EurocDataset::Open(root));
  EXPECT_EQ(s.gyro_scale, gyro_scale);
  EXPECT_EQ(s.accel_axes, accel_axes);
  // Zero errors are not written, and absent keys read as zero.
  const std::string plain = EurocImuSensorYaml(EurocImuSensorOf(noise), "imu0");
  EXPECT_THAT(plain, ::testing::Not(HasSubstr("accelerometer_axis_errors")));
  testing::WriteText(yaml, plain);
  EXPECT_TRUE(SettingsFromEuroc(EurocDataset::Open(root)).accel_axes.isZero());

  const auto error = [&](const std::string& value) -> std::string {
    testing::WriteText(yaml, plain + "accelerometer_axis_errors: " + value + "\n");
    try {
      ReadEurocImuSensor(yaml);
    } catch (const InputError& e) {
      return e.what();
    }
    return "no InputError";
  };
  EXPECT_THAT(error("[0, 0, 0, 0, 0, 0, 0, 0]"),
              HasSubstr("key 'accelerometer_axis_errors': expected 9 numbers, found 8"));
  EXPECT_THAT(error("[0, 0, 0, 0, 0, -0.3, 0, 0, 0]"),
              HasSubstr("key 'accelerometer_axis_errors': -0.3 is not an axis error"));
  EXPECT_THAT(error("[0, 0, 0, 0, 0, x, 0, 0, 0]"),
              HasSubstr("key 'accelerometer_axis_errors': sequence element: expected a number"));
  fs::remove_all(root);
}

class SettingsFiles : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::MakeTempDir("settings"); }
  void TearDown() override { fs::remove_all(dir_); }

  // The EuRoC test file with `pattern` (a regex over the text) replaced.
  fs::path Edited(const std::string& pattern, const std::string& replacement) {
    std::ifstream in(kTestData / "euroc_stereo_inertial.yaml");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string edited = std::regex_replace(text, std::regex(pattern), replacement);
    EXPECT_NE(edited, text) << "pattern did not match: " << pattern;
    fs::path file = dir_ / "edited.yaml";
    testing::WriteText(file, edited);
    return file;
  }
  std::string ReadError(const fs::path& file) {
    try {
      ReadOrbSlam3Settings(file);
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), file);
      return e.what();
    }
    ADD_FAILURE() << "no InputError";
    return "";
  }

  fs::path dir_;
};

TEST_F(SettingsFiles, RoundTripEurocAndTum) {
  for (const char* name : {"euroc_stereo_inertial.yaml", "tum_fr1_rgbd.yaml"}) {
    Settings s = ReadOrbSlam3Settings(kTestData / name);
    s.keyframe = {{"cone_threshold", 0.35}, {"ecog.grid", 8}, {"min_interval_s", 1e-5}};
    const fs::path out = dir_ / name;
    WriteOrbSlam3Settings(s, out);
    ExpectSettingsNear(ReadOrbSlam3Settings(out), s, 1e-15);
  }
  // What ORB-SLAM3 itself needs from the written file: reals where it reads floats, ints where
  // it reads ints, and float matrices.
  cv::FileStorage fs((dir_ / "euroc_stereo_inertial.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  EXPECT_TRUE(fs["Camera1.fx"].isReal());
  EXPECT_TRUE(fs["Stereo.ThDepth"].isReal());
  EXPECT_TRUE(fs["IMU.Frequency"].isReal());
  EXPECT_TRUE(fs["Camera.width"].isInt());
  EXPECT_TRUE(fs["Camera.fps"].isInt());
  EXPECT_TRUE(fs["ORBextractor.nFeatures"].isInt());
  EXPECT_EQ(fs["Camera.type"].string(), "PinHole");
  EXPECT_EQ(fs["File.version"].string(), "1.0");
  cv::Mat t_c1_c2;
  fs["Stereo.T_c1_c2"] >> t_c1_c2;
  ASSERT_EQ(t_c1_c2.type(), CV_32F);
  ASSERT_EQ(t_c1_c2.rows, 4);
  EXPECT_NEAR(t_c1_c2.at<float>(0, 3), 0.1100741378, 1e-7);
}

TEST_F(SettingsFiles, RoundTripKannalaBrandtAndRectified) {
  Settings kb;
  kb.camera1 = CameraModel::KannalaBrandt8(512, 512, 190.978, 190.973, 254.932, 256.897,
                                           {0.00348238, 0.000715034, -0.00205323, 0.000202936});
  kb.camera2 = CameraModel::KannalaBrandt8(512, 512, 190.44, 190.45, 255.0, 256.2,
                                           {0.0034, 0.0007, -0.0020, 0.0002});
  kb.fps = 20.5;
  kb.right_from_left =
      SE3d(SO3d::Exp(Eigen::Vector3d(0.01, -0.02, 0.003)), Eigen::Vector3d(-0.101, 0.002, -0.0004));
  kb.body_from_cam0 =
      SE3d(SO3d::Exp(Eigen::Vector3d(1.2, 0.1, -0.4)), Eigen::Vector3d(0.04, -0.03, 0.02));
  kb.imu = ImuNoise{0.004, 0.05, 4.4e-5, 0.00172, 200};
  kb.orb = {1500, 1.25, 9, 19, 6};
  kb.gyro_scale = Eigen::Vector3d(0.001, -0.0048, 0.0);
  kb.accel_axes << 0.0021, 1.3e-3, -0.4e-3,  //
      -0.9e-3, -0.0017, 2.2e-3,              //
      0.0, 1.0 / 3.0 * 1e-3, 0.0005;
  WriteOrbSlam3Settings(kb, dir_ / "kb.yaml");
  const Settings kb_back = ReadOrbSlam3Settings(dir_ / "kb.yaml");
  ExpectSettingsNear(kb_back, kb, 1e-15);
  EXPECT_EQ(kb_back.gyro_scale, kb.gyro_scale);
  EXPECT_EQ(kb_back.accel_axes, kb.accel_axes);  // every digit, row-major
  // A 3x3 double matrix to OpenCV too (ORB-SLAM3 ignores the key).
  cv::FileStorage fs((dir_ / "kb.yaml").string(), cv::FileStorage::READ);
  cv::Mat accel_axes;
  fs["IMU.AccelAxes"] >> accel_axes;
  ASSERT_EQ(accel_axes.type(), CV_64F);
  ASSERT_EQ(accel_axes.rows, 3);
  ASSERT_EQ(accel_axes.cols, 3);
  EXPECT_EQ(accel_axes.at<double>(1, 2), 2.2e-3);

  Settings rectified;
  rectified.rectified_stereo = true;
  rectified.camera1 = CameraModel::Pinhole(640, 480, 400, 400, 320, 240);
  rectified.fps = 10;
  rectified.stereo_baseline_m = 0.12;
  rectified.right_from_left = SE3d(SO3d(), Eigen::Vector3d(-0.12, 0, 0));
  rectified.depth_map_factor = 1000;
  WriteOrbSlam3Settings(rectified, dir_ / "rect.yaml");
  const Settings back = ReadOrbSlam3Settings(dir_ / "rect.yaml");
  ExpectSettingsNear(back, rectified, 1e-15);
  EXPECT_DOUBLE_EQ(back.Bf(), 48);
}

TEST_F(SettingsFiles, MissingOrMalformedKeysNameKeyFileAndLine) {
  const fs::path file = dir_ / "edited.yaml";
  EXPECT_THAT(ReadError(Edited("Camera1.fx: 458.654\n", "")),
              HasSubstr(file.string() + ": key 'Camera1.fx': missing (required)"));
  EXPECT_THAT(ReadError(Edited("Camera1.fy: 457.296", "Camera1.fy: abc")),
              HasSubstr(file.string() + ":17: key 'Camera1.fy': expected a number, found 'abc'"));
  EXPECT_THAT(ReadError(Edited("File.version: \"1.0\"", "File.version: \"0.9\"")),
              HasSubstr("key 'File.version': unsupported version '0.9'"));
  EXPECT_THAT(ReadError(Edited("\"PinHole\"", "\"Pinhole\"")),
              HasSubstr("key 'Camera.type': unknown camera type 'Pinhole'"));
  EXPECT_THAT(ReadError(Edited("Camera1.k2: 0.07395907", "Camera1.k2: nan")),
              HasSubstr("key 'Camera1.k2': expected a number"));
  EXPECT_THAT(ReadError(Edited("Camera.width: 752", "Camera.width: 752.5")),
              HasSubstr("key 'Camera.width': expected an integer"));
  EXPECT_THAT(ReadError(Edited("Camera.width: 752", "Camera.width: -752")),
              HasSubstr("key 'Camera.width': must be a positive integer"));
  EXPECT_THAT(ReadError(Edited("IMU.NoiseAcc: 2.0e-03\n", "")),
              HasSubstr("key 'IMU.NoiseAcc': missing (required)"));
  EXPECT_THAT(ReadError(Edited("IMU.Frequency: 200.0", "IMU.Frequency: 200.0\nIMU.GyroScaleY: 0.5")),
              HasSubstr("key 'IMU.GyroScaleY': must be within [-0.1, 0.1] (a fraction"));
  const auto with_accel_axes = [&](const std::string& matrix) {
    return Edited("IMU.Frequency: 200.0", "IMU.Frequency: 200.0\nIMU.AccelAxes: " + matrix);
  };
  EXPECT_THAT(ReadError(with_accel_axes("!!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n"
                                        "  data: [0.001, 0, 0, 0, 0.5, 0, 0, 0, 0]")),
              HasSubstr("key 'IMU.AccelAxes': entries must be within [-0.2, 0.2] (scale fractions, "
                        "misalignment in rad), found 0.5 at row 1, col 1"));
  EXPECT_THAT(ReadError(with_accel_axes("!!opencv-matrix\n  rows: 3\n  cols: 2\n  dt: d\n"
                                        "  data: [0, 0, 0, 0, 0, 0]")),
              HasSubstr("key 'IMU.AccelAxes': expected a 3x3 matrix, found 3x2"));
  EXPECT_THAT(ReadError(with_accel_axes("!!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n"
                                        "  data: [0, 0, 0, 0, 0, 0, 0, 0]")),
              HasSubstr("key 'IMU.AccelAxes': matrix data has 8 numbers, expected 9"));
  EXPECT_THAT(ReadError(with_accel_axes("!!opencv-matrix\n  rows: 3\n  cols: 3\n  dt: d\n"
                                        "  data: [0, 0, 0, 0, .nan, 0, 0, 0, 0]")),
              HasSubstr("key 'IMU.AccelAxes': matrix data: is not finite"));
  EXPECT_THAT(ReadError(with_accel_axes("[0, 0, 0, 0, 0, 0, 0, 0, 0]")),
              HasSubstr("key 'IMU.AccelAxes': expected a matrix (rows, cols, data)"));
  EXPECT_THAT(ReadError(Edited("Stereo.T_c1_c2", "Stereo.T_c1_c2_typo")),
              HasSubstr("key 'Stereo.T_c1_c2': missing (required with Camera2.*)"));
  EXPECT_THAT(ReadError(Edited("0.9999972564774497,", "1.5,")),
              HasSubstr(":42: key 'Stereo.T_c1_c2': not a rigid transform"));
  EXPECT_THAT(ReadError(Edited("rows: 4\n  cols: 4\n  dt: f\n  data: \\[0.99",
                               "rows: 3\n  cols: 4\n  dt: f\n  data: [0.99")),
              HasSubstr("key 'Stereo.T_c1_c2': expected a 4x4 matrix, found 3x4"));
  EXPECT_THAT(ReadError(Edited("ORBextractor.minThFAST: 7", "ORBextractor.minThFAST: 25")),
              HasSubstr("inconsistent settings: option orb.min_th_fast"));
  EXPECT_THAT(ReadError(Edited("Camera.fps: 20", "Camera.fps: [20")),
              HasSubstr(file.string() + ":"));  // parse error located by OpenCV
  EXPECT_THAT(ReadError(Edited("%YAML:1.0\n", "")), HasSubstr(":1: not an OpenCV YAML file"));
  testing::WriteText(file, "");
  EXPECT_THAT(ReadError(file), HasSubstr("empty file"));
  EXPECT_THAT(ReadError(dir_ / "absent.yaml"), HasSubstr("file not found"));
}

TEST_F(SettingsFiles, KeyframeParametersAndOptionalDefaults) {
  const fs::path file = dir_ / "mono.yaml";
  testing::WriteText(file,
                     "%YAML:1.0\nFile.version: \"1.0\"\nCamera.type: \"PinHole\"\n"
                     "Camera1.fx: 400.0\nCamera1.fy: 401.0\nCamera1.cx: 320.0\nCamera1.cy: 240.0\n"
                     "Camera.width: 640\nCamera.height: 480\nCamera.fps: 30\n"
                     "Keyframe.cone_threshold: 0.4\nKeyframe.max_gap_s: 2\n");
  const Settings s = ReadOrbSlam3Settings(file);
  EXPECT_TRUE(s.camera1.distortion().empty());
  EXPECT_TRUE(s.rgb_order);
  EXPECT_EQ(s.th_depth, 60);
  EXPECT_EQ(s.orb, OrbExtractorSettings{});
  EXPECT_FALSE(s.IsStereo());
  EXPECT_EQ(s.Bf(), 0);
  EXPECT_EQ(s.keyframe, (std::map<std::string, double>{{"cone_threshold", 0.4}, {"max_gap_s", 2}}));
}

// ORB settings out of what an extractor can do name the key (and its line), instead of
// overflowing far away (2e9 features became -294967296).
TEST_F(SettingsFiles, OrbValuesOutOfRangeNameTheKey) {
  for (const auto& [pattern, replacement, key] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"ORBextractor.nFeatures: *[0-9]+", "ORBextractor.nFeatures: 2e9", "nFeatures"},
           {"ORBextractor.nFeatures: *[0-9]+", "ORBextractor.nFeatures: 0", "nFeatures"},
           {"ORBextractor.nLevels: *[0-9]+", "ORBextractor.nLevels: 100", "nLevels"},
           {"ORBextractor.iniThFAST: *[0-9]+", "ORBextractor.iniThFAST: 300", "iniThFAST"},
           {"ORBextractor.scaleFactor: *[0-9.]+", "ORBextractor.scaleFactor: 1.0",
            "scaleFactor"}}) {
    const std::string error = ReadError(Edited(pattern, replacement));
    EXPECT_NE(error.find(key), std::string::npos) << replacement << ": " << error;
    EXPECT_NE(error.find("must be in"), std::string::npos) << replacement << ": " << error;
  }
}

TEST(SettingsCheck, RejectsInconsistentValues) {
  Settings s = ReadOrbSlam3Settings(kTestData / "euroc_stereo_inertial.yaml");
  EXPECT_NO_THROW(s.Check());
  Settings bad = s;
  bad.camera2 = CameraModel::KannalaBrandt8(752, 480, 457, 456, 380, 255, {0, 0, 0, 0});
  EXPECT_THROW(bad.Check(), OptionError);
  bad = s;
  bad.body_from_cam0.reset();
  EXPECT_THROW(bad.Check(), OptionError);
  bad = s;
  bad.camera2 = CameraModel::Pinhole(640, 480, 457, 456, 380, 255);
  EXPECT_THROW(bad.Check(), OptionError);
  bad = s;
  bad.camera1 = CameraModel();
  EXPECT_THROW(bad.Check(), OptionError);
  bad = s;
  bad.orb.scale_factor = 1.0;
  EXPECT_THROW(bad.Check(), OptionError);
  bad = s;
  bad.keyframe["bad key"] = 1;
  const fs::path dir = testing::MakeTempDir("settings");
  EXPECT_THROW(WriteOrbSlam3Settings(bad, dir / "x.yaml"), OptionError);
  EXPECT_FALSE(fs::exists(dir / "x.yaml"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pkslam
