#include "rgbd/voxel_map.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "core/util/error.h"
#include "core/util/output_file.h"
#include "io/point_cloud.h"

namespace pkslam::rgbd {
namespace {

constexpr std::int64_t kHalfRange = std::int64_t{1} << 20;  // 21 bits per axis

}  // namespace

VoxelMap::VoxelMap(double voxel_m) : voxel_m_(voxel_m), inverse_voxel_(1.0 / voxel_m) {
  PKSLAM_CHECK_OPTION(voxel_m > 0 && std::isfinite(voxel_m), "voxel", "{} m", voxel_m);
}

std::uint64_t VoxelMap::Key(const Eigen::Vector3d& p) const {
  std::uint64_t key = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double cell = std::floor(p[axis] * inverse_voxel_);
    PKSLAM_CHECK(std::abs(cell) < static_cast<double>(kHalfRange),
                 "point {} m outside the map range", p[axis]);
    key = (key << 21) | static_cast<std::uint64_t>(static_cast<std::int64_t>(cell) + kHalfRange);
  }
  return key;
}

void VoxelMap::Add(const Eigen::Vector3d& p_world, const cv::Vec3b& bgr) {
  Cell& c = voxels_[Key(p_world)];
  c.sum += p_world;
  c.colour_sum += Eigen::Vector3d(bgr[0], bgr[1], bgr[2]);
  ++c.count;
  ++added_;
}

void VoxelMap::AddCloud(const ColouredCloud& cloud, const SE3d& world_from_camera) {
  const Eigen::Matrix3d r = world_from_camera.RotationMatrix();
  const Eigen::Vector3d& t = world_from_camera.translation();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    Add(r * cloud.points[i].cast<double>() + t, cloud.colours[i]);
  }
}

std::vector<VoxelMap::Point> VoxelMap::Points() const {
  std::vector<std::pair<std::uint64_t, const Cell*>> cells;
  cells.reserve(voxels_.size());
  for (const auto& [key, cell] : voxels_) cells.emplace_back(key, &cell);
  std::sort(cells.begin(), cells.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Point> points;
  points.reserve(cells.size());
  for (const auto& [key, cell] : cells) {
    const double n = cell->count;
    const Eigen::Vector3d colour = (cell->colour_sum / n).array().round();
    points.push_back({(cell->sum / n).cast<float>(),
                      cv::Vec3b(static_cast<uchar>(colour[0]), static_cast<uchar>(colour[1]),
                                static_cast<uchar>(colour[2]))});
  }
  return points;
}

void VoxelMap::WritePly(const std::filesystem::path& file) const {
  WriteColouredPly(Points(), file,
                   fmt::format("pkslam rgbd map, world frame, voxel {} m", voxel_m_));
}

void WriteColouredPly(const std::vector<VoxelMap::Point>& points, const std::filesystem::path& file,
                      const std::string& comment) {
  PointCloud cloud;
  cloud.points.reserve(points.size());
  cloud.colours.reserve(points.size());
  for (const auto& p : points) {
    cloud.points.push_back(p.position);
    cloud.colours.push_back({p.bgr[2], p.bgr[1], p.bgr[0]});
  }
  WritePly(cloud, file, PlyColour::kRgb, comment);
}

}  // namespace pkslam::rgbd
