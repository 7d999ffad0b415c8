#include "imu/preintegration.h"

#include <cmath>
#include <utility>

#include "core/util/error.h"

namespace pkslam {
namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;

// Linear interpolation of the samples at time t; outside the samples' span the nearest end
// sample is held. `hint` is advanced monotonically (callers query increasing times).
ImuMeasurement SampleAt(const std::vector<ImuMeasurement>& samples, std::int64_t t,
                        std::size_t* hint) {
  if (t <= samples.front().t_ns) return samples.front();
  if (t >= samples.back().t_ns) return samples.back();
  std::size_t i = *hint;
  while (samples[i + 1].t_ns <= t) ++i;
  *hint = i;
  const ImuMeasurement& a = samples[i];
  const ImuMeasurement& b = samples[i + 1];
  const double s = static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  ImuMeasurement m;
  m.t_ns = t;
  m.gyro = a.gyro + s * (b.gyro - a.gyro);
  m.accel = a.accel + s * (b.accel - a.accel);
  return m;
}

}  // namespace

void PreintegrationOptions::Check() const {
  PKSLAM_CHECK_OPTION(reintegrate_gyro_bias_change >= 0, "reintegrate_gyro_bias_change", "{}",
                      reintegrate_gyro_bias_change);
  PKSLAM_CHECK_OPTION(reintegrate_accel_bias_change >= 0, "reintegrate_accel_bias_change", "{}",
                      reintegrate_accel_bias_change);
}

PreintegratedImu StartPreintegration(const ImuBias& bias, const ImuNoise& noise,
                                     ImuIntegrationScheme scheme) {
  noise.Check();
  PreintegratedImu pim;
  pim.bias = bias;
  pim.noise = noise;
  pim.scheme = scheme;
  return pim;
}

