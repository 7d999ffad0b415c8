// Test fixture: a synthetic scene of 3-D points with distinct descriptors seen by a set of
// cameras, turned into Frames / KeyFrames / MapPoints with consistent observations. Used by
// matcher, optimiser, tracking and mapping tests (test-only library pkslam_core_testing).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "core/features/descriptor.h"
#include "core/geometry/se3.h"
#include "core/sensor/camera_rig.h"
#include "map_model/atlas.h"
#include "map_model/frame.h"

namespace pkslam::testing {

// A 752x480 ideal pinhole rig (EuRoC-like rectified: fx = fy = 435, baseline 0.11 m),
// 8 levels, scale 1.2, th_depth = 35 * baseline.
std::shared_ptr<CameraRig> MakeStereoRig(Sensor sensor = Sensor::kStereo);

struct SyntheticScene {
  std::vector<Eigen::Vector3d> points_world;
  std::vector<Descriptor> descriptors;  // one random descriptor per point
  std::vector<int> octaves;             // a fixed pyramid level per point
};

// n points uniformly in a box [-w, w] x [-h, h] x [z0, z1] (world = first camera frame).
SyntheticScene MakeScene(int n, std::uint64_t seed, double w = 4.0, double h = 2.5, double z0 = 3.0,
                         double z1 = 8.0);

struct FrameOptions {
  double pixel_noise = 0.0;      // Gaussian sigma (pixels) added to keypoints
  int descriptor_bit_flips = 0;  // bits flipped per descriptor (appearance change)
  bool stereo = true;            // fill right_u/depth for points with depth
  double outlier_fraction = 0;   // share of keypoints moved to a random place
  std::uint64_t seed = 1;
};

// A frame seeing the scene from camera_from_world. point_of_keypoint[i] = scene point index
// of keypoint i. The frame's pose is NOT set (callers decide).
Frame MakeFrame(const SyntheticScene& scene, const std::shared_ptr<const CameraRig>& rig,
                const SE3d& camera_from_world, FrameId id, std::int64_t t_ns,
                const FrameOptions& options, std::vector<int>* point_of_keypoint);

// Builds a map: one keyframe per pose (true poses), a map point per scene point seen by at
// least two keyframes, observations, descriptors, normals and covisibility. Returns the
// keyframes in order; points are reachable from the map. Takes the Atlas lock itself.
struct SyntheticMap {
  std::vector<KeyFramePtr> keyframes;
  std::vector<MapPointPtr> point_of_scene_index;  // nullptr where no map point was made
  std::vector<std::vector<int>> keypoint_points;  // per keyframe: scene index per keypoint
};
SyntheticMap MakeMap(Atlas* atlas, const SyntheticScene& scene,
                     const std::shared_ptr<const CameraRig>& rig,
                     const std::vector<SE3d>& camera_from_world, const FrameOptions& options);

// Camera poses on a smooth path looking roughly along +z (small rotations), step metres.
std::vector<SE3d> MakeForwardPath(int n, double step, std::uint64_t seed);

}  // namespace pkslam::testing
