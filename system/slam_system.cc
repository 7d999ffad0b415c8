#include "system/slam_system.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <shared_mutex>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/output_file.h"
#include "core/util/wall_time.h"
#include "io/point_cloud.h"
#include "keyframe/selector_factory.h"
#include "map_model/estimation/calibration_apply.h"
#include "map_model/estimation/calibration_collect.h"
#include "map_model/keyframe.h"
#include "map_model/keyframe_database.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/storage/atlas_storage.h"
#include "map_model/storage/map_file.h"

namespace pkslam {

void SystemOptions::Check() const {
  PKSLAM_CHECK_OPTION(
      mapping_sync == "live" || mapping_sync == "lockstep" || mapping_sync == "free",
      "mapping_sync", "'{}' (live|lockstep|free)", mapping_sync);
  PKSLAM_CHECK_OPTION(live_pace > 0 && live_pace <= 100, "live_pace", "{}", live_pace);
  PKSLAM_CHECK_OPTION(
      calibration_thread == "auto" || calibration_thread == "thread" ||
          calibration_thread == "step",
      "calibration_thread", "'{}' (auto|thread|step)", calibration_thread);
  PKSLAM_CHECK_OPTION(ParseLiveClock(live_clock).has_value(), "live_clock", "'{}' (work|cpu|wall)",
                      live_clock);
  tracking.Check();
  mapping.Check();
  loop.Check();
}

SlamSystem::SlamSystem(const Settings& settings, std::shared_ptr<const Vocabulary> vocabulary,
                       SystemOptions options)
    : options_(std::move(options)),
      settings_(settings),
      setup_(MakeRig(settings, options_.sensor)),
      file_calibration_(CalibrationFromSettings(settings, options_.sensor)),
      vocabulary_(std::move(vocabulary)) {
  PKSLAM_CHECK(vocabulary_ != nullptr, "no vocabulary");
  if (options_.deterministic) {
    options_.mapping_sync = "lockstep";
    options_.tracking.pose.num_threads = 1;
    options_.mapping.ba.num_threads = 1;
    options_.loop.synchronous = true;
    options_.loop.num_threads = 1;
    options_.loop.global_ba_options.num_threads = 1;
  }
  if (options_.mapping_sync == "lockstep") options_.tracking.lockstep = true;
  // Lock-step maps each keyframe before the next frame: the adjustment belongs to its step.
  options_.mapping.calibration.own_thread =
      options_.mapping_sync != "lockstep" && options_.calibration_thread != "step";
  options_.tracking.seed = options_.seed;
  options_.loop.seed = options_.seed;
  options_.Check();
  selector_parameters_ = settings.keyframe;
  for (const auto& [k, v] : options_.selector_parameters) selector_parameters_[k] = v;
  auto selector = MakeKeyframeSelector(options_.selector, selector_parameters_);

  atlas_.SetDatabase(std::make_unique<KeyFrameDatabase>(*vocabulary_));
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kCalibration);
    atlas_.SetCalibration(lock, file_calibration_, setup_);
  }
  calibration_version_ = atlas_.calibration_version();
  mapper_ = std::make_unique<LocalMapper>(&atlas_, setup_.rig, options_.mapping);
  mapper_->SetCalibrationPrior(file_calibration_, ShapeFromSettings(settings, options_.sensor));
  OrbOptions orb;
  orb.n_features = settings.orb.n_features;
  orb.scale_factor = settings.orb.scale_factor;
  orb.n_levels = settings.orb.n_levels;
  orb.ini_th_fast = settings.orb.ini_th_fast;
  orb.min_th_fast = settings.orb.min_th_fast;
  tracker_ = std::make_unique<Tracker>(&atlas_, vocabulary_.get(), setup_.rig, std::move(selector),
                                       mapper_.get(), options_.tracking, orb);
  tracker_->EnableTrace(options_.trace);
  time_offset_s_ = IsInertial(options_.sensor) ? file_calibration_.time_offset_s : 0.0;
  tracker_->SetTimeOffset(time_offset_s_);
  SetTrackerImuAxisErrors(file_calibration_);
  tracker_->EnableFrameTracks(options_.frame_tracks);
  if (!options_.no_loop) {
    LocalMapper* mapper = mapper_.get();
    MappingControl control;
    control.request_stop = [mapper] { mapper->RequestStop(); };
    control.is_stopped = [this, mapper] { return mapper_finished_.load() || mapper->IsStopped(); };
    control.release = [mapper] { mapper->Release(); };
    loop_ =
        std::make_unique<LoopClosing>(&atlas_, options_.sensor, std::move(control), options_.loop);
    LoopClosing* loop = loop_.get();
    mapper_->SetKeyFrameConsumer([loop](const KeyFramePtr& kf) { loop->InsertKeyFrame(kf); });
    loop_->Start();
  }
  mapper_->EmulateLive(options_.mapping_sync == "live", options_.live_pace,
                       *ParseLiveClock(options_.live_clock));
  mapper_->Start();
  PKSLAM_LOG_INFO("sensor {}, camera {}, baseline {:.4f} m, selector {}{}",
                  SensorName(options_.sensor), setup_.rig->camera.ToString(), setup_.rig->baseline,
                  options_.selector, options_.deterministic ? ", deterministic" : "");
}

