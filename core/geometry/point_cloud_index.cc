#include "core/geometry/point_cloud_index.h"

#include <nanoflann.hpp>

namespace pkslam {
namespace {

struct CloudAdaptor {
  std::vector<Eigen::Vector3f> points;
  std::size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const { return points[i][dim]; }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox& /*bb*/) const {
    return false;
  }
};

using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, CloudAdaptor>,
                                        CloudAdaptor, 3, int>;

}  // namespace

struct PointCloudIndex::Impl {
  Impl(std::vector<Eigen::Vector3f> p, int leaf_size)
      : cloud{std::move(p)}, tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(leaf_size)) {}
  CloudAdaptor cloud;
  KdTree tree;  // references `cloud`; both live and move together inside the Impl
};

PointCloudIndex::PointCloudIndex(std::vector<Eigen::Vector3f> points, int leaf_size)
    : impl_(std::make_unique<Impl>(std::move(points), leaf_size)) {}
PointCloudIndex::~PointCloudIndex() = default;
PointCloudIndex::PointCloudIndex(PointCloudIndex&&) noexcept = default;
PointCloudIndex& PointCloudIndex::operator=(PointCloudIndex&&) noexcept = default;

const std::vector<Eigen::Vector3f>& PointCloudIndex::points() const { return impl_->cloud.points; }

std::pair<int, float> PointCloudIndex::Nearest(const Eigen::Vector3f& query) const {
  if (impl_->cloud.points.empty()) return {-1, 0.0f};
  int index = -1;
  float distance2 = 0;
  nanoflann::KNNResultSet<float, int> result(1);
  result.init(&index, &distance2);
  impl_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams(0));
  return {index, distance2};
}

}  // namespace pkslam