void IntegrateMeasurement(const Vec3& accel, const Vec3& gyro, double dt, PreintegratedImu* pim) {
  PKSLAM_CHECK(dt > 0 && std::isfinite(dt), "integration step dt = {}", dt);
  PKSLAM_CHECK(accel.allFinite() && gyro.allFinite(), "non-finite IMU measurement");
  PreintegratedImu& p = *pim;
  p.steps.push_back({accel, gyro, dt});

  const Vec3 a = accel - p.bias.accel;
  const Vec3 w = gyro - p.bias.gyro;
  const Vec3 w_dt = w * dt;
  const SO3d step_R = SO3d::Exp(w_dt);
  const Mat3 step_Rt = step_R.Matrix().transpose();
  const Mat3 jr_dt = SO3d::RightJacobian(w_dt) * dt;
  const double dt2 = dt * dt;
  // R_s = dR H rotates the step's specific force; H is the half-step rotation (midpoint) or I.
  const bool midpoint = p.scheme == ImuIntegrationScheme::kMidpoint;
  const Mat3 half_R = midpoint ? SO3d::Exp(0.5 * w_dt).Matrix() : Mat3::Identity();
  const Mat3 r_s = p.delta_R.Matrix() * half_R;
  const Vec3 acc_i = r_s * a;  // specific force in the interval's first body frame
  // Linearisation of R_s a: w.r.t. dphi (dR <- dR Exp(dphi)) it is -R_s hat(a) H^T dphi; w.r.t.
  // a change dw of w (gyro noise or -d b_g) it is -R_s hat(a) Jr(w dt / 2) dt / 2 dw.
  const Mat3 d_acc_dphi = -r_s * SO3d::Hat(a) * half_R.transpose();
  const Mat3 d_acc_dw =
      midpoint ? Mat3(-r_s * SO3d::Hat(a) * SO3d::RightJacobian(0.5 * w_dt) * (0.5 * dt))
               : Mat3::Zero();

  p.average_accel = (p.dt * p.average_accel + acc_i * dt) / (p.dt + dt);
  p.average_gyro = (p.dt * p.average_gyro + w * dt) / (p.dt + dt);

  // Position first (uses the old velocity), then velocity.
  p.delta_p += p.delta_v * dt + 0.5 * acc_i * dt2;
  p.delta_v += acc_i * dt;

  // Error-state transition of [dphi, dv, dp] and the input matrix of the noise [n_g, n_a]
  // (measurement = truth + noise; signs follow from dphi_{k+1} = E^T dphi_k - Jr dt n_g).
  Eigen::Matrix<double, 9, 9> A = Eigen::Matrix<double, 9, 9>::Identity();
  A.block<3, 3>(0, 0) = step_Rt;
  A.block<3, 3>(3, 0) = d_acc_dphi * dt;
  A.block<3, 3>(6, 0) = 0.5 * d_acc_dphi * dt2;
  A.block<3, 3>(6, 3) = Mat3::Identity() * dt;
  Eigen::Matrix<double, 9, 6> B = Eigen::Matrix<double, 9, 6>::Zero();
  B.block<3, 3>(0, 0) = -jr_dt;
  B.block<3, 3>(3, 0) = -d_acc_dw * dt;
  B.block<3, 3>(6, 0) = -0.5 * d_acc_dw * dt2;
  B.block<3, 3>(3, 3) = -r_s * dt;
  B.block<3, 3>(6, 3) = -0.5 * r_s * dt2;
  const Eigen::Matrix<double, 9, 9> c9 = p.covariance.topLeftCorner<9, 9>();
  p.covariance.topLeftCorner<9, 9>() =
      A * c9 * A.transpose() + B * DiscreteMeasurementCovariance(p.noise) * B.transpose();
  p.covariance.bottomRightCorner<6, 6>() += BiasRandomWalkCovariance(p.noise, dt);

  // Bias Jacobians: a bias change d b enters as w <- w - d b_g, a <- a - d b_a, so the same
  // linearisation applies (position first: it uses the old velocity Jacobians and J_R_bg).
  const Mat3 d_acc_dbg = d_acc_dphi * p.J_R_bg - d_acc_dw;
  p.J_p_ba += p.J_v_ba * dt - 0.5 * r_s * dt2;
  p.J_p_bg += p.J_v_bg * dt + 0.5 * d_acc_dbg * dt2;
  p.J_v_ba -= r_s * dt;
  p.J_v_bg += d_acc_dbg * dt;
  p.J_R_bg = step_Rt * p.J_R_bg - jr_dt;

  p.delta_R = p.delta_R * step_R;
  p.dt += dt;
}

namespace {

// What the gyro-scale and accelerometer-axis Jacobians need of one step's linearisation.
// IntegrateMeasurement spells the same lines out itself: computed through this function they
// changed the last bits of a mono-inertial run's keyframes
// (evaluation/studies/refactor/compare_builds.sh), and
// `--calibrate off` keeps its results bit for bit. GyroScaleJacobiansMatchRescaledReintegration
// (preintegration_test.cc) checks the two agree.
struct StepLinearisation {
  SO3d step_R;      // Exp(w dt)
  Mat3 step_Rt;     // its transpose
  Mat3 jr_dt;       // Jr(w dt) dt
  Mat3 r_s;         // the rotation the step's sample is integrated in (mid-step for midpoint)
  Mat3 d_acc_dphi;  // d(R_s a) / d dphi
  Mat3 d_acc_dw;    // d(R_s a) / d w
};

StepLinearisation LineariseStep(const SO3d& delta_R, const Vec3& a, const Vec3& w, double dt,
                                ImuIntegrationScheme scheme) {
  StepLinearisation m;
  const Vec3 w_dt = w * dt;
  m.step_R = SO3d::Exp(w_dt);
  m.step_Rt = m.step_R.Matrix().transpose();
  m.jr_dt = SO3d::RightJacobian(w_dt) * dt;
  const bool midpoint = scheme == ImuIntegrationScheme::kMidpoint;
  const Mat3 half_R = midpoint ? SO3d::Exp(0.5 * w_dt).Matrix() : Mat3::Identity();
  m.r_s = delta_R.Matrix() * half_R;
  m.d_acc_dphi = -m.r_s * SO3d::Hat(a) * half_R.transpose();
  m.d_acc_dw = midpoint ? Mat3(-m.r_s * SO3d::Hat(a) * SO3d::RightJacobian(0.5 * w_dt) * (0.5 * dt))
                        : Mat3::Zero();
  return m;
}

}  // namespace

