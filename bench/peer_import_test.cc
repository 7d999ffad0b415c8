#include "bench/peer_import.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>

#include "core/util/error.h"
#include "io/rigid_transform_file.h"
#include "io/test_fixtures.h"
#include "io/trajectory.h"
#include "tests/support/test_data.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

struct PeerRun {
  fs::path dataset;
  fs::path run;
  testing::EurocFixture fixture;
};

// A 5-frame EuRoC dataset and a peer output that tracked frames 1..3 (frame 0 and 4 lost).
PeerRun MakePeerRun(const std::string& name) {
  PeerRun p;
  const fs::path root = testing::MakeTempDir(name);
  p.dataset = root / "data";
  p.run = root / "run";
  p.fixture.Write(p.dataset);
  fs::create_directories(p.run);
  std::ofstream traj(p.run / "traj_tum.txt");
  for (int i = 1; i <= 3; ++i) {
    traj << fmt::format("{:.9f} {} 0 0 0 0 0 1\n", 1e-9 * static_cast<double>(p.fixture.FrameT(i)),
                        0.1 * i);
  }
  std::ofstream(p.run / "kf_tum.txt")
      << fmt::format("{:.9f} 0.1 0 0 0 0 0 1\n", 1e-9 * static_cast<double>(p.fixture.FrameT(1)));
  std::ofstream(p.run / "track_times.txt") << "0.05 0.020\n0.10 0.030\n0.15 0.010\n";
  std::ofstream(p.run / "summary.txt")
      << "images=5 seq_duration_s=0.25 wall_s=1.50 realtime_factor=0.17\npeak_rss_mb=321\n";
  std::ofstream(p.run / "time.txt") << "\tCommand being timed: \"nice -n 19 peer\"\n"
                                    << "\tUser time (seconds): 2.25\n"
                                    << "\tSystem time (seconds): 0.50\n";
  return p;
}

TEST(PeerImport, InertialRunBecomesABodyTrajectoryWithStats) {
  const PeerRun p = MakePeerRun("peer_import_inertial");
  ImportPeerRun(p.run, p.dataset, "stereo-inertial");
  ASSERT_TRUE(fs::exists(p.run / "trajectory_body.txt"));
  EXPECT_FALSE(fs::exists(p.run / "trajectory.txt"));
  EXPECT_FALSE(fs::exists(p.run / "body_from_camera.txt"));
  const Trajectory body = ReadTrajectory(p.run / "trajectory_body.txt", TrajectoryFormat::kTum);
  ASSERT_EQ(body.poses.size(), 3u);
  // TUM seconds hold EuRoC's nanosecond stamps to about a microsecond.
  EXPECT_NEAR(static_cast<double>(body.poses[0].t_ns - p.fixture.FrameT(1)), 0.0, 1e3);
  EXPECT_NEAR(body.poses[2].pose.translation().x(), 0.3, 1e-12);
  EXPECT_EQ(ReadTrajectory(p.run / "keyframes.txt", TrajectoryFormat::kTum).poses.size(), 1u);
  const YAML::Node stats = YAML::LoadFile((p.run / "stats.json").string());
  EXPECT_EQ(stats["frames"].as<int>(), 5);
  EXPECT_EQ(stats["lost_frames"].as<int>(), 2);
  EXPECT_EQ(stats["keyframes"].as<int>(), 1);
  EXPECT_DOUBLE_EQ(stats["wall_time_s"].as<double>(), 1.5);
  EXPECT_DOUBLE_EQ(stats["median_tracking_ms"].as<double>(), 20.0);
}

// The count of keyframes the peer created, when its script wrote one (the v0.3 peers do).
TEST(PeerImport, KeyframesCreatedAreImportedWhenThePeerCountedThem) {
  const PeerRun p = MakePeerRun("peer_import_created");
  ImportPeerRun(p.run, p.dataset, "stereo-inertial");
  EXPECT_FALSE(YAML::LoadFile((p.run / "stats.json").string())["keyframes_created"]);
  std::ofstream(p.run / "keyframes_created.txt") << "7\n";
  ImportPeerRun(p.run, p.dataset, "stereo-inertial");
  const YAML::Node stats = YAML::LoadFile((p.run / "stats.json").string());
  EXPECT_EQ(stats["keyframes_created"].as<int>(), 7);
  EXPECT_EQ(stats["keyframes"].as<int>(), 1);  // the final map's
}

