// The public API (api/include/pkslam/pkslam.h) over SlamSystem, the evaluator and the
// simulator.
#include "pkslam/pkslam.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "core/sensor/sensor.h"
#include "core/util/error.h"
#include "evaluation/evaluate.h"
#include "io/rigid_transform_file.h"
#include "io/settings.h"
#include "map_model/keyframe.h"
#include "sim/simulation_request.h"
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

SE3d ToSE3(const Eigen::Matrix4d& m, const char* what) {
  if (const auto problem = FindRigidTransformProblem(m)) {
    throw std::invalid_argument(fmt::format("{}: {}", what, problem->what));
  }
  return SE3d(SO3d(Eigen::Matrix3d(m.topLeftCorner<3, 3>())), m.topRightCorner<3, 1>());
}

// An 8-bit image of the settings' size as the grey image tracking reads (BGR converted).
cv::Mat GreyImage(const cv::Mat& image, const char* what, const CameraModel& camera) {
  if (image.empty()) throw std::invalid_argument(fmt::format("{}: empty image", what));
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw std::invalid_argument(fmt::format(
        "{}: expected 8-bit grey or BGR, got {} channel(s) of {}", what, image.channels(),
        image.depth() == CV_16U ? "16-bit" : image.depth() == CV_32F ? "float" : "another type"));
  }
  if (image.cols != camera.width() || image.rows != camera.height()) {
    throw std::invalid_argument(fmt::format("{}: {}x{} image, but the settings' camera is {}x{}",
                                            what, image.cols, image.rows, camera.width(),
                                            camera.height()));
  }
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

cv::Mat DepthImage(const cv::Mat& depth, const CameraModel& camera) {
  if (depth.empty()) throw std::invalid_argument("depth: empty image");
  if (depth.channels() != 1 || (depth.depth() != CV_16U && depth.depth() != CV_32F)) {
    throw std::invalid_argument("depth: expected one channel of uint16 (scaled by the settings' "
                                "depth factor) or float32 metres");
  }
  if (depth.cols != camera.width() || depth.rows != camera.height()) {
    throw std::invalid_argument(fmt::format("depth: {}x{} image, but the settings' camera is {}x{}",
                                            depth.cols, depth.rows, camera.width(),
                                            camera.height()));
  }
  return depth;
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
  // What the system was made from, so Reset() can make it again.
  Settings settings;
  std::shared_ptr<const Vocabulary> vocabulary;
  SystemOptions options;
  Sensor sensor = Sensor::kStereo;
  TrackResult last;
  bool shut_down = false;
  std::optional<std::int64_t> last_frame_t_ns;
  std::optional<std::int64_t> last_imu_t_ns;

  const CameraModel& camera() const { return system->settings().camera1; }
  // Before each frame: tracking is still open and time goes forward (a frame before the
  // previous one came back as an unsorted trajectory).
  void CheckFrame(std::int64_t t_ns) {
    if (shut_down) throw std::invalid_argument("Slam: tracking after Shutdown()");
    if (last_frame_t_ns && t_ns <= *last_frame_t_ns) {
      throw std::invalid_argument(fmt::format(
          "t_ns: {} is not after the previous frame's {}", t_ns, *last_frame_t_ns));
    }
    last_frame_t_ns = t_ns;
  }
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
    system.selector_parameters = options.selector_parameters;
    if (!options.deterministic) system.mapping_sync = "free";  // a live caller
    impl_->settings = settings;
    impl_->vocabulary = LoadRunVocabulary(run);
    impl_->options = system;
    impl_->system = std::make_unique<SlamSystem>(settings, impl_->vocabulary, system);
    impl_->sensor = *sensor;
    return 0;
  });
}

Slam::~Slam() = default;

SlamState Slam::TrackMonocular(const cv::Mat& image, std::int64_t t_ns) {
  const cv::Mat grey = GreyImage(image, "image", impl_->camera());
  impl_->CheckFrame(t_ns);
  return Guard([&] {
    impl_->last = impl_->system->TrackMonocular(grey, t_ns);
    return ToApi(impl_->last.state);
  });
}

