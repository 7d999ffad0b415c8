// The camera-IMU time offset of the realism preset is in the images, not only in a file: track
// a replay rendered with a 20 ms offset by stereo SLAM (images alone), then find the lag that
// best aligns the rotation rate of the tracked camera with the gyro. It must come out at the
// configured offset.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/geometry/se3.h"
#include "io/rigid_transform_file.h"
#include "io/trajectory.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

using testing::RunPkslam;

struct Gyro {
  std::vector<std::int64_t> t_ns;
  std::vector<Eigen::Vector3d> rate;
};

Gyro ReadGyro(const fs::path& csv) {
  Gyro g;
  std::ifstream in(csv);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream row(line);
    std::int64_t t = 0;
    Eigen::Vector3d w;
    row >> t >> w.x() >> w.y() >> w.z();
    g.t_ns.push_back(t);
    g.rate.push_back(w);
  }
  return g;
}

// Mean gyro over [t0, t1] (samples inside the window).
Eigen::Vector3d MeanRate(const Gyro& g, std::int64_t t0, std::int64_t t1) {
  const auto first = std::lower_bound(g.t_ns.begin(), g.t_ns.end(), t0);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (auto it = first; it != g.t_ns.end() && *it <= t1; ++it) {
    sum += g.rate[static_cast<std::size_t>(it - g.t_ns.begin())];
    ++n;
  }
  return n > 0 ? Eigen::Vector3d(sum / n) : Eigen::Vector3d::Constant(NAN);
}

TEST(RealismTiming, CameraImuOffsetIsRecoveredFromTheImages) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const fs::path dir = testing::MakeTempDir("realism_timing");
  const fs::path seq = dir / "seq";
  const auto sim = RunPkslam(fmt::format(
      "--log-level warn simulate --out '{}' --trajectory '{}' --start 20 --duration 10 "
      "--quality fast --quiet --no-cloud --realism euroc "
      "--realism-off calibration,imu,motion,ground-truth,appearance "
      "--realism-param timing.camera_imu_offset_ms=20 --realism-param timing.jitter_ms=0",
      seq.string(), (shared / "euroc/groundtruth/V1_02_medium.txt").string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const auto run = RunPkslam(fmt::format(
      "--log-level warn run --dataset '{}' --sensor stereo --out '{}' --quiet --deterministic",
      seq.string(), (dir / "out").string()));
  ASSERT_EQ(run.exit_code, 0) << run.output;

  const Trajectory camera = ReadTrajectory(dir / "out/trajectory.txt", TrajectoryFormat::kTum);
  const SE3d body_from_camera = ReadRigidTransform(dir / "out/body_from_camera.txt");
  const Gyro gyro = ReadGyro(seq / "mav0/imu0/data.csv");
  ASSERT_GT(camera.poses.size(), 150u);

  // Rotation rate of the tracked camera between consecutive frames, in the body frame.
  struct Interval {
    std::int64_t t0, t1;
    Eigen::Vector3d rate;
  };
  std::vector<Interval> intervals;
  for (std::size_t k = 0; k + 1 < camera.poses.size(); ++k) {
    const auto& a = camera.poses[k];
    const auto& b = camera.poses[k + 1];
    const double dt = 1e-9 * static_cast<double>(b.t_ns - a.t_ns);
    if (dt > 0.06) continue;  // a lost frame between them
    const Eigen::Vector3d w_cam = (a.pose.so3().Inverse() * b.pose.so3()).Log() / dt;
    intervals.push_back({a.t_ns, b.t_ns, body_from_camera.so3() * w_cam});
  }
  double best_lag_ms = 0.0;
  double best = INFINITY;
  double at_zero = 0.0;
  for (int lag_ms = -50; lag_ms <= 50; ++lag_ms) {
    const std::int64_t lag = std::int64_t{1'000'000} * lag_ms;
    double sse = 0.0;
    for (const Interval& i : intervals) {
      const Eigen::Vector3d g = MeanRate(gyro, i.t0 + lag, i.t1 + lag);
      if (g.allFinite()) sse += (g - i.rate).squaredNorm();
    }
    if (lag_ms == 0) at_zero = sse;
    if (sse < best) {
      best = sse;
      best_lag_ms = lag_ms;
    }
  }
  EXPECT_NEAR(best_lag_ms, 20.0, 3.0);
  EXPECT_GT(at_zero, 2.0 * best);  // the offset is a clear signal, not noise
  ::testing::Test::RecordProperty("recovered_offset_ms", std::to_string(best_lag_ms));
}

}  // namespace
}  // namespace pkslam
