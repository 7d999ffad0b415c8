// pkslam run: SLAM over a EuRoC or TUM RGB-D dataset.
#include <fmt/format.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>

#include "apps/calibration_flags.h"
#include "apps/cli_errors.h"
#include "apps/commands.h"
#include "apps/live_view.h"
#include "core/util/error.h"
#include "system/run_bag.h"
#include "system/run_dataset.h"
#include "system/run_source.h"

namespace pkslam::apps {
namespace {

// SIGINT/SIGTERM: the first stops the run at the next frame (the loop polls `interrupted`)
// and it writes its outputs, the trajectory first. A second one ends the process as soon as
// trajectory.txt is complete (at most a frame and the write later: a double Ctrl-C 10 ms apart
// left only run.log), a third at once. Signal handlers can only reach process-wide state,
// hence these atomics.
std::atomic<bool> interrupted{false};
std::atomic<int> interrupt_signal{0};
std::atomic<int> signals_received{0};

void OnSignal(int signal) {
  const int n = signals_received.fetch_add(1) + 1;
  if (n == 1) {
    interrupt_signal.store(signal);
    interrupted.store(true);
  } else if (n >= 3) {
    std::signal(signal, SIG_DFL);
    std::raise(signal);
  }
}

// From the moment trajectory.txt is complete a signal takes its default action; one that came
// while it was written takes it now.
void OnTrajectoryWritten() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  if (signals_received.load() >= 2) std::raise(interrupt_signal.load());
}

struct RunArgs {
  RunOptions options;
  std::optional<std::string> sensor;  // default: stereo for --dataset, mono otherwise
  std::string settings;
  std::string vocabulary;
  std::string out = "out";
  std::vector<std::string> params;
  bool strict = false;
  std::string video;
  std::optional<double> fps;
  std::optional<int> camera;
  std::string images;
  std::string timestamps;
  std::string bag;                    // --bag FILE (system/run_bag.h)
  std::string topics;                 // --topics for --bag
  std::optional<int> live_view_port;  // --live-view [PORT]
  std::string live_view_host = "127.0.0.1";
};

std::map<std::string, double> ParseParams(const std::vector<std::string>& params) {
  std::map<std::string, double> out;
  for (const auto& p : params) {
    const auto eq = p.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw OptionError(fmt::format("--param '{}': expected NAME=VALUE", p));
    }
    const std::string value = p.substr(eq + 1);
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(value, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != value.size() || value.empty()) {
      throw OptionError(fmt::format("--param '{}': '{}' is not a number", p, value));
    }
    std::string name = p.substr(0, eq);
    if (name.rfind("Keyframe.", 0) == 0) name = name.substr(9);
    out[name] = v;
  }
  return out;
}

// Exactly one input, and the options that go with it.
void CheckOneInput(const RunArgs& args, const RunOptions& o) {
  const int inputs = (o.dataset.empty() ? 0 : 1) + (args.video.empty() ? 0 : 1) +
                     (args.camera ? 1 : 0) + (args.images.empty() ? 0 : 1) +
                     (args.bag.empty() ? 0 : 1);
  if (inputs != 1) {
    throw OptionError("give exactly one input: --dataset, --bag, --video, --camera or --images");
  }
  if (!args.topics.empty() && args.bag.empty()) throw OptionError("--topics goes with --bag");
  if (args.fps && args.video.empty()) throw OptionError("--fps goes with --video");
  if (args.images.empty() != args.timestamps.empty()) {
    throw OptionError("--images and --timestamps go together");
  }
}

// The run in two lines, where its outputs are, and what to look at.
void PrintSummary(const RunSummary& s, const RunOptions& o) {
  fmt::print("frames {} tracked {} lost {} keyframes {} map points {} maps {}\n", s.frames,
             s.tracked, s.lost, s.keyframes, s.map_points, s.maps);
  fmt::print("wall {:.2f} s for {:.2f} s of data ({:.2f}x real time), median tracking {:.2f} ms\n",
             s.wall_s, s.sequence_s, s.wall_s > 0 ? s.sequence_s / s.wall_s : 0.0,
             s.median_tracking_ms);
  // trajectory_body.txt (body = IMU frame, what EuRoC ground truth describes) is written for
  // every metric run (system/run_outputs.cc); a visual monocular map has no metric lever arm.
  fmt::print(
      "outputs: {}/{{trajectory.txt, {}keyframes.txt, map_points.ply, stats.json, "
      "run.log}} (docs/run.md lists all)\n",
      o.out.string(), o.system.sensor == Sensor::kMonocular ? "" : "trajectory_body.txt, ");
  if (s.input.degraded()) {
    fmt::print("degraded input: {} warning(s), see {}/stats.json \"input\"\n",
               s.input.warnings.size(), o.out.string());
  }
  if (!s.estimate.warnings.empty()) {
    fmt::print("suspect estimate: {}; see {}/stats.json \"estimate\"\n",
               s.estimate.warnings.front(), o.out.string());
  }
}

