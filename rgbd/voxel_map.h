// Voxel-grid coloured map (seed 000, step 7): points from all frames, in the world frame, are
// merged per cubic voxel (mean position and mean colour), which downsamples the model to the
// voxel size (the thesis compares 1, 5 and 10 cm) and bounds its memory.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <unordered_map>

#include "core/geometry/se3.h"
#include "rgbd/depth_cloud.h"

namespace pkslam::rgbd {

class VoxelMap {
 public:
  // voxel_m > 0. Coordinates beyond +-2^20 voxels from the origin are rejected (Error).
  explicit VoxelMap(double voxel_m);

  double voxel_m() const { return voxel_m_; }
  // Number of occupied voxels (points in the output).
  std::size_t size() const { return voxels_.size(); }
  // Points added so far (before merging).
  std::uint64_t points_added() const { return added_; }

  void Add(const Eigen::Vector3d& p_world, const cv::Vec3b& bgr);
  // Every point of a camera-frame cloud, moved to the world by world_from_camera.
  void AddCloud(const ColouredCloud& cloud, const SE3d& world_from_camera);

  struct Point {
    Eigen::Vector3f position;
    cv::Vec3b bgr;
  };
  // One point per voxel (mean position and colour), in voxel-key order (deterministic).
  std::vector<Point> Points() const;

  // Binary little-endian PLY: float x y z, uchar red green blue. Throws Error when the file
  // cannot be written.
  void WritePly(const std::filesystem::path& file) const;

 private:
  struct Cell {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Vector3d colour_sum = Eigen::Vector3d::Zero();  // B, G, R
    std::uint32_t count = 0;
  };
  std::uint64_t Key(const Eigen::Vector3d& p) const;

  double voxel_m_;
  double inverse_voxel_;
  std::uint64_t added_ = 0;
  std::unordered_map<std::uint64_t, Cell> voxels_;
};

// Writes coloured points as binary little-endian PLY (as VoxelMap::WritePly).
void WriteColouredPly(const std::vector<VoxelMap::Point>& points, const std::filesystem::path& file,
                      const std::string& comment);

}  // namespace pkslam::rgbd
