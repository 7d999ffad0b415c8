// The simulator's IMU model checked against a real IMU: replaying EuRoC V1_01's ground truth
// must reproduce (after low-pass filtering away rotor vibration, noise and bias) what the
// VI-Sensor's ADIS16448 measured during the same flight.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "io/trajectory.h"
#include "sim/imu_simulator.h"
#include "sim/motion_trajectory.h"
#include "tests/support/test_data.h"

namespace pkslam::sim {
namespace {

struct Series {
  std::vector<std::int64_t> t;
  std::vector<Eigen::Vector3d> gyro;
  std::vector<Eigen::Vector3d> accel;
};

Series ReadEurocImu(const std::filesystem::path& file, std::int64_t lo, std::int64_t hi) {
  std::ifstream in(file);
  Series s;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream ss(line);
    std::string f;
    std::vector<double> v;
    std::getline(ss, f, ',');
    const std::int64_t t = std::stoll(f);
    while (std::getline(ss, f, ',')) v.push_back(std::stod(f));
    if (t < lo || t > hi || v.size() != 6) continue;
    s.t.push_back(t);
    s.gyro.emplace_back(v[0], v[1], v[2]);
    s.accel.emplace_back(v[3], v[4], v[5]);
  }
  return s;
}

// Centred moving average over `half` samples each side.
std::vector<Eigen::Vector3d> Smooth(const std::vector<Eigen::Vector3d>& x, int half) {
  std::vector<Eigen::Vector3d> out(x.size(), Eigen::Vector3d::Zero());
  for (int i = half; i + half < static_cast<int>(x.size()); ++i) {
    for (int j = -half; j <= half; ++j) out[i] += x[i + j];
    out[i] /= 2 * half + 1;
  }
  return out;
}

TEST(RealImu, ReplayedV101MatchesTheRecordedImu) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const Trajectory gt = ReadTrajectory(shared / "euroc/groundtruth/V1_01_easy_original.txt");
  const std::int64_t t0 = gt.poses.front().t_ns + 30'000'000'000;
  const std::int64_t t1 = t0 + 60'000'000'000;
  const SplineTrajectory traj = FitTrajectory(gt.poses, t0, t1, ReplayOptions());
  const Series real = ReadEurocImu(shared / "euroc/V1_01_easy_static/mav0/imu0/data.csv", t0, t1);
  ASSERT_GT(real.t.size(), 10000u);
  Series sim;
  for (std::int64_t t : real.t) {
    Eigen::Vector3d g, a;
    IdealImu(traj.State(t), 9.81, &g, &a);
    sim.gyro.push_back(g);
    sim.accel.push_back(a);
  }
  const int half = 25;  // 0.25 s window: removes 35-90 Hz vibration and white noise
  const auto rg = Smooth(real.gyro, half), ra = Smooth(real.accel, half);
  const auto sg = Smooth(sim.gyro, half), sa = Smooth(sim.accel, half);
  Eigen::Vector3d bias_g = Eigen::Vector3d::Zero(), bias_a = Eigen::Vector3d::Zero();
  int n = 0;
  for (std::size_t i = half; i + half < rg.size(); ++i, ++n) {
    bias_g += rg[i] - sg[i];
    bias_a += ra[i] - sa[i];
  }
  bias_g /= n;
  bias_a /= n;
  double err_g = 0, err_a = 0, sig_g = 0, sig_a = 0;
  Eigen::Vector3d mean_sa = Eigen::Vector3d::Zero();
  for (std::size_t i = half; i + half < rg.size(); ++i) mean_sa += sa[i] / n;
  for (std::size_t i = half; i + half < rg.size(); ++i) {
    err_g += (rg[i] - sg[i] - bias_g).squaredNorm() / n;
    err_a += (ra[i] - sa[i] - bias_a).squaredNorm() / n;
    sig_g += sg[i].squaredNorm() / n;
    sig_a += (sa[i] - mean_sa).squaredNorm() / n;
  }
  std::printf(
      "V1_01 30-90 s, 0.25 s low-pass: gyro signal rms %.3f rad/s, sim-real rms %.3f; "
      "accel dynamic rms %.3f m/s^2, sim-real rms %.3f; bias g (%.4f %.4f %.4f) "
      "a (%.3f %.3f %.3f)\n",
      std::sqrt(sig_g), std::sqrt(err_g), std::sqrt(sig_a), std::sqrt(err_a), bias_g.x(),
      bias_g.y(), bias_g.z(), bias_a.x(), bias_a.y(), bias_a.z());
  EXPECT_LT(std::sqrt(err_g), 0.1 * std::sqrt(sig_g));
  EXPECT_LT(std::sqrt(err_a), 0.35 * std::sqrt(sig_a));
}

}  // namespace
}  // namespace pkslam::sim
