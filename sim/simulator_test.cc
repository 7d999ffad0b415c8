#include "sim/simulator.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core/persistence.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>

#include "core/util/error.h"
#include "io/dataset_info.h"
#include "io/settings.h"
#include "io/trajectory.h"
#include "tests/support/test_data.h"

namespace pkslam::sim {
namespace {

namespace fs = std::filesystem;

// The header of EuRoC's state_groundtruth_estimate0/data.csv (the real slice lacks the file).
constexpr const char* kEurocGroundTruthHeader =
    "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
    "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
    "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
    "b_a_RS_S_z [m s^-2]";

std::vector<std::string> Lines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

std::vector<std::string> Split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string f; std::getline(ss, f, sep);) out.push_back(f);
  return out;
}

SimulationOptions ShortReplay(const fs::path& shared, const fs::path& out) {
  SimulationOptions o;
  o.output_dir = out;
  o.trajectory = shared / "euroc/groundtruth/V1_02_medium.txt";
  o.start_s = 20.0;
  o.duration_s = 0.5;
  o.quality = Quality::kFast;
  o.quiet = true;
  o.cloud_spacing_m = 0.05;
  o.visibility_cell_m = 0.1;
  return o;
}

// Compares a sensor.yaml of ours with the real one through OpenCV's parser (what EuRoC
// tools and ORB-SLAM3 use): same keys, same numbers (our defaults are EuRoC's calibration).
void CompareSensorYaml(const fs::path& real, const fs::path& ours) {
  cv::FileStorage a(real.string(), cv::FileStorage::READ);
  cv::FileStorage b(ours.string(), cv::FileStorage::READ);
  ASSERT_TRUE(a.isOpened() && b.isOpened()) << ours;
  std::set<std::string> keys_a, keys_b;
  for (const auto& n : a.root()) keys_a.insert(n.name());
  for (const auto& n : b.root()) keys_b.insert(n.name());
  EXPECT_EQ(keys_a, keys_b) << ours;
  for (const std::string& key : keys_a) {
    const cv::FileNode na = a[key];
    const cv::FileNode nb = b[key];
    if (key == "comment") continue;
    if (na.isString()) {
      EXPECT_EQ(na.string(), nb.string()) << key;
    } else if (na.isSeq()) {
      ASSERT_EQ(na.size(), nb.size()) << key;
      for (std::size_t i = 0; i < na.size(); ++i) {
        EXPECT_NEAR(na[static_cast<int>(i)].real(), nb[static_cast<int>(i)].real(), 1e-12) << key;
      }
    } else if (na.isMap()) {  // T_BS
      EXPECT_EQ(static_cast<int>(na["rows"]), static_cast<int>(nb["rows"]));
      EXPECT_EQ(static_cast<int>(na["cols"]), static_cast<int>(nb["cols"]));
      ASSERT_EQ(na["data"].size(), 16u);
      ASSERT_EQ(nb["data"].size(), 16u);
      for (int i = 0; i < 16; ++i) {
        EXPECT_NEAR(na["data"][i].real(), nb["data"][i].real(), 1e-12) << key;
      }
    } else {
      EXPECT_NEAR(na.real(), nb.real(), 1e-12) << key;
    }
  }
}

