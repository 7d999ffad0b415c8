// Test support: a synthetic RGB-D room (an axis-aligned box with blocky random-coloured walls
// and a box standing in it) rendered exactly by ray casting, and a writer of TUM RGB-D
// folders. Test-only (listed with the tests).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core.hpp>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"

namespace pkslam::rgbd::testing {

// 320x240 pinhole, fx = fy = 260.
CameraModel TestCamera();

struct RenderedView {
  cv::Mat colour_bgr;  // CV_8UC3
  cv::Mat depth_m;     // CV_32FC1, exact z depth
};

// The room seen from world_from_camera (camera optical frame: x right, y down, z forward;
// the world is the room's frame, the room spans x in [-1.6, 1.6], y in [-1.5, 1.2], z in
// [-2.5, 2.0]). depth_noise_m: Gaussian noise sigma added to depth (seeded by `seed`).
RenderedView RenderRoom(const CameraModel& camera, const SE3d& world_from_camera,
                        double depth_noise_m = 0.0, unsigned seed = 1);

// A smooth camera path: camera at frame k (30 Hz), moving sideways and turning slowly.
SE3d PathPose(int k);

// Writes DIR/{rgb,depth}/*.png, rgb.txt, depth.txt, groundtruth.txt and settings.yaml for
// `frames` frames along PathPose. Returns the timestamps in ns.
std::vector<std::int64_t> WriteTumRoom(const std::filesystem::path& dir, int frames,
                                       double depth_noise_m = 0.0);

}  // namespace pkslam::rgbd::testing