// A run that did not end well exits non-zero (docs/run.md lists the codes).
void ThrowExitStatus(const RunSummary& s, const RunArgs& args) {
  if (s.interrupted) {
    const int signal = interrupt_signal.load();
    throw CommandExit{128 + signal,
                      fmt::format("interrupted by {} after {} frames (outputs "
                                  "written for them)",
                                  signal == SIGTERM ? "SIGTERM" : "SIGINT", s.frames)};
  }
  if (!s.estimate.no_estimate.empty()) {
    throw CommandExit{kExitNoEstimate,
                      fmt::format("error: no estimate: {}; see {}/stats.json \"estimate\"",
                                  s.estimate.no_estimate, args.options.out.string())};
  }
  if (args.strict && s.input.degraded()) {
    throw CommandExit{kExitDegraded, "--strict: the run finished on degraded input"};
  }
  if (args.strict && s.estimate.suspect()) {
    throw CommandExit{kExitSuspect, "--strict: the run's estimate is suspect"};
  }
}

// `pkslam run` once its flags are read.
void Run(RunArgs& args) {
  RunOptions& o = args.options;
  // --sensor was checked against SensorNames(), which ParseSensor reads back.
  o.system.sensor =
      *ParseSensor(args.sensor.value_or(o.dataset.empty() && args.bag.empty() ? "mono" : "stereo"));
  if (!args.settings.empty()) o.settings = args.settings;
  if (!args.vocabulary.empty()) o.vocabulary = args.vocabulary;
  o.out = args.out;
  o.system.selector_parameters = ParseParams(args.params);
  RunControl control;
  control.interrupt = &interrupted;
  // Until the first frame a signal takes its default action: reading a dataset polls no flag
  // (and OpenCV's parser has been seen to loop on a bad file).
  control.frames_starting = [] {
    std::signal(SIGINT, OnSignal);
    std::signal(SIGTERM, OnSignal);
  };
  control.trajectory_written = OnTrajectoryWritten;
  CheckOneInput(args, o);
  std::unique_ptr<LiveView> live;
  if (args.live_view_port) {
    LiveViewOptions live_options;
    live_options.port = *args.live_view_port;
    live_options.host = args.live_view_host;
    live = std::make_unique<LiveView>(live_options);
    fmt::print("live view: {}\n", live->url());
    std::fflush(stdout);
    control.frame_tracked = [&live](const SlamSystem& system, const TrackResult& r,
                                    const cv::Mat& image,
                                    std::int64_t t_ns) { live->OnFrame(system, r, image, t_ns); };
    control.tracking_finished = [&live] { live->Finish(nullptr); };
  }
  std::unique_ptr<FrameSource> source;
  if (!args.video.empty()) source = OpenVideoFile(args.video, args.fps);
  if (args.camera) source = OpenCamera(*args.camera);
  if (!args.images.empty()) source = OpenImageFolder(args.images, args.timestamps);
  const RunSummary s = source ? RunFrameSource(o, *source, control)
                       : !args.bag.empty()
                           ? RunBag(o, args.bag, ParseBagTopics(args.topics), control)
                           : RunDataset(o, control);
  PrintSummary(s, o);
  ThrowExitStatus(s, args);
}

