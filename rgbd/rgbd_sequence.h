// Input side shared by `pkslam rgbd-odometry` and `pkslam planar`: a TUM RGB-D folder (real,
// or the simulator's --rgbd output) with its camera and ground truth, loaded frame by frame,
// and the evaluation helpers both commands use.
//
// Camera intrinsics, in order: --settings FILE; DIR/settings.yaml (the simulator writes one);
// for real TUM folders named rgbd_dataset_freiburg{1,2,3}_* the published calibration of that
// Kinect (TUM's ROS defaults for fr3, whose images are already undistorted). Otherwise an
// InputError asks for --settings.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"
#include "io/trajectory.h"
#include "io/tum_rgbd_dataset.h"

namespace pkslam::rgbd {

struct RgbdSequenceOptions {
  std::filesystem::path dataset;
  std::optional<std::filesystem::path> settings;
  // Depth PNG value per metre; 0 = the dataset's (settings.yaml or TUM's 5000).
  double depth_factor = 0;
  // Listed images whose files are missing: false = InputError naming the first one; true =
  // skip them (the frame pairs that remain are processed).
  bool skip_missing = false;
  // Process at most this many frames (0 = all), starting at `first_frame`.
  int max_frames = 0;
  int first_frame = 0;

  void Check() const;
};

struct RgbdSequence {
  TumRgbdDataset dataset;
  CameraModel camera;
  std::string camera_source;               // where the intrinsics came from (for logs, stats)
  std::optional<Trajectory> ground_truth;  // world_from_camera, when groundtruth.txt exists
  std::vector<std::size_t> frames;         // association indices to process, in order

  std::size_t size() const { return frames.size(); }
};

// Throws InputError for a missing folder, unreadable lists/settings, missing images (unless
// skip_missing) and a camera whose size differs from the images'.
RgbdSequence OpenRgbdSequence(const RgbdSequenceOptions& options);

struct RgbdFrame {
  std::int64_t t_ns = 0;  // the colour image's timestamp
  cv::Mat colour_bgr;     // CV_8UC3
  cv::Mat depth_m;        // CV_32FC1 metres, 0 = none
};

// The k-th frame of the sequence (k < size()). Throws InputError for an unreadable image or
// colour/depth sizes that differ from the camera's.
RgbdFrame LoadRgbdFrame(const RgbdSequence& sequence, std::size_t k);

// Ground-truth pose at t_ns, interpolated between the bracketing poses when they are at most
// max_gap_ns apart (exact matches need no interpolation); nullopt otherwise.
std::optional<SE3d> InterpolatePose(const Trajectory& trajectory, std::int64_t t_ns,
                                    std::int64_t max_gap_ns = 100'000'000);

// Error of a relative motion estimate against the truth: |translation| [m] and angle [deg] of
// truth^-1 * estimate.
struct RelativePoseError {
  double translation_m = 0;
  double rotation_deg = 0;
};
RelativePoseError CompareRelativePose(const SE3d& estimate, const SE3d& truth);

}  // namespace pkslam::rgbd
