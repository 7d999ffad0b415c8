#include "bench/run_evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/geometry/se3.h"
#include "core/util/error.h"
#include "io/trajectory.h"
#include "tests/support/test_data.h"

namespace pkslam::bench {
namespace {

namespace fs = std::filesystem;

// A EuRoC-layout dataset with ground truth along a 4 m helix, and a run folder whose body
// trajectory is that ground truth in another world frame, scaled by `scale`, with the
// x coordinate of every 2nd pose offset by +-`offset`.
struct Fixture {
  fs::path dataset;
  fs::path run;
};

Fixture MakeRun(const std::string& name, double scale, double offset) {
  Fixture f;
  const fs::path root = testing::MakeTempDir(name);
  f.dataset = root / "data";
  f.run = root / "run";
  fs::create_directories(f.dataset / "mav0" / "state_groundtruth_estimate0");
  fs::create_directories(f.run);
  std::ofstream gt(f.dataset / "mav0" / "state_groundtruth_estimate0" / "data.csv");
  gt << "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
        "q_RS_z []\n";
  std::ofstream est(f.run / "trajectory_body.txt");
  std::ofstream kf(f.run / "keyframes.txt");
  const SE3d est_from_world(SO3d::Exp(Eigen::Vector3d(0.1, -0.2, 0.7)), Eigen::Vector3d(1, 2, 3));
  const std::int64_t t0 = 1'600'000'000'000'000'000;
  for (int i = 0; i < 100; ++i) {
    const double a = 0.1 * i;
    const SE3d world_from_body(SO3d::Exp(Eigen::Vector3d(0, 0, a)),
                               Eigen::Vector3d(std::cos(a), std::sin(a), 0.04 * i));
    const std::int64_t t = t0 + std::int64_t{i} * 50'000'000;
    const Eigen::Quaterniond q = world_from_body.so3().quaternion();
    const Eigen::Vector3d p = world_from_body.translation();
    gt << fmt::format("{},{},{},{},{},{},{},{}\n", t, p.x(), p.y(), p.z(), q.w(), q.x(), q.y(),
                      q.z());
    SE3d e = est_from_world * world_from_body;
    Eigen::Vector3d pe = scale * e.translation();
    pe.x() += (i % 2 == 0 ? offset : -offset);
    const Eigen::Quaterniond qe = e.so3().quaternion();
    const std::string line = fmt::format("{:.9f} {:.9f} {:.9f} {:.9f} {} {} {} {}\n", 1e-9 * t,
                                         pe.x(), pe.y(), pe.z(), qe.x(), qe.y(), qe.z(), qe.w());
    est << line;
    if (i % 10 == 0) kf << line;
  }
  std::ofstream(f.run / "stats.json")
      << R"({"frames": 120, "keyframes": 10, "map_points": 900, "lost_frames": 3,
            "wall_time_s": 4.5, "median_tracking_ms": 21.5, "tracking_ms": [1.0, 2.0]})";
  return f;
}

TEST(EvaluateRun, MeasuresAteBothAlignmentsAndReadsStats) {
  const Fixture f = MakeRun("bench_eval_stereo", 1.0, 0.01);
  RunResult r;
  r.alignment = "se3";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);
  EXPECT_TRUE(r.ok);
  // Alternating +-1 cm in x: after the best alignment every pose is 1 cm off.
  EXPECT_NEAR(r.ate_se3_m, 0.01, 2e-4);
  EXPECT_NEAR(r.ate_sim3_m, 0.01, 2e-4);
  EXPECT_NEAR(r.scale, 1.0, 1e-3);
  EXPECT_DOUBLE_EQ(r.ate_m, r.ate_se3_m);
  EXPECT_TRUE(std::isfinite(r.rpe_trans_m));
  EXPECT_EQ(r.frames, 120);
  EXPECT_EQ(r.keyframes, 10);
  EXPECT_EQ(r.map_points, 900);
  EXPECT_EQ(r.lost_frames, 3);
  EXPECT_DOUBLE_EQ(r.wall_s, 4.5);
  EXPECT_DOUBLE_EQ(r.median_tracking_ms, 21.5);
  EXPECT_NEAR(r.coverage, 100.0 / 120.0, 1e-12);
  EXPECT_TRUE(fs::exists(f.run / "plot_trajectory.csv"));
  EXPECT_TRUE(fs::exists(f.run / "plot_keyframes.csv"));
}

