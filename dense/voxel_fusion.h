// Fusion of per-keyframe point sets in a sparse voxel grid: every voxel averages the
// positions and colours of the points that fall into it and counts the distinct views
// (keyframes) that put a point there. The multi-view consistency filter keeps only voxels
// confirmed by at least `min_views` views: a surface patch two keyframes agree on to within a
// voxel, where stereo outliers and depth-edge artefacts of a single view do not survive.
//
// Not thread-safe: one thread adds views (the dense driver computes depth maps in parallel
// and fuses them in keyframe order, so the result does not depend on the thread count).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "io/point_cloud.h"

namespace pkslam::dense {

class VoxelGrid {
 public:
  // Voxel side in metres (> 0; throws OptionError otherwise).
  explicit VoxelGrid(double voxel_m);

  // Adds the points (world frame) of one view. `colours` is empty or one per point. `support`
  // is empty (1 each) or one per point: the keyframes that agreed on that depth (itself
  // included, dense/depth_consistency.h); a voxel averages its points weighted by support, so
  // confirmed, averaged depths outweigh single-view ones. A view's points must arrive in one
  // call or in consecutive calls with the same `view` id; a view id that comes back later
  // counts as a new view. Points beyond +-2^20 voxels from the origin throw Error.
  void AddView(int view, const std::vector<Eigen::Vector3f>& points,
               const std::vector<Rgb>& colours, const std::vector<std::uint8_t>& support = {});

  std::size_t NumVoxels() const { return voxels_.size(); }
  double voxel_m() const { return voxel_m_; }

  // One point per voxel seen by >= min_views views: support-weighted mean position and colour
  // (when colours were given), views = the larger of the distinct views that put a point
  // there and the largest support of its points (capped at 255; 1 = one keyframe's
  // unconfirmed depth); ordered by voxel index (deterministic).
  PointCloud Extract(int min_views) const;

  // Voxel count per number of views (index v: voxels seen by exactly v views; last bin
  // collects >= its index). For reporting.
  std::vector<std::size_t> ViewHistogram(int max_views) const;

 private:
  struct Voxel {
    float offset_sum[3] = {0, 0, 0};  // weighted sum of (point - voxel corner), metres
    float colour_sum[3] = {0, 0, 0};  // weighted
    float weight = 0;
    std::int32_t last_view = -1;
    std::uint16_t views = 0;
    std::uint8_t support = 0;  // largest point support
  };

  double voxel_m_;
  bool has_colour_ = false;
  std::unordered_map<std::uint64_t, Voxel> voxels_;
};

}  // namespace pkslam::dense
