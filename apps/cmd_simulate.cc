// `pkslam simulate`: rendered EuRoC-format (or TUM RGB-D) sequences with exact ground truth.
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

#include "apps/cli_errors.h"
#include "apps/commands.h"
#include "core/util/error.h"
#include "sim/scene_description.h"
#include "sim/simulation_request.h"
#include "sim/simulator.h"

namespace pkslam::apps {
namespace {

// The flags; the policy that turns them into options is sim::ResolveSimulation.
struct SimulateArgs {
  sim::SimulationRequest request;
  std::vector<double> blackout;
  std::vector<double> gyro_bias;
  std::vector<double> accel_bias;
  std::string out;
  std::string trajectory;
  bool no_imu_noise = false;
  bool no_cloud = false;
  bool no_images = false;
  bool no_auto_exposure = false;
  bool list_scenes = false;
  bool realism_report = false;
};

Eigen::Vector3d ToVector(const std::vector<double>& v, const char* name) {
  if (v.empty()) return Eigen::Vector3d::Zero();
  if (v.size() != 3) throw OptionError(fmt::format("{} needs x,y,z", name));
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

// The request the flags make (the ones CLI11 does not write into it directly).
void CompleteRequest(SimulateArgs& a, const CLI::App& cmd) {
  sim::SimulationRequest& r = a.request;
  r.options.output_dir = a.out;
  r.options.trajectory = a.trajectory;
  if (!a.blackout.empty()) r.blackout = std::make_pair(a.blackout.at(0), a.blackout.at(1));
  r.gyro_bias = ToVector(a.gyro_bias, "--gyro-bias");
  r.accel_bias = ToVector(a.accel_bias, "--accel-bias");
  r.imu_noise = !a.no_imu_noise;
  r.cloud = !a.no_cloud;
  r.images = !a.no_images;
  r.auto_exposure = !a.no_auto_exposure;
  r.given.read_noise = cmd.count("--noise") > 0;
  r.given.blur = cmd.count("--blur") > 0;
  r.given.vignetting = cmd.count("--vignetting") > 0;
  r.given.gain_drift = cmd.count("--gain-drift") > 0;
  r.given.motion_blur = cmd.count("--motion-blur") > 0;
}

void Run(SimulateArgs& a, const CLI::App& cmd) {
  if (a.list_scenes) {
    for (const auto& name : sim::BuiltinSceneNames()) std::cout << name << '\n';
    return;
  }
  CompleteRequest(a, cmd);
  if (a.realism_report) {
    std::cout << sim::FormatRealismReport(sim::ResolveRealism(sim::RealismOf(a.request)));
    return;
  }
  sim::SimulationOptions o;
  const sim::SimulationSummary s = sim::Simulate(a.request, &o);
  const double duration = 1e-9 * static_cast<double>(s.end_ns - s.begin_ns);
  if (s.layout == "bench") {
    std::cout << fmt::format(
        "bench: {} {} frames ({}x{} x{} camera{}) in {:.2f} s: {:.1f} frames/s wall "
        "(render + image formation, no files); CPU {:.1f} ms/frame = {:.1f} frames/s on 2 "
        "idle cores\n",
        s.frames, o.rgbd ? "RGB-D" : "stereo", s.image_width, s.image_height, o.rgbd ? 1 : 2,
        o.rgbd ? "" : "s", s.render_seconds, s.frames_per_second,
        1e3 * s.render_cpu_seconds / std::max(s.frames, 1),
        2.0 * s.frames / std::max(s.render_cpu_seconds, 1e-9));
    return;
  }
  std::cout << fmt::format(
      "simulate: {} -> {} ({})\n  {} frames, {} IMU samples, {:.3f} s, path {:.3f} m, "
      "mean speed {:.2f} m/s, angular rate mean {:.1f} / max {:.1f} deg/s\n"
      "  scene: {} objects ({} removed near the path), cloud {} points, observed cloud {} "
      "points\n",
      o.trajectory.empty() ? "random " + a.request.motion : o.trajectory.string(),
      o.output_dir.string(), s.layout, s.frames, s.imu_samples, duration, s.path_length_m,
      s.mean_speed_mps, s.mean_angular_rate_dps, s.max_angular_rate_dps,
      s.scene.objects_placed - s.scene.objects_removed, s.scene.objects_removed, s.cloud_points,
      s.observed_points);
  std::cout << fmt::format("  realism {}: ", sim::RealismPresetName(o.realism.preset));
  for (sim::RealismSource source : sim::kRealismSources) {
    std::cout << fmt::format("{} {} ", sim::RealismSourceName(source),
                             o.realism.On(source) ? "on" : "off");
  }
  std::cout << fmt::format("(scene {}; mean exposure {:.2f} ms, saturated {:.1f}%)\n", o.scene,
                           s.mean_exposure_ms, 100.0 * s.saturated_share);
  if (s.frames > 0 && s.total_seconds > 0.0) {
    std::cout << fmt::format(
        "  {:.1f} frames/s end to end (rendering, image formation and PNG files)\n",
        s.frames / s.total_seconds);
  }
  if (o.camera == "tumvi" && sim::WritesStereoSequence(o)) {
    std::cout << fmt::format(
        "  TUM-VI files: {}/dso/camchain.yaml, imu_config.yaml, "
        "mav0/mocap0/data.csv\n",
        o.output_dir.string());
  }
  if (o.camera == "kitti" && sim::WritesStereoSequence(o)) {
    const std::filesystem::path kitti = o.output_dir / "kitti";
    std::cout << fmt::format("  KITTI layout: {}/sequences/00 (poses: {}/poses/00.txt)\n",
                             kitti.string(), kitti.string());
  }
}

}  // namespace

void RegisterSimulateCommand(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  sim::SimulationRequest& request = args->request;
  sim::SimulationOptions& o = request.options;
  auto* cmd = app.add_subcommand(
      "simulate",
      "Render a EuRoC-format stereo+IMU (or TUM RGB-D) sequence with exact ground truth");
  cmd->add_option("--out", args->out, "Output directory (created)");
  // The default scene is chosen from --realism (sim::ResolveSimulation): no default here.
  o.scene.clear();
  auto* traj = cmd->add_option("--trajectory", args->trajectory,
                               "Replay this ground truth (TUM txt or EuRoC csv)")
                   ->check(CLI::ExistingFile);
  cmd->add_option("--motion", request.motion, "Random motion level: easy|medium|difficult")
      ->capture_default_str()
      ->excludes(traj);
  cmd->add_option("--duration", o.duration_s,
                  "Seconds to simulate (0: replay to the end / 60 s of random motion)")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();
  cmd->add_option("--start", o.start_s, "Replay: start this many seconds into the file")
      ->capture_default_str();
  cmd->add_option("--scene", o.scene,
                  "Built-in scene (see --list-scenes) or YAML file (default: by --realism: "
                  "euroc_vicon_room / euroc_machine_hall for MH_* replays; vicon_room / "
                  "machine_hall with --realism ideal)");
  cmd->add_option("--realism", request.realism.preset,
                  "ideal|euroc: error sources of real EuRoC recordings (appearance, calibration, "
                  "timing, imu, motion, ground-truth); default euroc for replays of ground truth "
                  "(--trajectory), ideal otherwise (docs/realism.md)");
  cmd->add_option("--realism-off", request.realism.off,
                  "Switch these sources of the euroc preset off (ablation), e.g. "
                  "calibration,timing")
      ->delimiter(',');
  cmd->add_option("--realism-param", request.realism.params,
                  "Override a size: NAME=VALUE (names in --realism-report), repeatable");
  cmd->add_option("--device-seed", request.realism.device_seed,
                  "Seed of the device errors (calibration, IMU axes): one rig for all sequences")
      ->capture_default_str();
  cmd->add_flag("--realism-report", args->realism_report,
                "Print every error source of the chosen --realism with its size and documented "
                "source, then exit");
  cmd->add_option("--texture", o.texture_mode, "rich|weak|repetitive (default: the scene's)");
  cmd->add_option("--seed", o.seed, "Random seed (same seed -> identical bytes)")
      ->capture_default_str();
  cmd->add_flag("--rgbd", o.rgbd, "TUM RGB-D output (colour + depth) instead of EuRoC stereo");
  cmd->add_option(
         "--camera", o.camera,
         "Stereo rig of EuRoC-format output: euroc (752x480, 20 Hz), kitti (KITTI "
         "odometry's 1241x376 pair, 0.537 m baseline, 10 Hz, settings.yaml with 2000 "
         "ORB features; also written in KITTI's layout under OUT/kitti), vga (640x480, 20 Hz, "
         "1000 features), tumvi (TUM-VI's 512x512 fisheye pair, 20 Hz, TUM-VI's IMU "
         "noise; also its dso/camchain.yaml and mocap0); run with --settings DATASET/settings.yaml "
         "to use its feature "
         "count")
      ->check(OneOf({"euroc", "kitti", "vga", "tumvi"}))
      ->capture_default_str();
  cmd->add_option("--blackout", args->blackout, "Black images between T0 and T1 (s from start)")
      ->expected(2);
  cmd->add_option("--noise", o.sensor.read_noise_dn, "Image read noise sigma (8-bit levels)")
      ->capture_default_str();
  cmd->add_option("--blur", o.sensor.blur_sigma_px, "Optical blur sigma (pixels)")
      ->capture_default_str();
  cmd->add_option("--motion-blur", o.motion_blur_exposure_s,
                  "Exposure time (s) for motion blur; 0 = off")
      ->capture_default_str();
  cmd->add_option("--gain-drift", o.sensor.gain_drift,
                  "Random exposure/gain drift (relative sigma per sqrt(s))")
      ->capture_default_str();
  cmd->add_flag("--no-auto-exposure", args->no_auto_exposure,
                "Fixed gain instead of auto exposure");
  cmd->add_option("--vignetting", o.sensor.vignetting, "Brightness loss at 45 deg off-axis")
      ->capture_default_str();
  cmd->add_flag("--vibration", o.imu.vibration, "Add rotor vibration (35-90 Hz) to the IMU");
  cmd->add_flag("--no-imu-noise", args->no_imu_noise, "Exact IMU (no noise, constant biases)");
  cmd->add_option("--gyro-bias", args->gyro_bias, "Initial gyro bias x,y,z (rad/s)")
      ->delimiter(',')
      ->expected(3);
  cmd->add_option("--accel-bias", args->accel_bias, "Initial accelerometer bias x,y,z (m/s^2)")
      ->delimiter(',')
      ->expected(3);
  cmd->add_option("--clearance", o.scene_build.clearance_m,
                  "Objects closer than this to the camera path are removed (m)")
      ->capture_default_str();
  cmd->add_option("--quality", request.quality, "fast|default|high")->capture_default_str();
  cmd->add_flag("--no-cloud", args->no_cloud, "Do not write reference_cloud.ply");
  cmd->add_option("--tracks", o.landmark_tracks,
                  "Also write the exact 2-D tracks of this many surface landmarks in cam0 "
                  "(truth/tracks_*.txt, for `pkslam tracks export --simulated`; 0: none)")
      ->capture_default_str();
  cmd->add_flag("--no-images", args->no_images, "IMU and ground truth only (no rendering)");
  cmd->add_option("--cloud-spacing", o.cloud_spacing_m, "Reference cloud point spacing (m)")
      ->capture_default_str();
  cmd->add_option("--observed-range", o.observed_range_m,
                  "reference_observed.ply: the surfaces cam0 saw within this depth (m) in any "
                  "frame (0: not written)")
      ->capture_default_str();
  cmd->add_option("--observed-cell", o.observed_cell_m,
                  "Granularity of the observed surface cells (m)")
      ->capture_default_str();
  cmd->add_flag("--reference-only", o.reference_only,
                "Only render cam0 and write the two reference clouds (same options as an "
                "earlier run add them to it; write into another folder)");
  cmd->add_flag("--bench", o.bench, "Only render (no files) and report frames/s");
  cmd->add_option("--bench-frames", o.bench_frames, "Frames rendered by --bench (0: all)")
      ->capture_default_str();
  cmd->add_flag("--quiet", o.quiet, "No progress bar");
  cmd->add_flag("--list-scenes", args->list_scenes, "Print the built-in scene names");
  cmd->callback([args, cmd] { Run(*args, *cmd); });
}

}  // namespace pkslam::apps