// Speed measures of stats.json fill the speed columns; absent ones (older runs, peers) stay
// empty rather than failing the evaluation.
TEST(EvaluateRun, ReadsSpeedFromStatsWhenPresent) {
  const Fixture f = MakeRun("bench_eval_speed", 1.0, 0.0);
  RunResult r;
  r.alignment = "se3";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);  // the fixture's stats lack them
  EXPECT_TRUE(r.ok);
  EXPECT_TRUE(std::isnan(r.realtime_factor));
  EXPECT_TRUE(std::isnan(r.p95_tracking_ms));
  EXPECT_TRUE(std::isnan(r.mapping_ms_per_kf));
  EXPECT_TRUE(std::isnan(r.cpu_s));
  EXPECT_TRUE(std::isnan(r.peak_memory_mib));

  std::ofstream(f.run / "stats.json", std::ios::trunc)
      << R"({"frames": 120, "keyframes": 10, "map_points": 900, "lost_frames": 3,
            "wall_time_s": 4.5, "median_tracking_ms": 21.5, "realtime_factor": 1.25,
            "p95_tracking_ms": 40.5, "median_local_mapping_ms": 55.0, "process_cpu_s": 9.75,
            "peak_memory_mib": 512.0, "mapping_wait_s": 0.5, "keyframes_created": 12})";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);
  EXPECT_DOUBLE_EQ(r.realtime_factor, 1.25);
  EXPECT_DOUBLE_EQ(r.p95_tracking_ms, 40.5);
  EXPECT_DOUBLE_EQ(r.mapping_ms_per_kf, 55.0);
  EXPECT_DOUBLE_EQ(r.cpu_s, 9.75);
  EXPECT_DOUBLE_EQ(r.peak_memory_mib, 512.0);

  // Without realtime_factor: sequence duration / wall time; null measures stay empty.
  std::ofstream(f.run / "stats.json", std::ios::trunc)
      << R"({"frames": 120, "keyframes": 10, "map_points": 0, "lost_frames": 3,
            "wall_time_s": 4.5, "median_tracking_ms": 21.5, "sequence_duration_s": 9.0,
            "p95_tracking_ms": null})";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);
  EXPECT_DOUBLE_EQ(r.realtime_factor, 2.0);
  EXPECT_TRUE(std::isnan(r.p95_tracking_ms));

  // `pkslam run` writes 0 when it measured no wall time: not a realtime factor.
  std::ofstream(f.run / "stats.json", std::ios::trunc)
      << R"({"frames": 120, "keyframes": 10, "map_points": 0, "lost_frames": 3,
            "wall_time_s": 0.0, "median_tracking_ms": 21.5, "realtime_factor": 0.0})";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);
  EXPECT_TRUE(std::isnan(r.realtime_factor));

  std::ofstream(f.run / "stats.json", std::ios::trunc)
      << R"({"frames": 120, "keyframes": 10, "map_points": 0, "lost_frames": 3,
            "wall_time_s": 4.5, "median_tracking_ms": 21.5, "process_cpu_s": "lots"})";
  EXPECT_THROW(EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r), InputError);
}

// The suspect flag: stats.json "estimate" when present, else (runs written before it) a loss
// for good in loop_closing; unknown when neither is there.
TEST(EvaluateRun, ReadsTheSuspectFlagOfNewAndOlderStats) {
  const Fixture f = MakeRun("bench_eval_suspect", 1.0, 0.0);
  RunResult r;
  r.alignment = "se3";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);
  EXPECT_TRUE(std::isnan(r.suspect));
  const std::string head =
      R"({"frames": 120, "keyframes": 10, "map_points": 0, "lost_frames": 3,
          "wall_time_s": 4.5, "median_tracking_ms": 21.5, )";
  std::ofstream(f.run / "stats.json", std::ios::trunc)
      << head << R"("estimate": {"suspect": true, "warnings": ["lost"]}})";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);
  EXPECT_DOUBLE_EQ(r.suspect, 1.0);
  std::ofstream(f.run / "stats.json", std::ios::trunc)
      << head << R"("loop_closing": {"new_map_or_reset_times_s": [14.2]}})";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);
  EXPECT_DOUBLE_EQ(r.suspect, 1.0);
  std::ofstream(f.run / "stats.json", std::ios::trunc)
      << head << R"("loop_closing": {"new_map_or_reset_times_s": []}})";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);
  EXPECT_DOUBLE_EQ(r.suspect, 0.0);
  std::ofstream(f.run / "stats.json", std::ios::trunc)
      << head << R"("estimate": {"suspect": "maybe"}})";
  EXPECT_THROW(EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r), InputError);
}

