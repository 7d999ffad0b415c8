// An EuRoC folder written again in KITTI odometry's layout (io/kitti_dataset.h): `pkslam simulate
// --camera kitti` writes both, so the KITTI reader, runs and `eval --kitti` are tested end to
// end on sequences with exact ground truth.
#pragma once

#include <filesystem>
#include <string>

namespace pkslam {

// From the EuRoC folder `euroc_root` (a rectified pinhole stereo pair: cam0 and cam1 with the
// same intrinsics, no distortion, cam1 along cam0's x axis; ground truth), writes
//   kitti_root/sequences/NAME/{image_0, image_1}/NNNNNN.png (hard links to the EuRoC images, or
//   copies where links are impossible), times.txt (seconds from the first stereo pair),
//   calib.txt (P0..P3, Tr)
//   kitti_root/poses/NAME.txt (world_from_cam0 relative to the first frame's cam0)
// Throws InputError naming the sensor file when the rig is not a rectified pair, or the ground
// truth file when a frame has no ground-truth sample within 2.5 ms.
void WriteKittiLayoutFromEuroc(const std::filesystem::path& euroc_root,
                               const std::filesystem::path& kitti_root, const std::string& name);

}  // namespace pkslam
