#include "dense/voxel_fusion.h"

#include <algorithm>
#include <cmath>

#include "core/util/error.h"

namespace pkslam::dense {
namespace {

constexpr std::int64_t kHalfRange = std::int64_t{1} << 20;  // 21 bits per axis

std::uint64_t PackKey(std::int64_t i, std::int64_t j, std::int64_t k) {
  return (static_cast<std::uint64_t>(i + kHalfRange) << 42) |
         (static_cast<std::uint64_t>(j + kHalfRange) << 21) |
         static_cast<std::uint64_t>(k + kHalfRange);
}

Eigen::Vector3i UnpackKey(std::uint64_t key) {
  constexpr std::uint64_t mask = (std::uint64_t{1} << 21) - 1;
  return {static_cast<int>(static_cast<std::int64_t>((key >> 42) & mask) - kHalfRange),
          static_cast<int>(static_cast<std::int64_t>((key >> 21) & mask) - kHalfRange),
          static_cast<int>(static_cast<std::int64_t>(key & mask) - kHalfRange)};
}

}  // namespace

VoxelGrid::VoxelGrid(double voxel_m) : voxel_m_(voxel_m) {
  PKSLAM_CHECK_OPTION(voxel_m > 0 && std::isfinite(voxel_m), "--voxel", "{} m", voxel_m);
}

void VoxelGrid::AddView(int view, const std::vector<Eigen::Vector3f>& points,
                        const std::vector<Rgb>& colours, const std::vector<std::uint8_t>& support) {
  PKSLAM_CHECK(view >= 0, "view id {} < 0", view);
  PKSLAM_CHECK(colours.empty() || colours.size() == points.size(), "{} colours for {} points",
               colours.size(), points.size());
  PKSLAM_CHECK(support.empty() || support.size() == points.size(), "{} supports for {} points",
               support.size(), points.size());
  if (!colours.empty()) has_colour_ = true;
  const double inv = 1.0 / voxel_m_;
  for (std::size_t n = 0; n < points.size(); ++n) {
    const Eigen::Vector3f& p = points[n];
    const std::int64_t i = static_cast<std::int64_t>(std::floor(p.x() * inv));
    const std::int64_t j = static_cast<std::int64_t>(std::floor(p.y() * inv));
    const std::int64_t k = static_cast<std::int64_t>(std::floor(p.z() * inv));
    PKSLAM_CHECK(std::abs(i) < kHalfRange && std::abs(j) < kHalfRange && std::abs(k) < kHalfRange,
                 "point ({}, {}, {}) is outside the voxel grid's range", p.x(), p.y(), p.z());
    Voxel& v = voxels_[PackKey(i, j, k)];
    const std::uint8_t s = support.empty() ? 1 : std::max<std::uint8_t>(support[n], 1);
    const float w = s;
    v.offset_sum[0] += w * static_cast<float>(p.x() - static_cast<double>(i) * voxel_m_);
    v.offset_sum[1] += w * static_cast<float>(p.y() - static_cast<double>(j) * voxel_m_);
    v.offset_sum[2] += w * static_cast<float>(p.z() - static_cast<double>(k) * voxel_m_);
    if (!colours.empty()) {
      for (int c = 0; c < 3; ++c) v.colour_sum[c] += w * colours[n][c];
    }
    v.weight += w;
    v.support = std::max(v.support, s);
    if (v.last_view != view) {
      v.last_view = view;
      if (v.views < UINT16_MAX) ++v.views;
    }
  }
}

PointCloud VoxelGrid::Extract(int min_views) const {
  std::vector<std::uint64_t> keys;
  keys.reserve(voxels_.size());
  for (const auto& [key, voxel] : voxels_) {
    if (voxel.views >= min_views) keys.push_back(key);
  }
  std::sort(keys.begin(), keys.end());
  PointCloud cloud;
  cloud.points.reserve(keys.size());
  cloud.views.reserve(keys.size());
  if (has_colour_) cloud.colours.reserve(keys.size());
  for (std::uint64_t key : keys) {
    const Voxel& v = voxels_.at(key);
    const Eigen::Vector3i ijk = UnpackKey(key);
    const double n = v.weight;
    Eigen::Vector3f p;
    for (int a = 0; a < 3; ++a) {
      p[a] = static_cast<float>(ijk[a] * voxel_m_ + v.offset_sum[a] / n);
    }
    cloud.points.push_back(p);
    cloud.views.push_back(
        static_cast<std::uint8_t>(std::min<int>(std::max<int>(v.views, v.support), 255)));
    if (has_colour_) {
      Rgb c;
      for (int a = 0; a < 3; ++a) {
        c[a] = static_cast<std::uint8_t>(std::lround(v.colour_sum[a] / n));
      }
      cloud.colours.push_back(c);
    }
  }
  return cloud;
}

std::vector<std::size_t> VoxelGrid::ViewHistogram(int max_views) const {
  PKSLAM_CHECK(max_views >= 1, "max_views {}", max_views);
  std::vector<std::size_t> histogram(static_cast<std::size_t>(max_views) + 1, 0);
  for (const auto& [key, voxel] : voxels_) {
    ++histogram[std::min<int>(voxel.views, max_views)];
  }
  return histogram;
}

}  // namespace pkslam::dense
