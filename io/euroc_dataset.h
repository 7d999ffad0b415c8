// EuRoC ASL dataset reader: ROOT/mav0/{cam0,cam1,imu0,state_groundtruth_estimate0}, each with
// sensor.yaml and data.csv. Lists, IMU and ground truth are read and validated up front;
// images are loaded lazily (LoadCam0/LoadCam1). Image rows whose file is missing are counted,
// reported in one warning and skipped. An EurocDataset is immutable after Open and may be
// read from several threads.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/geometry/se3.h"
#include "io/dataset_common.h"
#include "io/euroc_sensor.h"

namespace pkslam {

// Plausibility limits of IMU samples: beyond them a value is not a measurement in rad/s and
// m/s^2. Defaults: the widest MEMS ranges (2000 deg/s, 50 g); EuRoC's ADIS16448 measures up
// to 1000 deg/s and 18 g.
struct ImuLimits {
  double max_gyro_rad_s = 35.0;
  double max_accel_m_s2 = 490.0;

  void Check() const;
};

struct EurocOptions {
  // Read imu0/ when present.
  bool read_imu = true;
  // Read state_groundtruth_estimate0/data.csv when present.
  bool read_ground_truth = true;
  // An IMU interval longer than this many nominal periods is reported as a gap (not fatal).
  double imu_gap_periods = 2.5;
  // A camera interval longer than this many nominal periods is reported as a frame gap.
  double frame_gap_periods = 1.5;
  ImuLimits imu_limits;

  void Check() const;
};

// One row of state_groundtruth_estimate0/data.csv.
struct EurocGroundTruthState {
  std::int64_t t_ns = 0;
  SE3d world_from_body;                                      // p_RS_R, q_RS (w, x, y, z)
  Eigen::Vector3d velocity_world = Eigen::Vector3d::Zero();  // v_RS_R [m/s]
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();       // b_w_RS_S [rad/s]
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();      // b_a_RS_S [m/s^2]
};

// A stereo frame: cam0 and cam1 images with the same timestamp (exact match).
struct StereoPair {
  std::int64_t t_ns = 0;
  std::size_t left = 0;   // index into cam0().images
  std::size_t right = 0;  // index into cam1().images
};

class EurocDataset {
 public:
  // `root` is the sequence directory (containing mav0/) or mav0/ itself. Throws InputError
  // (file, line) for missing/empty/malformed files, wrong column counts, non-increasing or
  // duplicate timestamps; OptionError for bad options.
  static EurocDataset Open(const std::filesystem::path& root, const EurocOptions& options = {});
  // Image streams that did not come from an EuRoC folder (a KITTI sequence, io/kitti_dataset.h):
  // no sensor files, no IMU, no ground truth; `root` names the dataset in messages.
  static EurocDataset FromImageStreams(const std::filesystem::path& root, ImageStream cam0,
                                       std::optional<ImageStream> cam1);
  // True if `root` has the EuRoC layout (mav0/cam0/data.csv or cam0/data.csv).
  static bool LooksLikeEuroc(const std::filesystem::path& root);

  const std::filesystem::path& mav0() const { return mav0_; }

  const EurocCameraSensor& cam0_sensor() const { return cam0_sensor_; }
  const ImageStream& cam0() const { return cam0_; }
  bool has_cam1() const { return cam1_.has_value(); }
  const EurocCameraSensor& cam1_sensor() const;  // requires has_cam1()
  const ImageStream& cam1() const;               // requires has_cam1()
  // Exact-timestamp matches among usable (existing) cam0/cam1 images, time-ordered.
  const std::vector<StereoPair>& stereo_pairs() const { return stereo_pairs_; }

  bool has_imu() const { return imu_sensor_.has_value(); }
  const EurocImuSensor& imu_sensor() const;  // requires has_imu()
  const std::vector<ImuSample>& imu() const { return imu_; }
  const std::vector<TimeGap>& imu_gaps() const { return imu_gaps_; }
  // Samples with t0_ns < t <= t1_ns (what a frame at t1 integrates after a frame at t0).
  std::vector<ImuSample> ImuBetween(std::int64_t t0_ns, std::int64_t t1_ns) const;

  bool has_ground_truth() const { return !ground_truth_.empty(); }
  const std::vector<EurocGroundTruthState>& ground_truth() const { return ground_truth_; }

  // Load image i of cam0().images / cam1().images as 8-bit grey. Throws InputError naming the
  // file when it has vanished or is corrupt; Error when i is out of range.
  cv::Mat LoadCam0(std::size_t i) const;
  cv::Mat LoadCam1(std::size_t i) const;

 private:
  EurocDataset() = default;

  std::filesystem::path mav0_;
  EurocCameraSensor cam0_sensor_;
  ImageStream cam0_;
  std::optional<EurocCameraSensor> cam1_sensor_;
  std::optional<ImageStream> cam1_;
  std::vector<StereoPair> stereo_pairs_;
  std::optional<EurocImuSensor> imu_sensor_;
  std::vector<ImuSample> imu_;
  std::vector<TimeGap> imu_gaps_;
  std::vector<EurocGroundTruthState> ground_truth_;
};

// Lower-level readers (also used by tests and tools). Each throws InputError(file, line).
// data.csv of a camera: "#timestamp [ns],filename"; paths are resolved against image_dir.
std::vector<ImageEntry> ReadEurocImageList(const std::filesystem::path& data_csv,
                                           const std::filesystem::path& image_dir);
// imu0/data.csv: t_ns, w_x, w_y, w_z [rad/s], a_x, a_y, a_z [m/s^2].
// Samples beyond `limits` (or not finite) are errors naming the line.
std::vector<ImuSample> ReadEurocImu(const std::filesystem::path& data_csv,
                                    const ImuLimits& limits = {});
// state_groundtruth_estimate0/data.csv: t_ns, p(3), q(w,x,y,z), v(3), b_w(3), b_a(3).
std::vector<EurocGroundTruthState> ReadEurocGroundTruth(const std::filesystem::path& data_csv);

}  // namespace pkslam
