#include "sim/imu_simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "io/trajectory.h"
#include "sim/euroc_writer.h"
#include "sim/motion_generator.h"
#include "sim/scene_builder.h"
#include "sim/sim_testing.h"
#include "tests/support/test_data.h"

namespace pkslam::sim {
namespace {

constexpr double kGravity = 9.81;

// Navigation state integrated from IMU values: q (world_from_body), v, p (world).
struct NavState {
  Eigen::Quaterniond q;
  Eigen::Vector3d v;
  Eigen::Vector3d p;
};

struct Derivative {
  Eigen::Vector4d dq;  // quaternion coefficient rates (x, y, z, w)
  Eigen::Vector3d dv;
  Eigen::Vector3d dp;
};

Derivative F(const NavState& s, const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel) {
  Derivative d;
  const Eigen::Quaterniond omega(0.0, gyro.x(), gyro.y(), gyro.z());
  d.dq = 0.5 * (s.q * omega).coeffs();
  d.dv = s.q.normalized() * accel + Eigen::Vector3d(0, 0, -kGravity);
  d.dp = s.v;
  return d;
}

NavState Add(const NavState& s, const Derivative& d, double h) {
  NavState r;
  r.q.coeffs() = s.q.coeffs() + h * d.dq;
  r.v = s.v + h * d.dv;
  r.p = s.p + h * d.dp;
  return r;
}

// Classic RK4 over [t, t + h] with the IMU values at t, t + h/2 and t + h.
NavState Rk4(const NavState& s, double h, const Eigen::Vector3d g[3], const Eigen::Vector3d a[3]) {
  const Derivative k1 = F(s, g[0], a[0]);
  const Derivative k2 = F(Add(s, k1, h / 2), g[1], a[1]);
  const Derivative k3 = F(Add(s, k2, h / 2), g[1], a[1]);
  const Derivative k4 = F(Add(s, k3, h), g[2], a[2]);
  NavState r;
  r.q.coeffs() = s.q.coeffs() + h / 6 * (k1.dq + 2 * k2.dq + 2 * k3.dq + k4.dq);
  r.q.normalize();
  r.v = s.v + h / 6 * (k1.dv + 2 * k2.dv + 2 * k3.dv + k4.dv);
  r.p = s.p + h / 6 * (k1.dp + 2 * k2.dp + 2 * k3.dp + k4.dp);
  return r;
}

struct IntegrationError {
  double position_m;
  double angle_deg;
};

IntegrationError Compare(const NavState& s, const SE3d& truth) {
  return {(s.p - truth.translation()).norm(),
          (SO3d(s.q).Inverse() * truth.so3()).Log().norm() * 180.0 / M_PI};
}

NavState Start(const SplineTrajectory& traj, std::int64_t t) {
  const BodyState st = traj.State(t);
  return {st.world_from_body.quaternion(), st.velocity_world, st.world_from_body.translation()};
}

// (a) RK4 with 5 ms steps using the exact (noise-free) IMU model at sub-sample times.
IntegrationError IntegrateAnalytic(const SplineTrajectory& traj, std::int64_t t0, std::int64_t t1) {
  NavState s = Start(traj, t0);
  const std::int64_t h = 5'000'000;
  for (std::int64_t t = t0; t < t1; t += h) {
    Eigen::Vector3d g[3];
    Eigen::Vector3d a[3];
    for (int i = 0; i < 3; ++i) IdealImu(traj.State(t + i * h / 2), kGravity, &g[i], &a[i]);
    s = Rk4(s, 1e-9 * h, g, a);
  }
  return Compare(s, traj.WorldFromBody(t1));
}

// (b) Only the simulator's 200 Hz samples: RK4 with 10 ms steps whose mid-point values are
// the samples in between (a 4th-order scheme that needs no values the dataset lacks).
IntegrationError IntegrateSamples(const SplineTrajectory& traj, const std::vector<ImuSample>& imu,
                                  std::size_t steps) {
  NavState s = Start(traj, imu.front().t_ns);
  for (std::size_t k = 0; k + 2 < imu.size() && k < 2 * steps; k += 2) {
    const Eigen::Vector3d g[3] = {imu[k].gyro, imu[k + 1].gyro, imu[k + 2].gyro};
    const Eigen::Vector3d a[3] = {imu[k].accel, imu[k + 1].accel, imu[k + 2].accel};
    s = Rk4(s, 1e-9 * static_cast<double>(imu[k + 2].t_ns - imu[k].t_ns), g, a);
  }
  return Compare(s, traj.WorldFromBody(imu[2 * steps].t_ns));
}

void CheckIntegration(const SplineTrajectory& traj, std::int64_t t0, const char* label) {
  const std::int64_t t1 = t0 + 10'000'000'000;
  ImuOptions o;
  o.noise = false;
  const std::vector<ImuSample> imu = SimulateImu(BodyMotion(traj), t0, t1, o, 1);
  ASSERT_EQ(imu.size(), 2001u);
  const IntegrationError analytic = IntegrateAnalytic(traj, t0, t1);
  const IntegrationError samples = IntegrateSamples(traj, imu, 1000);
  std::printf("%s, 10 s: analytic RK4 %.3g m %.3g deg; 200 Hz samples RK4 %.3g m %.3g deg\n", label,
              analytic.position_m, analytic.angle_deg, samples.position_m, samples.angle_deg);
  EXPECT_LT(analytic.position_m, 1e-3);
  EXPECT_LT(analytic.angle_deg, 0.01);
  EXPECT_LT(samples.position_m, 1e-3);
  EXPECT_LT(samples.angle_deg, 0.01);
}

TEST(ImuSimulator, NoiseFreeImuIntegratesToTheGroundTruthReplay) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const auto poses = ReadTrajectory(shared / "euroc/groundtruth/V1_02_medium.txt").poses;
  const std::int64_t t0 = poses.front().t_ns + 20'000'000'000;
  const SplineTrajectory traj = FitTrajectory(poses, t0, t0 + 10'000'000'000, ReplayOptions());
  CheckIntegration(traj, t0, "V1_02_medium replay");
}

TEST(ImuSimulator, NoiseFreeImuIntegratesToTheGroundTruthDifficultFlight) {
  const SplineTrajectory traj = RandomTestFlight(MotionLevel::kDifficult, 13, 5);
  CheckIntegration(traj, 2'000'000'000, "difficult random flight");
}

// A body at rest (identity pose) for noise statistics.
SplineTrajectory Static(double seconds) {
  const KnotGrid grid =
      KnotGrid::Covering(0, static_cast<std::int64_t>(seconds * 1e9), 1'000'000'000);
  return SplineTrajectory(
      PositionSpline6(grid, std::vector<Eigen::Vector3d>(PositionSpline6::NumControl(grid),
                                                         Eigen::Vector3d(1, 2, 3))),
      RotationSpline4(grid, std::vector<SO3d>(RotationSpline4::NumControl(grid))));
}

// Non-overlapping Allan variance of e (per axis, summed over axes / 3) at cluster size m.
double AllanVariance(const std::vector<Eigen::Vector3d>& e, std::size_t m, int* count) {
  std::vector<Eigen::Vector3d> means;
  for (std::size_t i = 0; i + m <= e.size(); i += m) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t j = i; j < i + m; ++j) sum += e[j];
    means.push_back(sum / static_cast<double>(m));
  }
  double acc = 0;
  for (std::size_t i = 1; i < means.size(); ++i) acc += (means[i] - means[i - 1]).squaredNorm();
  *count += static_cast<int>(3 * (means.size() - 1));
  return acc;
}

TEST(ImuSimulator, NoiseDensitiesAndRandomWalksMatchTheConfiguration) {
  // Ten independent 2000 s runs at rest; statistics from measurement - exact value only.
  const double seconds = 2000;
  const SplineTrajectory traj = Static(seconds);
  ImuOptions o;
  const double dt = 0.005;
  const std::size_t m_short = 10;    // tau = 0.05 s: white noise dominates
  const std::size_t m_long = 20000;  // tau = 100 s: random walk dominates
  double g_short = 0, g_long = 0, a_short = 0, a_long = 0;
  int n_short = 0, n_long = 0, dummy = 0;
  double g_std = 0, a_std = 0;
  std::size_t n_samples = 0;
  for (int run = 0; run < 10; ++run) {
    const auto imu =
        SimulateImu(BodyMotion(traj), 0, static_cast<std::int64_t>(seconds * 1e9), o, 100 + run);
    std::vector<Eigen::Vector3d> eg, ea;
    eg.reserve(imu.size());
    ea.reserve(imu.size());
    Eigen::Vector3d g_ideal, a_ideal;
    IdealImu(traj.State(0), o.gravity, &g_ideal, &a_ideal);
    for (const auto& s : imu) {
      eg.push_back(s.gyro - g_ideal);
      ea.push_back(s.accel - a_ideal);
      g_std += (s.gyro - g_ideal - s.gyro_bias).squaredNorm();
      a_std += (s.accel - a_ideal - s.accel_bias).squaredNorm();
      n_samples += 3;
    }
    g_short += AllanVariance(eg, m_short, &n_short);
    a_short += AllanVariance(ea, m_short, &dummy);
    g_long += AllanVariance(eg, m_long, &n_long);
    dummy = 0;
    a_long += AllanVariance(ea, m_long, &dummy);
  }
  // AVAR(tau) = N^2 / tau + K^2 tau / 3 for white noise N and random walk K.
  const double tau_s = m_short * dt;
  const double tau_l = m_long * dt;
  auto density = [&](double avar_s, double avar_l) {
    // Solve the 2x2 system of the two Allan variances for N^2 and K^2.
    const double k2 = (avar_l - avar_s * tau_s / tau_l) / (tau_l / 3 - tau_s * tau_s / (3 * tau_l));
    const double n2 = (avar_s - k2 * tau_s / 3) * tau_s;
    return std::make_pair(std::sqrt(n2), std::sqrt(k2));
  };
  const auto [gn, gk] = density(g_short / (2 * n_short), g_long / (2 * n_long));
  const auto [an, ak] = density(a_short / (2 * n_short), a_long / (2 * n_long));
  const double g_white = std::sqrt(g_std / n_samples * dt);
  const double a_white = std::sqrt(a_std / n_samples * dt);
  std::printf("gyro:  white %.4e (std*sqrt(dt) %.4e) vs %.4e, walk %.4e vs %.4e\n", gn, g_white,
              o.gyro_noise_density, gk, o.gyro_random_walk);
  std::printf("accel: white %.4e (std*sqrt(dt) %.4e) vs %.4e, walk %.4e vs %.4e\n", an, a_white,
              o.accel_noise_density, ak, o.accel_random_walk);
  EXPECT_NEAR(gn, o.gyro_noise_density, 0.1 * o.gyro_noise_density);
  EXPECT_NEAR(an, o.accel_noise_density, 0.1 * o.accel_noise_density);
  EXPECT_NEAR(g_white, o.gyro_noise_density, 0.1 * o.gyro_noise_density);
  EXPECT_NEAR(a_white, o.accel_noise_density, 0.1 * o.accel_noise_density);
  EXPECT_NEAR(gk, o.gyro_random_walk, 0.1 * o.gyro_random_walk);
  EXPECT_NEAR(ak, o.accel_random_walk, 0.1 * o.accel_random_walk);
}

TEST(ImuSimulator, BiasesVibrationAndDeterminism) {
  const SplineTrajectory traj = Static(30);
  ImuOptions o;
  o.noise = false;
  o.initial_gyro_bias = Eigen::Vector3d(0.01, -0.02, 0.003);
  o.initial_accel_bias = Eigen::Vector3d(0.1, 0.0, -0.2);
  o.vibration = true;
  const auto imu = SimulateImu(BodyMotion(traj), 0, 20'000'000'000, o, 9);
  Eigen::Vector3d g_ideal, a_ideal;
  IdealImu(traj.State(0), o.gravity, &g_ideal, &a_ideal);
  EXPECT_LT((a_ideal - Eigen::Vector3d(0, 0, 9.81)).norm(), 1e-12);  // at rest: +g up
  double accel_ms = 0, gyro_ms = 0;
  Eigen::Vector3d accel_mean = Eigen::Vector3d::Zero();
  for (const auto& s : imu) {
    EXPECT_EQ(s.gyro_bias, o.initial_gyro_bias);  // constant without noise
    accel_ms += (s.accel - a_ideal - o.initial_accel_bias).squaredNorm();
    gyro_ms += (s.gyro - g_ideal - o.initial_gyro_bias).squaredNorm();
    accel_mean += s.accel;
  }
  accel_mean /= static_cast<double>(imu.size());
  EXPECT_NEAR(std::sqrt(accel_ms / imu.size()), o.vibration_accel_rms,
              0.05 * o.vibration_accel_rms);
  EXPECT_NEAR(std::sqrt(gyro_ms / imu.size()), o.vibration_gyro_rms, 0.05 * o.vibration_gyro_rms);
  EXPECT_LT((accel_mean - a_ideal - o.initial_accel_bias).norm(), 0.01);  // tones average out

  ImuOptions noisy;
  const auto a = SimulateImu(BodyMotion(traj), 0, 1'000'000'000, noisy, 42);
  const auto b = SimulateImu(BodyMotion(traj), 0, 1'000'000'000, noisy, 42);
  const auto c = SimulateImu(BodyMotion(traj), 0, 1'000'000'000, noisy, 43);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].gyro, b[i].gyro);
    ASSERT_EQ(a[i].accel, b[i].accel);
  }
  EXPECT_NE(a[5].gyro, c[5].gyro);
}

// Scale factors, misalignment and g-sensitivity act on the true rate and specific force as
// documented (gyro = M_g w + G f + b, accel = M_a f + b), and quantisation rounds to LSBs.
TEST(ImuSimulator, SensorErrorsFollowTheErrorModel) {
  const SplineTrajectory traj = RandomTestFlight(MotionLevel::kDifficult, 4.0, 5);
  ImuOptions o;
  o.noise = false;
  o.initial_gyro_bias = Eigen::Vector3d(0.01, -0.02, 0.003);
  o.errors.gyro_matrix << 1.002, 0.0004, -0.0003, 0.0002, 0.998, 0.0005, -0.0001, 0.0003, 1.001;
  o.errors.accel_matrix << 0.997, 0.0002, 0.0001, -0.0004, 1.003, 0.0002, 0.0003, 0.0001, 1.002;
  o.errors.gyro_g_sensitivity = 1e-4 * Eigen::Matrix3d::Ones();
  const auto imu = SimulateImu(BodyMotion(traj), 0, 3'000'000'000, o, 2);
  double worst = 0.0;
  for (const auto& s : imu) {
    Eigen::Vector3d w, f;
    IdealImu(traj.State(s.t_ns), o.gravity, &w, &f);
    const Eigen::Vector3d gyro =
        o.errors.gyro_matrix * w + o.errors.gyro_g_sensitivity * f + o.initial_gyro_bias;
    const Eigen::Vector3d accel = o.errors.accel_matrix * f;
    worst = std::max({worst, (gyro - s.gyro).norm(), (accel - s.accel).norm()});
  }
  EXPECT_LT(worst, 1e-12);
  // With errors the measurements differ from the ideal ones by more than the noise would.
  Eigen::Vector3d w, f;
  IdealImu(traj.State(imu[100].t_ns), o.gravity, &w, &f);
  EXPECT_GT((imu[100].accel - f).norm(), 0.01);

  o.errors = ImuSensorErrors();
  o.errors.gyro_quantum = 0.04 * M_PI / 180.0;
  o.errors.accel_quantum = 9.81 / 1200.0;
  o.noise = true;
  for (const auto& s : SimulateImu(BodyMotion(traj), 0, 1'000'000'000, o, 3)) {
    for (int k = 0; k < 3; ++k) {
      const double g_lsb = s.gyro[k] / o.errors.gyro_quantum;
      const double a_lsb = s.accel[k] / o.errors.accel_quantum;
      ASSERT_NEAR(g_lsb, std::round(g_lsb), 1e-6);
      ASSERT_NEAR(a_lsb, std::round(a_lsb), 1e-6);
    }
  }
}

}  // namespace
}  // namespace pkslam::sim
