#include "system/run_dataset.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <thread>

#include "core/util/error.h"
#include "core/util/json_writer.h"
#include "core/util/log.h"
#include "core/util/output_file.h"
#include "core/util/prefetch.h"
#include "core/util/progress.h"
#include "io/dataset_fingerprint.h"
#include "io/rigid_transform_file.h"
#include "io/trajectory.h"
#include "system/rig_factory.h"
#include "system/run_input.h"
#include "system/run_outputs.h"

namespace pkslam {
namespace fs = std::filesystem;

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

namespace {

// Offline runs feed frames as fast as tracking takes them (hundreds per second). A monocular
// map gets its points only from local mapping, and ORB-SLAM's rule refuses monocular keyframes
// while local mapping is busy: uncoupled ("free"), the map starved of keyframes and tracking was
// lost in fast turns (mono-inertial V1_02 replay: lost after 13 s in 3 of 3 runs); lock-step ran
// at 0.4x real time. Offline monocular runs therefore emulate a live run ("live",
// SystemOptions::live_pace): tracking sees local mapping as a live run fed at twice real time
// would, waiting only when that is not yet known. On the 40 s V1_02 replay (docs/speed.md) that
// keeps lock-step's accuracy (median ATE mono 8.71 vs 8.34 mm over 8 seeds, mono-inertial 17.15
// vs 17.31 mm) at 2.76x and 3.16x real time. Stereo and RGB-D ran "free" (ORB-SLAM3's coupling)
// until issue 37, which showed that an uncoupled offline result depends on the machine (how much
// of a core local mapping gets while tracking races ahead): every offline run now emulates the
// live run on the work clock (docs/speed.md "One core or two"). --realtime runs stay "free".
std::string MappingSync(const RunOptions& options) {
  if (!options.mapping_sync.empty()) return options.mapping_sync;
  return !options.realtime ? "live" : "free";
}

// --realtime restarts its pacing after frame intervals longer than this (or not increasing).
constexpr std::int64_t kMaxFrameGapNs = 1'000'000'000;

// --realtime: paces frames to their timestamps from an origin that a timestamp jump moves (a
// recording pause or a broken stamp is not slept through).
class RealtimePacer {
 public:
  RealtimePacer(bool on, std::chrono::steady_clock::time_point wall_start, std::int64_t t0_ns)
      : on_(on), wall_(wall_start), t_ns_(t0_ns), previous_t_ns_(t0_ns) {}

  // Before frame `index` (taken at t_ns): sleeps until its time, or until interrupted.
  void WaitFor(std::int64_t t_ns, int index, const std::atomic<bool>* interrupt) {
    if (on_ && index > 0 && (t_ns - previous_t_ns_ > kMaxFrameGapNs || t_ns <= previous_t_ns_)) {
      PKSLAM_LOG_INFO("--realtime pacing restarts after the timestamp jump at frame {}", index);
      wall_ = std::chrono::steady_clock::now();
      t_ns_ = t_ns;
    }
    previous_t_ns_ = t_ns;
    if (on_) SleepUntilOrInterrupted(wall_ + std::chrono::nanoseconds(t_ns - t_ns_), interrupt);
  }

 private:
  bool on_;
  std::chrono::steady_clock::time_point wall_;
  std::int64_t t_ns_;
  std::int64_t previous_t_ns_;
};

TrackResult TrackFrame(SlamSystem& system, Sensor sensor, const LoadedImages& loaded,
                       std::int64_t t_ns) {
  if (IsStereo(sensor)) return system.TrackStereo(loaded.a, loaded.b, t_ns);
  if (IsRgbd(sensor)) return system.TrackRgbd(loaded.a, loaded.b, t_ns);
  return system.TrackMonocular(loaded.a, t_ns);
}

// Appends each tracked pose to OUT/trajectory.txt.partial: the trajectory so far, for a run that
// is killed before it writes its outputs.
class PartialTrajectory {
 public:
  explicit PartialTrajectory(const fs::path& file) : file_(file) { file_.Append(kTumHeader); }

  void Add(std::int64_t t_ns, const SE3d& camera_from_world) {
    file_.Append(FormatTumLine({t_ns, camera_from_world.Inverse()}));
    if (!file_.ok() && !warned_) {
      warned_ = true;
      PKSLAM_LOG_WARN("cannot write {}: {} (the run goes on; its outputs follow at the end)",
                      file_.path().string(), file_.error());
    }
  }