TEST(Simulator, ReplayWritesEurocFormatLikeTheRealDataset) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path out = testing::MakeTempDir("sim_euroc");
  SimulationOptions o = ShortReplay(shared, out);
  o.blackout_begin_s = 0.2;
  o.blackout_end_s = 0.3;
  const SimulationSummary s = RunSimulation(o);
  EXPECT_EQ(s.layout, "euroc");
  EXPECT_EQ(s.frames, 11);
  EXPECT_EQ(s.imu_samples, 101);
  const fs::path real = shared / "euroc/V1_01_easy_static/mav0";
  const fs::path mav = out / "mav0";

  // Headers identical to the real files.
  for (const char* f : {"cam0/data.csv", "cam1/data.csv", "imu0/data.csv"}) {
    EXPECT_EQ(Lines(mav / f).at(0), Lines(real / f).at(0)) << f;
  }
  EXPECT_EQ(Lines(mav / "state_groundtruth_estimate0/data.csv").at(0), kEurocGroundTruthHeader);
  for (const char* f : {"cam0/sensor.yaml", "cam1/sensor.yaml", "imu0/sensor.yaml",
                        "state_groundtruth_estimate0/sensor.yaml"}) {
    CompareSensorYaml(real / f, mav / f);
  }
  EXPECT_EQ(Lines(mav / "body.yaml").at(0), Lines(real / "body.yaml").at(0));

  // IMU: 7 columns, 5 ms apart; ground truth: 17 columns at the IMU timestamps.
  const auto imu = Lines(mav / "imu0/data.csv");
  const auto gt = Lines(mav / "state_groundtruth_estimate0/data.csv");
  ASSERT_EQ(imu.size(), 102u);
  ASSERT_EQ(gt.size(), 102u);
  std::set<std::int64_t> imu_times;
  for (std::size_t i = 1; i < imu.size(); ++i) {
    const auto f = Split(imu[i], ',');
    ASSERT_EQ(f.size(), 7u);
    imu_times.insert(std::stoll(f[0]));
    EXPECT_EQ(Split(gt[i], ',').size(), 17u);
    EXPECT_EQ(Split(gt[i], ',')[0], f[0]);
    if (i > 1) {
      EXPECT_EQ(std::stoll(f[0]) - std::stoll(Split(imu[i - 1], ',')[0]), 5'000'000);
    }
  }
  // Images: `t,t.png`, 752x480 8-bit grey like the real ones, at IMU timestamps (20 Hz).
  const cv::Mat real_image =
      cv::imread((real / "cam0/data" / Split(Lines(real / "cam0/data.csv").at(1), ',')[1]).string(),
                 cv::IMREAD_UNCHANGED);
  const auto ts = Lines(out / "timestamps.txt");
  for (const char* cam : {"cam0", "cam1"}) {
    const auto rows = Lines(mav / cam / "data.csv");
    ASSERT_EQ(rows.size(), 12u);
    for (std::size_t i = 1; i < rows.size(); ++i) {
      const auto f = Split(rows[i], ',');
      ASSERT_EQ(f.size(), 2u);
      EXPECT_EQ(f[1], f[0] + ".png");
      EXPECT_EQ(ts.at(i - 1), f[0]);
      const std::int64_t t = std::stoll(f[0]);
      EXPECT_TRUE(imu_times.count(t)) << "image not at an IMU timestamp";
      const cv::Mat image = cv::imread((mav / cam / "data" / f[1]).string(), cv::IMREAD_UNCHANGED);
      ASSERT_EQ(image.type(), real_image.type());
      ASSERT_EQ(image.size(), real_image.size());
      // Stored like the real files (not deflated: as cheap to decode).
      EXPECT_GE(std::filesystem::file_size(mav / cam / "data" / f[1]),
                static_cast<std::uintmax_t>(image.total()));
      const double rel = 1e-9 * static_cast<double>(t - s.begin_ns);
      const bool black = rel >= 0.2 && rel <= 0.3;
      EXPECT_EQ(cv::countNonZero(image) == 0, black) << "t = " << rel << " s";
    }
  }
  EXPECT_EQ(*imu_times.begin(), std::stoll(ts.at(0)));

  // Settings (ORB-SLAM3 format) and the record of options.
  const Settings settings = ReadOrbSlam3Settings(out / "settings.yaml");
  EXPECT_DOUBLE_EQ(settings.camera1.fx(), 458.654);
  ASSERT_TRUE(settings.imu.has_value());
  EXPECT_DOUBLE_EQ(settings.imu->gyro_noise_density, 1.6968e-4);
  EXPECT_NEAR(settings.BaselineM(), 0.110078, 1e-5);  // EuRoC's baseline
  // `pkslam info` reads the sequence: 11 stereo pairs over the 0.5 s window, IMU at 200 Hz.
  const DatasetInfo info = ComputeDatasetInfo(out);
  EXPECT_EQ(info.layout, DatasetLayout::kEuroc);
  ASSERT_TRUE(info.stereo_pairs.has_value());
  EXPECT_EQ(*info.stereo_pairs, 11u);
  EXPECT_NEAR(info.ImageDurationS(), 0.5, 1e-9);
  ASSERT_NE(info.Find("imu0"), nullptr);
  EXPECT_NEAR(info.Find("imu0")->measured_rate_hz, 200.0, 1e-6);
  EXPECT_TRUE(info.Find("cam0")->missing_files.empty());
  EXPECT_NE(testing::ReadFileBytes(out / "sim.yaml").find("seed: 1"), std::string::npos);
  EXPECT_GT(s.cloud_points, 100u);
  EXPECT_EQ(testing::ReadFileBytes(out / "reference_cloud.ply")
                .rfind("ply\nformat binary_little_endian 1.0", 0),
            0u);
}

