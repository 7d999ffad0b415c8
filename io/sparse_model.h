// The sparse model of a run (RUN/sparse_model.txt): the final keyframes of the largest map with
// their keypoints and which map point each keypoint observes, and the map points with their
// observations. Written by `pkslam run` (system/sparse_model_builder.h), read by
// `pkslam export-colmap`.
//
// Text format (one record per line, '#' lines are comments):
//   pkslam_sparse_model 1
//   camera W H fx fy cx cy bf          the ideal pinhole of the keypoints (rectified left camera
//                                      for stereo; camera1 without distortion otherwise);
//                                      bf = fx * baseline (0 for monocular)
//   keyframes N
//   keyframe ID T_NS tx ty tz qx qy qz qw K     camera_from_world; then K keypoint lines:
//   U V OCTAVE POINT_ID                undistorted pixel, pyramid level, map point id or -1
//   points M
//   point ID X Y Z N KF_1 IDX_1 ... KF_N IDX_N   world position; N observations (keyframe id,
//                                               keypoint index)
// Keyframes are in id order, points in id order; every observation names a listed keyframe
// and a keypoint whose POINT_ID is this point, and vice versa (the reader checks).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <utility>
#include <vector>

#include "core/geometry/se3.h"

namespace pkslam {

struct SparseKeypoint {
  float u = 0, v = 0;          // undistorted / rectified pixel
  int octave = 0;              // pyramid level
  std::int64_t point_id = -1;  // observed map point, -1 = none
};

struct SparseKeyframe {
  std::int64_t id = 0;
  std::int64_t t_ns = 0;
  SE3d camera_from_world;
  std::vector<SparseKeypoint> keypoints;
};

struct SparsePoint {
  std::int64_t id = 0;
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();
  std::vector<std::pair<std::int64_t, int>> observations;  // (keyframe id, keypoint index)
};

struct SparseCamera {
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  double bf = 0;
};

struct SparseModel {
  SparseCamera camera;
  std::vector<SparseKeyframe> keyframes;  // id order
  std::vector<SparsePoint> points;        // id order
  std::filesystem::path source;           // the file it was read from (for messages)

  // Throws Error on broken cross references (see the format notes).
  void CheckConsistency() const;
};

// Throws Error when the file cannot be written.
void WriteSparseModel(const SparseModel& model, const std::filesystem::path& file);
// Throws InputError naming the file and line for malformed or inconsistent content.
SparseModel ReadSparseModel(const std::filesystem::path& file);

}  // namespace pkslam
