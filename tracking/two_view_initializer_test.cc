// Monocular two-view initialisation on synthetic scenes (map_model/testing/synthetic_map.h):
// general and planar scenes, degenerate motions, outliers and determinism.
#include "tracking/two_view_initializer.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/util/error.h"
#include "map_model/testing/synthetic_map.h"

namespace pkslam {
namespace {

using testing::FrameOptions;
using testing::SyntheticScene;

struct TwoViewCase {
  Frame first, second;
  std::vector<int> matches12;
  std::vector<int> point_of_keypoint1;
  SE3d camera2_from_camera1;
  SyntheticScene scene;
};

// Camera 1 = world. Matches pair the keypoints of the same scene point (those of the second
// frame moved by its outlier_fraction become wrong matches).
TwoViewCase MakeCase(SyntheticScene scene, const SE3d& camera2_from_camera1, double pixel_noise,
                     double outlier_fraction = 0.0) {
  TwoViewCase c;
  c.scene = std::move(scene);
  c.camera2_from_camera1 = camera2_from_camera1;
  auto rig = testing::MakeStereoRig(Sensor::kMonocular);
  FrameOptions o1;
  o1.pixel_noise = pixel_noise;
  o1.stereo = false;
  o1.seed = 3;
  FrameOptions o2 = o1;
  o2.seed = 4;
  o2.outlier_fraction = outlier_fraction;
  std::vector<int> point_of_keypoint2;
  c.first = testing::MakeFrame(c.scene, rig, SE3d(), 0, 0, o1, &c.point_of_keypoint1);
  c.second = testing::MakeFrame(c.scene, rig, camera2_from_camera1, 1, 50'000'000, o2,
                                &point_of_keypoint2);
  std::vector<int> keypoint2_of_point(c.scene.points_world.size(), -1);
  for (int i2 = 0; i2 < static_cast<int>(point_of_keypoint2.size()); ++i2) {
    keypoint2_of_point[point_of_keypoint2[i2]] = i2;
  }
  c.matches12.assign(c.first.size(), -1);
  for (int i1 = 0; i1 < c.first.size(); ++i1) {
    c.matches12[i1] = keypoint2_of_point[c.point_of_keypoint1[i1]];
  }
  return c;
}

// Points on the plane z = 5 + 0.4 x + 0.2 y (world = camera 1).
SyntheticScene MakePlanarScene(int n, std::uint64_t seed) {
  SyntheticScene scene = testing::MakeScene(n, seed, 5.0, 3.0, 3.0, 8.0);
  for (auto& p : scene.points_world) p.z() = 5.0 + 0.4 * p.x() + 0.2 * p.y();
  return scene;
}

// camera2_from_camera1 for a camera moved by `position` (in camera 1) and rotated by `angles`.
SE3d Move(const Eigen::Vector3d& position, const Eigen::Vector3d& angles) {
  return SE3d(SO3d::Exp(angles), position).Inverse();
}

struct Errors {
  double rotation_deg = 0;
  double translation_deg = 0;
  double median_point_error = 0;  // relative, after the best scale
  int num_points = 0;
};

Errors Evaluate(const TwoViewCase& c, const TwoViewResult& r) {
  Errors e;
  const SE3d delta = r.camera2_from_camera1 * c.camera2_from_camera1.Inverse();
  e.rotation_deg = delta.so3().Log().norm() * 180.0 / M_PI;
  const Eigen::Vector3d t_true = c.camera2_from_camera1.translation().normalized();
  const Eigen::Vector3d t_est = r.camera2_from_camera1.translation();
  e.translation_deg =
      std::acos(std::clamp(t_true.dot(t_est) / t_est.norm(), -1.0, 1.0)) * 180.0 / M_PI;
  // Least-squares scale of the estimated points onto the true ones.
  double num = 0, den = 0;
  for (int i = 0; i < c.first.size(); ++i) {
    if (!r.triangulated[i]) continue;
    const Eigen::Vector3d& truth = c.scene.points_world[c.point_of_keypoint1[i]];
    num += r.points[i].dot(truth);
    den += r.points[i].squaredNorm();
  }
  const double scale = den > 0 ? num / den : 0;
  std::vector<double> rel;
  for (int i = 0; i < c.first.size(); ++i) {
    if (!r.triangulated[i]) continue;
    const Eigen::Vector3d& truth = c.scene.points_world[c.point_of_keypoint1[i]];
    rel.push_back((scale * r.points[i] - truth).norm() / truth.norm());
  }
  e.num_points = static_cast<int>(rel.size());
  if (!rel.empty()) {
    std::nth_element(rel.begin(), rel.begin() + rel.size() / 2, rel.end());
    e.median_point_error = rel[rel.size() / 2];
  }
  return e;
}

// Failure context: what the reconstruction saw.
std::string Describe(const TwoViewReport& r) {
  std::string s = fmt::format(
      "{}: matches {} S_H {:.1f} S_F {:.1f} R_H {:.3f} H share {:.3f} inliers {} good [",
      ToString(r.rejection), r.num_matches, r.score_homography, r.score_fundamental,
      r.homography_ratio, r.homography_share, r.num_model_inliers);
  for (std::size_t i = 0; i < r.hypothesis_good.size(); ++i) {
    s += fmt::format(" {}/{:.2f}deg", r.hypothesis_good[i], r.hypothesis_parallax[i]);
  }
  return s + " ]";
}

// Triangulated keypoints whose match in the second frame is not within 5 px of the true
// projection of their scene point (moved there as an outlier).
int CountTriangulatedWrongMatches(const TwoViewCase& c, const TwoViewResult& r) {
  int wrong = 0;
  for (int i1 = 0; i1 < c.first.size(); ++i1) {
    if (!r.triangulated[i1]) continue;
    const Eigen::Vector3d p2 =
        c.camera2_from_camera1 * c.scene.points_world[c.point_of_keypoint1[i1]];
    const auto uv = c.second.rig().camera.Project(p2);
    const cv::Point2f kp = c.second.keypoints_undistorted()[c.matches12[i1]].pt;
    if (!uv || (*uv - Eigen::Vector2d(kp.x, kp.y)).norm() > 5.0) ++wrong;
  }
  return wrong;
}

int CountMatches(const std::vector<int>& matches12) {
  return static_cast<int>(
      std::count_if(matches12.begin(), matches12.end(), [](int m) { return m >= 0; }));
}

TEST(TwoViewInitializer, GeneralSceneUsesFundamentalAndRecoversMotionAndStructure) {
  const TwoViewCase c =
      MakeCase(testing::MakeScene(1500, 21), Move({0.8, 0.05, 0.1}, {0.01, -0.04, 0.02}), 1.0);
  ASSERT_GT(CountMatches(c.matches12), 800);
  TwoViewReport report;
  const auto r = ReconstructTwoView(c.first, c.second, c.matches12, TwoViewOptions{}, &report);
  ASSERT_TRUE(r.has_value()) << Describe(report);
  EXPECT_FALSE(r->used_homography);
  EXPECT_LT(report.homography_ratio, 0.5);
  ASSERT_EQ(r->points.size(), static_cast<std::size_t>(c.first.size()));
  ASSERT_EQ(r->triangulated.size(), static_cast<std::size_t>(c.first.size()));
  const Errors e = Evaluate(c, *r);
  EXPECT_LT(e.rotation_deg, 0.5);
  EXPECT_LT(e.translation_deg, 2.0);
  EXPECT_LT(e.median_point_error, 0.02);
  // Most matches are triangulated (1 px noise: ~16% fail the 1.96 px epipolar gate), and the count
  // is reported consistently.
  EXPECT_GT(e.num_points, 0.8 * CountMatches(c.matches12));
  EXPECT_EQ(e.num_points, r->num_triangulated);
  EXPECT_GT(r->parallax_deg, 1.0);
  EXPECT_NEAR(r->camera2_from_camera1.translation().norm(), 1.0, 1e-9);
}

TEST(TwoViewInitializer, PlanarSceneUsesHomographyAndRecoversMotion) {
  const TwoViewCase c =
      MakeCase(MakePlanarScene(1200, 22), Move({0.6, 0.1, 0.0}, {0.0, -0.05, 0.01}), 1.0);
  TwoViewReport report;
  const auto r = ReconstructTwoView(c.first, c.second, c.matches12, TwoViewOptions{}, &report);
  ASSERT_TRUE(r.has_value()) << Describe(report);
  EXPECT_TRUE(r->used_homography);
  EXPECT_GE(report.homography_share, 0.8);
  EXPECT_EQ(report.hypothesis_good.size(), 8u);
  const Errors e = Evaluate(c, *r);
  EXPECT_LT(e.rotation_deg, 0.5);
  EXPECT_LT(e.translation_deg, 2.0);
  EXPECT_LT(e.median_point_error, 0.02);
}

TEST(TwoViewInitializer, OrbSlamRulesAloneDoNotPickHomographyOnAPlane) {
  // Documents why degenerate_f_share exists: with ORB-SLAM's scoring a degenerate F fits the
  // plane and out-scores H, so R_H < 0.5 and the (meaningless) F is tried instead.
  const TwoViewCase c =
      MakeCase(MakePlanarScene(1200, 22), Move({0.6, 0.1, 0.0}, {0.0, -0.05, 0.01}), 1.0);
  TwoViewOptions options;
  options.refine_iterations = 0;
  options.reject_degenerate_samples = false;
  options.degenerate_f_share = 2.0;
  options.refine_motion = false;
  TwoViewReport report;
  EXPECT_FALSE(ReconstructTwoView(c.first, c.second, c.matches12, options, &report));
  EXPECT_FALSE(report.used_homography);
  EXPECT_LT(report.homography_ratio, 0.5);
  EXPECT_GT(report.homography_share, 0.8) << Describe(report);
}

TEST(TwoViewInitializer, PureRotationIsRejected) {
  const TwoViewCase c =
      MakeCase(testing::MakeScene(1500, 23), Move({0, 0, 0}, {0.02, 0.08, 0.0}), 1.0);
  ASSERT_GT(CountMatches(c.matches12), 500);
  TwoViewReport report;
  EXPECT_FALSE(ReconstructTwoView(c.first, c.second, c.matches12, TwoViewOptions{}, &report));
  EXPECT_NE(report.rejection, TwoViewRejection::kNone);
  EXPECT_NE(report.rejection, TwoViewRejection::kTooFewMatches);
}

TEST(TwoViewInitializer, TinyBaselineIsRejected) {
  const TwoViewCase c =
      MakeCase(testing::MakeScene(1500, 24), Move({0.01, 0.0, 0.0}, {0.0, 0.01, 0.0}), 1.0);
  TwoViewReport report;
  EXPECT_FALSE(ReconstructTwoView(c.first, c.second, c.matches12, TwoViewOptions{}, &report));
  EXPECT_NE(report.rejection, TwoViewRejection::kNone);
  EXPECT_NE(report.rejection, TwoViewRejection::kTooFewMatches);
}

TEST(TwoViewInitializer, MinParallaxOptionDecides) {
  // ~2-4 degrees of parallax: accepted at 1 degree, refused at 10.
  const TwoViewCase c =
      MakeCase(testing::MakeScene(1500, 25), Move({0.3, 0.0, 0.0}, {0.0, 0.02, 0.0}), 0.5);
  TwoViewOptions options;
  const auto accepted = ReconstructTwoView(c.first, c.second, c.matches12, options);
  ASSERT_TRUE(accepted.has_value());
  EXPECT_GT(accepted->parallax_deg, 1.0);
  EXPECT_LT(accepted->parallax_deg, 10.0);
  options.min_parallax_deg = 10.0;
  TwoViewReport report;
  EXPECT_FALSE(ReconstructTwoView(c.first, c.second, c.matches12, options, &report));
  EXPECT_EQ(report.rejection, TwoViewRejection::kLowParallax);
}

TEST(TwoViewInitializer, TwentyPercentOutliersStillCorrect) {
  const TwoViewCase c = MakeCase(testing::MakeScene(1500, 26),
                                 Move({0.8, -0.05, 0.1}, {-0.01, -0.04, 0.0}), 1.0, 0.2);
  TwoViewReport report;
  const auto r = ReconstructTwoView(c.first, c.second, c.matches12, TwoViewOptions{}, &report);
  ASSERT_TRUE(r.has_value()) << Describe(report);
  EXPECT_FALSE(r->used_homography);
  const Errors e = Evaluate(c, *r);
  EXPECT_LT(e.rotation_deg, 0.5);
  EXPECT_LT(e.translation_deg, 2.0);
  EXPECT_LT(e.median_point_error, 0.02);
  // ~80% true matches of which ~84% pass the 1.96 px epipolar gates at 1 px noise.
  const int matches = CountMatches(c.matches12);
  EXPECT_GT(r->num_triangulated, 0.6 * matches);
  EXPECT_LT(r->num_triangulated, 0.8 * matches);
  // Hardly any wrong match gets a point (a few land near their epipolar line by chance).
  const int wrong = CountTriangulatedWrongMatches(c, *r);
  EXPECT_LT(wrong, 0.02 * r->num_triangulated) << wrong;
}

TEST(TwoViewInitializer, SameSeedIsDeterministicAndOtherSeedsAgree) {
  const TwoViewCase c =
      MakeCase(testing::MakeScene(1000, 27), Move({0.4, 0.1, 0.0}, {0.0, -0.03, 0.01}), 1.0, 0.1);
  TwoViewOptions options;
  options.seed = 5;
  const auto a = ReconstructTwoView(c.first, c.second, c.matches12, options);
  options.parallel = false;  // threads change nothing
  const auto b = ReconstructTwoView(c.first, c.second, c.matches12, options);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->camera2_from_camera1.Matrix(), b->camera2_from_camera1.Matrix());
  EXPECT_EQ(a->triangulated, b->triangulated);
  EXPECT_EQ(a->points, b->points);
  EXPECT_EQ(a->parallax_deg, b->parallax_deg);

