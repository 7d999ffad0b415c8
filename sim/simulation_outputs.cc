#include "sim/simulation_outputs.h"

#include <algorithm>
#include <cmath>

#include "core/util/error.h"
#include "core/util/output_guard.h"
#include "io/settings.h"
#include "sim/depth_sensor.h"
#include "sim/random.h"

namespace pkslam::sim {

std::int64_t Ns(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

void WriteSettings(const std::filesystem::path& file, const std::vector<CameraRig>& cameras,
                   const SimulationOptions& o) {
  Settings settings;
  settings.camera1 = cameras[0].camera;
  settings.fps = cameras[0].rate_hz;
  if (o.rgbd) {
    settings.depth_map_factor = 5000.0;
    settings.stereo_baseline_m = 0.07;  // ORB-SLAM3's virtual RGB-D baseline (TUM files)
    settings.th_depth = 40.0;
    // The noise the depth images carry, so runs weight the depth the way it was simulated.
    if (o.depth_noise > 0) {
      settings.depth_noise_k = KinectDepthModel().EffectiveNoiseK(o.depth_noise);
    }
  } else {
    settings.orb.n_features = OrbFeaturesFor(o.camera);
    settings.camera2 = cameras[1].camera;
    settings.right_from_left = cameras[1].body_from_camera.Inverse() * cameras[0].body_from_camera;
    if (o.write_imu) {
      settings.body_from_cam0 = cameras[0].body_from_camera;
      ImuNoise noise;
      noise.gyro_noise_density = o.imu.gyro_noise_density;
      noise.accel_noise_density = o.imu.accel_noise_density;
      noise.gyro_random_walk = o.imu.gyro_random_walk;
      noise.accel_random_walk = o.imu.accel_random_walk;
      noise.rate_hz = o.imu.rate_hz;
      settings.imu = noise;
    }
  }
  WriteOrbSlam3Settings(settings, file);
}

void MotionStatistics(const SplineTrajectory& traj, std::int64_t begin, std::int64_t end,
                      std::int64_t step, SimulationSummary* s) {
  std::vector<Eigen::Vector3d> p;
  double rate_sum = 0.0;
  int n = 0;
  for (std::int64_t t = begin; t <= end; t += step) {
    const BodyState st = traj.State(t);
    p.push_back(st.world_from_body.translation());
    const double rate = st.omega_body.norm() * 180.0 / M_PI;
    rate_sum += rate;
    s->max_angular_rate_dps = std::max(s->max_angular_rate_dps, rate);
    ++n;
  }
  s->path_length_m = PathLength(p);
  const double duration = 1e-9 * static_cast<double>(end - begin);
  s->mean_speed_mps = duration > 0.0 ? s->path_length_m / duration : 0.0;
  s->mean_angular_rate_dps = n > 0 ? rate_sum / n : 0.0;
}

void WriteImuAndGroundTruth(const BodyMotion& motion, const std::vector<ImuSample>& imu,
                            const SimulationOptions& o, EurocWriter* euroc) {
  const bool gt_errors = o.realism.On(RealismSource::kGroundTruth);
  const GroundTruthErrorOptions& g = o.realism.ground_truth;
  const std::int64_t offset = Ns(1e-3 * g.time_offset_ms);
  Rng noise(DeriveSeed(o.seed, 0x47544E4F495345));  // "GTNOISE"
  for (const ImuSample& s : imu) {
    if (o.write_imu) euroc->WriteImu(s);
    const BodyState exact = motion.State(s.t_ns);
    const GroundTruthRow exact_row{s.t_ns, exact.world_from_body, exact.velocity_world, s.gyro_bias,
                                   s.accel_bias};
    if (!gt_errors) {
      euroc->WriteGroundTruth(exact_row);
      continue;
    }
    euroc->WriteExactGroundTruth(exact_row);
    const std::int64_t t_true = std::clamp(s.t_ns + offset, motion.begin_ns(), motion.end_ns());
    const BodyState st = motion.State(t_true);
    Eigen::Vector3d dp;
    Eigen::Vector3d dr;
    for (int i = 0; i < 3; ++i) dp[i] = 1e-3 * g.position_noise_mm * noise.Normal();
    for (int i = 0; i < 3; ++i) dr[i] = g.rotation_noise_deg * M_PI / 180.0 * noise.Normal();
    const SE3d noisy(st.world_from_body.so3() * SO3d::Exp(dr),
                     st.world_from_body.translation() + dp);
    euroc->WriteGroundTruth({s.t_ns, noisy, st.velocity_world, s.gyro_bias, s.accel_bias});
  }
}

void WriteReferenceClouds(const Scene& scene, const SurfaceVisibility* visibility,
                          const SurfaceVisibility* observed, const SimulationOptions& o,
                          SimulationSummary* summary) {
  summary->cloud_points = WriteReferenceCloud(scene, visibility, o.cloud_spacing_m,
                                              o.output_dir / "reference_cloud.ply");
  if (observed != nullptr) {
    summary->observed_points = WriteReferenceCloud(
        scene, observed, o.cloud_spacing_m, o.output_dir / "reference_observed.ply",
        fmt::format("observed reference: surfaces cam0 saw within {} m", o.observed_range_m));
  }
}

void ClearEarlierRender(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(dir, ec) || (fs::is_directory(dir, ec) && fs::is_empty(dir, ec))) return;
  // sim.yaml is written last; the marker first, so an interrupted render is recognised too.
  if (!fs::is_directory(dir, ec) ||
      !(fs::exists(dir / "sim.yaml", ec) || fs::exists(dir / kOwnedFolderMarker, ec))) {
    throw OptionError(fmt::format(
        "--out {}: exists and is not a pkslam render (no sim.yaml); simulate writes into an empty "
        "or new folder, or replaces an earlier render",
        dir.string()));
  }
  static constexpr const char* kRenderEntries[] = {"mav0",
                                                   "truth",
                                                   "rgb",
                                                   "depth",
                                                   "rgb.txt",
                                                   "depth.txt",
                                                   "associations.txt",
                                                   "groundtruth.txt",
                                                   "settings.yaml",
                                                   "timestamps.txt",
                                                   "reference_cloud.ply",
                                                   "reference_observed.ply",
                                                   "sim.yaml"};
  for (const char* name : kRenderEntries) {
    fs::remove_all(dir / name, ec);
    if (ec) throw OutputError(dir / name, ec.message());
  }
}

}  // namespace pkslam::sim