TEST(EvaluateRun, MonocularUsesSim3AndRecoversScale) {
  const Fixture f = MakeRun("bench_eval_mono", 0.5, 0.0);
  RunResult r;
  r.alignment = "sim3";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);
  EXPECT_NEAR(r.scale, 2.0, 1e-6);  // ref_from_est undoes the half scale
  EXPECT_LT(r.ate_sim3_m, 1e-6);
  EXPECT_GT(r.ate_se3_m, 0.1);  // a rigid alignment cannot fix the scale
  EXPECT_DOUBLE_EQ(r.ate_m, r.ate_sim3_m);
}

// A monocular map has no metric scale: its camera poses are compared with the ground truth
// moved into the camera (body_from_camera.txt); trajectory_body.txt, whose metric lever arm
// does not fit the map's unit, is not used.
TEST(EvaluateRun, MonocularComparesCameraPosesWhenTheRunHasTheExtrinsic) {
  const Fixture f = MakeRun("bench_eval_mono_camera", 0.5, 0.0);
  const SE3d body_from_camera(SO3d::Exp(Eigen::Vector3d(0.2, 0.1, 1.5)),
                              Eigen::Vector3d(-0.02, -0.3, 0.01));
  const Trajectory gt = ReadTrajectory(FindGroundTruth(f.dataset));
  {
    std::ofstream extrinsic(f.run / "body_from_camera.txt");
    const Eigen::Matrix4d m = body_from_camera.Matrix();
    for (int row = 0; row < 4; ++row) {
      extrinsic << fmt::format("{:.15f} {:.15f} {:.15f} {:.15f}\n", m(row, 0), m(row, 1), m(row, 2),
                               m(row, 3));
    }
    std::ofstream est(f.run / "trajectory.txt");
    std::ofstream est_body(f.run / "trajectory_body.txt");
    for (const StampedPose& p : gt.poses) {
      // The camera in a map of half the metric unit (any world frame would do), and the body
      // as pkslam run writes it: the metric lever arm applied in map units.
      const SE3d world_from_camera = p.pose * body_from_camera;
      const SE3d map_from_camera(world_from_camera.so3(), 0.5 * world_from_camera.translation());
      const SE3d map_from_body = map_from_camera * body_from_camera.Inverse();
      for (const auto& [out, pose] : {std::pair<std::ofstream*, SE3d>{&est, map_from_camera},
                                      std::pair<std::ofstream*, SE3d>{&est_body, map_from_body}}) {
        const Eigen::Vector3d pe = pose.translation();
        const Eigen::Quaterniond q = pose.so3().quaternion();
        *out << fmt::format("{:.9f} {:.9f} {:.9f} {:.9f} {} {} {} {}\n", 1e-9 * p.t_ns, pe.x(),
                            pe.y(), pe.z(), q.x(), q.y(), q.z(), q.w());
      }
    }
  }
  RunResult r;
  r.sensor = "mono";
  r.alignment = "sim3";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);
  EXPECT_NEAR(r.scale, 2.0, 1e-6);
  EXPECT_LT(r.ate_sim3_m, 1e-6);
  // trajectory_body.txt carries the lever arm (0.3 m here) scale times: centimetres off.
  r.sensor = "stereo";
  EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r);
  EXPECT_GT(r.ate_sim3_m, 0.02);
  r.sensor = "mono";
  // Stereo runs keep comparing body poses (trajectory_body.txt is right for metric maps), and
  // so do monocular runs of older versions without the extrinsic file.
  fs::remove(f.run / "trajectory_body.txt");
  EXPECT_NO_THROW(EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r));
  r.sensor = "stereo";
  EXPECT_THROW(EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r), InputError);
  r.sensor = "mono";
  fs::remove(f.run / "body_from_camera.txt");
  EXPECT_THROW(EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r), InputError);
}

TEST(EvaluateRun, MissingOrBrokenFilesAreInputErrors) {
  const Fixture f = MakeRun("bench_eval_bad", 1.0, 0.0);
  RunResult r;
  r.alignment = "se3";
  fs::remove(f.run / "trajectory_body.txt");
  EXPECT_THROW(EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r), InputError);
  std::ofstream(f.run / "stats.json") << "{\"frames\": 1}";
  EXPECT_THROW(EvaluateRun({f.run, f.dataset, std::nullopt, 1.0}, &r), InputError);
  EXPECT_THROW(FindGroundTruth(f.run), InputError);
}

}  // namespace
}  // namespace pkslam::bench
