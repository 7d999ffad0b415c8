#include "system/run_dataset.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <future>
#include <thread>

#include "core/camera/stereo_rectification.h"
#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "core/util/log.h"
#include "core/util/output_file.h"
#include "core/util/prefetch.h"
#include "core/util/progress.h"
#include "io/dataset_fingerprint.h"
#include "io/euroc_dataset.h"
#include "io/kitti_dataset.h"
#include "io/rigid_transform_file.h"
#include "io/settings_euroc.h"
#include "io/trajectory.h"
#include "io/tum_rgbd_dataset.h"
#include "system/rig_factory.h"
#include "system/run_outputs.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

// One input frame, however the dataset stores it.
struct DatasetFrame {
  std::int64_t t_ns;
  std::size_t a;  // left / rgb index
  std::size_t b;  // right / depth index
};

}  // namespace

void RunOptions::Check() const {
  if (dataset.empty()) throw OptionError("--dataset is required");
  if (max_frames < 0) throw OptionError(fmt::format("--max-frames {} < 0", max_frames));
  if (first_frame < 0) throw OptionError(fmt::format("--first-frame {} < 0", first_frame));
  if (system.tracking.localise_only && !load_map) {
    throw OptionError("--localise-only needs --load-map (a map to localise in)");
  }
  imu_limits.Check();
  system.Check();
}

fs::path DefaultVocabularyPath() {
  const fs::path name = "Vocabulary/pkslam_orb_k10_L6.bin";
  // Next to the executable's build tree first (build/bin/pkslam -> source/Vocabulary), or an
  // installed prefix (PREFIX/bin/pkslam -> PREFIX/share/pkslam), then the source tree this
  // binary was built from.
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (fs::path dir = exe.parent_path(); !dir.empty() && dir != dir.root_path();
         dir = dir.parent_path()) {
      if (fs::exists(dir / name)) return dir / name;
      const fs::path installed = dir / "share/pkslam" / name.filename();
      if (fs::exists(installed)) return installed;
    }
  }
  return fs::path(PKSLAM_SOURCE_DIR) / name;
}

void RunSummary::Count(const TrackResult& result) {
  ++frames;
  if (result.state == TrackingState::kOk) ++tracked;
  if (result.new_keyframe) {
    ++keyframe_reasons[result.keyframe_reason.empty() ? "unnamed" : result.keyframe_reason];
  }
  if (result.keyframe_declined_queue_full) ++keyframes_declined_queue_full;
  if (result.selector_decided) ++selector_decisions;
  for (const auto& criterion : result.criteria_held) ++criteria_held[criterion];
}

void SleepUntilOrInterrupted(std::chrono::steady_clock::time_point due,
                             const std::atomic<bool>* interrupt) {
  while ((interrupt == nullptr || !interrupt->load()) && std::chrono::steady_clock::now() < due) {
    std::this_thread::sleep_until(
        std::min(due, std::chrono::steady_clock::now() + std::chrono::milliseconds(50)));
  }
}

std::shared_ptr<const Vocabulary> LoadRunVocabulary(const RunOptions& options) {
  const fs::path vocabulary_path = options.vocabulary.value_or(DefaultVocabularyPath());
  if (!fs::exists(vocabulary_path)) {
    throw InputError(vocabulary_path, "vocabulary not found (pass --vocabulary)");
  }
  if (!fs::is_regular_file(vocabulary_path)) {
    // A directory read as a file failed with "basic_filebuf::underflow error".
    throw InputError(vocabulary_path, "vocabulary is not a file (pass the .bin or .txt file)");
  }
  PKSLAM_LOG_INFO("loading vocabulary {}", vocabulary_path.string());
  return std::make_shared<const Vocabulary>(Vocabulary::Load(vocabulary_path));
}