TEST(Simulator, SameSeedGivesIdenticalBytes) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path a = testing::MakeTempDir("sim_seed_a");
  const fs::path b = testing::MakeTempDir("sim_seed_b");
  const fs::path c = testing::MakeTempDir("sim_seed_c");
  SimulationOptions o = ShortReplay(shared, a);
  o.duration_s = 0.2;
  RunSimulation(o);
  o.output_dir = b;
  RunSimulation(o);
  o.output_dir = c;
  o.seed = 2;
  RunSimulation(o);
  int files = 0;
  int differ_c = 0;
  for (const auto& entry : fs::recursive_directory_iterator(a)) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), a);
    ASSERT_TRUE(fs::exists(b / rel)) << rel;
    EXPECT_EQ(testing::ReadFileBytes(entry.path()), testing::ReadFileBytes(b / rel)) << rel;
    ++files;
    if (fs::exists(c / rel) &&
        testing::ReadFileBytes(entry.path()) != testing::ReadFileBytes(c / rel))
      ++differ_c;
  }
  EXPECT_GT(files, 20);
  EXPECT_GT(differ_c, 10);  // images, IMU, biases, sim.yaml change with the seed
  // The motion does not depend on the seed: same ground-truth poses.
  const auto ga = ReadTrajectory(a / "mav0/state_groundtruth_estimate0/data.csv").poses;
  const auto gc = ReadTrajectory(c / "mav0/state_groundtruth_estimate0/data.csv").poses;
  ASSERT_EQ(ga.size(), gc.size());
  EXPECT_EQ(ga.back().pose.translation(), gc.back().pose.translation());
}

TEST(Simulator, FullV102ReplayKeepsDurationAndPathLength) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path source = shared / "euroc/groundtruth/V1_02_medium.txt";
  const fs::path out = testing::MakeTempDir("sim_v102");
  SimulationOptions o;
  o.output_dir = out;
  o.trajectory = source;
  o.write_images = false;
  o.write_cloud = false;
  o.quality = Quality::kFast;
  o.quiet = true;
  RunSimulation(o);
  const Trajectory src_traj = ReadTrajectory(source);
  const Trajectory sim_traj = ReadTrajectory(out / "mav0/state_groundtruth_estimate0/data.csv");
  const auto& src = src_traj.poses;
  const auto& sim = sim_traj.poses;
  const double src_s = DurationSeconds(src_traj);
  const double sim_s = DurationSeconds(sim_traj);
  const double src_m = PathLengthMeters(src_traj);
  const double sim_m = PathLengthMeters(sim_traj);
  std::printf("V1_02 source %.3f s %.3f m; simulated %.3f s %.3f m\n", src_s, src_m, sim_s, sim_m);
  EXPECT_EQ(sim.front().t_ns, src.front().t_ns);
  EXPECT_NEAR(sim_s, src_s, 0.005);
  EXPECT_NEAR(sim_m, src_m, 0.01 * src_m);
  EXPECT_TRUE(sim_traj.has_extras());           // 17-column EuRoC ground truth
  EXPECT_FALSE(fs::exists(out / "mav0/cam0"));  // --no-images: IMU and ground truth only
  // The replay follows the source closely (not just in length).
  double max_err = 0;
  std::size_t j = 0;
  for (const auto& s : src) {
    while (j + 1 < sim.size() && sim[j].t_ns < s.t_ns) ++j;
    if (std::llabs(sim[j].t_ns - s.t_ns) > 100'000) continue;  // 10 us source rounding
    max_err = std::max(max_err, (sim[j].pose.translation() - s.pose.translation()).norm());
  }
  EXPECT_LT(max_err, 0.01);
}

