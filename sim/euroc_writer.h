// Writes a sequence in the EuRoC ASL layout, byte-compatible with the real dataset's text
// files (same headers, units, naming; see ../shared/data/euroc/V1_01_easy_static):
//   DIR/mav0/body.yaml
//   DIR/mav0/camK/{sensor.yaml, data.csv, data/<t_ns>.png}
//   DIR/mav0/imu0/{sensor.yaml, data.csv}
//   DIR/mav0/state_groundtruth_estimate0/{sensor.yaml, data.csv}   (17 columns)
// plus DIR/timestamps.txt (image timestamps, one per line, as ORB-SLAM3's EuRoC examples use).
// Threads: an EurocWriter is used by one thread; only WritePng may run elsewhere.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"
#include "sim/imu_simulator.h"

namespace pkslam::sim {

struct CameraRig {
  std::string name = "cam0";
  CameraModel camera;
  SE3d body_from_camera;  // EuRoC's T_BS
  double rate_hz = 20.0;
};

// EuRoC's cam0 / cam1 calibration (from the dataset's sensor.yaml files).
CameraRig EurocCam0();
CameraRig EurocCam1();
// The stereo rig of EuRoC-format output by --camera: "euroc" (EuRoC's cam0/cam1, 752x480),
// "kitti" (KITTI odometry's grey pair: 1241x376, f 718.856 px, 0.537 m baseline, no
// distortion), "vga" (640x480 with TUM's default Kinect intrinsics, 0.11 m baseline, no
// distortion), "tumvi" (TUM-VI's 512x512 Kannala-Brandt fisheye pair with its own extrinsics).
// kitti and vga are mounted like EuRoC's cam0; OptionError for other names.
std::vector<CameraRig> StereoRig(const std::string& camera);
// ORB features per image the camera's ORB-SLAM3 settings use (EuRoC 1200, KITTI 2000, TUM and
// TUM-VI 1000).
int OrbFeaturesFor(const std::string& camera);

// One row of state_groundtruth_estimate0/data.csv.
struct GroundTruthRow {
  std::int64_t t_ns = 0;
  SE3d world_from_body;
  Eigen::Vector3d velocity_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();
};

// Doubles as the shortest text that reads back exactly, always with a decimal point
// ("1.0", "0.0148655429818", "1.76187114e-05").
std::string FormatDouble(double v);

class EurocWriter {
 public:
  // Creates DIR/mav0/... (DIR may exist; existing files are overwritten). Throws Error when
  // the directories cannot be created.
  EurocWriter(const std::filesystem::path& dir, const std::vector<CameraRig>& cameras,
              const ImuOptions& imu, bool write_imu);

  // Writes camK/data/<t_ns>.png and its data.csv row. Rows must come in time order.
  void WriteImage(int camera, std::int64_t t_ns, const cv::Mat& image);
  // The same in two steps, so PNG encoding can run on another thread: AddImage writes the
  // csv rows (in order, on the owning thread) and returns the file to WritePng() into.
  std::filesystem::path AddImage(int camera, std::int64_t t_ns);
  void WriteImu(const ImuSample& sample);
  void WriteGroundTruth(const GroundTruthRow& row);
  // Diagnostics beside a sequence whose files carry realism errors (sim/realism.h): DIR/truth/
  // with the exact calibration (camK_sensor.yaml, same layout as mav0/camK/sensor.yaml), the
  // exact ground truth (state_groundtruth_exact.csv, same columns as the written one), the
  // exposure times of the frames (frame_times.csv: image stamp, mid-exposure time on the IMU
  // clock, exposure length) and the drawn errors (realism_draw.yaml).
  void OpenTruth(const std::vector<CameraRig>& true_cameras, const std::string& draw_yaml);
  void WriteExactGroundTruth(const GroundTruthRow& row);
  void WriteFrameTime(std::int64_t stamp_ns, std::int64_t exposure_mid_ns, double exposure_s);
  // Flushes and closes all files; throws Error on a write failure. Called by the destructor
  // too (which swallows errors).
  void Close();
  ~EurocWriter();

  std::filesystem::path mav0() const { return dir_ / "mav0"; }

 private:
  std::filesystem::path dir_;
  std::vector<std::ofstream> camera_csv_;
  std::ofstream imu_csv_;
  std::ofstream gt_csv_;
  std::ofstream exact_gt_csv_;  // truth/ (OpenTruth)
  std::ofstream frame_times_;   // truth/ (OpenTruth)
  std::ofstream timestamps_;
  std::int64_t last_timestamp_ = -1;
  bool closed_ = false;
};

// zlib level of EuRoC-layout images: 0 (stored, not deflated), as the real EuRoC files are
// (752 x 480 grey: 362,136 bytes). Decoding a level-1 file of the simulator's noisy images took
// 3 times as long (about 11 ms against 4 ms), a quarter of a stereo-inertial run's CPU time,
// which real data does not cost.
inline constexpr int kEurocPngCompression = 0;

// Writes `image` as PNG with zlib `compression` 0-9 (fixed, so the bytes are reproducible);
// throws Error on failure. Thread-safe (no shared state).
void WritePng(const std::filesystem::path& file, const cv::Mat& image, int compression = 1);

}  // namespace pkslam::sim
