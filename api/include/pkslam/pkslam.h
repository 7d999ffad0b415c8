// pkslam as a library: the one public header of the installed package
// (find_package(pkslam) -> pkslam::pkslam). A SLAM system made from an ORB-SLAM3 settings file
// and a vocabulary; feed it images (and IMU samples) with timestamps, read the pose and the
// tracking state, save and load maps, get the trajectories. Everything else in pkslam is
// internal to the library (namespace pkslam::api keeps these names apart from it).
//
//   pkslam::api::SlamOptions options;
//   options.settings = "cam.yaml";
//   options.vocabulary = "ORBvoc.bin";
//   options.sensor = "stereo";
//   pkslam::api::Slam slam(options);
//   for (...) slam.TrackStereo(left, right, t_ns);
//   slam.Shutdown();
//   for (const pkslam::api::StampedBodyPose& p : slam.BodyTrajectory()) ...
// While it runs: MapPoints(), KeyFrames(), TrackedKeypoints(), SetLocalisationMode(), Reset().
// Evaluate() measures a trajectory against ground truth; Simulate() renders a sequence to try it
// on.
//
// Frames: camera trajectories hold world_from_camera (the left camera), body trajectories
// world_from_body (the IMU: what EuRoC ground truth describes). Every name says which.
//
// Threads: one Slam per caller thread; it runs its own local-mapping and loop-closing threads.
// Errors: std::invalid_argument for a bad argument (naming it: an image of the wrong size or
// type, a frame time that does not increase, a non-finite IMU sample, a call after Shutdown),
// std::runtime_error with a one-line message for everything else (bad files name the file).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>
#include <vector>

namespace pkslam::api {

inline constexpr const char* kApiVersion = "0.3.0";

enum class SlamState { kNotInitialized, kOk, kRecentlyLost, kLost };
const char* SlamStateName(SlamState state);

struct StampedPose {
  std::int64_t t_ns = 0;
  Eigen::Matrix4d world_from_camera = Eigen::Matrix4d::Identity();
};

struct StampedBodyPose {
  std::int64_t t_ns = 0;
  Eigen::Matrix4d world_from_body = Eigen::Matrix4d::Identity();
};

struct ImuSample {
  std::int64_t t_ns = 0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();   // rad/s
  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  // m/s^2
};

// A map point of the largest map: its world position and how many keyframes observe it.
struct MapPoint {
  std::int64_t id = 0;
  Eigen::Vector3d world_position = Eigen::Vector3d::Zero();
  int observations = 0;
};

// A keyframe of the largest map.
struct KeyFrame {
  std::int64_t id = 0;
  std::int64_t t_ns = 0;
  Eigen::Matrix4d world_from_camera = Eigen::Matrix4d::Identity();
};

// A keypoint of the last frame that tracking matched to a map point and kept as an inlier of
// the pose: its undistorted pixel in the left (or only) image, and the point's id.
struct TrackedKeypoint {
  float u = 0, v = 0;
  std::int64_t map_point_id = 0;
};

struct SlamOptions {
  std::string settings;    // ORB-SLAM3 v1.0 settings file (camera, ORB, IMU)
  std::string vocabulary;  // DBoW2 text or pkslam binary vocabulary
  // mono | stereo | rgbd | mono-inertial | stereo-inertial | rgbd-inertial
  std::string sensor = "stereo";
  std::string selector = "orbslam3";  // keyframe selector (orbslam3, pks, pks-released, ...)
  // Selector parameters over the settings' Keyframe.* values (docs/keyframe_selectors.md), e.g.
  // {"delta", 30} for PKS; a name the selector does not know is an error.
  std::map<std::string, double> selector_parameters;
  bool deterministic = false;         // fixed seeds, local mapping in lock-step
  bool localise_only = false;         // with LoadMap before the first frame
  bool loop_closing = true;
};

class Slam {
 public:
  explicit Slam(const SlamOptions& options);
  ~Slam();
  Slam(const Slam&) = delete;
  Slam& operator=(const Slam&) = delete;

  // Images: 8-bit grey or BGR (converted to grey), of the settings' size; depth: 16-bit
  // (settings' depth factor) or 32-bit float metres. Stereo pairs raw or rectified, as the
  // settings describe the rig. Frame times must increase. Inertial sensors: add the IMU samples
  // up to (a little past) each frame's time first.
  SlamState TrackMonocular(const cv::Mat& image, std::int64_t t_ns);
  SlamState TrackStereo(const cv::Mat& left, const cv::Mat& right, std::int64_t t_ns);
  SlamState TrackRgbd(const cv::Mat& image, const cv::Mat& depth, std::int64_t t_ns);
  void AddImu(const std::vector<ImuSample>& samples);

  SlamState state() const;
  // world_from_camera of the last frame when it was tracked.
  std::optional<Eigen::Matrix4d> CurrentPose() const;
  int NumKeyFrames() const;
  int NumMapPoints() const;
  // The largest map (the one the outputs describe), copied: safe while tracking goes on.
  std::vector<MapPoint> MapPoints() const;
  std::vector<KeyFrame> KeyFrames() const;
  // The last frame's tracked keypoints (empty when it was not tracked).
  std::vector<TrackedKeypoint> TrackedKeypoints() const;