TEST(Simulator, RgbdWritesTumLayout) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path out = testing::MakeTempDir("sim_rgbd");
  SimulationOptions o = ShortReplay(shared, out);
  o.duration_s = 0.2;
  o.rgbd = true;
  const SimulationSummary s = RunSimulation(o);
  EXPECT_EQ(s.layout, "tum_rgbd");
  const auto rgb = Lines(out / "rgb.txt");
  const auto assoc = Lines(out / "associations.txt");
  ASSERT_EQ(rgb.size(), 3u + 7u);  // 3 comment lines, 30 Hz over 0.2 s
  ASSERT_EQ(assoc.size(), 7u);
  const auto f = Split(assoc[3], ' ');
  ASSERT_EQ(f.size(), 4u);
  const cv::Mat colour = cv::imread((out / f[1]).string(), cv::IMREAD_UNCHANGED);
  const cv::Mat depth = cv::imread((out / f[3]).string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(colour.type(), CV_8UC3);
  EXPECT_EQ(depth.type(), CV_16U);
  EXPECT_EQ(depth.size(), cv::Size(640, 480));
  // Depth in metres * 5000: a room of a few metres.
  double lo = 0, hi = 0;
  cv::minMaxLoc(depth, &lo, &hi);
  EXPECT_GT(hi / 5000.0, 0.5);
  EXPECT_LT(hi / 5000.0, 8.01);
  EXPECT_GT(Lines(out / "groundtruth.txt").size(), 20u);
  const Settings settings = ReadOrbSlam3Settings(out / "settings.yaml");
  EXPECT_EQ(settings.depth_map_factor, 5000.0);
  const DatasetInfo info = ComputeDatasetInfo(out);
  EXPECT_EQ(info.layout, DatasetLayout::kTumRgbd);
  ASSERT_TRUE(info.rgbd_pairs.has_value());
  EXPECT_EQ(*info.rgbd_pairs, 7u);
}

// Sharpness: variance of the Laplacian.
double Sharpness(const cv::Mat& image) {
  cv::Mat lap;
  cv::Laplacian(image, lap, CV_64F);
  cv::Scalar mean, sd;
  cv::meanStdDev(lap, mean, sd);
  return sd[0] * sd[0];
}

TEST(Simulator, MotionBlurSoftensMovingFrames) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path sharp_dir = testing::MakeTempDir("sim_sharp");
  const fs::path blur_dir = testing::MakeTempDir("sim_blur");
  SimulationOptions o = ShortReplay(shared, sharp_dir);
  o.duration_s = 0.1;
  o.write_cloud = false;
  o.sensor.read_noise_dn = 0.0;
  o.sensor.shot_noise_gain = 0.0;
  RunSimulation(o);
  o.output_dir = blur_dir;
  o.motion_blur_exposure_s = 0.03;  // 30 ms at ~1 m/s and ~30 deg/s: several pixels
  RunSimulation(o);
  const std::string name = Split(Lines(sharp_dir / "mav0/cam0/data.csv").at(2), ',')[1];
  const cv::Mat sharp =
      cv::imread((sharp_dir / "mav0/cam0/data" / name).string(), cv::IMREAD_GRAYSCALE);
  const cv::Mat blurred =
      cv::imread((blur_dir / "mav0/cam0/data" / name).string(), cv::IMREAD_GRAYSCALE);
  std::printf("Laplacian variance: sharp %.1f, motion-blurred %.1f\n", Sharpness(sharp),
              Sharpness(blurred));
  EXPECT_LT(Sharpness(blurred), 0.8 * Sharpness(sharp));
  EXPECT_NEAR(cv::mean(blurred)[0], cv::mean(sharp)[0], 8.0);  // same exposure
}

TEST(Simulator, BadInputsAreReportedWithFileAndLine) {
  const fs::path dir = testing::MakeTempDir("sim_bad");
  {
    std::ofstream f(dir / "traj.txt");
    f << "# t x y z qx qy qz qw\n1.0 0 0 0 0 0 0 1\n2.0 0 0 zero 0 0 0 1\n";
  }
  SimulationOptions o;
  o.output_dir = dir / "out";
  o.trajectory = dir / "traj.txt";
  o.quiet = true;
  try {
    RunSimulation(o);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 3u);
    EXPECT_NE(std::string(e.what()).find("traj.txt:3"), std::string::npos);
  }
  o.trajectory = dir / "missing.txt";
  EXPECT_THROW(RunSimulation(o), InputError);
  o.trajectory.clear();
  o.scene = (dir / "no_scene.yaml").string();
  EXPECT_THROW(RunSimulation(o), InputError);
  o.scene = "vicon_room";
  o.blackout_begin_s = 2.0;
  o.blackout_end_s = 1.0;
  EXPECT_THROW(RunSimulation(o), OptionError);
}

}  // namespace
}  // namespace pkslam::sim