GyroScaleJacobians GyroScaleJacobiansOf(const PreintegratedImu& pim) {
  // A change dk of the scale factors changes each step's rate by -diag(gyro) dk (the step's
  // measurement, before the bias, is what the factor multiplies): the bias recursion with a
  // per-step input matrix diag(gyro) in place of the identity.
  GyroScaleJacobians j;
  SO3d delta_R;
  for (const PreintegratedImu::Step& s : pim.steps) {
    const StepLinearisation m =
        LineariseStep(delta_R, s.accel - pim.bias.accel, s.gyro - pim.bias.gyro, s.dt, pim.scheme);
    const Mat3 d = s.gyro.asDiagonal();
    const Mat3 d_acc_dk = m.d_acc_dphi * j.rotation - m.d_acc_dw * d;
    j.position += j.velocity * s.dt + 0.5 * d_acc_dk * s.dt * s.dt;
    j.velocity += d_acc_dk * s.dt;
    j.rotation = m.step_Rt * j.rotation - m.jr_dt * d;
    delta_R = delta_R * m.step_R;
  }
  return j;
}

AccelAxesJacobians AccelAxesJacobiansOf(const PreintegratedImu& pim) {
  // A change dE' moves each step's corrected sample by -dE' a = -(I3 kron a^T) vec(dE'): the
  // accelerometer bias's recursion (J_v_ba, J_p_ba) with that input matrix in place of -I.
  AccelAxesJacobians j;
  SO3d delta_R;
  for (const PreintegratedImu::Step& s : pim.steps) {
    const StepLinearisation m =
        LineariseStep(delta_R, s.accel - pim.bias.accel, s.gyro - pim.bias.gyro, s.dt, pim.scheme);
    Eigen::Matrix<double, 3, 9> d = Eigen::Matrix<double, 3, 9>::Zero();
    for (int r = 0; r < 3; ++r) d.block<1, 3>(r, 3 * r) = -s.accel.transpose();
    const Eigen::Matrix<double, 3, 9> d_acc = m.r_s * d;
    j.position += j.velocity * s.dt + 0.5 * d_acc * s.dt * s.dt;
    j.velocity += d_acc * s.dt;
    delta_R = delta_R * m.step_R;
  }
  return j;
}

void TransformAccel(const Mat3& m, PreintegratedImu* pim) {
  PKSLAM_CHECK(m.allFinite() && std::abs(m.determinant()) > 0.5, "accelerometer axis transform");
  if (m == Mat3::Identity()) return;
  for (PreintegratedImu::Step& s : pim->steps) s.accel = m * s.accel;
  ImuBias bias = pim->bias;
  bias.accel = m * bias.accel;
  Reintegrate(bias, pim);
}

void RescaleGyro(const Vec3& factor, PreintegratedImu* pim) {
  PKSLAM_CHECK(factor.allFinite() && factor.minCoeff() > 0, "gyro rescale factor ({}, {}, {})",
               factor.x(), factor.y(), factor.z());
  if (factor == Vec3::Ones()) return;
  for (PreintegratedImu::Step& s : pim->steps) s.gyro = s.gyro.cwiseProduct(factor);
  ImuBias bias = pim->bias;
  bias.gyro = bias.gyro.cwiseProduct(factor);
  Reintegrate(bias, pim);
}

