// KITTI odometry sequences (sequences/NN/{image_0,image_1,image_2,image_3,times.txt,calib.txt}
// and poses/NN.txt; Geiger et al., "Are we ready for autonomous driving?", CVPR 2012):
// read as the lists, calibration and ground truth pkslam's runs and evaluation use.
//   times.txt   one time per frame, seconds from the sequence's start
//   calib.txt   "P0: 12 numbers" .. "P3:", "Tr:": 3x4 projection matrices of the rectified
//               cameras (P_k = K [I | t_k], t_k = (-fx b_k, 0, 0) for camera k's baseline b_k
//               to camera 0), row-major
//   image_0/1   grey left/right, image_2/3 colour left/right, NNNNNN.png per frame
//   poses/NN.txt  per frame, world_from_cam0 as 12 numbers (3x4 row-major), world = cam0 of
//               frame 0
// Images are rectified and undistorted: the rig is a rectified pinhole pair.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "io/dataset_common.h"
#include "io/settings.h"
#include "io/trajectory.h"

namespace pkslam {

struct KittiOptions {
  // Colour pair (image_2, image_3) instead of the grey one (image_0, image_1).
  bool colour = false;
};

struct KittiSequence {
  std::filesystem::path root;  // sequences/NN
  ImageStream left;            // image_0 (or image_2)
  ImageStream right;           // image_1 (or image_3); empty when the folder is absent
  // Intrinsics of the rectified left camera and the pair's baseline (m), from calib.txt.
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double baseline_m = 0;
  int width = 0, height = 0;  // of the first left image
  double rate_hz = 0;         // from the median frame interval
  bool colour = false;
};

// True when `root` holds times.txt, calib.txt and image_0/ (or image_2/).
bool LooksLikeKitti(const std::filesystem::path& root);

// Reads times.txt, calib.txt and the image lists. Throws InputError naming the file (and line)
// for a missing or malformed file, times that do not increase, or a left/right projection
// matrix that is not a rectified pair of the left camera.
KittiSequence OpenKittiSequence(const std::filesystem::path& root,
                                const KittiOptions& options = {});

// Times in seconds from times.txt, as nanoseconds (the stamps of the frames and of the ground
// truth).
std::vector<std::int64_t> ReadKittiTimes(const std::filesystem::path& times_txt);

// The run's settings: a rectified pinhole pair (or the left camera alone) with ORB-SLAM3's
// KITTI settings (2000 features, ThDepth 40).
Settings SettingsFromKitti(const KittiSequence& sequence);

// poses/NN.txt with one stamp per line (times.txt): world_from_cam0 per frame. Throws
// InputError naming the file and line for a line without 12 numbers, a non-rigid rotation, or
// a pose count that differs from the stamps'.
Trajectory ReadKittiPoses(const std::filesystem::path& poses_txt,
                          const std::vector<std::int64_t>& t_ns);

// For poses/NN.txt: ../sequences/NN/times.txt when it exists, else empty.
std::filesystem::path KittiTimesFor(const std::filesystem::path& poses_txt);

// Writes world_from_cam0 per pose as 12 numbers per line (KITTI's result format).
void WriteKittiPoses(const Trajectory& trajectory, const std::filesystem::path& file);

}  // namespace pkslam
