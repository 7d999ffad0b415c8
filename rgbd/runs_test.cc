// The two dataset runs end to end on a small synthetic TUM RGB-D folder, and their input errors.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/util/error.h"
#include "io/trajectory.h"
#include "rgbd/odometry_run.h"
#include "rgbd/planar_run.h"
#include "rgbd/test_scene.h"
#include "tests/support/test_data.h"

namespace pkslam::rgbd {
namespace {
namespace fs = std::filesystem;

// A fresh 12-frame synthetic sequence (rendering takes well under a second).
fs::path RoomDataset() {
  const fs::path dir = pkslam::testing::MakeTempDir("rgbd_room");
  testing::WriteTumRoom(dir, 12, 0.002);
  return dir;
}

TEST(RunRgbdOdometry, WritesOutputsAndTracksTheSyntheticRoom) {
  OdometryRunOptions options;
  options.input.dataset = RoomDataset();
  options.odometry.orb.n_features = 800;
  options.odometry.depth.max_depth_m = 5.0;
  options.out = pkslam::testing::MakeTempDir("rgbd_odo_out");
  options.quiet = true;
  const OdometryRunResult r = RunRgbdOdometry(options);
  EXPECT_EQ(r.frames, 12);
  EXPECT_EQ(r.tracked, 11);
  EXPECT_EQ(r.poses, 12);
  ASSERT_TRUE(r.ate.has_value());
  EXPECT_LT(r.ate->ate_translation_m.rmse, 0.01);
  EXPECT_GT(r.map_points, 1000u);
  for (const char* f : {"trajectory.txt", "map.ply", "stats.json", "frames.csv"}) {
    EXPECT_TRUE(fs::exists(options.out / f)) << f;
  }
  const Trajectory written = ReadTrajectory(options.out / "trajectory.txt");
  EXPECT_EQ(written.size(), 12u);
  EXPECT_GT(r.mean_times.total(), 0.0);
  EXPECT_NE(FormatStageTable("room", r.mean_times).find("preprocessing"), std::string::npos);
}

TEST(RunPlanar, RegistersWithGapsAndComparesWithFullIcp) {
  PlanarRunOptions options;
  options.input.dataset = RoomDataset();
  options.gaps = {1, 3};
  options.reference_full_icp = true;
  options.full_stride = 2;
  options.threshold_table = true;
  options.out = pkslam::testing::MakeTempDir("rgbd_planar_out");
  options.quiet = true;
  const PlanarRunResult r = RunPlanar(options);
  ASSERT_EQ(r.gaps.size(), 2u);
  EXPECT_EQ(r.gaps[0].planar.pairs, 11);
  EXPECT_EQ(r.gaps[1].planar.pairs, 3);  // frames 0, 3, 6, 9
  for (const GapResult& g : r.gaps) {
    ASSERT_TRUE(g.full.has_value());
    ASSERT_TRUE(g.speedup_percent.has_value());
    ASSERT_TRUE(g.model_error_m.has_value());
    ASSERT_EQ(g.planar.translation_errors_m.size(), static_cast<std::size_t>(g.planar.pairs));
    ASSERT_EQ(g.full->translation_errors_m.size(), static_cast<std::size_t>(g.full->pairs));
    EXPECT_GT(g.planar.total_ms(), g.planar.without_segmentation_ms());
  }
  // Consecutive frames (~1.3 cm apart): both registrations stay within 3 cm of the truth
  // (point-to-point ICP on planar walls is weakly constrained along them).
  for (const double e : r.gaps[0].planar.translation_errors_m) EXPECT_LT(e, 0.03);
  for (const double e : r.gaps[0].full->translation_errors_m) EXPECT_LT(e, 0.03);
  ASSERT_EQ(r.threshold_table.size(), 5u);
  EXPECT_GE(r.threshold_table[0].segments, r.threshold_table[4].segments);  // 10 vs 30
  for (const char* f : {"trajectory.txt", "trajectory_gap1.txt", "trajectory_gap3.txt",
                        "trajectory_full_icp_gap1.txt", "map.ply", "stats.json", "pairs.csv"}) {
    EXPECT_TRUE(fs::exists(options.out / f)) << f;
  }
  EXPECT_NE(FormatGapTable(r).find("speedup%"), std::string::npos);
  EXPECT_NE(FormatThresholdTable(r).find("planes@45"), std::string::npos);
}

TEST(RgbdInput, MissingFolderIsAnInputError) {
  RgbdSequenceOptions options;
  options.dataset = "/nonexistent/rgbd_folder";
  EXPECT_THROW(OpenRgbdSequence(options), InputError);
}

TEST(RgbdInput, MissingDepthFileIsAnInputErrorUnlessSkipped) {
  const fs::path dir = pkslam::testing::MakeTempDir("rgbd_missing");
  testing::WriteTumRoom(dir, 3);
  fs::path removed;
  for (const auto& e : fs::directory_iterator(dir / "depth")) {
    removed = e.path();
    break;
  }
  fs::remove(removed);
  RgbdSequenceOptions options;
  options.dataset = dir;
  try {
    OpenRgbdSequence(options);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(removed.filename().string()), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("--skip-missing"), std::string::npos);
  }
  options.skip_missing = true;
  EXPECT_EQ(OpenRgbdSequence(options).size(), 2u);
}

TEST(RgbdInput, NoIntrinsicsIsAnInputError) {
  const fs::path dir = pkslam::testing::MakeTempDir("rgbd_nocam");
  testing::WriteTumRoom(dir, 2);
  fs::remove(dir / "settings.yaml");
  RgbdSequenceOptions options;
  options.dataset = dir;
  EXPECT_THROW(OpenRgbdSequence(options), InputError);
}

TEST(RgbdInput, WrongImageSizeIsAnInputError) {
  const fs::path dir = pkslam::testing::MakeTempDir("rgbd_size");
  testing::WriteTumRoom(dir, 2);
  std::ofstream(dir / "settings.yaml")
      << "%YAML:1.0\nFile.version: \"1.0\"\nCamera.type: \"PinHole\"\nCamera1.fx: 260.0\n"
         "Camera1.fy: 260.0\nCamera1.cx: 159.5\nCamera1.cy: 119.5\nCamera.width: 640\n"
         "Camera.height: 480\nCamera.fps: 30\n";
  RgbdSequenceOptions options;
  options.dataset = dir;
  const RgbdSequence seq = OpenRgbdSequence(options);
  EXPECT_THROW(LoadRgbdFrame(seq, 0), InputError);
}

TEST(InterpolatePose, InterpolatesBetweenBracketingPoses) {
  Trajectory t;
  t.poses.push_back({0, SE3d()});
  t.poses.push_back({100, SE3d(SO3d(), Eigen::Vector3d(1, 0, 0))});
  const auto mid = InterpolatePose(t, 25);
  ASSERT_TRUE(mid);
  EXPECT_NEAR(mid->translation().x(), 0.25, 1e-12);
  EXPECT_FALSE(InterpolatePose(t, 101));
  EXPECT_FALSE(InterpolatePose(t, 50, 10));  // bracket wider than allowed
}

}  // namespace
}  // namespace pkslam::rgbd
