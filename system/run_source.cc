#include "system/run_source.h"

#include <chrono>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/output_file.h"
#include "core/util/progress.h"
#include "io/rigid_transform_file.h"
#include "io/dataset_common.h"
#include "io/settings.h"
#include "io/trajectory.h"
#include "system/run_outputs.h"

namespace pkslam {

namespace fs = std::filesystem;

RunSummary RunFrameSource(const RunOptions& options_in, FrameSource& source,
                          const RunControl& control) {
  RunOptions options = options_in;
  if (options.dataset.empty()) options.dataset = source.Name();  // the label in stats.json
  if (options.system.sensor != Sensor::kMonocular) {
    throw OptionError(
        fmt::format("{}: sensor {} needs a dataset; a video, camera or image folder "
                    "runs with --sensor mono",
                    source.Name(), SensorName(options.system.sensor)));
  }
  if (!options.settings) {
    throw OptionError(
        fmt::format("{}: pass --settings (the camera's ORB-SLAM3 settings file)", source.Name()));
  }
  options.Check();
  fs::create_directories(options.out);
  RemoveRunOutputs(options.out);
  AddLogFile(options.out / "run.log");
  struct LogGuard {
    ~LogGuard() { RemoveLogFiles(); }
  } log_guard;

  const Settings settings = ReadOrbSlam3Settings(*options.settings);
  CheckTimeBase(source.ListedTimes(), settings.fps, "the settings' Camera.fps", source.Name(),
                "frames are");
  RunSummary summary;
  summary.dataset_fingerprint = source.Name();
  auto vocabulary = LoadRunVocabulary(options);
  SystemOptions system_options = options.system;
  // A file is replayed as fast as tracking takes it, like a dataset (monocular: local mapping
  // as a live run would see it); a camera is live.
  const bool live_source = !source.Count().has_value();
  system_options.mapping_sync =
      !options.mapping_sync.empty() ? options.mapping_sync : (live_source ? "free" : "live");
  SlamSystem system(settings, vocabulary, system_options);
  if (options.load_map) summary.map_loaded = system.LoadMap(*options.load_map);
  WriteRigidTransform(system.rig().body_from_camera, options.out / "body_from_camera.txt",
                      "body_from_camera (row-major 4x4, metres)");

  std::size_t total = source.Count().value_or(0);
  if (total > 0)
    total -= std::min<std::size_t>(total, static_cast<std::size_t>(options.first_frame));
  if (options.max_frames > 0 &&
      (total == 0 || total > static_cast<std::size_t>(options.max_frames))) {
    total = static_cast<std::size_t>(options.max_frames);
  }
  Progress progress("tracking", total, options.quiet);
  const auto wall_start = std::chrono::steady_clock::now();
  AppendFile partial(options.out / kPartialTrajectory);
  partial.Append(kTumHeader);
  const auto interrupted = [&] {
    return control.interrupt != nullptr && control.interrupt->load();
  };
  if (control.frames_starting) control.frames_starting();
  std::optional<std::int64_t> first_t_ns;
  std::int64_t last_t_ns = 0;
  int skipped = 0;
  while (options.max_frames == 0 || summary.frames < options.max_frames) {
    if (interrupted()) {
      summary.interrupted = true;
      PKSLAM_LOG_WARN("interrupted after {} frames; writing what exists", summary.frames);
      break;
    }
    std::optional<SourceFrame> frame = source.Next();
    if (!frame) break;
    if (skipped < options.first_frame) {
      ++skipped;
      continue;
    }
    const CameraModel& camera = settings.camera1;
    if (frame->image.cols != camera.width() || frame->image.rows != camera.height()) {
      throw InputError(
          source.Name(),
          fmt::format("frame {}: {}x{} image, but the calibration is {}x{}", summary.frames,
                      frame->image.cols, frame->image.rows, camera.width(), camera.height()));
    }
    if (options.realtime && first_t_ns) {
      SleepUntilOrInterrupted(wall_start + std::chrono::nanoseconds(frame->t_ns - *first_t_ns),
                              control.interrupt);
    }
    if (!first_t_ns) first_t_ns = frame->t_ns;
    last_t_ns = frame->t_ns;
    const TrackResult r = system.TrackMonocular(frame->image, frame->t_ns);
    summary.Count(r);
    if (r.camera_from_world) {
      partial.Append(FormatTumLine({frame->t_ns, r.camera_from_world->Inverse()}));
    }
    if (control.frame_tracked) control.frame_tracked(system, r, frame->image, frame->t_ns);
    progress.SetSuffix(fmt::format("{} KFs {}", TrackingStateName(r.state), system.NumKeyFrames()));
    progress.Add();
  }
  progress.Finish();
  if (control.tracking_finished) control.tracking_finished();
  if (summary.frames == 0) throw InputError(source.Name(), "no frames to process");
  WriteTrajectoryOutputs(system, options);
  if (control.trajectory_written) control.trajectory_written();
  system.Shutdown();
  if (options.save_map) summary.map_saved = system.SaveMap(*options.save_map);
  summary.wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  summary.sequence_s = static_cast<double>(last_t_ns - first_t_ns.value_or(last_t_ns)) * 1e-9;
  WriteRunOutputs(system, options, &summary);
  std::error_code ec;
  fs::remove(options.out / kPartialTrajectory, ec);
  PKSLAM_LOG_INFO(
      "{}: {} frames ({} tracked), {} keyframes, {} map points; {:.1f} s wall for "
      "{:.1f} s of video; outputs in {}",
      source.Name(), summary.frames, summary.tracked, summary.keyframes, summary.map_points,
      summary.wall_s, summary.sequence_s, options.out.string());
  return summary;
}

}  // namespace pkslam