// What to run on: a dataset, bag, video, camera or image folder, and its settings.
void AddInputOptions(CLI::App* cmd, const std::shared_ptr<RunArgs>& args) {
  cmd->add_option("--dataset", args->options.dataset,
                  "Dataset directory (EuRoC ASL, TUM RGB-D, or a KITTI sequences/NN folder)");
  cmd->add_option("--video", args->video,
                  "Monocular: a video file (OpenCV VideoCapture), with --settings CAM.yaml; "
                  "timestamps from the container or --fps");
  cmd->add_option("--fps", args->fps,
                  "--video: stamp frame k at k / FPS s instead of the "
                  "container's timestamps");
  cmd->add_option("--camera", args->camera,
                  "Monocular: live camera N (e.g. 0 for /dev/video0), "
                  "with --settings; Ctrl-C stops");
  cmd->add_option("--images", args->images,
                  "Monocular: a folder of images, with --timestamps and --settings");
  cmd->add_option("--timestamps", args->timestamps,
                  "--images: one frame per line, 't_ns' (DIR/t_ns.png) or 't name' (t in s "
                  "with a decimal point, else ns)");
  cmd->add_option("--bag", args->bag,
                  "A ROS 1 bag (EuRoC, TUM-VI), with --settings: the run of the EuRoC folder "
                  "`pkslam convert --bag` makes (docs/bags.md)");
  cmd->add_option("--topics", args->topics,
                  "--bag: topics of the streams, e.g. cam0=/cam0/image_raw,cam1=/cam1/image_raw,"
                  "imu=/imu0 (the defaults)");
  cmd->add_option("--sensor", args->sensor,
                  "Sensor configuration (default: stereo for --dataset and --bag, mono for "
                  "--video, --camera and --images)")
      ->check(OneOf(SensorNames()));
  cmd->add_option("--settings", args->settings,
                  "ORB-SLAM3 v1.0 settings file (EuRoC: default from the sensor.yaml files)");
  cmd->add_option("--vocabulary", args->vocabulary, "ORB vocabulary (DBoW2 .txt or pkslam .bin)");
}

// The system: outputs folder, selector, seeds, loop closing, online calibration.
void AddSystemOptions(CLI::App* cmd, const std::shared_ptr<RunArgs>& args) {
  cmd->add_option("--out", args->out, "Output directory")->capture_default_str();
  cmd->add_option("--selector", args->options.system.selector, "Keyframe selector")
      ->capture_default_str();
  cmd->add_option("--param", args->params,
                  "Selector parameter NAME=VALUE (overrides the settings' Keyframe.NAME)");
  cmd->add_flag("--deterministic", args->options.system.deterministic,
                "Fixed seeds; local mapping in lock-step: identical output run to run");
  cmd->add_option("--seed", args->options.system.seed,
                  "Run seed for RANSAC sampling (benchmarks: one per repeated run)")
      ->capture_default_str();
  cmd->add_flag("--no-loop", args->options.system.no_loop,
                "Disable loop closing and map merging (for experiments)");
  cmd->add_flag_function(
      "--no-gravity-refinement",
      [args](std::int64_t) { args->options.system.mapping.inertial.gravity_refinement = false; },
      "Inertial sensors: keep gravity fixed after the 15 s visual-inertial BA, as ORB-SLAM3 "
      "(for experiments)");
  using Search = TrackingOptions::InertialSearch;
  const std::string last_frame = TrackingOptions::InertialSearchName(Search::kLastFrame);
  const std::string orbslam3 = TrackingOptions::InertialSearchName(Search::kOrbSlam3);
  cmd->add_option_function<std::string>(
         "--inertial-search",
         [args, orbslam3](const std::string& mode) {
           args->options.system.tracking.inertial_search =
               mode == orbslam3 ? Search::kOrbSlam3 : Search::kLastFrame;
         },
         "Inertial sensors, how a tracked frame finds its matches: last-frame (match the "
         "IMU-predicted frame against the last frame, then the local map narrowly) | orbslam3 "
         "(ORB-SLAM3's: the prediction alone, then the local map searched wider; for studies of "
         "keyframe rules, docs/pks_study.md)")
      ->check(OneOf({last_frame, orbslam3}))
      ->default_str(last_frame);
  cmd->add_option_function<std::string>(
         "--calibrate",
         [args](const std::string& mode) {
           args->options.system.mapping.calibration.enabled = mode == "online";
         },
         "online: estimate the rig's calibration while mapping (intrinsics, stereo and "
         "camera-IMU extrinsics, time offset, gyro scale factors; docs/calibration.md) | off: take the settings' "
         "calibration as exact")
      ->check(OneOf({"online", "off"}))
      ->default_str("off");
  AddCalibrationFreedomFlags(cmd, &args->options.system.mapping.calibration, "--calibrate online");
  cmd->add_option("--calibrate-thread", args->options.system.calibration_thread,
                  "--calibrate online: where each adjustment solves: thread (beside local "
                  "mapping, which goes on meanwhile), step (inside local mapping's keyframe step, "
                  "holding it), auto (thread, paced by the live emulation in offline runs so "
                  "they repeat; step in lock-step runs such as --deterministic)")
      ->check(OneOf({"auto", "thread", "step"}))
      ->default_str("auto");
}

