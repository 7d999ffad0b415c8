#include "sim/simulator.h"

#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <ctime>
#include <opencv2/imgproc.hpp>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/output_guard.h"
#include "core/util/progress.h"
#include "io/settings.h"
#include "io/trajectory.h"
#include "sim/depth_sensor.h"
#include "sim/euroc_writer.h"
#include "sim/random.h"
#include "sim/realism_draw.h"
#include "sim/reference_cloud.h"
#include "sim/simulation_outputs.h"
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

bool InBlackout(const SimulationOptions& o, std::int64_t t_ns, std::int64_t begin_ns) {
  if (o.blackout_begin_s < 0.0) return false;
  const double t = 1e-9 * static_cast<double>(t_ns - begin_ns);
  return t >= o.blackout_begin_s && t <= o.blackout_end_s;
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

// The options as this render resolves them (recorded in sim.yaml), the cameras and the realism
// draw: the calibration SLAM will read, the IMU's axis errors and biases, the replay fit.
struct ResolvedSimulation {
  SimulationOptions o;
  QualitySettings quality;
  SceneDescription description;
  std::vector<CameraRig> cameras;
  RealismDraw draw;
};

ResolvedSimulation Resolve(const SimulationOptions& options) {
  ResolvedSimulation r{
      options, SettingsFor(options.quality), LoadSceneDescription(options.scene), {}, {}};
  SimulationOptions& o = r.o;
  if (o.motion_blur_samples == 0) o.motion_blur_samples = r.quality.motion_blur_samples;
  o.scene_build.texture_size = r.quality.texture_size;
  o.scene_build.colour = o.rgbd;
  o.scene_build.texture_mode =
      ParseTextureMode(o.texture_mode.empty() ? r.description.texture_mode : o.texture_mode);
  o.scene_build.seed = o.seed;
  if (o.rgbd) {
    r.cameras.push_back(RgbdCamera(o.rgbd_rate_hz));
  } else {
    r.cameras = StereoRig(o.camera);
    for (auto& c : r.cameras) c.rate_hz = o.camera_rate_hz;
  }
  const RealismOptions& realism = o.realism;
  r.draw = DrawRealism(realism, r.cameras, o.seed);
  if (realism.On(RealismSource::kImu)) {
    o.imu.errors = r.draw.imu_errors;
    o.imu.initial_gyro_bias += r.draw.gyro_bias;
    o.imu.initial_accel_bias += r.draw.accel_bias;
  }
  if (realism.On(RealismSource::kMotion)) {
    o.replay.position_knot_s = realism.motion.position_knot_s;
    o.replay.rotation_knot_s = realism.motion.rotation_knot_s;
    o.replay.position_cutoff_hz = realism.motion.position_cutoff_hz;
    o.replay.rotation_cutoff_hz = realism.motion.rotation_cutoff_hz;
  }
  return r;
}

struct Flight {
  SplineTrajectory traj;
  std::int64_t begin_ns = 0;
  std::int64_t end_ns = 0;
};

// A replayed trajectory's window, or a random flight through the nominal scene.
Flight MakeFlight(ResolvedSimulation* r) {
  SimulationOptions& o = r->o;
  Flight f;
  if (!o.trajectory.empty()) {
    const std::vector<StampedPose> samples = ReadTrajectory(o.trajectory).poses;
    f.begin_ns = samples.front().t_ns + Ns(o.start_s);
    f.end_ns = o.duration_s > 0.0 ? f.begin_ns + Ns(o.duration_s) : samples.back().t_ns;
    if (f.end_ns > samples.back().t_ns || f.begin_ns >= f.end_ns) {
      throw InputError(
          o.trajectory,
          fmt::format("window --start {} --duration {} is outside the {:.3f} s "
                      "trajectory",
                      o.start_s, o.duration_s,
                      1e-9 * static_cast<double>(samples.back().t_ns - samples.front().t_ns)));
    }
    f.traj = FitTrajectory(samples, f.begin_ns, f.end_ns, o.replay);
  } else {
    if (o.duration_s > 0.0) o.motion.duration_s = o.duration_s;
    const Scene nominal = BuildScene(r->description, o.scene_build, {});
    f.begin_ns = kRandomEpochNs;
    f.end_ns = f.begin_ns + Ns(o.motion.duration_s);
    f.traj = GenerateMotion(nominal, o.motion, r->cameras[0].body_from_camera, o.seed, f.begin_ns);
  }
  return f;
}

BodyMotion MakeBodyMotion(const Flight& f, const SimulationOptions& o) {
  const RealismOptions& realism = o.realism;
  const bool vibrate = realism.On(RealismSource::kMotion) && realism.motion.vibration &&
                       realism.motion.vibration_scale > 0.0;
  if (!vibrate) return BodyMotion(f.traj);
  VibrationOptions vibration_options;
  vibration_options.scale = realism.motion.vibration_scale;
  return BodyMotion(f.traj, Vibration(EurocVibrationSpectrum(), vibration_options,
                                      DeriveSeed(o.seed, 0x56494254)));  // "VIBT"
}

// The scene built around the path of the body and the cameras.
Scene SceneAroundFlight(const ResolvedSimulation& r, const Flight& f, SimulationSummary* summary) {
  std::vector<Eigen::Vector3d> path;
  for (std::int64_t t = f.begin_ns; t <= f.end_ns; t += Ns(0.05)) {
    const SE3d pose = f.traj.WorldFromBody(t);
    path.push_back(pose.translation());
    for (const auto& c : r.cameras) path.push_back((pose * c.body_from_camera).translation());
  }
  Scene scene = BuildScene(r.description, r.o.scene_build, path, &summary->scene);
  PKSLAM_LOG_INFO(
      "simulate: scene '{}' room [{:.1f} {:.1f} {:.1f}]..[{:.1f} {:.1f} {:.1f}] m, "
      "{} objects ({} removed near the path)",
      scene.name, summary->scene.room_min.x(), summary->scene.room_min.y(),
      summary->scene.room_min.z(), summary->scene.room_max.x(), summary->scene.room_max.y(),
      summary->scene.room_max.z(), summary->scene.objects_placed - summary->scene.objects_removed,
      summary->scene.objects_removed);
  return scene;
}

struct Writers {
  std::unique_ptr<EurocWriter> euroc;  // EuRoC layout (with IMU and ground truth)
  std::unique_ptr<TumRgbdWriter> tum;  // TUM RGB-D layout
};

Writers OpenWriters(const ResolvedSimulation& r) {
  const SimulationOptions& o = r.o;
  Writers w;
  if (o.reference_only) {
    std::error_code ec;
    std::filesystem::create_directories(o.output_dir, ec);
    if (ec) throw Error(fmt::format("cannot create {}: {}", o.output_dir.string(), ec.message()));
  } else if (!o.bench) {
    ClearEarlierRender(o.output_dir);
    CreateOwnedDirectory(o.output_dir);
    if (o.rgbd) {
      w.tum = std::make_unique<TumRgbdWriter>(o.output_dir);
    } else {
      // Without images (IMU + ground truth only) there are no camera folders at all.
      // sensor.yaml files carry the calibration SLAM reads (with realism: the erroneous one).
      w.euroc = std::make_unique<EurocWriter>(
          o.output_dir, o.write_images ? r.draw.written_cameras : std::vector<CameraRig>{}, o.imu,
          o.write_imu);
      if (o.realism.preset != RealismPreset::kIdeal) {
        w.euroc->OpenTruth(r.cameras, RealismDrawYaml(r.draw));
      }
    }
  }
  return w;
}

// When the frames are taken: from the flight's begin at the camera rate.
struct FrameClock {
  std::int64_t first = 0;
  std::int64_t period = 0;
  int frames = 0;
};

FrameClock MakeFrameClock(const SimulationOptions& o, const Flight& f) {
  const double rate = o.rgbd ? o.rgbd_rate_hz : o.camera_rate_hz;
  FrameClock c{f.begin_ns, Ns(1.0 / rate), 0};
  if (o.rgbd) {
    c.period = (c.period + 500) / 1000 * 1000;  // TUM timestamps are whole microseconds
    c.first = (f.begin_ns + 999) / 1000 * 1000;
  }
  c.frames = o.write_images ? static_cast<int>((f.end_ns - c.first) / c.period) + 1 : 0;
  if (o.bench && o.bench_frames > 0) c.frames = std::min(c.frames, o.bench_frames);
  return c;
}

RenderOptions ColourAndDepth(bool rgbd) {
  RenderOptions options;
  options.colour = rgbd;
  options.depth = rgbd;
  return options;
}

// One frame's images as the rig takes them.
struct RenderedFrame {
  std::vector<cv::Mat> images;
  std::int64_t t_exposure = 0;
  bool black = false;
  double exposure = 0.0;
};

// Forms each frame's images: the scene rendered over the exposure (motion blur), developed by
// each camera's sensor model at the rig's auto exposure; cam0's rays mark the surfaces seen.
class FrameFormer {
 public:
  FrameFormer(const ResolvedSimulation& r, const Scene& scene, const BodyMotion& motion,
              std::int64_t begin_ns, int frames, std::array<SurfaceVisibility*, 2> cam0_marks)
      : r_(r),
        motion_(motion),
        begin_ns_(begin_ns),
        renderer_(scene, ColourAndDepth(r.o.rgbd)),
        buffers_(r.cameras.size()),
        cam0_marks_(cam0_marks),
        exposure_model_(r.o.sensor.max_exposure_s > 0.0),
        rate_(r.o.rgbd ? r.o.rgbd_rate_hz : r.o.camera_rate_hz) {
    for (std::size_t c = 0; c < r.cameras.size() && frames > 0; ++c) {
      rays_.emplace_back(r.cameras[c].camera, r.quality.supersample);
    }
    for (std::size_t c = 0; c < rays_.size(); ++c) {
      sensors_.emplace_back(r.o.sensor, rays_[c], DeriveSeed(r.o.seed, 0x43414D00 + c));
    }
  }

  RenderedFrame Form(int k, std::int64_t t);
  // cam0's last buffers (the depth TUM output needs).
  const RenderBuffers& cam0() const { return buffers_[0]; }
  double exposure_sum() const { return exposure_sum_; }
  double saturated_sum() const { return saturated_sum_; }

 private:
  void Expose(int k, double exposure, std::int64_t t_exposure, RenderedFrame* f);

  const ResolvedSimulation& r_;
  const BodyMotion& motion_;
  std::int64_t begin_ns_;
  Renderer renderer_;
  std::vector<CameraRays> rays_;
  std::vector<SensorModel> sensors_;
  std::vector<RenderBuffers> buffers_;
  std::array<SurfaceVisibility*, 2> cam0_marks_;
  bool exposure_model_;
  double rate_;
  double exposure_sum_ = 0.0;
  double saturated_sum_ = 0.0;
};

RenderedFrame FrameFormer::Form(int k, std::int64_t t) {
  const SimulationOptions& o = r_.o;
  const std::vector<CameraRig>& cameras = r_.cameras;
  RenderedFrame f;
  f.images.resize(cameras.size());
  f.t_exposure = ExposureTime(o, r_.draw, motion_, t, k);
  f.black = InBlackout(o, t, begin_ns_);
  f.exposure = o.motion_blur_exposure_s;
  if (!f.black && o.reference_only) {  // cam0 alone, no image formation
    const int samples = BlurSamples(motion_.State(f.t_exposure), f.exposure, cameras[0].camera.fx(),
                                    o.motion_blur_samples);
    RenderFrame(renderer_, rays_[0], motion_, cameras[0].body_from_camera, f.t_exposure, f.exposure,
                samples, &buffers_[0], cam0_marks_);
  } else if (!f.black) {
    Expose(k, f.exposure, f.t_exposure, &f);
  } else {
    for (std::size_t c = 0; c < cameras.size(); ++c) {
      f.images[c] = cv::Mat::zeros(cameras[c].camera.height(), cameras[c].camera.width(),
                                   o.rgbd ? CV_8UC3 : CV_8UC1);
    }
  }
  return f;
}

// One exposure for the rig (the VI-Sensor shares it between cameras), set by the auto exposure
// from the frames before; the first frame is metered on a sharp render.
void FrameFormer::Expose(int k, double exposure, std::int64_t t_exposure, RenderedFrame* f) {
  const SimulationOptions& o = r_.o;
  const std::vector<CameraRig>& cameras = r_.cameras;
  SensorModel& meter = sensors_[0];
  if (exposure_model_) {
    if (!meter.initialised()) {
      RenderFrame(renderer_, rays_[0], motion_, cameras[0].body_from_camera, t_exposure, 0.0, 1,
                  &buffers_[0], {});
      meter.NextGain(buffers_[0].radiance, 1.0 / rate_);
    }
    exposure = meter.exposure_s();
  }
  const int samples = BlurSamples(motion_.State(t_exposure), exposure, cameras[0].camera.fx(),
                                  o.motion_blur_samples);
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    RenderFrame(renderer_, rays_[c], motion_, cameras[c].body_from_camera, t_exposure, exposure,
                samples, &buffers_[c],
                c == 0 ? std::span<SurfaceVisibility* const>(cam0_marks_)
                       : std::span<SurfaceVisibility* const>{});
  }
  const double gain = meter.NextGain(buffers_[0].radiance, 1.0 / rate_);
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    f->images[c] = sensors_[c].Develop(buffers_[c].radiance, CameraGain(o, gain, k, c),
                                       static_cast<std::uint64_t>(k) * 8 + c);
  }
  f->exposure = exposure;
  exposure_sum_ += exposure;
  if (f->images[0].channels() == 1) {
    saturated_sum_ += static_cast<double>(cv::countNonZero(f->images[0] >= 255)) /
                      static_cast<double>(f->images[0].total());
  }
}