SlamState Slam::TrackStereo(const cv::Mat& left, const cv::Mat& right, std::int64_t t_ns) {
  const cv::Mat left_grey = GreyImage(left, "left", impl_->camera());
  const cv::Mat right_grey = GreyImage(right, "right", impl_->camera());
  impl_->CheckFrame(t_ns);
  return Guard([&] {
    impl_->last = impl_->system->TrackStereo(left_grey, right_grey, t_ns);
    return ToApi(impl_->last.state);
  });
}

SlamState Slam::TrackRgbd(const cv::Mat& image, const cv::Mat& depth, std::int64_t t_ns) {
  const cv::Mat grey = GreyImage(image, "image", impl_->camera());
  const cv::Mat checked_depth = DepthImage(depth, impl_->camera());
  impl_->CheckFrame(t_ns);
  return Guard([&] {
    impl_->last = impl_->system->TrackRgbd(grey, checked_depth, t_ns);
    return ToApi(impl_->last.state);
  });
}

void Slam::AddImu(const std::vector<ImuSample>& samples) {
  if (impl_->shut_down) throw std::invalid_argument("Slam: AddImu after Shutdown()");
  std::vector<ImuMeasurement> m;
  m.reserve(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const ImuSample& s = samples[i];
    // Checked here, where the caller can see which sample: downstream a NaN failed only at the
    // next frame's preintegration.
    if (!s.gyro.allFinite() || !s.accel.allFinite()) {
      throw std::invalid_argument(fmt::format("IMU sample {} (t_ns {}): not finite", i, s.t_ns));
    }
    if (impl_->last_imu_t_ns && s.t_ns <= *impl_->last_imu_t_ns) {
      throw std::invalid_argument(fmt::format("IMU sample {}: t_ns {} is not after the previous "
                                              "sample's {}",
                                              i, s.t_ns, *impl_->last_imu_t_ns));
    }
    impl_->last_imu_t_ns = s.t_ns;
    m.push_back({s.t_ns, s.gyro, s.accel});
  }
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

std::vector<MapPoint> Slam::MapPoints() const {
  std::vector<MapPoint> out;
  for (const auto& p : impl_->system->MapPoints()) {
    out.push_back({p.id, p.world_position, p.observations});
  }
  return out;
}

std::vector<KeyFrame> Slam::KeyFrames() const {
  std::vector<KeyFrame> out;
  for (const auto& k : impl_->system->KeyFrames()) {
    out.push_back({k.id, k.t_ns, k.world_from_camera.Matrix()});
  }
  return out;
}

std::vector<TrackedKeypoint> Slam::TrackedKeypoints() const {
  std::vector<TrackedKeypoint> out;
  for (const auto& o : impl_->system->TrackedObservations()) out.push_back({o.u, o.v, o.point});
  return out;
}

void Slam::SetLocalisationMode(bool on) {
  if (impl_->shut_down) throw std::invalid_argument("Slam: SetLocalisationMode after Shutdown()");
  impl_->system->SetLocalisationMode(on);
}

bool Slam::LocalisationMode() const { return impl_->system->localisation_mode(); }

void Slam::Reset() {
  Guard([&] {
    // The old system's threads stop before the new one starts (one set of threads at a time).
    impl_->system->Shutdown();
    impl_->system.reset();
    impl_->system =
        std::make_unique<SlamSystem>(impl_->settings, impl_->vocabulary, impl_->options);
    return 0;
  });
  impl_->last = TrackResult{};
  impl_->shut_down = false;
  impl_->last_frame_t_ns.reset();
  impl_->last_imu_t_ns.reset();
}

std::string Slam::Selector() const { return impl_->system->selector_name(); }

std::map<std::string, double> Slam::SelectorParameters() const {
  return impl_->system->selector_parameters();
}

void Slam::SaveMap(const std::string& file) const {
  Guard([&] { return impl_->system->SaveMap(file); });
}

void Slam::LoadMap(const std::string& file) {
  Guard([&] { return impl_->system->LoadMap(file); });
}

void Slam::Shutdown() {
  impl_->system->Shutdown();
  impl_->shut_down = true;
}

std::vector<StampedPose> Slam::CameraTrajectory() const {
  return ToApi(impl_->system->FrameTrajectory());
}

std::vector<StampedBodyPose> Slam::BodyTrajectory() const {
  if (impl_->sensor == Sensor::kMonocular) {
    throw std::runtime_error(
        "BodyTrajectory: a visual monocular map has no metric scale for the camera-body lever "
        "arm; compare CameraTrajectory() with Evaluate(..., body_from_camera)");
  }
  const SE3d camera_from_body = impl_->system->rig().body_from_camera.Inverse();
  std::vector<StampedBodyPose> out;
  for (const pkslam::StampedPose& p : impl_->system->FrameTrajectory().poses) {
    out.push_back({p.t_ns, (p.pose * camera_from_body).Matrix()});
  }
  return out;
}

Eigen::Matrix4d Slam::BodyFromCamera() const {
  return impl_->system->rig().body_from_camera.Matrix();
}

std::vector<StampedPose> Slam::KeyFrameTrajectory() const {
  return ToApi(impl_->system->KeyFrameTrajectory());
}

namespace {

// As `pkslam eval` reads and pairs (repeated stamps kept, one-to-one association), so the two
// agree to the last digit on the same files.
Evaluation EvaluateAgainst(const std::string& ground_truth_file, const pkslam::Trajectory& est,
                           const std::string& align,
                           const std::optional<Eigen::Matrix4d>& body_from_camera) {
  EvaluationOptions options;
  options.alignment = ParseAlignmentMethod(align);
  pkslam::Trajectory gt = ReadTrajectory(ground_truth_file, TrajectoryFormat::kAuto,
                                         DuplicateTimestamps::kKeepAll);
  if (body_from_camera) gt = ChangeSensorFrame(gt, ToSE3(*body_from_camera, "body_from_camera"));
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
                    const std::string& align,
                    const std::optional<Eigen::Matrix4d>& body_from_camera) {
  return Guard([&] {
    return EvaluateAgainst(ground_truth_file,
                           ReadTrajectory(estimate_file, TrajectoryFormat::kAuto,
                                          DuplicateTimestamps::kKeepAll),
                           align, body_from_camera);
  });
}

Evaluation Evaluate(const std::string& ground_truth_file, const std::vector<StampedPose>& estimate,
                    const std::string& align,
                    const std::optional<Eigen::Matrix4d>& body_from_camera) {
  pkslam::Trajectory est;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    est.poses.push_back({estimate[i].t_ns, ToSE3(estimate[i].world_from_camera,
                                                 fmt::format("estimate pose {}", i).c_str())});
  }
  return Guard([&] { return EvaluateAgainst(ground_truth_file, est, align, body_from_camera); });
}

Evaluation Evaluate(const std::string& ground_truth_file,
                    const std::vector<StampedBodyPose>& estimate, const std::string& align) {
  pkslam::Trajectory est;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    est.poses.push_back({estimate[i].t_ns, ToSE3(estimate[i].world_from_body,
                                                 fmt::format("estimate pose {}", i).c_str())});
  }
  return Guard([&] { return EvaluateAgainst(ground_truth_file, est, align, std::nullopt); });
}