  // Localisation mode (ORB-SLAM3's ActivateLocalizationMode / DeactivateLocalizationMode): from
  // the next frame on, track against the current map without making keyframes, so the map no
  // longer grows; off again, mapping resumes. Inertial sensors track visually while it is on.
  void SetLocalisationMode(bool on);
  bool LocalisationMode() const;
  // Forget everything (maps, trajectory, IMU queue) and start again with the same options, as
  // ORB-SLAM3's Reset(): the next frame initialises a new map; frame times may start over.
  void Reset();
  // The keyframe selector and the parameters it was given (settings' Keyframe.* with
  // SlamOptions::selector_parameters over them; unlisted parameters are at its defaults).
  std::string Selector() const;
  std::map<std::string, double> SelectorParameters() const;

  // Map files (docs/maps.md): SaveMap after Shutdown for the final map; LoadMap before the
  // first frame.
  void SaveMap(const std::string& file) const;
  void LoadMap(const std::string& file);

  // Finishes local mapping and loop closing (idempotent; the destructor calls it). Tracking
  // after it is an error.
  void Shutdown();
  // Every tracked frame, re-expressed through its keyframe's final pose: as camera poses, and as
  // body poses (camera poses moved by BodyFromCamera(); not for visual monocular maps, whose
  // unknown scale does not fit the metric lever arm: compare their camera poses with
  // Evaluate(..., body_from_camera)). The keyframes as camera poses.
  std::vector<StampedPose> CameraTrajectory() const;
  std::vector<StampedBodyPose> BodyTrajectory() const;
  std::vector<StampedPose> KeyFrameTrajectory() const;
  [[deprecated("ambiguous frame: use CameraTrajectory() or BodyTrajectory()")]]
  std::vector<StampedPose> Trajectory() const { return CameraTrajectory(); }
  // The rig's camera-to-body transform (the settings' IMU.T_b_c1; identity without an IMU).
  Eigen::Matrix4d BodyFromCamera() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// ATE / RPE of an estimate against ground truth (`pkslam eval`, evo-compatible): associate by
// time (max 10 ms), align ("se3", "sim3", "posyaw", "none"), RPE over 1-frame pairs. The ground
// truth and the estimate are files (TUM, EuRoC csv or ORB-SLAM3 format, detected) or poses.
// Camera poses against body ground truth need `body_from_camera` (the truth is moved into the
// camera, as `pkslam eval --body-from-camera`); without it such a pair is refused with that hint
// (a near-constant orientation offset), never measured as if the frames were the same.
struct Evaluation {
  std::size_t pairs = 0;
  double scale = 1.0;  // of the alignment (1 unless sim3)
  double ate_rmse_m = 0, ate_mean_m = 0, ate_median_m = 0, ate_max_m = 0;
  double ate_rot_rmse_deg = 0;
  double rpe_trans_rmse_m = 0, rpe_rot_rmse_deg = 0;
};
Evaluation Evaluate(const std::string& ground_truth_file, const std::string& estimate_file,
                    const std::string& align = "se3",
                    const std::optional<Eigen::Matrix4d>& body_from_camera = std::nullopt);
Evaluation Evaluate(const std::string& ground_truth_file, const std::vector<StampedPose>& estimate,
                    const std::string& align = "se3",
                    const std::optional<Eigen::Matrix4d>& body_from_camera = std::nullopt);
Evaluation Evaluate(const std::string& ground_truth_file,
                    const std::vector<StampedBodyPose>& estimate, const std::string& align = "se3");

// Renders an EuRoC-format stereo+IMU sequence (or a TUM RGB-D one) with exact ground truth into
// `out`, as `pkslam simulate` does with the same choices (the same bytes for the same seed; its
// --help and docs/realism.md explain each). A bad value raises std::invalid_argument naming it.
struct SimulateOptions {
  std::string out;                  // created if missing
  std::string trajectory;           // replay this ground truth (TUM/EuRoC); empty: random motion
  double duration_s = 10.0;         // 0: a replay to the file's end / 60 s of random motion
  double start_s = 0.0;             // replay: start this far into the file
  std::uint64_t seed = 1;           // same seed, same bytes
  std::string motion = "medium";    // random motion: easy | medium | difficult
  std::string quality = "default";  // fast | default | high
  std::string realism;              // ideal | euroc; empty: euroc for replays, ideal otherwise
  std::vector<std::string> realism_off;     // sources of the euroc preset switched off
  std::vector<std::string> realism_params;  // "NAME=VALUE" size overrides
  std::uint64_t device_seed = 1;            // the rig's errors (one rig for all sequences)
  std::string scene;                        // built-in name or YAML file; empty: by the realism
  std::string camera = "euroc";             // euroc | kitti | vga | tumvi
  bool rgbd = false;                        // TUM RGB-D output instead of EuRoC stereo
  bool cloud = true;                        // reference clouds
  bool imu_noise = true;
  bool quiet = true;  // no progress bar
};
struct SimulateSummary {
  std::string layout;  // "euroc" | "tum_rgbd"
  int frames = 0;
  int imu_samples = 0;
  double duration_s = 0;
  double path_length_m = 0;
};
SimulateSummary Simulate(const SimulateOptions& options);

}  // namespace pkslam::api