// The layout's last files: TUM ground truth, settings, reference clouds, truth/ tracks, sim.yaml.
void FinishLayout(const ResolvedSimulation& r, const Scene& scene, const BodyMotion& motion,
                  const FrameClock& clock, std::int64_t end_ns, Writers* w,
                  const SurfaceVisibility* visibility, const SurfaceVisibility* observed,
                  const LandmarkTracks* landmark_tracks, SimulationSummary* summary) {
  const SimulationOptions& o = r.o;
  if (w->tum) {
    // Ground truth of the colour camera at 100 Hz (TUM's motion-capture rate).
    for (std::int64_t t = clock.first; t <= end_ns; t += 10'000'000) {
      w->tum->WriteGroundTruth(t, motion.WorldFromBody(t) * r.cameras[0].body_from_camera);
    }
    w->tum->Close();
    WriteSettings(o.output_dir / "settings.yaml", r.draw.written_cameras, o);
    summary->layout = "tum_rgbd";
  } else {
    w->euroc->Close();
    WriteSettings(o.output_dir / "settings.yaml", r.draw.written_cameras, o);
    summary->layout = "euroc";
  }
  if (o.write_cloud) WriteReferenceClouds(scene, visibility, observed, o, summary);
  if (landmark_tracks) landmark_tracks->Write(o.output_dir / "truth");
  WriteSimYaml(o.output_dir / "sim.yaml", o, *summary);
}

}  // namespace