SlamSystem::~SlamSystem() { Shutdown(); }

void SlamSystem::Shutdown() {
  if (shut_down_) return;
  shut_down_ = true;
  mapper_->Finish();
  mapper_finished_.store(true);
  if (loop_) loop_->Finish();
  if (options_.mapping.calibration.enabled) FinishCalibration();
}

void SlamSystem::FinishCalibration() {
  const OnlineCalibrationOptions& o = options_.mapping.calibration;
  const auto collect_start = std::chrono::steady_clock::now();
  CalibrationBundleProblem problem;
  RigSetup setup;
  {
    auto lock = MapReader(atlas_).Lock();
    const Map* map = LargestMap();
    if (map == nullptr || map->keyframes().empty()) return;
    KeyFrame* newest = map->keyframes().rbegin()->second.get();
    const bool inertial =
        IsInertial(options_.sensor) && map->imu_status().inertial_ba1_done;
    CalibrationCollectOptions collect;
    collect.max_observations_per_keyframe = o.final_max_observations_per_keyframe;
    collect.imu_axes_jacobians = o.gyro_scale || o.accel_axes;
    setup = atlas_.rig_setup();
    problem = CollectCalibrationBundle(lock, newest, inertial, setup, atlas_.calibration(),
                                       file_calibration_, collect);
  }
  final_timing_.collect_ms = WallMsSince(collect_start);
  PKSLAM_LOG_INFO("final calibration adjustment: {} keyframes, {} observations, {} inertial edges{}",
                  problem.bundle.visual.keyframes.size(), problem.raw.size(),
                  problem.bundle.edges.size(), problem.inertial ? "" : " (visual only)");
  final_gates_ = DecideFreedom(problem, options_.sensor, o);
  problem.free = final_gates_.free;
  if (!problem.free.Any() || problem.empty()) return;
  CalibrationBundleOptions ba;
  ba.iterations_first = o.final_iterations_first;
  ba.iterations_second = o.final_iterations_second;
  ba.num_threads = options_.mapping.ba.num_threads;
  ba.prior = o.prior;
  CalibrationBundleResult result = SolveCalibrationBundle(problem, ba);
  final_timing_.solve_ms = result.solve_ms;
  final_timing_.covariance_ms = result.covariance_ms;
  if (result.bundle.visual.iterations == 0) return;
  if (const auto why = ImplausibleEstimate(problem, result.estimate, o,
                                           o.final_max_step_prior_sigmas)) {
    PKSLAM_LOG_WARN("final calibration adjustment not applied (the run keeps mapping's estimate, "
                    "without sigmas): {}",
                    *why);
    final_note_ = "final adjustment not applied: " + *why;
    return;
  }
  RigSetup next;
  try {
    next = BuildRig(result.estimate, ShapeFromSettings(settings_, options_.sensor));
  } catch (const OptionError& e) {
    PKSLAM_LOG_WARN("final calibration estimate rejected: {}", e.what());
    return;
  }
  const auto apply_start = std::chrono::steady_clock::now();
  {
    // Only the calibration moves (the bodies stay where mapping left them): the adjustment's
    // keyframe poses are not written back. On the MH_01 true-calibration replay they scattered
    // the keyframes of a stationary stretch by 1-3 cm (ATE 6.8 -> 77.5 mm), while elsewhere
    // they changed the ATE by under 2 mm either way (docs/calibration.md, "A quick look").
    auto lock = MapEditor(&atlas_).Write(MapEdit::kCalibration);
    MoveToCalibration(lock, &atlas_, result.estimate, next);
  }
  RefinePointsToCalibration(&atlas_, problem.bundle.visual.map_id);
  // Tracking has ended: its records follow the keyframes here.
  SyncCalibration();
  final_timing_.apply_ms = WallMsSince(apply_start);
  PKSLAM_LOG_INFO("final calibration adjustment: gathered in {:.0f} ms, solved in {:.0f} ms "
                  "(covariance {:.0f} ms), applied in {:.0f} ms",
                  final_timing_.collect_ms, final_timing_.solve_ms, final_timing_.covariance_ms,
                  final_timing_.apply_ms);
  final_calibration_ = std::move(result);
}