 private:
  AppendFile file_;
  bool warned_ = false;
};

// Data time of the frames processed, without the timestamp jumps --realtime does not sleep
// through (the real-time factor of a run with a 1000 s jump is not 200).
double SequenceSeconds(const std::vector<DatasetFrame>& frames, int processed,
                       const std::vector<TimestampJump>& jumps) {
  std::int64_t skipped_ns = 0;
  for (const TimestampJump& j : jumps) {
    if (static_cast<int>(j.frame) < processed && j.dt_ns > kMaxFrameGapNs) skipped_ns += j.dt_ns;
  }
  return static_cast<double>(frames[std::max(0, processed - 1)].t_ns - frames.front().t_ns -
                             skipped_ns) *
         1e-9;
}

// Shuts the system down and writes every output; `summary` gets the counts.
void FinishRun(SlamSystem& system, const RunOptions& options, const RunControl& control,
               RunSummary* summary) {
  // The trajectory before the shutdown, which waits for local mapping and loop closing (a
  // global BA can take seconds): a second Ctrl-C or a kill then ends the process with the
  // trajectory of every frame on disk. WriteRunOutputs writes it again from the final map.
  WriteTrajectoryOutputs(system, options);
  if (control.trajectory_written) control.trajectory_written();
  system.Shutdown();
  // Saved also after an interruption: the map of the frames processed.
  if (options.save_map) summary->map_saved = system.SaveMap(*options.save_map);
}

}  // namespace

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
  const RunInput input = OpenRunInput(options, &report);
  const std::vector<DatasetFrame>& frames = input.frames;
  summary.dataset_fingerprint =
      DatasetFingerprint(input.euroc ? input.euroc->cam0() : input.tum->rgb());
  const std::vector<std::int64_t> frame_t_ns = input.FrameTimes();
  // Jumps of more than a few frame periods: a recording pause, a dropped stretch, a broken
  // stamp. Listed, and --realtime restarts its pacing after those over kMaxFrameGapNs.
  const std::vector<TimestampJump> jumps =
      ReportTimestampJumps(frame_t_ns, options.dataset.string(), &report);

  auto vocabulary = LoadRunVocabulary(options);
  SystemOptions system_options = options.system;
  system_options.mapping_sync = MappingSync(options);
  SlamSystem system(input.settings, vocabulary, system_options);
  if (options.load_map) summary.map_loaded = system.LoadMap(*options.load_map);
  // Written now as well as at the end: evaluating a killed run's partial trajectory against
  // body-frame ground truth needs it.
  WriteRigidTransform(system.rig().body_from_camera, options.out / "body_from_camera.txt",
                      "body_from_camera (row-major 4x4, metres)");

  // --- the frame loop ---
  Progress progress("tracking", frames.size(), options.quiet);
  const auto wall_start = std::chrono::steady_clock::now();
  const std::int64_t t0 = frames.front().t_ns;
  // Inertial sensors: IMU samples are fed up to a little past each frame (the preintegration
  // needs one at or after the frame's time).
  const std::int64_t kImuLookaheadNs = system.ImuLookaheadNs();
  std::int64_t imu_fed_ns = t0 - kImuLookaheadNs;
  const std::optional<EurocDataset>& euroc = input.euroc;
  if (IsInertial(sensor) && (!euroc || !euroc->has_imu() || euroc->imu().empty())) {
    throw InputError(options.dataset,
                     fmt::format("sensor {} needs IMU data (mav0/imu0)", SensorName(sensor)));
  }
  if (IsInertial(sensor)) {
    CheckImuForFrames(euroc->imu(), euroc->imu_gaps().size(), euroc->mav0() / "imu0/data.csv",
                      frame_t_ns, kImuLookaheadNs, options.allow_imu_gaps, &report);
  }
  // Images are decoded in a thread of their own, a couple of frames ahead of tracking.
  Prefetcher<LoadedImages> images(
      frames.size(), [&input](std::size_t k) { return input.Load(k); }, 2);
  RealtimePacer pacer(options.realtime, wall_start, t0);
  const auto interrupted = [&] { return interrupt != nullptr && interrupt->load(); };
  PartialTrajectory partial(options.out / kPartialTrajectory);
  if (control.frames_starting) control.frames_starting();
  for (const DatasetFrame& s : frames) {
    pacer.WaitFor(s.t_ns, summary.frames, interrupt);
    if (interrupted()) {
      summary.interrupted = true;
      PKSLAM_LOG_WARN("interrupted after {} frames; writing what exists", summary.frames);
      break;
    }
    if (IsInertial(sensor)) {
      system.AddImu(euroc->ImuBetween(imu_fed_ns, s.t_ns + kImuLookaheadNs));
      imu_fed_ns = s.t_ns + kImuLookaheadNs;
    }
    const LoadedImages loaded = *images.Next();
    if (loaded.no_depth) ++report.frames_without_depth;
    const TrackResult r = TrackFrame(system, sensor, loaded, s.t_ns);
    summary.Count(r);
    if (r.camera_from_world) partial.Add(s.t_ns, *r.camera_from_world);
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
  FinishRun(system, options, control, &summary);
  summary.wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  summary.sequence_s = SequenceSeconds(frames, summary.frames, jumps);
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
