// The public API (api/include/pkslam/pkslam.h) over SlamSystem.
#include "pkslam/pkslam.h"

#include <stdexcept>

#include "core/sensor/sensor.h"
#include "core/util/error.h"
#include "evaluation/evaluate.h"
#include "io/settings.h"
#include "map_model/keyframe.h"
#include "system/run_dataset.h"
#include "system/slam_system.h"

namespace pkslam::api {
namespace {

SlamState ToApi(TrackingState s) {
  switch (s) {
    case TrackingState::kNotInitialized:
      return SlamState::kNotInitialized;
    case TrackingState::kOk:
      return SlamState::kOk;
    case TrackingState::kRecentlyLost:
      return SlamState::kRecentlyLost;
    case TrackingState::kLost:
      return SlamState::kLost;
  }
  return SlamState::kLost;
}

std::vector<StampedPose> ToApi(const Trajectory& trajectory) {
  std::vector<StampedPose> out;
  out.reserve(trajectory.poses.size());
  for (const pkslam::StampedPose& p : trajectory.poses) out.push_back({p.t_ns, p.pose.Matrix()});
  return out;
}

// Internal errors keep their one-line message; the public header promises runtime_error.
template <typename F>
auto Guard(F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const Error& e) {
    throw std::runtime_error(e.what());
  }
}

}  // namespace

const char* SlamStateName(SlamState state) {
  switch (state) {
    case SlamState::kNotInitialized:
      return "NOT_INITIALIZED";
    case SlamState::kOk:
      return "OK";
    case SlamState::kRecentlyLost:
      return "RECENTLY_LOST";
    case SlamState::kLost:
      return "LOST";
  }
  return "?";
}

struct Slam::Impl {
  std::unique_ptr<SlamSystem> system;
  TrackResult last;
};

Slam::Slam(const SlamOptions& options) : impl_(std::make_unique<Impl>()) {
  Guard([&] {
    const auto sensor = ParseSensor(options.sensor);
    if (!sensor) throw OptionError(fmt::format("unknown sensor '{}'", options.sensor));
    const Settings settings = ReadOrbSlam3Settings(options.settings);
    RunOptions run;
    if (!options.vocabulary.empty()) run.vocabulary = options.vocabulary;
    SystemOptions system;
    system.sensor = *sensor;
    system.selector = options.selector;
    system.deterministic = options.deterministic;
    system.no_loop = !options.loop_closing;
    system.tracking.localise_only = options.localise_only;
    if (!options.deterministic) system.mapping_sync = "free";  // a live caller
    impl_->system = std::make_unique<SlamSystem>(settings, LoadRunVocabulary(run), system);
    return 0;
  });
}

Slam::~Slam() = default;

SlamState Slam::TrackMonocular(const cv::Mat& image, std::int64_t t_ns) {
  return Guard([&] {
    impl_->last = impl_->system->TrackMonocular(image, t_ns);
    return ToApi(impl_->last.state);
  });
}

SlamState Slam::TrackStereo(const cv::Mat& left, const cv::Mat& right, std::int64_t t_ns) {
  return Guard([&] {
    impl_->last = impl_->system->TrackStereo(left, right, t_ns);
    return ToApi(impl_->last.state);
  });
}

SlamState Slam::TrackRgbd(const cv::Mat& image, const cv::Mat& depth, std::int64_t t_ns) {
  return Guard([&] {
    impl_->last = impl_->system->TrackRgbd(image, depth, t_ns);
    return ToApi(impl_->last.state);
  });
}

void Slam::AddImu(const std::vector<ImuSample>& samples) {
  std::vector<ImuMeasurement> m;
  m.reserve(samples.size());
  for (const ImuSample& s : samples) m.push_back({s.t_ns, s.gyro, s.accel});
  Guard([&] {
    impl_->system->AddImu(m);
    return 0;
  });
}

SlamState Slam::state() const { return ToApi(impl_->last.state); }

std::optional<Eigen::Matrix4d> Slam::CurrentPose() const {
  if (!impl_->last.camera_from_world) return std::nullopt;
  return impl_->last.camera_from_world->Inverse().Matrix();
}

int Slam::NumKeyFrames() const { return impl_->system->NumKeyFrames(); }
int Slam::NumMapPoints() const { return impl_->system->NumMapPoints(); }

void Slam::SaveMap(const std::string& file) const {
  Guard([&] { return impl_->system->SaveMap(file); });
}

void Slam::LoadMap(const std::string& file) {
  Guard([&] { return impl_->system->LoadMap(file); });
}

void Slam::Shutdown() { impl_->system->Shutdown(); }

std::vector<StampedPose> Slam::Trajectory() const {
  return ToApi(impl_->system->FrameTrajectory());
}

std::vector<StampedPose> Slam::KeyFrameTrajectory() const {
  return ToApi(impl_->system->KeyFrameTrajectory());
}

namespace {

Evaluation EvaluateAgainst(const std::string& ground_truth_file, const pkslam::Trajectory& est,
                           const std::string& align) {
  EvaluationOptions options;
  options.alignment = ParseAlignmentMethod(align);
  const pkslam::Trajectory gt = ReadTrajectory(ground_truth_file);
  const EvaluationResult r = EvaluateTrajectories(gt, est, options);
  Evaluation out;
  out.pairs = r.pairs.size();
  out.scale = r.scale();
  out.ate_rmse_m = r.ate_translation_m.rmse;
  out.ate_mean_m = r.ate_translation_m.mean;
  out.ate_median_m = r.ate_translation_m.median;
  out.ate_max_m = r.ate_translation_m.max;
  out.ate_rot_rmse_deg = r.ate_rotation_deg.rmse;
  if (r.rpe) {
    out.rpe_trans_rmse_m = r.rpe->translation_m.rmse;
    out.rpe_rot_rmse_deg = r.rpe->rotation_deg.rmse;
  }
  return out;
}

}  // namespace

Evaluation Evaluate(const std::string& ground_truth_file, const std::string& estimate_file,
                    const std::string& align) {
  return Guard(
      [&] { return EvaluateAgainst(ground_truth_file, ReadTrajectory(estimate_file), align); });
}

Evaluation Evaluate(const std::string& ground_truth_file, const std::vector<StampedPose>& estimate,
                    const std::string& align) {
  return Guard([&] {
    pkslam::Trajectory est;
    for (const StampedPose& p : estimate) {
      const Eigen::Matrix3d r = p.world_from_camera.topLeftCorner<3, 3>();
      est.poses.push_back({p.t_ns, SE3d(SO3d(r), p.world_from_camera.topRightCorner<3, 1>())});
    }
    return EvaluateAgainst(ground_truth_file, est, align);
  });
}

}  // namespace pkslam::api
