#include "rgbd/planar_frame.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <set>

#include "core/util/error.h"
#include "rgbd/test_scene.h"

namespace pkslam::rgbd {
namespace {

// A segment on the plane with the given normal through `centre`, covering `box`.
MergeInput Segment(const Eigen::Vector3d& normal, const Eigen::Vector3d& centre, cv::Rect box) {
  const Eigen::Vector3d n = normal.normalized();
  const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a);
  MergeInput s;
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j)
      s.moments.Add(centre + 0.02 * (i - 4.5) * a + 0.02 * (j - 4.5) * b);
  }
  s.plane = *s.moments.Fit(PlaneFitMethod::kPca);
  s.rms_m = s.moments.RmsDistance(s.plane);
  s.bbox = box;
  return s;
}

Eigen::Vector3d Tilted(double degrees) {
  const double r = degrees * M_PI / 180;
  return {std::sin(r), 0, -std::cos(r)};
}

TEST(MergeSegments, MergesNeighboursWhoseNormalsAgreeWithinTheAngle) {
  // A - B touch (10 deg apart), B - C touch (70 deg from B), D is far away (parallel to A).
  const std::vector<MergeInput> segments = {
      Segment(Tilted(0), {0, 0, 2}, cv::Rect(0, 0, 10, 10)),
      Segment(Tilted(10), {0.2, 0, 2}, cv::Rect(10, 0, 10, 10)),
      Segment(Tilted(80), {0.4, 0, 2}, cv::Rect(20, 0, 10, 10)),
      Segment(Tilted(0), {0, 0.5, 2}, cv::Rect(100, 100, 10, 10))};
  PlanarFrameOptions options;
  options.fit = PlaneFitMethod::kPca;
  options.merge_max_fit_rms_m = 0.05;
  options.merge_angle_deg = 45;
  auto groups = MergeSegments(segments, options);
  ASSERT_EQ(groups.size(), 3u);
  EXPECT_EQ(groups[0], (std::vector<int>{0, 1}));
  EXPECT_EQ(groups[1], (std::vector<int>{2}));
  EXPECT_EQ(groups[2], (std::vector<int>{3}));
  options.merge_angle_deg = 5;
  EXPECT_EQ(MergeSegments(segments, options).size(), 4u);
  options.merge_angle_deg = 85;  // now B-C agree, but the merged fit error is too large
  options.merge_max_fit_rms_m = 0.01;
  groups = MergeSegments(segments, options);
  EXPECT_EQ(groups.size(), 3u);
}

TEST(MergeSegments, ParallelPlanesAtDifferentDepthsStayApart) {
  const std::vector<MergeInput> segments = {
      Segment(Tilted(0), {0, 0, 2}, cv::Rect(0, 0, 10, 10)),
      Segment(Tilted(0), {0.2, 0, 2.3}, cv::Rect(10, 0, 10, 10))};
  PlanarFrameOptions options;
  EXPECT_EQ(MergeSegments(segments, options).size(), 2u);
}

TEST(MergeSegments, SmallSegmentOffALargePlaneStaysApart) {
  // A large wall (100 x the points of the small one) and a small parallel patch 5 cm in front:
  // the union's RMS stays below 2 cm (the wall dominates it) but the patch is off the plane.
  MergeInput wall = Segment(Tilted(0), {0, 0, 2}, cv::Rect(0, 0, 10, 10));
  for (int k = 0; k < 99; ++k) wall.moments.Add(Segment(Tilted(0), {0, 0, 2}, {}).moments);
  const MergeInput patch = Segment(Tilted(0), {0.2, 0, 1.95}, cv::Rect(10, 0, 10, 10));
  PointMoments both = wall.moments;
  both.Add(patch.moments);
  PlanarFrameOptions options;
  ASSERT_LT(both.RmsDistance(*both.Fit(options.fit)), options.merge_max_fit_rms_m);
  EXPECT_EQ(MergeSegments({wall, patch}, options).size(), 2u);
  options.merge_max_fit_rms_m = 0.06;  // a 5 cm step is within this tolerance
  EXPECT_EQ(MergeSegments({wall, patch}, options).size(), 1u);
}

TEST(MergeSegments, BoxesTouchingOnlyAtACornerAreNeighbours) {
  const std::vector<MergeInput> segments = {
      Segment(Tilted(0), {0, 0, 2}, cv::Rect(0, 0, 10, 10)),
      Segment(Tilted(0), {0.2, 0.2, 2}, cv::Rect(10, 10, 10, 10)),
      Segment(Tilted(0), {0.4, 0.4, 2}, cv::Rect(22, 22, 10, 10))};  // a 2-pixel gap
  PlanarFrameOptions options;
  const auto groups = MergeSegments(segments, options);
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0], (std::vector<int>{0, 1}));
}