CalibrationReport SlamSystem::calibration_report() const {
  CalibrationReport report;
  report.online = options_.mapping.calibration.enabled;
  if (report.online) report.solved_in = options_.mapping.calibration.own_thread ? "thread" : "step";
  report.sensor = options_.sensor;
  report.file = file_calibration_;
  {
    auto lock = MapReader(atlas_).Lock();
    report.estimate = atlas_.calibration();
  }
  report.history = mapper_->stats().calibration_refinements;
  if (final_calibration_) {
    report.parameters = final_calibration_->parameters;
    report.covariance_ok = final_calibration_->covariance_ok;
    report.parameter_covariance = final_calibration_->parameter_covariance;
    report.frozen = final_gates_.frozen;
  } else {
    CalibrationFreedom none;
    report.parameters =
        CalibrationParameters(file_calibration_, report.estimate, none,
                              options_.mapping.calibration.prior, IsInertial(options_.sensor));
    if (!report.history.empty()) report.frozen = report.history.back().gates.frozen;
  }
  report.note = final_note_;
  report.final_timing = final_timing_;
  return report;
}

namespace {

SlamSystem::MapFileInfo CountMaps(const AtlasRecord& record) {
  SlamSystem::MapFileInfo info;
  info.maps = static_cast<int>(record.maps.size());
  for (const MapRecord& m : record.maps) {
    info.keyframes += static_cast<int>(m.keyframes.size());
    info.map_points += static_cast<int>(m.points.size());
  }
  return info;
}

}  // namespace

SlamSystem::MapFileInfo SlamSystem::SaveMap(const std::filesystem::path& file) const {
  const auto start = std::chrono::steady_clock::now();
  AtlasRecord record;
  {
    auto lock = MapReader(atlas_).Lock();
    record = AtlasStorage::Snapshot(atlas_, *setup_.rig, vocabulary_->Fingerprint());
  }
  WriteMapFile(file, record);
  MapFileInfo info = CountMaps(record);
  info.bytes = std::filesystem::file_size(file);
  info.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  PKSLAM_LOG_INFO("map saved to {}: {} map(s), {} keyframes, {} points, {:.1f} MB, {:.2f} s",
                  file.string(), info.maps, info.keyframes, info.map_points, info.bytes / 1e6,
                  info.seconds);
  return info;
}

SlamSystem::MapFileInfo SlamSystem::LoadMap(const std::filesystem::path& file) {
  const auto start = std::chrono::steady_clock::now();
  const AtlasRecord record = ReadMapFile(file);
  // A map whose calibration was estimated online is in that calibration: the session continues
  // in it (the settings' values stay the prior), provided it is the same rig.
  RigCalibration calibration = file_calibration_;
  RigSetup setup = setup_;
  if (record.calibration) {
    try {
      calibration = FromCalibrationRecord(*record.calibration);
      CheckSameRig(file_calibration_, calibration);
      setup = BuildRig(calibration, ShapeFromSettings(settings_, options_.sensor));
    } catch (const OptionError& e) {
      throw InputError(file, fmt::format("map built with another camera: {}", e.what()));
    }
  }
  CheckCompatible(file, record, vocabulary_->Fingerprint(), *setup.rig);
  if (record.maps.empty()) throw InputError(file, "the map file holds no map");
  {
    auto lock = MapEditor(&atlas_).Write(MapEdit::kLoadMap);
    atlas_.SetCalibration(lock, calibration, setup);
    try {
      AtlasStorage::Restore(lock, record, setup.rig, &atlas_);
    } catch (const InputError&) {
      throw;
    } catch (const Error& e) {
      // The restore's consistency checks speak in source locations; the user needs only what
      // is inconsistent (a checksum that matches means the bytes were written this way).
      std::string what = e.what();
      const std::size_t failed = what.find("' failed: ");
      if (failed != std::string::npos) what = what.substr(failed + 10);
      throw InputError(file, fmt::format("inconsistent map (damaged, though its checksum "
                                         "matches): {}",
                                         what));
    }
    if (options_.tracking.localise_only) {
      // Every loaded map still counts as this session's here: the largest one.
      atlas_.SetCurrentMap(lock, atlas_.FindMap(LargestMap()->id()));
    } else {
      atlas_.CreateNewMap(
          lock);  // this session's map; loop closing merges it when it recognises one
    }
  }
  SyncCalibration();
  session_first_keyframe_id_ = record.next_keyframe_id;
  if (options_.tracking.localise_only) tracker_->StartLocalisation();
  MapFileInfo info = CountMaps(record);
  info.bytes = std::filesystem::file_size(file);
  info.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  PKSLAM_LOG_INFO("map loaded from {}: {} map(s), {} keyframes, {} points, {:.2f} s{}",
                  file.string(), info.maps, info.keyframes, info.map_points, info.seconds,
                  options_.tracking.localise_only ? "; localisation only" : "");
  return info;
}

