#include "tracking/tracker.h"

#include <chrono>
#include <mutex>
#include <shared_mutex>

#include "core/bow/vocabulary.h"
#include "core/util/cpu_time.h"
#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/wall_time.h"
#include "map_model/keyframe.h"
#include "map_model/map_editor.h"
#include "map_model/map_point.h"
#include "map_model/matching/orb_matcher.h"
#include "tracking/frame_tracking.h"
#include "tracking/pose_optimizer.h"

namespace pkslam {
namespace {

// CPU and wall time of building or tracking a frame (for its FrameRecord).
struct StepTimer {
  double cpu_start = ThreadCpuSeconds();
  std::chrono::steady_clock::time_point wall_start = std::chrono::steady_clock::now();

  void Stop(double* cpu_ms, double* wall_ms) const {
    *cpu_ms = 1e3 * (ThreadCpuSeconds() - cpu_start);
    *wall_ms = WallMsSince(wall_start);
  }
};

// The inertial side for an inertial rig, none otherwise.
std::unique_ptr<InertialTracking> MakeInertialTracking(const CameraRig& rig) {
  if (!IsInertial(rig.sensor)) return nullptr;
  PKSLAM_CHECK(rig.imu.has_value(), "inertial sensor without IMU noise model");
  return std::make_unique<InertialTracking>(*rig.imu);
}

}  // namespace

Tracker::Tracker(Atlas* atlas, const Vocabulary* vocabulary, std::shared_ptr<const CameraRig> rig,
                 std::unique_ptr<KeyframeSelector> selector, MappingBackend* mapping,
                 TrackingOptions options, OrbOptions orb_options)
    : atlas_(atlas),
      vocabulary_(vocabulary),
      rig_(std::move(rig)),
      selector_(std::move(selector)),
      mapping_(mapping),
      options_(options),
      builder_(rig_, orb_options),
      starter_(atlas_, vocabulary_, IsMonocular(rig_->sensor), options_),
      inserter_(atlas_, vocabulary_, selector_.get(), mapping_, options_,
                IsMonocular(rig_->sensor)),
      imu_(MakeInertialTracking(*rig_)),
      map_tracker_(atlas_, vocabulary_, options_, rig_, imu_.get()) {
  options_.Check();
  PKSLAM_CHECK(
      atlas_ != nullptr && vocabulary_ != nullptr && selector_ != nullptr && mapping_ != nullptr,
      "tracker needs an atlas, a vocabulary, a selector and local mapping");
}

Tracker::~Tracker() = default;

TrackResult Tracker::TrackStereo(const cv::Mat& left, const cv::Mat& right, std::int64_t t_ns) {
  PKSLAM_CHECK(IsStereo(rig_->sensor), "TrackStereo with a {} rig", SensorName(rig_->sensor));
  const StepTimer timer;
  Frame frame = builder_.BuildStereo(atlas_->NextFrameId(), t_ns, left, right);
  timer.Stop(&build_cpu_ms_, &build_ms_);
  return Track(std::move(frame));
}

TrackResult Tracker::TrackRgbd(const cv::Mat& image, const cv::Mat& depth, std::int64_t t_ns) {
  PKSLAM_CHECK(IsRgbd(rig_->sensor), "TrackRgbd with a {} rig", SensorName(rig_->sensor));
  const StepTimer timer;
  Frame frame = builder_.BuildRgbd(atlas_->NextFrameId(), t_ns, image, depth);
  timer.Stop(&build_cpu_ms_, &build_ms_);
  return Track(std::move(frame));
}

TrackResult Tracker::TrackMonocular(const cv::Mat& image, std::int64_t t_ns) {
  PKSLAM_CHECK(IsMonocular(rig_->sensor), "TrackMonocular with a {} rig", SensorName(rig_->sensor));
  const bool initialising = state_ == TrackingState::kNotInitialized;
  const StepTimer timer;
  Frame frame = builder_.BuildMonocular(atlas_->NextFrameId(), t_ns, image, initialising);
  timer.Stop(&build_cpu_ms_, &build_ms_);
  return Track(std::move(frame));
}

void Tracker::SetRig(const RigSetup& setup, const RigSetup& old_setup) {
  const SE3d new_from_old = setup.rig->body_from_camera.Inverse() * rig_->body_from_camera;
  const SE3d old_from_new = new_from_old.Inverse();
  const RigWarp warp(old_setup, setup);
  rig_ = setup.rig;
  builder_.SetRig(rig_);
  map_tracker_.SetRig(rig_);
  if (imu_) imu_->samples().SetNoise(*rig_->imu);
  if (frames_.last.size() > 0 || frames_.last.HasPose())
    frames_.last.Recalibrate(rig_, warp, new_from_old);
  if (Frame* first = starter_.pair_first()) first->Recalibrate(rig_, warp, new_from_old);
  if (frames_.velocity) frames_.velocity = new_from_old * *frames_.velocity * old_from_new;
  records_.MoveCamera(new_from_old);
}

TrackResult Tracker::Track(Frame frame) {
  frame.imu.time_offset_s = time_offset_s_;
  const StepTimer timer;
  double frame_wait_ms = 0;
  frames_.current = std::move(frame);
  mapping_->NoteFrameTime(frames_.current.t_ns());
  if (imu_) PreintegrateImu();
  TrackResult result;
  bool new_keyframe = false;

  if (state_ == TrackingState::kNotInitialized) {
    StartMap();
    new_keyframe = state_ == TrackingState::kOk;
    if (new_keyframe) result.keyframe_reason = "initialisation";
  } else {
    bool ok = false;
    SelectorInput selector_input;
    // Live emulation (offline runs): whether local mapping takes keyframes at this frame's
    // time. It may block until that is known, so it is asked before the Atlas lock is taken
    // (mapping needs the lock to finish); the wait is not tracking time. Without emulation
    // the selector sees local mapping's state after the frame is tracked, as ORB-SLAM3.
    const auto wait_start = std::chrono::steady_clock::now();
    const bool emulated = mapping_->EmulatesLive();
    const bool idle_at_frame = emulated && mapping_->AcceptsKeyFramesAt(frames_.current.t_ns());
    frame_wait_ms = WallMsSince(wait_start);
    {
      auto lock = MapReader(*atlas_).Lock();
      if (imu_) SyncWithInertialMapLocked(/*correct_current=*/false);  // the world tracked in
      // Local mapping may have fused points of the last frame into others meanwhile.
      FollowReplacedPoints(&frames_.last);
      ok = options_.localise_only ? TrackLocalisationOnly() : TrackInMap();
      if (ok) {
        frames_.velocity = frames_.current.camera_from_world() * frames_.last.world_from_camera();
        DropUnmappedMatches(&frames_.current);
      }
      if (ok && !options_.localise_only) {
        selector_input =
            DecideKeyFrame(emulated ? idle_at_frame : mapping_->AcceptsKeyFrames(), &result);
      }
    }
    if (ok) {
      new_keyframe = ActOnDecision(selector_input, &result);
    } else {
      frames_.velocity.reset();
    }
  }

  // Localisation only keeps the loaded map whatever happens: the next frame relocalises.
  if (state_ == TrackingState::kLost && !options_.localise_only) HandleLost();

  double cpu_ms = 0, ms = 0;
  timer.Stop(&cpu_ms, &ms);
  RecordFrame(new_keyframe, ms - frame_wait_ms, cpu_ms);
  records_.back().visual_odometry =
      options_.localise_only && localisation_.visual_odometry() && state_ == TrackingState::kOk;
  result.state = state_;
  result.new_keyframe = new_keyframe;
  result.inliers = frames_.inliers;
  if (frames_.current.HasPose() && state_ == TrackingState::kOk) {
    result.camera_from_world = frames_.current.camera_from_world();
  }
  if (state_ != TrackingState::kNotInitialized) {
    if (!frames_.current.reference_kf) frames_.current.reference_kf = frames_.reference_kf;
    frames_.last = std::move(frames_.current);
  }
  return result;
}

bool Tracker::TrackInMap() {
  const bool imu_ready = ImuReady();
  bool ok = false;
  if (state_ == TrackingState::kOk && imu_ready) {
    ok = map_tracker_.TrackWithImu(records_.back(), &frames_) ||
         map_tracker_.TrackReferenceKeyFrame(&frames_);
  } else if (state_ == TrackingState::kRecentlyLost && imu_ready) {
    // IMU-only prediction; the local map search decides.
    ok = map_tracker_.PredictWithImu(&frames_);
  } else if (state_ == TrackingState::kOk) {
    const bool motion_model = frames_.velocity && !frames_.JustRelocalised();
    ok = (motion_model && map_tracker_.TrackWithMotionModel(records_.back(), &frames_)) ||
         map_tracker_.TrackReferenceKeyFrame(&frames_);
  } else if (state_ == TrackingState::kRecentlyLost) {
    ok = map_tracker_.Relocalise(&frames_);
  }
  if (ok) ok = map_tracker_.TrackLocalMap(state_, imu_ready, &frames_);

  if (ok) {
    state_ = TrackingState::kOk;
  } else if (state_ == TrackingState::kOk) {
    const bool keep = atlas_->current_map()->NumKeyFrames() >
                      options_.MinKeyFramesToKeepMap(IsMonocular(rig_->sensor));
    state_ = keep ? TrackingState::kRecentlyLost : TrackingState::kLost;
    lost_since_t_ns_ = frames_.current.t_ns();
  } else if (state_ == TrackingState::kRecentlyLost &&
             (frames_.current.t_ns() - lost_since_t_ns_) * 1e-9 >
                 options_.recently_lost_timeout_s) {
    state_ = TrackingState::kLost;
  }
  return ok;
}

SelectorInput Tracker::DecideKeyFrame(bool mapping_idle, TrackResult* result) {
  return inserter_.Decide(KeyFrameContextNow(), frames_, mapping_idle,
                          &result->keyframe_declined_queue_full);
}

bool Tracker::ActOnDecision(const SelectorInput& selector_input, TrackResult* result) {
  // Localisation decides nothing; the last decision is an earlier frame's.
  const SelectorDecision* decision = inserter_.DecisionFor(frames_.current.id());
  bool new_keyframe = false;
  if (decision != nullptr && decision->interrupt_local_ba) mapping_->InterruptBundleAdjustment();
  if (decision != nullptr && decision->insert) {
    inserter_.Insert(KeyFrameContextNow(), selector_input, &frames_);
    new_keyframe = true;
  }
  // Outliers went into the keyframe (BA decides on them), not into the next frame's pose.
  DropOutlierMatches(&frames_.current);
  if (decision != nullptr) {
    result->keyframe_reason = decision->reason;
    result->selector_decided = true;
    result->criteria_held = CriteriaHeld(*decision);
  }
  return new_keyframe;
}

std::vector<FrameRecord::Observation> Tracker::LastFrameInliers() const {
  if (state_ != TrackingState::kOk) return {};
  return InlierObservations(frames_.last);
}

void Tracker::RecordFrame(bool keyframe, double ms, double cpu_ms) {
  FrameRecord r;
  r.t_ns = frames_.current.t_ns();
  r.frame_id = frames_.current.id();
  r.state = state_;
  r.keyframe = keyframe;
  r.tracking_ms = build_ms_ + ms;
  r.tracking_cpu_ms = cpu_ms;
  r.build_cpu_ms = build_cpu_ms_;
  r.inliers = frames_.inliers;
  const KeyFramePtr& ref =
      frames_.current.reference_kf ? frames_.current.reference_kf : frames_.reference_kf;
  // Inertial: RECENTLY_LOST frames carry the IMU prediction and are recorded too.
  const bool posed =
      state_ == TrackingState::kOk || (imu_ != nullptr && state_ == TrackingState::kRecentlyLost);
  if (posed && frames_.current.HasPose() && ref) {
    auto lock = MapReader(*atlas_).Lock();
    if (imu_) SyncWithInertialMapLocked(/*correct_current=*/true);
    records_.SetPose(ref, keyframe, &frames_.current, &r);
  }
  records_.Add(std::move(r));
}

void Tracker::HandleLost() {
  int keyframes = 0;
  {
    auto lock = MapReader(*atlas_).Lock();
    keyframes = atlas_->current_map()->NumKeyFrames();
  }
  if (keyframes <= options_.MinKeyFramesToKeepMap(IsMonocular(rig_->sensor))) {
    PKSLAM_LOG_WARN("tracking lost at t = {:.3f} s with {} keyframes: resetting the map",
                    frames_.current.t_s(), keyframes);
    Reset();
    return;
  }
  PKSLAM_LOG_WARN("tracking lost at t = {:.3f} s: starting a new map", frames_.current.t_s());
  mapping_->ResetQueue();
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kReset);
    atlas_->CreateNewMap(lock);
  }
  StartOver();
}

void Tracker::Reset() {
  mapping_->ResetQueue();
  {
    auto lock = MapEditor(atlas_).Write(MapEdit::kReset);
    // Records of the dropped map lose their reference (those frames end up without pose).
    Map* map = atlas_->current_map();
    records_.Forget(map);
    frames_.last.map_points.assign(frames_.last.map_points.size(), nullptr);
    frames_.current.map_points.assign(frames_.current.map_points.size(), nullptr);
    map_tracker_.local_map().Clear();
    frames_.reference_kf.reset();
    frames_.last_kf.reset();
    frames_.current.reference_kf.reset();
    frames_.last.reference_kf.reset();
    atlas_->ResetCurrentMap(lock);
  }
  StartOver();
}

void Tracker::StartOver() {
  state_ = TrackingState::kNotInitialized;
  frames_.velocity.reset();
  starter_.Reset();
  frames_.reference_kf.reset();
  frames_.last_kf.reset();
  map_tracker_.local_map().Clear();
  selector_->Reset();
}

}  // namespace pkslam
