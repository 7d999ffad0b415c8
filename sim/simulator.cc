#include "sim/simulator.h"

#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <ctime>
#include <opencv2/imgproc.hpp>

#include "core/util/error.h"
#include "core/util/output_guard.h"
#include "core/util/log.h"
#include "core/util/progress.h"
#include "io/settings.h"
#include "io/trajectory.h"
#include "sim/depth_sensor.h"
#include "sim/euroc_writer.h"
#include "sim/random.h"
#include "sim/realism_draw.h"
#include "sim/reference_cloud.h"
#include "sim/tum_rgbd_writer.h"

namespace pkslam::sim {
namespace {

// Random flights start at this clock (2020-09-13T12:26:40Z): a plausible EuRoC-like epoch.
constexpr std::int64_t kRandomEpochNs = 1'600'000'000'000'000'000;

struct QualitySettings {
  int texture_size;
  int supersample;
  int motion_blur_samples;
};

QualitySettings SettingsFor(Quality q) {
  switch (q) {
    case Quality::kFast:
      return {512, 1, 3};
    case Quality::kDefault:
      return {1024, 1, 5};
    case Quality::kHigh:
      return {2048, 2, 9};
  }
  return {1024, 1, 5};
}

std::int64_t Ns(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

// The colour camera of RGB-D output: TUM's default Kinect intrinsics, mounted like cam0.
CameraRig RgbdCamera(double rate_hz) {
  CameraRig c = EurocCam0();
  c.name = "rgb";
  c.camera = CameraModel::Pinhole(640, 480, 525.0, 525.0, 319.5, 239.5);
  c.rate_hz = rate_hz;
  return c;
}

// Renders the radiance seen by a camera at time t, averaged over the exposure (motion blur).
void RenderFrame(const Renderer& renderer, const CameraRays& rays, const BodyMotion& motion,
                 const SE3d& body_from_camera, std::int64_t t_ns, double exposure_s, int samples,
                 RenderBuffers* out, std::span<SurfaceVisibility* const> visibility) {
  if (exposure_s <= 0.0 || samples <= 1) {
    renderer.Render(rays, motion.WorldFromBody(t_ns) * body_from_camera, out, visibility);
    return;
  }
  RenderBuffers sub;
  cv::Mat sum;
  for (int i = 0; i < samples; ++i) {
    const std::int64_t ti = std::clamp(t_ns + Ns(exposure_s * ((i + 0.5) / samples - 0.5)),
                                       motion.begin_ns(), motion.end_ns());
    const bool centre = i == samples / 2;
    renderer.Render(rays, motion.WorldFromBody(ti) * body_from_camera, &sub,
                    centre ? visibility : std::span<SurfaceVisibility* const>{});
    if (i == 0) {
      sum = sub.radiance.clone();
    } else {
      sum += sub.radiance;
    }
    if (centre && !sub.depth.empty()) out->depth = sub.depth.clone();
  }
  out->radiance = sum / samples;
}

// ORB-SLAM3-format settings of the simulated rig (io/settings.h writes the file).
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

bool InBlackout(const SimulationOptions& o, std::int64_t t_ns, std::int64_t begin_ns) {
  if (o.blackout_begin_s < 0.0) return false;
  const double t = 1e-9 * static_cast<double>(t_ns - begin_ns);
  return t >= o.blackout_begin_s && t <= o.blackout_end_s;
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

// IMU samples, and the ground truth as evaluation will see it (realism: the state at the stamp
// plus the ground-truth time offset, with motion-capture noise) and exactly (truth/).
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

// When the frame stamped t was exposed (mid-exposure, IMU clock): the camera-IMU time offset
// plus per-frame jitter (realism timing), inside the motion's range.
std::int64_t ExposureTime(const SimulationOptions& o, const RealismDraw& draw,
                          const BodyMotion& motion, std::int64_t t_ns, int frame) {
  std::int64_t t = t_ns;
  if (o.realism.On(RealismSource::kTiming)) {
    t += Ns(1e-3 * draw.camera_imu_offset_ms);
    if (o.realism.timing.jitter_ms > 0.0) {
      Rng jitter(DeriveSeed(o.seed, 0x4A49545445520000ULL + static_cast<std::uint64_t>(frame)));
      t += Ns(1e-3 * o.realism.timing.jitter_ms * jitter.Normal());
    }
  }
  return std::clamp(t, motion.begin_ns(), motion.end_ns());
}

// Sub-renders a motion-blurred frame needs: one per 1.5 px of image motion over the exposure
// (rotation at the focal length plus translation seen at 1.5 m), at most `max_samples`. Copies
// 1.5 px apart merge under the optical blur (sigma ~0.7 px), and a smear shorter than that is
// within it.
int BlurSamples(const BodyState& state, double exposure_s, double focal_px, int max_samples) {
  if (exposure_s <= 0.0 || max_samples <= 1) return 1;
  const double motion_px =
      exposure_s * focal_px * (state.omega_body.norm() + state.velocity_world.norm() / 1.5);
  const int n = static_cast<int>(std::ceil(motion_px / 1.5));
  return std::clamp(n, 1, max_samples);
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

// A render goes into an empty folder or replaces an earlier render (sim.yaml) there, entry by
// entry, so a --no-images render never leaves older images beside new IMU and ground truth. Any
// other folder is left alone: `--out` onto a recording would mix the two (docs/robustness.md).
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
  static constexpr const char* kRenderEntries[] = {
      "mav0",          "truth",           "rgb",        "depth",
      "rgb.txt",       "depth.txt",       "associations.txt", "groundtruth.txt",
      "settings.yaml", "timestamps.txt",  "reference_cloud.ply", "reference_observed.ply",
      "sim.yaml"};
  for (const char* name : kRenderEntries) {
    fs::remove_all(dir / name, ec);
    if (ec) throw OutputError(dir / name, ec.message());
  }
}

// The gain camera c develops frame k with: the rig's exposure gain, cam1's relative response,
// and each camera's frame-to-frame flicker (its own random stream per frame and camera, so the
// draw depends on nothing else).
double CameraGain(const SimulationOptions& o, double rig_gain, int k, std::size_t c) {
  double gain = c == 1 ? rig_gain * o.cam1_relative_gain : rig_gain;
  if (c < o.gain_flicker.size() && o.gain_flicker[c] > 0.0) {
    Rng flicker(DeriveSeed(o.seed, 0x464C4B00 + static_cast<std::uint64_t>(k) * 8 + c));
    gain *= std::max(1.0 + o.gain_flicker[c] * flicker.Normal(), 0.0);
  }
  return gain;
}

}  // namespace


SimulationSummary RunSimulation(const SimulationOptions& options) {
  options.Check();
  SimulationOptions o = options;  // resolved copy (recorded in sim.yaml)
  const QualitySettings quality = SettingsFor(o.quality);
  if (o.motion_blur_samples == 0) o.motion_blur_samples = quality.motion_blur_samples;
  const SceneDescription description = LoadSceneDescription(o.scene);
  o.scene_build.texture_size = quality.texture_size;
  o.scene_build.colour = o.rgbd;
  o.scene_build.texture_mode =
      ParseTextureMode(o.texture_mode.empty() ? description.texture_mode : o.texture_mode);
  o.scene_build.seed = o.seed;

  std::vector<CameraRig> cameras;
  if (o.rgbd) {
    cameras.push_back(RgbdCamera(o.rgbd_rate_hz));
  } else {
    cameras = StereoRig(o.camera);
    for (auto& c : cameras) c.rate_hz = o.camera_rate_hz;
  }
  // Realism: the calibration SLAM will read, the IMU's axis errors and biases, the replay fit.
  const RealismOptions& realism = o.realism;
  const RealismDraw draw = DrawRealism(realism, cameras, o.seed);
  if (realism.On(RealismSource::kImu)) {
    o.imu.errors = draw.imu_errors;
    o.imu.initial_gyro_bias += draw.gyro_bias;
    o.imu.initial_accel_bias += draw.accel_bias;
  }
  if (realism.On(RealismSource::kMotion)) {
    o.replay.position_knot_s = realism.motion.position_knot_s;
    o.replay.rotation_knot_s = realism.motion.rotation_knot_s;
    o.replay.position_cutoff_hz = realism.motion.position_cutoff_hz;
    o.replay.rotation_cutoff_hz = realism.motion.rotation_cutoff_hz;
  }

  // Motion.
  SimulationSummary summary;
  SplineTrajectory traj;
  std::int64_t begin_ns = 0;
  std::int64_t end_ns = 0;
  if (!o.trajectory.empty()) {
    const std::vector<StampedPose> samples = ReadTrajectory(o.trajectory).poses;
    begin_ns = samples.front().t_ns + Ns(o.start_s);
    end_ns = o.duration_s > 0.0 ? begin_ns + Ns(o.duration_s) : samples.back().t_ns;
    if (end_ns > samples.back().t_ns || begin_ns >= end_ns) {
      throw InputError(
          o.trajectory,
          fmt::format("window --start {} --duration {} is outside the {:.3f} s "
                      "trajectory",
                      o.start_s, o.duration_s,
                      1e-9 * static_cast<double>(samples.back().t_ns - samples.front().t_ns)));
    }
    traj = FitTrajectory(samples, begin_ns, end_ns, o.replay);
  } else {
    if (o.duration_s > 0.0) o.motion.duration_s = o.duration_s;
    const Scene nominal = BuildScene(description, o.scene_build, {});
    begin_ns = kRandomEpochNs;
    end_ns = begin_ns + Ns(o.motion.duration_s);
    traj = GenerateMotion(nominal, o.motion, cameras[0].body_from_camera, o.seed, begin_ns);
  }
  summary.begin_ns = begin_ns;
  summary.end_ns = end_ns;
  MotionStatistics(traj, begin_ns, end_ns, o.imu.period_ns(), &summary);
  const bool vibrate = realism.On(RealismSource::kMotion) && realism.motion.vibration &&
                       realism.motion.vibration_scale > 0.0;
  VibrationOptions vibration_options;
  vibration_options.scale = realism.motion.vibration_scale;
  const BodyMotion motion =
      vibrate ? BodyMotion(traj, Vibration(EurocVibrationSpectrum(), vibration_options,
                                           DeriveSeed(o.seed, 0x56494254)))  // "VIBT"
              : BodyMotion(traj);

  // Scene around the path of the body and the cameras.
  std::vector<Eigen::Vector3d> path;
  for (std::int64_t t = begin_ns; t <= end_ns; t += Ns(0.05)) {
    const SE3d pose = traj.WorldFromBody(t);
    path.push_back(pose.translation());
    for (const auto& c : cameras) path.push_back((pose * c.body_from_camera).translation());
  }
  const Scene scene = BuildScene(description, o.scene_build, path, &summary.scene);
  PKSLAM_LOG_INFO(
      "simulate: scene '{}' room [{:.1f} {:.1f} {:.1f}]..[{:.1f} {:.1f} {:.1f}] m, "
      "{} objects ({} removed near the path)",
      scene.name, summary.scene.room_min.x(), summary.scene.room_min.y(),
      summary.scene.room_min.z(), summary.scene.room_max.x(), summary.scene.room_max.y(),
      summary.scene.room_max.z(), summary.scene.objects_placed - summary.scene.objects_removed,
      summary.scene.objects_removed);

  // IMU and ground truth (EuRoC layout only).
  std::unique_ptr<EurocWriter> euroc;
  std::unique_ptr<TumRgbdWriter> tum;
  if (o.reference_only) {
    std::error_code ec;
    std::filesystem::create_directories(o.output_dir, ec);
    if (ec) throw Error(fmt::format("cannot create {}: {}", o.output_dir.string(), ec.message()));
  } else if (!o.bench) {
    ClearEarlierRender(o.output_dir);
    CreateOwnedDirectory(o.output_dir);
    if (o.rgbd) {
      tum = std::make_unique<TumRgbdWriter>(o.output_dir);
    } else {
      // Without images (IMU + ground truth only) there are no camera folders at all.
      // sensor.yaml files carry the calibration SLAM reads (with realism: the erroneous one).
      euroc = std::make_unique<EurocWriter>(
          o.output_dir, o.write_images ? draw.written_cameras : std::vector<CameraRig>{}, o.imu,
          o.write_imu);
      if (realism.preset != RealismPreset::kIdeal) {
        euroc->OpenTruth(cameras, RealismDrawYaml(draw));
      }
    }
  }
  if (!o.rgbd && !o.reference_only) {
    const std::vector<ImuSample> imu = SimulateImu(motion, begin_ns, end_ns, o.imu, o.seed);
    summary.imu_samples = static_cast<int>(imu.size());
    if (euroc) WriteImuAndGroundTruth(motion, imu, o, euroc.get());
  }

  // Camera frames.
  const double rate = o.rgbd ? o.rgbd_rate_hz : o.camera_rate_hz;
  std::int64_t period = Ns(1.0 / rate);
  std::int64_t first = begin_ns;
  if (o.rgbd) {
    period = (period + 500) / 1000 * 1000;  // TUM timestamps are whole microseconds
    first = (begin_ns + 999) / 1000 * 1000;
  }
  int frames = o.write_images ? static_cast<int>((end_ns - first) / period) + 1 : 0;
  if (o.bench && o.bench_frames > 0) frames = std::min(frames, o.bench_frames);
  RenderOptions render_options;
  render_options.colour = o.rgbd;
  render_options.depth = o.rgbd;
  const Renderer renderer(scene, render_options);
  std::vector<CameraRays> rays;
  std::vector<SensorModel> sensors;
  for (std::size_t c = 0; c < cameras.size() && frames > 0; ++c) {
    rays.emplace_back(cameras[c].camera, quality.supersample);
  }
  for (std::size_t c = 0; c < rays.size(); ++c) {
    sensors.emplace_back(o.sensor, rays[c], DeriveSeed(o.seed, 0x43414D00 + c));
  }
  std::unique_ptr<SurfaceVisibility> visibility;
  std::unique_ptr<SurfaceVisibility> observed;
  if (o.write_cloud && !o.bench && frames > 0) {
    visibility =
        std::make_unique<SurfaceVisibility>(scene, static_cast<float>(o.visibility_cell_m));
    if (o.observed_range_m > 0.0) {
      observed = std::make_unique<SurfaceVisibility>(scene, static_cast<float>(o.observed_cell_m),
                                                     static_cast<float>(o.observed_range_m));
    }
  }
  // cam0's rays mark both (the dense tool reconstructs the left camera's view).
  const std::array<SurfaceVisibility*, 2> cam0_marks = {visibility.get(), observed.get()};
  const PixelNoise depth_noise;
  const bool exposure_model = o.sensor.max_exposure_s > 0.0;
  const bool write_truth = euroc && realism.preset != RealismPreset::kIdeal;
  double exposure_sum = 0.0;
  double saturated_sum = 0.0;
  Progress progress(o.bench ? "bench" : "simulate", static_cast<std::size_t>(frames), o.quiet);
  double render_seconds = 0.0;
  double render_cpu = 0.0;
  std::vector<RenderBuffers> buffers(cameras.size());
  tbb::task_group writers;
  // On an exception below, let running PNG tasks finish before the group goes away.
  struct WaitOnExit {
    tbb::task_group& group;
    ~WaitOnExit() {
      try {
        group.wait();
      } catch (...) {  // the first error is already propagating
      }
    }
  } wait_on_exit{writers};
  std::unique_ptr<LandmarkTracks> landmark_tracks;
  if (o.landmark_tracks > 0 && frames > 0 && !o.bench && !o.reference_only) {
    landmark_tracks = std::make_unique<LandmarkTracks>(
        scene, cameras[0].camera, LandmarkTracksOptions{o.landmark_tracks, 8.0, o.seed});
  }
  const auto loop_start = std::chrono::steady_clock::now();
  for (int k = 0; k < frames; ++k) {
    const std::int64_t t = first + k * period;
    const std::int64_t t_exposure = ExposureTime(o, draw, motion, t, k);
    const bool black = InBlackout(o, t, begin_ns);
    std::vector<cv::Mat> images(cameras.size());
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t cpu0 = std::clock();
    double exposure = o.motion_blur_exposure_s;
    if (!black && o.reference_only) {  // cam0 alone, no image formation
      const int samples = BlurSamples(motion.State(t_exposure), exposure, cameras[0].camera.fx(),
                                      o.motion_blur_samples);
      RenderFrame(renderer, rays[0], motion, cameras[0].body_from_camera, t_exposure, exposure,
                  samples, &buffers[0], cam0_marks);
    } else if (!black) {
      // One exposure for the rig (the VI-Sensor shares it between cameras), set by the auto
      // exposure from the frames before; the first frame is metered on a sharp render.
      SensorModel& meter = sensors[0];
      if (exposure_model) {
        if (!meter.initialised()) {
          RenderFrame(renderer, rays[0], motion, cameras[0].body_from_camera, t_exposure, 0.0, 1,
                      &buffers[0], {});
          meter.NextGain(buffers[0].radiance, 1.0 / rate);
        }
        exposure = meter.exposure_s();
      }
      const int samples = BlurSamples(motion.State(t_exposure), exposure, cameras[0].camera.fx(),
                                      o.motion_blur_samples);
      for (std::size_t c = 0; c < cameras.size(); ++c) {
        RenderFrame(renderer, rays[c], motion, cameras[c].body_from_camera, t_exposure, exposure,
                    samples, &buffers[c],
                    c == 0 ? std::span<SurfaceVisibility* const>(cam0_marks)
                           : std::span<SurfaceVisibility* const>{});
      }
      const double gain = meter.NextGain(buffers[0].radiance, 1.0 / rate);
      for (std::size_t c = 0; c < cameras.size(); ++c) {
        images[c] = sensors[c].Develop(buffers[c].radiance, CameraGain(o, gain, k, c),
                                       static_cast<std::uint64_t>(k) * 8 + c);
      }
      exposure_sum += exposure;
      if (images[0].channels() == 1) {
        saturated_sum += static_cast<double>(cv::countNonZero(images[0] >= 255)) /
                         static_cast<double>(images[0].total());
      }
    } else {
      for (std::size_t c = 0; c < cameras.size(); ++c) {
        images[c] = cv::Mat::zeros(cameras[c].camera.height(), cameras[c].camera.width(),
                                   o.rgbd ? CV_8UC3 : CV_8UC1);
      }
    }
    if (landmark_tracks) {
      // The pose the image shows (mid-exposure), stamped with the image's timestamp.
      landmark_tracks->AddFrame(k, t,
                                motion.WorldFromBody(t_exposure) * cameras[0].body_from_camera);
    }
    render_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    render_cpu += static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    // PNG encoding of this frame overlaps the rendering of the next one (a second core's
    // worth of work); list files are written here, in order.
    writers.wait();
    if (write_truth) euroc->WriteFrameTime(t, t_exposure, black ? 0.0 : exposure);
    if (euroc) {
      for (std::size_t c = 0; c < cameras.size(); ++c) {
        const std::filesystem::path file = euroc->AddImage(static_cast<int>(c), t);
        writers.run([file, image = images[c]] { WritePng(file, image, kEurocPngCompression); });
      }
    }
    if (tum) {
      const cv::Mat depth =
          black ? cv::Mat::zeros(images[0].size(), CV_16U)
                : KinectDepthImage(buffers[0].depth, KinectDepthModel(), o.depth_noise, depth_noise,
                                   DeriveSeed(o.seed, 0x44455054 + k), 5000.0);
      const auto files = tum->AddFrame(t);
      writers.run([files, colour = images[0], depth] {
        TumRgbdWriter::WriteImages(files.first, files.second, colour, depth);
      });
    }
    progress.Add();
  }
  writers.wait();
  progress.Finish();
  summary.frames = frames;
  summary.image_width = cameras[0].camera.width();
  summary.image_height = cameras[0].camera.height();
  summary.total_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
  summary.render_seconds = render_seconds;
  summary.render_cpu_seconds = render_cpu;
  summary.frames_per_second = render_seconds > 0.0 ? frames / render_seconds : 0.0;
  if (frames > 0) {
    summary.mean_exposure_ms = 1e3 * exposure_sum / frames;
    summary.saturated_share = saturated_sum / frames;
  }

  if (o.bench) {
    summary.layout = "bench";
    return summary;
  }
  if (o.reference_only) {
    summary.layout = "reference";
    WriteReferenceClouds(scene, visibility.get(), observed.get(), o, &summary);
    return summary;
  }
  if (tum) {
    // Ground truth of the colour camera at 100 Hz (TUM's motion-capture rate).
    for (std::int64_t t = first; t <= end_ns; t += 10'000'000) {
      tum->WriteGroundTruth(t, motion.WorldFromBody(t) * cameras[0].body_from_camera);
    }
    tum->Close();
    WriteSettings(o.output_dir / "settings.yaml", draw.written_cameras, o);
    summary.layout = "tum_rgbd";
  } else {
    euroc->Close();
    WriteSettings(o.output_dir / "settings.yaml", draw.written_cameras, o);
    summary.layout = "euroc";
  }
  if (o.write_cloud) WriteReferenceClouds(scene, visibility.get(), observed.get(), o, &summary);
  if (landmark_tracks) landmark_tracks->Write(o.output_dir / "truth");
  WriteSimYaml(o.output_dir / "sim.yaml", o, summary);
  return summary;
}

}  // namespace pkslam::sim