std::int64_t SlamSystem::ImuClock(std::int64_t t_ns) const {
  // Inertial sensors only: without an IMU there is no other clock.
  if (!IsInertial(options_.sensor)) return t_ns;
  return t_ns + static_cast<std::int64_t>(std::llround(time_offset_s_ * 1e9));
}

void SlamSystem::SetTrackerImuAxisErrors(const RigCalibration& calibration) {
  const bool inertial = IsInertial(options_.sensor);
  tracker_->SetImuAxisErrors(inertial ? calibration.gyro_scale : Eigen::Vector3d::Zero(),
                             inertial ? calibration.accel_axes : Eigen::Matrix3d::Zero());
}

void SlamSystem::SyncCalibration() {
  if (atlas_.calibration_version() == calibration_version_) return;
  RigSetup setup;
  RigCalibration calibration;
  {
    auto lock = MapReader(atlas_).Lock();
    setup = atlas_.rig_setup();
    calibration = atlas_.calibration();
    calibration_version_ = atlas_.calibration_version();
  }
  tracker_->SetRig(setup, setup_);
  setup_ = std::move(setup);
  time_offset_s_ = IsInertial(options_.sensor) ? calibration.time_offset_s : 0.0;
  tracker_->SetTimeOffset(time_offset_s_);
  SetTrackerImuAxisErrors(calibration);
}

TrackResult SlamSystem::TrackStereo(const cv::Mat& left, const cv::Mat& right, std::int64_t t_ns) {
  SyncCalibration();
  if (setup_.rectification) {
    const auto [l, r] = setup_.rectification->Rectify(left, right);
    return tracker_->TrackStereo(l, r, ImuClock(t_ns));
  }
  return tracker_->TrackStereo(left, right, ImuClock(t_ns));
}

TrackResult SlamSystem::TrackRgbd(const cv::Mat& image, const cv::Mat& depth, std::int64_t t_ns) {
  SyncCalibration();
  return tracker_->TrackRgbd(image, depth, ImuClock(t_ns));
}

TrackResult SlamSystem::TrackMonocular(const cv::Mat& image, std::int64_t t_ns) {
  SyncCalibration();
  if (setup_.undistortion) {
    return tracker_->TrackMonocular(setup_.undistortion->Undistort(image), ImuClock(t_ns));
  }
  return tracker_->TrackMonocular(image, ImuClock(t_ns));
}

std::int64_t SlamSystem::ImuLookaheadNs() const {
  // The preintegration needs a sample at or after the frame's IMU time.
  constexpr std::int64_t kMarginNs = 20'000'000;
  return kMarginNs + std::max<std::int64_t>(0, ImuClock(0));
}

CalibrationBundleResult SlamSystem::RefineCalibration(const CalibrationFreedom& free,
                                                      const CalibrationBundleOptions& options,
                                                      int max_observations_per_keyframe) const {
  CalibrationBundleProblem problem;
  {
    auto lock = MapReader(atlas_).Lock();
    const Map* map = LargestMap();
    if (map == nullptr || map->keyframes().empty()) return {};
    KeyFrame* newest = map->keyframes().rbegin()->second.get();
    CalibrationCollectOptions collect;
    collect.max_observations_per_keyframe = max_observations_per_keyframe;
    collect.imu_axes_jacobians = free.gyro_scale || free.accel_axes;
    problem = CollectCalibrationBundle(lock, newest, IsInertial(options_.sensor), setup_,
                                       file_calibration_, file_calibration_, collect);
  }
  problem.free = free;
  return SolveCalibrationBundle(problem, options);
}