  options.seed = 6;
  const auto other = ReconstructTwoView(c.first, c.second, c.matches12, options);
  ASSERT_TRUE(other.has_value());
  EXPECT_NE(other->camera2_from_camera1.Matrix(), a->camera2_from_camera1.Matrix());
  for (const auto* r : {&*a, &*other}) {
    const Errors e = Evaluate(c, *r);
    EXPECT_LT(e.rotation_deg, 0.5);
    EXPECT_LT(e.translation_deg, 2.0);
  }
}

TEST(TwoViewInitializer, TooFewMatchesAndBadInput) {
  const TwoViewCase c =
      MakeCase(testing::MakeScene(1000, 28), Move({0.4, 0.0, 0.0}, {0.0, 0.0, 0.0}), 0.5);
  std::vector<int> few = c.matches12;
  int kept = 0;
  for (int& m : few) {
    if (m >= 0 && ++kept > 40) m = -1;
  }
  TwoViewReport report;
  EXPECT_FALSE(ReconstructTwoView(c.first, c.second, few, TwoViewOptions{}, &report));
  EXPECT_EQ(report.rejection, TwoViewRejection::kTooFewMatches);
  EXPECT_EQ(report.num_matches, 40);

  std::vector<int> short_matches(c.matches12.begin(), c.matches12.end() - 1);
  EXPECT_THROW(ReconstructTwoView(c.first, c.second, short_matches, TwoViewOptions{}), Error);
  std::vector<int> out_of_range = c.matches12;
  out_of_range[0] = c.second.size();
  EXPECT_THROW(ReconstructTwoView(c.first, c.second, out_of_range, TwoViewOptions{}), Error);
  TwoViewOptions bad;
  bad.iterations = 0;
  EXPECT_THROW(bad.Check(), OptionError);
}

}  // namespace
}  // namespace pkslam