TEST(BuildPlanarFrame, RoomViewGivesPlanesAndSamplesOnThem) {
  const CameraModel camera = testing::TestCamera();
  const auto view = testing::RenderRoom(camera, testing::PathPose(0), 0.003, 5);
  PlanarFrameOptions options;
  const PlanarFrame frame =
      BuildPlanarFrame(view.colour_bgr, view.depth_m, DepthLifter(camera), options);
  EXPECT_GT(frame.segments, 20);                   // one per colour block at least
  EXPECT_LT(frame.planes, frame.segments_fitted);  // merging joined blocks of the same face
  EXPECT_GT(frame.planes, 3);
  EXPECT_LT(frame.dropped_fraction, 0.05);
  std::size_t expected_samples = 0;
  std::set<int> used;
  for (const PlanarSegment& s : frame.planar) {
    expected_samples += std::min<std::size_t>(s.point_ids.size(), 200);
    EXPECT_EQ(static_cast<int>(s.point_ids.size()), s.points);
    for (const int id : s.point_ids) EXPECT_TRUE(used.insert(id).second);  // disjoint
  }
  EXPECT_EQ(frame.samples.size(), expected_samples);
  // Each sample lies on some plane (it was projected onto its own).
  for (std::size_t i = 0; i < frame.samples.size(); i += 37) {
    double best = 1e9;
    for (const PlanarSegment& s : frame.planar) {
      best = std::min(best, std::abs(s.plane.SignedDistance(frame.samples[i].cast<double>())));
    }
    EXPECT_LT(best, 1e-5);
  }
  // The largest plane is flat (a wall of the room).
  const auto largest =
      std::max_element(frame.planar.begin(), frame.planar.end(),
                       [](const auto& a, const auto& b) { return a.points < b.points; });
  EXPECT_LT(largest->rms_m, 0.01);
  EXPECT_GT(frame.segmentation_ms, 0.0);
}

TEST(BuildPlanarFrame, SmallPlanesCanBeLeftOutOfTheSamples) {
  const CameraModel camera = testing::TestCamera();
  const auto view = testing::RenderRoom(camera, testing::PathPose(0), 0.003, 5);
  PlanarFrameOptions options;
  const PlanarFrame all =
      BuildPlanarFrame(view.colour_bgr, view.depth_m, DepthLifter(camera), options);
  options.min_sampled_plane_points = 500;
  const PlanarFrame large =
      BuildPlanarFrame(view.colour_bgr, view.depth_m, DepthLifter(camera), options);
  EXPECT_EQ(all.planes, large.planes);  // the same planes; only the sampling differs
  EXPECT_EQ(all.sampled_planes, all.planes);
  std::size_t expected = 0;
  int sampled = 0;
  for (const PlanarSegment& s : large.planar) {
    if (s.point_ids.size() < 500) continue;
    expected += std::min<std::size_t>(s.point_ids.size(), 200);
    ++sampled;
  }
  EXPECT_GT(sampled, 0);
  EXPECT_LT(sampled, large.planes);
  EXPECT_EQ(large.sampled_planes, sampled);
  EXPECT_EQ(large.samples.size(), expected);
}

TEST(BuildPlanarFrame, KMeansBaselineProducesPlanesWithoutMerging) {
  const CameraModel camera = testing::TestCamera();
  const auto view = testing::RenderRoom(camera, testing::PathPose(0));
  PlanarFrameOptions options;
  options.segmentation = SegmentationMethod::kKMeans;
  options.kmeans_clusters = 40;
  options.kmeans_stride = 4;
  const PlanarFrame frame =
      BuildPlanarFrame(view.colour_bgr, view.depth_m, DepthLifter(camera), options);
  EXPECT_EQ(frame.segments, 40);
  EXPECT_EQ(frame.planes, frame.segments_fitted);
  EXPECT_GT(frame.planes, 30);
  EXPECT_FALSE(frame.samples.empty());
}

TEST(PlanarFrameOptions, RejectsBadValues) {
  PlanarFrameOptions options;
  options.merge_angle_deg = 120;
  EXPECT_THROW(options.Check(), OptionError);
  EXPECT_THROW(ParseSegmentationMethod("som"), OptionError);
}

}  // namespace
}  // namespace pkslam::rgbd