const Map* SlamSystem::LargestMap() const {
  // Among the maps of this session: a map loaded from a file (--load-map) describes this
  // session's frames only once it holds one of its keyframes (merged with the session's map) or
  // the session localises in it; an output of any other loaded map would be an empty
  // trajectory. Without a loaded map every map qualifies, and this is the largest map, as
  // ORB-SLAM3 chooses. O(maps): NumKeyFrames() asks it for every frame's progress line.
  const auto of_session = [this](const Map* m) {
    return m->max_keyframe_id() >= session_first_keyframe_id_ ||
           (options_.tracking.localise_only && m == atlas_.current_map());
  };
  const Map* best = nullptr;
  for (const bool session_only : {true, false}) {
    for (const Map* m : atlas_.maps()) {
      if (session_only && !of_session(m)) continue;
      if (best == nullptr || m->NumKeyFrames() > best->NumKeyFrames()) best = m;
    }
    if (best != nullptr) break;
  }
  return best;
}

namespace {

// camera_from_world of a (possibly retired) keyframe through its parent chain.
SE3d CameraFromWorld(const KeyFrame* kf) {
  SE3d camera_from_kf;
  while (kf->IsBad() && kf->parent() != nullptr) {
    camera_from_kf = camera_from_kf * kf->camera_from_parent();
    kf = kf->parent();
  }
  return camera_from_kf * kf->camera_from_world();
}

}  // namespace

Trajectory SlamSystem::FrameTrajectory() const {
  auto lock = MapReader(atlas_).Lock();
  Trajectory out;
  const Map* map = LargestMap();
  for (const FrameRecord& r : tracker_->records()) {
    if (!r.reference || r.reference->map() != map) continue;
    const SE3d camera_from_world = r.camera_from_reference * CameraFromWorld(r.reference.get());
    out.poses.push_back({r.t_ns, camera_from_world.Inverse()});
  }
  return out;
}

Trajectory SlamSystem::KeyFrameTrajectory() const {
  auto lock = MapReader(atlas_).Lock();
  Trajectory out;
  const Map* map = LargestMap();
  if (map == nullptr) return out;
  for (const auto& [id, kf] : map->keyframes()) {
    out.poses.push_back({kf->t_ns(), kf->world_from_camera()});
  }
  std::sort(out.poses.begin(), out.poses.end(),
            [](const StampedPose& a, const StampedPose& b) { return a.t_ns < b.t_ns; });
  return out;
}

std::vector<SlamSystem::MapPointView> SlamSystem::MapPoints() const {
  std::vector<MapPointView> out;
  auto lock = MapReader(atlas_).Lock();
  if (const Map* map = LargestMap()) {
    out.reserve(map->map_points().size());
    for (const auto& [id, mp] : map->map_points()) {
      out.push_back({id, mp->position(), static_cast<int>(mp->observations().size())});
    }
  }
  return out;
}

std::vector<SlamSystem::KeyFrameView> SlamSystem::KeyFrames() const {
  std::vector<KeyFrameView> out;
  auto lock = MapReader(atlas_).Lock();
  if (const Map* map = LargestMap()) {
    for (const auto& [id, kf] : map->keyframes()) {
      out.push_back({id, kf->t_ns(), kf->world_from_camera()});
    }
  }
  std::sort(out.begin(), out.end(),
            [](const KeyFrameView& a, const KeyFrameView& b) { return a.t_ns < b.t_ns; });
  return out;
}

void SlamSystem::WriteMapPly(const std::filesystem::path& file) const {
  // Copied under the shared lock, written after it (io/point_cloud.h: "views" = the keyframes
  // observing each point, capped at 255).
  PointCloud cloud;
  {
    auto lock = MapReader(atlas_).Lock();
    if (const Map* map = LargestMap()) {
      for (const auto& [id, mp] : map->map_points()) {
        cloud.points.push_back(mp->position().cast<float>());
        cloud.views.push_back(
            static_cast<std::uint8_t>(std::min<std::size_t>(255, mp->observations().size())));
      }
    }
  }
  WritePly(cloud, file, PlyColour::kNone, "pkslam map points (world frame)");
}

int SlamSystem::NumKeyFrames() const {
  auto lock = MapReader(atlas_).Lock();
  const Map* map = LargestMap();
  return map != nullptr ? map->NumKeyFrames() : 0;
}

int SlamSystem::NumMapPoints() const {
  auto lock = MapReader(atlas_).Lock();
  const Map* map = LargestMap();
  return map != nullptr ? map->NumMapPoints() : 0;
}

int SlamSystem::NumMaps() const {
  auto lock = MapReader(atlas_).Lock();
  return atlas_.NumMaps();
}

}  // namespace pkslam