int IntegrateSamples(const std::vector<ImuMeasurement>& samples, std::int64_t t_begin_ns,
                     std::int64_t t_end_ns, PreintegratedImu* pim) {
  PKSLAM_CHECK(!samples.empty(), "no IMU samples for [{}, {}] ns", t_begin_ns, t_end_ns);
  PKSLAM_CHECK(t_end_ns > t_begin_ns, "empty interval [{}, {}] ns", t_begin_ns, t_end_ns);
  for (std::size_t i = 1; i < samples.size(); ++i) {
    PKSLAM_CHECK(samples[i].t_ns > samples[i - 1].t_ns, "IMU samples not increasing at {} ns",
                 samples[i].t_ns);
  }
  // Knots: t_begin, the sample times strictly inside, t_end.
  std::vector<std::int64_t> knots{t_begin_ns};
  for (const ImuMeasurement& s : samples) {
    if (s.t_ns > t_begin_ns && s.t_ns < t_end_ns) knots.push_back(s.t_ns);
  }
  knots.push_back(t_end_ns);
  std::size_t hint = 0;
  ImuMeasurement prev = SampleAt(samples, knots.front(), &hint);
  for (std::size_t k = 1; k < knots.size(); ++k) {
    const ImuMeasurement next = SampleAt(samples, knots[k], &hint);
    const double dt = static_cast<double>(knots[k] - knots[k - 1]) * 1e-9;
    IntegrateMeasurement(0.5 * (prev.accel + next.accel), 0.5 * (prev.gyro + next.gyro), dt, pim);
    prev = next;
  }
  return static_cast<int>(knots.size()) - 1;
}

SO3d DeltaRotation(const PreintegratedImu& pim, const ImuBias& bias) {
  return pim.delta_R * SO3d::Exp(pim.J_R_bg * (bias.gyro - pim.bias.gyro));
}

Vec3 DeltaVelocity(const PreintegratedImu& pim, const ImuBias& bias) {
  return pim.delta_v + pim.J_v_bg * (bias.gyro - pim.bias.gyro) +
         pim.J_v_ba * (bias.accel - pim.bias.accel);
}

Vec3 DeltaPosition(const PreintegratedImu& pim, const ImuBias& bias) {
  return pim.delta_p + pim.J_p_bg * (bias.gyro - pim.bias.gyro) +
         pim.J_p_ba * (bias.accel - pim.bias.accel);
}

void Reintegrate(const ImuBias& bias, PreintegratedImu* pim) {
  std::vector<PreintegratedImu::Step> steps = std::move(pim->steps);
  *pim = StartPreintegration(bias, pim->noise, pim->scheme);
  pim->steps.reserve(steps.size());
  for (const PreintegratedImu::Step& s : steps) IntegrateMeasurement(s.accel, s.gyro, s.dt, pim);
}

bool UpdateBias(const ImuBias& bias, const PreintegrationOptions& options, PreintegratedImu* pim) {
  const ImuBias change = bias - pim->bias;
  if (change.gyro.norm() <= options.reintegrate_gyro_bias_change &&
      change.accel.norm() <= options.reintegrate_accel_bias_change) {
    return false;
  }
  Reintegrate(bias, pim);
  return true;
}

void MergePrevious(const PreintegratedImu& previous, PreintegratedImu* pim) {
  PKSLAM_CHECK(&previous != pim, "MergePrevious with itself");
  std::vector<PreintegratedImu::Step> steps = previous.steps;
  steps.insert(steps.end(), pim->steps.begin(), pim->steps.end());
  pim->steps = std::move(steps);
  Reintegrate(pim->bias, pim);
}

NavState PredictState(const NavState& start, const PreintegratedImu& pim, const ImuBias& bias,
                      const Vec3& gravity_world) {
  const SO3d& r_i = start.world_from_body.so3();
  const Vec3& p_i = start.world_from_body.translation();
  const Vec3& v_i = start.velocity_world;
  const double t = pim.dt;
  NavState end;
  end.world_from_body =
      SE3d(r_i * DeltaRotation(pim, bias),
           p_i + v_i * t + 0.5 * t * t * gravity_world + r_i * DeltaPosition(pim, bias));
  end.velocity_world = v_i + t * gravity_world + r_i * DeltaVelocity(pim, bias);
  return end;
}

Eigen::Matrix<double, 9, 9> PreintegrationSqrtInformation(const PreintegratedImu& pim) {
  return SqrtInformation<9>(pim.covariance.topLeftCorner<9, 9>());
}

}  // namespace pkslam