SimulateSummary Simulate(const SimulateOptions& options) {
  sim::SimulationRequest request;
  sim::SimulationOptions& o = request.options;
  o.scene = options.scene;
  o.output_dir = options.out;
  o.trajectory = options.trajectory;
  o.duration_s = options.duration_s;
  o.start_s = options.start_s;
  o.seed = options.seed;
  o.camera = options.camera;
  o.rgbd = options.rgbd;
  o.quiet = options.quiet;
  request.motion = options.motion;
  request.quality = options.quality;
  request.realism.preset = options.realism;
  request.realism.off = options.realism_off;
  request.realism.params = options.realism_params;
  request.realism.device_seed = options.device_seed;
  request.cloud = options.cloud;
  request.imu_noise = options.imu_noise;
  if (options.out.empty()) throw std::invalid_argument("out: an output folder is needed");
  if (!options.trajectory.empty() && !std::filesystem::is_regular_file(options.trajectory)) {
    throw std::invalid_argument(fmt::format("trajectory: {} is not a file", options.trajectory));
  }
  const sim::SimulationSummary s = Guard([&] {
    try {
      return sim::Simulate(request);
    } catch (const OptionError& e) {
      throw std::invalid_argument(e.what());
    }
  });
  SimulateSummary out;
  out.layout = s.layout;
  out.frames = s.frames;
  out.imu_samples = s.imu_samples;
  out.duration_s = 1e-9 * static_cast<double>(s.end_ns - s.begin_ns);
  out.path_length_m = s.path_length_m;
  return out;
}

}  // namespace pkslam::api