// The peer's speed in the keys `pkslam run` uses, so the speed table holds both systems.
TEST(PeerImport, SpeedStatsMatchPkslamRunKeys) {
  const PeerRun p = MakePeerRun("peer_import_speed");
  ImportPeerRun(p.run, p.dataset, "stereo");
  const YAML::Node stats = YAML::LoadFile((p.run / "stats.json").string());
  // 5 frames 50 ms apart: last - first = 0.2 s (pkslam's definition, not summary.txt's 0.25).
  EXPECT_NEAR(stats["sequence_duration_s"].as<double>(), 0.2, 1e-9);
  // Over its frame loop (the sum of the Track*() times, 60 ms), not the process's 1.5 s.
  EXPECT_NEAR(stats["tracking_loop_s"].as<double>(), 0.06, 1e-9);
  EXPECT_NEAR(stats["realtime_factor"].as<double>(), 0.2 / 0.06, 1e-9);
  EXPECT_DOUBLE_EQ(stats["p95_tracking_ms"].as<double>(), 30.0);  // of 10, 20, 30 ms
  EXPECT_DOUBLE_EQ(stats["process_cpu_s"].as<double>(), 2.75);    // user + system
  EXPECT_DOUBLE_EQ(stats["peak_memory_mib"].as<double>(), 321.0);
  // Without time.txt, summary.txt and track_times.txt: no CPU time, memory or realtime
  // factor (null).
  fs::remove(p.run / "time.txt");
  fs::remove(p.run / "summary.txt");
  fs::remove(p.run / "track_times.txt");
  ImportPeerRun(p.run, p.dataset, "stereo");
  const YAML::Node bare = YAML::LoadFile((p.run / "stats.json").string());
  EXPECT_TRUE(bare["process_cpu_s"].IsNull());
  EXPECT_TRUE(bare["peak_memory_mib"].IsNull());
  EXPECT_TRUE(bare["realtime_factor"].IsNull());
}

TEST(PeerImport, VisualRunKeepsCameraPosesAndTheExtrinsicThePeerRead) {
  const PeerRun p = MakePeerRun("peer_import_visual");
  fs::remove(p.run / "track_times.txt");
  fs::remove(p.run / "summary.txt");
  ImportPeerRun(p.run, p.dataset, "mono");
  ASSERT_TRUE(fs::exists(p.run / "trajectory.txt"));
  EXPECT_FALSE(
      fs::exists(p.run / "trajectory_body.txt"));  // a monocular map has no metric lever arm
  const SE3d body_from_camera = ReadRigidTransform(p.run / "body_from_camera.txt");
  EXPECT_NEAR(body_from_camera.translation().x(), -0.0216401454975, 1e-12);
  // Stereo: also the body trajectory (camera poses moved through the extrinsic), which the
  // bench compares stereo runs by.
  ImportPeerRun(p.run, p.dataset, "stereo");
  const Trajectory camera = ReadTrajectory(p.run / "trajectory.txt", TrajectoryFormat::kTum);
  const Trajectory body = ReadTrajectory(p.run / "trajectory_body.txt", TrajectoryFormat::kTum);
  ASSERT_EQ(body.poses.size(), camera.poses.size());
  const SE3d expected = camera.poses[1].pose * body_from_camera.Inverse();
  EXPECT_NEAR((body.poses[1].pose.translation() - expected.translation()).norm(), 0.0, 1e-6);
  const YAML::Node stats = YAML::LoadFile((p.run / "stats.json").string());
  EXPECT_TRUE(stats["wall_time_s"].IsNull());  // no summary.txt: not measured
  EXPECT_TRUE(stats["median_tracking_ms"].IsNull());
}

TEST(PeerImport, MissingOrEmptyTrajectoryIsAnInputError) {
  const PeerRun p = MakePeerRun("peer_import_missing");
  std::ofstream(p.run / "traj_tum.txt", std::ios::trunc).flush();
  EXPECT_THROW(ImportPeerRun(p.run, p.dataset, "stereo-inertial"), InputError);
  fs::remove(p.run / "traj_tum.txt");
  EXPECT_THROW(ImportPeerRun(p.run, p.dataset, "stereo-inertial"), InputError);
}

TEST(PeerImport, CommandPlaceholdersAreSubstituted) {
  const auto argv = PeerArguments(
      {"bash", "{suite_dir}/run.sh", "{dataset}", "{sensor}", "{out}", "--seed={seed}"}, "/d/seq",
      "mono-inertial", "/o/run", 7, "/s");
  const std::vector<std::string> expected = {"bash",          "/s/run.sh", "/d/seq",
                                             "mono-inertial", "/o/run",    "--seed=7"};
  EXPECT_EQ(argv, expected);
}

}  // namespace
}  // namespace pkslam::bench
