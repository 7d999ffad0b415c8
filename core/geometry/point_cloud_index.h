// Nearest-neighbour queries on a fixed 3-D point set (a nanoflann k-d tree): ICP's pairing in
// rgbd/ and the cloud-to-cloud distances of dense/.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <utility>
#include <vector>

namespace pkslam {

// A k-d tree over a fixed point set (float coordinates). Immutable after construction;
// concurrent queries are safe.
class PointCloudIndex {
 public:
  // `leaf_size`: points per leaf (nanoflann's leaf_max_size; a speed trade-off only, but ties
  // between equally near points may resolve differently with another value).
  explicit PointCloudIndex(std::vector<Eigen::Vector3f> points, int leaf_size = 16);
  ~PointCloudIndex();
  PointCloudIndex(PointCloudIndex&&) noexcept;
  PointCloudIndex& operator=(PointCloudIndex&&) noexcept;

  const std::vector<Eigen::Vector3f>& points() const;
  std::size_t size() const { return points().size(); }
  // Index of the nearest point and its squared distance; index -1 for an empty cloud.
  std::pair<int, float> Nearest(const Eigen::Vector3f& query) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pkslam