RunSummary RunDataset(const RunOptions& options, const RunControl& control) {
  const std::atomic<bool>* interrupt = control.interrupt;
  options.Check();
  const Sensor sensor = options.system.sensor;
  if (!fs::is_directory(options.dataset)) {
    throw InputError(options.dataset, "dataset directory does not exist");
  }
  fs::create_directories(options.out);
  RemoveRunOutputs(options.out);
  AddLogFile(options.out / "run.log");
  struct LogGuard {
    ~LogGuard() { RemoveLogFiles(); }
  } log_guard;

  RunSummary summary;
  InputReport& report = summary.input;
  // --- dataset and settings ---
  std::optional<EurocDataset> euroc;
  std::optional<TumRgbdDataset> tum;
  std::vector<DatasetFrame> sources;
  Settings settings;
  // A KITTI sequence runs as an EuRoC dataset of its two image streams (no IMU, no sensor
  // files), with the settings calib.txt gives unless --settings names a file.
  std::optional<KittiSequence> kitti;
  if (LooksLikeKitti(options.dataset)) {
    KittiOptions ko;
    ko.colour = options.kitti_colour;
    kitti = OpenKittiSequence(options.dataset, ko);
  }
  if (kitti || EurocDataset::LooksLikeEuroc(options.dataset)) {
    EurocOptions eo;
    // The IMU sensor carries the body frame (EuRoC ground truth) even for visual-only runs.
    eo.read_imu = true;
    eo.imu_limits = options.imu_limits;
    euroc = kitti ? EurocDataset::FromImageStreams(options.dataset, kitti->left, kitti->right)
                  : EurocDataset::Open(options.dataset, eo);
    if (kitti && IsInertial(sensor)) {
      throw OptionError("a KITTI odometry sequence has no IMU: use stereo or mono");
    }
    if (IsRgbd(sensor)) throw OptionError("an EuRoC dataset has no depth: use stereo or mono");
    if (IsInertial(sensor) && !euroc->has_imu()) {
      throw InputError(euroc->mav0() / "imu0", fmt::format("sensor {} needs IMU data (imu0/ "
                                                           "with sensor.yaml and data.csv): "
                                                           "missing",
                                                           SensorName(sensor)));
    }
    if (IsStereo(sensor)) {
      if (!euroc->has_cam1()) {
        throw InputError(euroc->mav0() / "cam1",
                         fmt::format("sensor {} needs cam1 (missing)", SensorName(sensor)));
      }
      for (const auto& p : euroc->stereo_pairs()) sources.push_back({p.t_ns, p.left, p.right});
      // cam1 with fewer rows dropped frames with an info-level note only.
      const std::size_t listed = std::max(euroc->cam0().images.size(), euroc->cam1().images.size());
      report.frames_skipped = static_cast<int>(listed - sources.size());
      if (report.frames_skipped > 0) {
        report.Warn(fmt::format(
            "{}: {} of {} frames skipped: cam0 has {} images, cam1 {}, {} with the same "
            "timestamp in both",
            euroc->mav0().string(), report.frames_skipped, listed, euroc->cam0().images.size(),
            euroc->cam1().images.size(), sources.size()));
      }
    } else {
      const auto& images = euroc->cam0().images;
      for (std::size_t i = 0; i < images.size(); ++i) sources.push_back({images[i].t_ns, i, 0});
    }
    settings = options.settings ? ReadOrbSlam3Settings(*options.settings)
               : kitti          ? SettingsFromKitti(*kitti)
                                : SettingsFromEuroc(*euroc);
    if (IsStereo(sensor) && settings.camera2 && settings.right_from_left) {
      // Checked here, where the calibration's file is known, to name it.
      try {
        StereoRectification::Check(settings.camera1, *settings.camera2, *settings.right_from_left);
      } catch (const OptionError& e) {
        throw InputError(options.settings.value_or(euroc->mav0() / "cam1" / "sensor.yaml"),
                         e.what());
      }
    }
  } else if (TumRgbdDataset::LooksLikeTumRgbd(options.dataset)) {
    tum = TumRgbdDataset::Open(options.dataset);
    if (IsStereo(sensor)) throw OptionError("a TUM RGB-D dataset has no stereo pair");
    if (IsRgbd(sensor)) {
      for (const auto& a : tum->associations()) {
        sources.push_back({tum->rgb().images[a.rgb].t_ns, a.rgb, a.depth});
      }
      tum->RequireValidDepth();
      report.frames_skipped = static_cast<int>(tum->rgb().images.size() - sources.size());
      if (report.frames_skipped > 0) {
        report.Warn(
            fmt::format("{}: {} of {} rgb frames skipped: no depth image within the "
                        "association window",
                        options.dataset.string(), report.frames_skipped, tum->rgb().images.size()));
      }
    } else {
      const auto& images = tum->rgb().images;
      for (std::size_t i = 0; i < images.size(); ++i) sources.push_back({images[i].t_ns, i, 0});
    }
    const fs::path fallback = options.dataset / "settings.yaml";
    if (!options.settings && !fs::exists(fallback)) {
      throw InputError(options.dataset,
                       "TUM RGB-D layout needs --settings (or settings.yaml in the dataset)");
    }
    settings = ReadOrbSlam3Settings(options.settings.value_or(fallback));
    if (!settings.depth_map_factor) settings.depth_map_factor = tum->depth_factor();
    if (IsRgbd(sensor)) {
      tum->CheckDepthScale(
          *settings.depth_map_factor,
          "RGBD.DepthMapFactor of " + options.settings.value_or(fallback).string());
    }
  } else {
    throw InputError(options.dataset,
                     "not a EuRoC (mav0/cam0/data.csv) or TUM RGB-D (rgb.txt, depth.txt) dataset");
  }
  if (sources.empty()) throw InputError(options.dataset, "no frames to process");
  summary.dataset_fingerprint = DatasetFingerprint(euroc ? euroc->cam0() : tum->rgb());
  if (options.first_frame > 0) {
    if (options.first_frame >= static_cast<int>(sources.size())) {
      throw InputError(options.dataset, fmt::format("--first-frame {}: the dataset has {} frames",
                                                    options.first_frame, sources.size()));
    }
    sources.erase(sources.begin(), sources.begin() + options.first_frame);
  }
  if (options.max_frames > 0 && static_cast<int>(sources.size()) > options.max_frames) {
    sources.resize(options.max_frames);
  }
  std::vector<std::int64_t> frame_t_ns;
  frame_t_ns.reserve(sources.size());
  for (const DatasetFrame& s : sources) frame_t_ns.push_back(s.t_ns);
  // Jumps of more than a few frame periods: a recording pause, a dropped stretch, a broken
  // stamp. Listed, and --realtime restarts its pacing after those over kMaxFrameGapNs.
  const std::vector<TimestampJump> jumps =
      ReportTimestampJumps(frame_t_ns, options.dataset.string(), &report);

  auto vocabulary = LoadRunVocabulary(options);

  SystemOptions system_options = options.system;
  // Offline runs feed frames as fast as tracking takes them (hundreds per second). A
  // monocular map gets its points only from local mapping, and ORB-SLAM's rule refuses
  // monocular keyframes while local mapping is busy: uncoupled ("free"), the map starved of
  // keyframes and tracking was lost in fast turns (mono-inertial V1_02 replay: lost after
  // 13 s in 3 of 3 runs); lock-step ran at 0.4x real time. Offline monocular runs therefore
  // emulate a live run ("live", SystemOptions::live_pace): tracking sees local mapping as a
  // live run fed at twice real time would, waiting only when that is not yet known. On the
  // 40 s V1_02 replay (docs/speed.md) that keeps lock-step's accuracy (median ATE mono 8.71 vs
  // 8.34 mm over 8 seeds, mono-inertial 17.15 vs 17.31 mm) at 2.76x and 3.16x real time.
  // Stereo and RGB-D ran "free" (ORB-SLAM3's coupling) until issue 37, which showed that an
  // uncoupled offline result depends on the machine (how much of a core local mapping gets
  // while tracking races ahead): every offline run now emulates the live run on the work clock
  // (docs/speed.md "One core or two"). --realtime runs stay "free".
  if (!options.mapping_sync.empty()) {
    system_options.mapping_sync = options.mapping_sync;
  } else {
    system_options.mapping_sync = !options.realtime ? "live" : "free";
  }
  SlamSystem system(settings, vocabulary, system_options);
  if (options.load_map) summary.map_loaded = system.LoadMap(*options.load_map);
  // Written now as well as at the end: evaluating a killed run's partial trajectory against
  // body-frame ground truth needs it.
  WriteRigidTransform(system.rig().body_from_camera, options.out / "body_from_camera.txt",
                      "body_from_camera (row-major 4x4, metres)");

  // --- the frame loop ---
  Progress progress("tracking", sources.size(), options.quiet);
  const auto wall_start = std::chrono::steady_clock::now();
  const std::int64_t t0 = sources.front().t_ns;
  // Inertial sensors: IMU samples are fed up to a little past each frame (the preintegration
  // needs one at or after the frame's time).
  const std::int64_t kImuLookaheadNs = system.ImuLookaheadNs();
  // --realtime restarts its pacing after frame intervals longer than this (or not increasing).
  constexpr std::int64_t kMaxFrameGapNs = 1'000'000'000;
  std::int64_t imu_fed_ns = t0 - kImuLookaheadNs;
  if (IsInertial(sensor) && (!euroc || !euroc->has_imu() || euroc->imu().empty())) {
    throw InputError(options.dataset,
                     fmt::format("sensor {} needs IMU data (mav0/imu0)", SensorName(sensor)));
  }
  if (IsInertial(sensor)) {
    CheckImuForFrames(euroc->imu(), euroc->imu_gaps().size(), euroc->mav0() / "imu0/data.csv",
                      frame_t_ns, kImuLookaheadNs, options.allow_imu_gaps, &report);
  }
  // Images are decoded in a thread of their own, a couple of frames ahead of tracking; a pair's
  // second image (right / depth) concurrently with its first: decoding a 640x480 colour PNG
  // takes about 8 ms and its depth PNG 3 ms, so one loader thread in series capped 30 Hz RGB-D
  // at 2.8x real time.
  struct LoadedImages {
    cv::Mat a;              // left / rgb
    cv::Mat b;              // right / depth (empty for monocular)
    bool no_depth = false;  // RGB-D: not one valid depth pixel (counted off the tracking thread)
  };
  Prefetcher<LoadedImages> images(
      sources.size(),
      [&](std::size_t k) {
        const DatasetFrame& s = sources[k];
        std::future<cv::Mat> second;  // its destructor waits, also when the first one throws
        if (euroc && IsStereo(sensor)) {
          second = std::async(std::launch::async, [&] { return euroc->LoadCam1(s.b); });
        } else if (tum && IsRgbd(sensor)) {
          second = std::async(std::launch::async, [&] { return tum->LoadDepthRaw(s.b); });
        }
        LoadedImages loaded;
        loaded.a = euroc ? euroc->LoadCam0(s.a) : tum->LoadRgbGrey(s.a);
        if (second.valid()) loaded.b = second.get();
        loaded.no_depth = tum && IsRgbd(sensor) && cv::countNonZero(loaded.b) == 0;
        // Images of another size than the calibration's were tracked with wrong intrinsics
        // (monocular) or failed deep in the rectification (stereo, RGB-D), naming no image.
        const auto require_size = [&](const cv::Mat& image, const CameraModel& camera,
                                      const fs::path& path) {
          if (image.cols != camera.width() || image.rows != camera.height()) {
            throw InputError(path,
                             fmt::format("{}x{} image, but the calibration is {}x{}", image.cols,
                                         image.rows, camera.width(), camera.height()));
          }
        };
        require_size(loaded.a, settings.camera1,
                     euroc ? euroc->cam0().images[s.a].path : tum->rgb().images[s.a].path);
        if (euroc && IsStereo(sensor)) {
          require_size(loaded.b, settings.camera2.value_or(settings.camera1),
                       euroc->cam1().images[s.b].path);
        } else if (tum && IsRgbd(sensor)) {
          require_size(loaded.b, settings.camera1, tum->depth().images[s.b].path);
        }
        return loaded;
      },
      2);
  // --realtime paces frames to their timestamps from this origin; a timestamp jump moves it
  // (a recording pause or a broken stamp is not slept through).
  auto pace_wall = wall_start;
  std::int64_t pace_t_ns = t0;
  std::int64_t previous_t_ns = t0;
  const auto interrupted = [&] { return interrupt != nullptr && interrupt->load(); };
  // The trajectory so far, for a run that is killed before it writes its outputs.
  AppendFile partial(options.out / kPartialTrajectory);
  partial.Append(kTumHeader);
  bool partial_warned = false;
  if (control.frames_starting) control.frames_starting();
  for (const DatasetFrame& s : sources) {
    if (options.realtime && summary.frames > 0 &&
        (s.t_ns - previous_t_ns > kMaxFrameGapNs || s.t_ns <= previous_t_ns)) {
      PKSLAM_LOG_INFO("--realtime pacing restarts after the timestamp jump at frame {}",
                      summary.frames);
      pace_wall = std::chrono::steady_clock::now();
      pace_t_ns = s.t_ns;
    }
    previous_t_ns = s.t_ns;
    if (options.realtime) {
      SleepUntilOrInterrupted(pace_wall + std::chrono::nanoseconds(s.t_ns - pace_t_ns), interrupt);
    }
    if (interrupted()) {
      summary.interrupted = true;
      PKSLAM_LOG_WARN("interrupted after {} frames; writing what exists", summary.frames);
      break;
    }
    TrackResult r;
    if (IsInertial(sensor)) {
      system.AddImu(euroc->ImuBetween(imu_fed_ns, s.t_ns + kImuLookaheadNs));
      imu_fed_ns = s.t_ns + kImuLookaheadNs;
    }
    const LoadedImages loaded = *images.Next();
    if (loaded.no_depth) ++report.frames_without_depth;
    if (IsStereo(sensor)) {
      r = system.TrackStereo(loaded.a, loaded.b, s.t_ns);
    } else if (IsRgbd(sensor)) {
      r = system.TrackRgbd(loaded.a, loaded.b, s.t_ns);
    } else {
      r = system.TrackMonocular(loaded.a, s.t_ns);
    }
    summary.Count(r);
    if (r.camera_from_world) {
      partial.Append(FormatTumLine({s.t_ns, r.camera_from_world->Inverse()}));
      if (!partial.ok() && !partial_warned) {
        partial_warned = true;
        PKSLAM_LOG_WARN("cannot write {}: {} (the run goes on; its outputs follow at the end)",
                        partial.path().string(), partial.error());
      }
    }
    if (control.frame_tracked) control.frame_tracked(system, r, loaded.a, s.t_ns);
    progress.SetSuffix(fmt::format("{} KFs {}", TrackingStateName(r.state), system.NumKeyFrames()));
    progress.Add();
  }
  progress.Finish();
  if (control.tracking_finished) control.tracking_finished();
  if (report.frames_without_depth > 0) {
    report.Warn(fmt::format("{}: {} of {} depth images hold no valid depth (all zero)",
                            options.dataset.string(), report.frames_without_depth, summary.frames));
  }
  // The trajectory before the shutdown, which waits for local mapping and loop closing (a
  // global BA can take seconds): a second Ctrl-C or a kill then ends the process with the
  // trajectory of every frame on disk. WriteRunOutputs writes it again from the final map.
  WriteTrajectoryOutputs(system, options);
  if (control.trajectory_written) control.trajectory_written();
  system.Shutdown();

  // Saved also after an interruption: the map of the frames processed.
  if (options.save_map) summary.map_saved = system.SaveMap(*options.save_map);
  summary.wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  // Data time without the timestamp jumps --realtime does not sleep through (the real-time
  // factor of a run with a 1000 s jump is not 200).
  std::int64_t skipped_ns = 0;
  for (const TimestampJump& j : jumps) {
    if (static_cast<int>(j.frame) < summary.frames && j.dt_ns > kMaxFrameGapNs) {
      skipped_ns += j.dt_ns;
    }
  }
  summary.sequence_s =
      static_cast<double>(sources[std::max(0, summary.frames - 1)].t_ns - t0 - skipped_ns) * 1e-9;
  WriteRunOutputs(system, options, &summary);
  // The outputs are complete: the crash copy has served its purpose.
  std::error_code ec;
  fs::remove(options.out / kPartialTrajectory, ec);
  PKSLAM_LOG_INFO(
      "{} frames ({} tracked), {} keyframes, {} map points, {} map(s); "
      "{:.1f} s wall for {:.1f} s of data; outputs in {}",
      summary.frames, summary.tracked, summary.keyframes, summary.map_points, summary.maps,
      summary.wall_s, summary.sequence_s, options.out.string());
  if (report.degraded()) {
    PKSLAM_LOG_WARN("degraded input: {} warning(s) (stats.json \"input\"): {}",
                    report.warnings.size(), report.warnings.front());
  }
  return summary;
}

}  // namespace pkslam