// How tracking meets local mapping in time.
void AddPacingOptions(CLI::App* cmd, const std::shared_ptr<RunArgs>& args) {
  cmd->add_flag("--realtime", args->options.realtime, "Pace frames to their timestamps");
  cmd->add_flag(
      "--kitti-colour", args->options.kitti_colour,
      "KITTI sequences: track the colour pair (image_2, image_3) instead of the grey one");
  cmd->add_option("--mapping-sync", args->options.mapping_sync,
                  "How tracking meets local mapping: live (offline default: local mapping as a "
                  "live run at --live-pace would see it, without sleeping), lockstep (each "
                  "keyframe mapped before the next frame; --deterministic), free (no coupling; "
                  "--realtime default)")
      ->check(OneOf({"live", "lockstep", "free"}));
  cmd->add_option("--live-pace", args->options.system.live_pace,
                  "--mapping-sync live: playback speed of the emulated live run (2: as if frames "
                  "came twice as fast as their timestamps)")
      ->capture_default_str();
  cmd->add_option("--live-clock", args->options.system.live_clock,
                  "--mapping-sync live: measure local mapping's work in units of work priced "
                  "at a reference machine's speed (work: the same result on every machine), in "
                  "its thread's CPU time (cpu: this machine, however loaded) or in wall time "
                  "(wall: this machine under its present load)")
      ->check(OneOf({"work", "cpu", "wall"}))
      ->capture_default_str();
}

// Slices, map files, localisation, extra outputs, the live view and input checks.
void AddSessionOptions(CLI::App* cmd, const std::shared_ptr<RunArgs>& args) {
  cmd->add_option("--max-frames", args->options.max_frames, "Stop after N frames (0: all)");
  cmd->add_option("--first-frame", args->options.first_frame,
                  "Skip the dataset's first N frames (run on a slice)")
      ->capture_default_str();
  cmd->add_option("--load-map", args->options.load_map,
                  "Start from a map file (--save-map of an earlier run with the same camera and "
                  "vocabulary); the new session's map merges into it when recognised");
  cmd->add_option("--save-map", args->options.save_map,
                  "Write the final Atlas to a map file (also after Ctrl-C)");
  cmd->add_flag("--localise-only", args->options.system.tracking.localise_only,
                "With --load-map: track in the loaded map only, no keyframes or points; lost "
                "frames relocalise");
  cmd->add_flag("--trace", args->options.system.trace, "Write OUT/keyframe_trace.csv");
  cmd->add_flag("--frame-tracks", args->options.system.frame_tracks,
                "Write OUT/frame_tracks.txt: every tracked frame's matched map points as 2-D "
                "tracks (for `pkslam tracks reconstruct`)");
  cmd->add_option("--live-view", args->live_view_port,
                  "Serve a live 3-D view of the run at http://127.0.0.1:PORT/ (default port "
                  "8765): the path so far, keyframes, map points, the current image with its "
                  "tracked keypoints")
      ->expected(0, 1)
      ->default_str("8765");
  cmd->add_option("--live-view-host", args->live_view_host,
                  "Address the live view listens on (0.0.0.0: reachable from other machines)")
      ->capture_default_str();
  cmd->add_flag("--quiet", args->options.quiet, "No progress line");
  cmd->add_flag("--allow-imu-gaps", args->options.allow_imu_gaps,
                "Inertial sensors: run although some frames have no IMU samples (tracked "
                "without IMU; the run is flagged degraded)");
  cmd->add_option("--imu-max-gyro", args->options.imu_limits.max_gyro_rad_s,
                  "IMU plausibility: a gyro sample beyond this (rad/s) is an error")
      ->capture_default_str();
  cmd->add_option("--imu-max-accel", args->options.imu_limits.max_accel_m_s2,
                  "IMU plausibility: an accelerometer sample beyond this (m/s^2) is an error")
      ->capture_default_str();
  cmd->add_flag("--strict", args->strict,
                "Exit 3 when the run finished on degraded input (skipped frames, timestamp "
                "jumps, frames without IMU or depth; see stats.json \"input\"), 4 when its "
                "estimate is suspect (tracking lost for good, maps stitched or left apart; "
                "see stats.json \"estimate\")");
}

}  // namespace

void RegisterRunCommand(CLI::App& app) {
  auto args = std::make_shared<RunArgs>();
  auto* cmd = app.add_subcommand("run",
                                 "Run SLAM over a EuRoC, TUM RGB-D or KITTI odometry dataset, a "
                                 "video, a camera or an image folder");
  AddInputOptions(cmd, args);
  AddSystemOptions(cmd, args);
  AddPacingOptions(cmd, args);
  AddSessionOptions(cmd, args);
  cmd->callback([args] { Run(*args); });
}

}  // namespace pkslam::apps