SimulationSummary RunSimulation(const SimulationOptions& options) {
  options.Check();
  ResolvedSimulation r = Resolve(options);
  const SimulationOptions& o = r.o;
  const std::vector<CameraRig>& cameras = r.cameras;

  SimulationSummary summary;
  const Flight flight = MakeFlight(&r);
  summary.begin_ns = flight.begin_ns;
  summary.end_ns = flight.end_ns;
  MotionStatistics(flight.traj, flight.begin_ns, flight.end_ns, o.imu.period_ns(), &summary);
  const BodyMotion motion = MakeBodyMotion(flight, o);
  const Scene scene = SceneAroundFlight(r, flight, &summary);

  // IMU and ground truth (EuRoC layout only).
  Writers writers = OpenWriters(r);
  EurocWriter* euroc = writers.euroc.get();
  if (!o.rgbd && !o.reference_only) {
    const std::vector<ImuSample> imu =
        SimulateImu(motion, flight.begin_ns, flight.end_ns, o.imu, o.seed);
    summary.imu_samples = static_cast<int>(imu.size());
    if (euroc) WriteImuAndGroundTruth(motion, imu, o, euroc);
  }

  // Camera frames.
  const FrameClock clock = MakeFrameClock(o, flight);
  const int frames = clock.frames;
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
  FrameFormer former(r, scene, motion, flight.begin_ns, frames, {visibility.get(), observed.get()});
  const PixelNoise depth_noise;
  const bool write_truth = euroc && o.realism.preset != RealismPreset::kIdeal;
  Progress progress(o.bench ? "bench" : "simulate", static_cast<std::size_t>(frames), o.quiet);
  double render_seconds = 0.0;
  double render_cpu = 0.0;
  tbb::task_group png_writers;
  // On an exception below, let running PNG tasks finish before the group goes away.
  struct WaitOnExit {
    tbb::task_group& group;
    ~WaitOnExit() {
      try {
        group.wait();
      } catch (...) {  // the first error is already propagating
      }
    }
  } wait_on_exit{png_writers};
  std::unique_ptr<LandmarkTracks> landmark_tracks;
  if (o.landmark_tracks > 0 && frames > 0 && !o.bench && !o.reference_only) {
    landmark_tracks = std::make_unique<LandmarkTracks>(
        scene, cameras[0].camera, LandmarkTracksOptions{o.landmark_tracks, 8.0, o.seed});
  }
  const auto loop_start = std::chrono::steady_clock::now();
  for (int k = 0; k < frames; ++k) {
    const std::int64_t t = clock.first + k * clock.period;
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t cpu0 = std::clock();
    const RenderedFrame f = former.Form(k, t);
    if (landmark_tracks) {
      // The pose the image shows (mid-exposure), stamped with the image's timestamp.
      landmark_tracks->AddFrame(k, t,
                                motion.WorldFromBody(f.t_exposure) * cameras[0].body_from_camera);
    }
    render_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    render_cpu += static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    // PNG encoding of this frame overlaps the rendering of the next one (a second core's
    // worth of work); list files are written here, in order.
    png_writers.wait();
    if (write_truth) euroc->WriteFrameTime(t, f.t_exposure, f.black ? 0.0 : f.exposure);
    if (euroc) {
      for (std::size_t c = 0; c < cameras.size(); ++c) {
        const std::filesystem::path file = euroc->AddImage(static_cast<int>(c), t);
        png_writers.run(
            [file, image = f.images[c]] { WritePng(file, image, kEurocPngCompression); });
      }
    }
    if (writers.tum) {
      const cv::Mat depth =
          f.black ? cv::Mat::zeros(f.images[0].size(), CV_16U)
                  : KinectDepthImage(former.cam0().depth, KinectDepthModel(), o.depth_noise,
                                     depth_noise, DeriveSeed(o.seed, 0x44455054 + k), 5000.0);
      const auto files = writers.tum->AddFrame(t);
      png_writers.run([files, colour = f.images[0], depth] {
        TumRgbdWriter::WriteImages(files.first, files.second, colour, depth);
      });
    }
    progress.Add();
  }
  png_writers.wait();
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
    summary.mean_exposure_ms = 1e3 * former.exposure_sum() / frames;
    summary.saturated_share = former.saturated_sum() / frames;
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
  FinishLayout(r, scene, motion, clock, flight.end_ns, &writers, visibility.get(), observed.get(),
               landmark_tracks.get(), &summary);
  return summary;
}

}  // namespace pkslam::sim
