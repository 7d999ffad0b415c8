#include "core/features/stereo_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "core/camera/stereo_rectification.h"
#include "core/camera/test_cameras.h"
#include "core/features/orb_extractor.h"
#include "core/features/synthetic_texture.h"
#include "core/util/error.h"
#include "core/util/quantile.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

constexpr double kFx = 450.0;
constexpr double kBaseline = 0.11;
constexpr double kBf = kFx * kBaseline;

// Rectified pair of a piecewise-planar scene: the disparity, as a function of the right
// image pixel (x, y), is a slanted plane for x < 250, a fronto-parallel plane up to 500 and a
// plane tilted in y beyond (nearer planes to the right, so nothing folds over).
double RightDisparity(double x, double y) {
  if (x < 250.0) return 12.3 + 0.02 * x;
  if (x < 500.0) return 30.65;
  return 34.0 + 0.01 * y;
}

struct Pair {
  cv::Mat left;
  cv::Mat right;
};

Pair MakePair(std::uint64_t seed) {
  Pair pair;
  pair.left = SyntheticTexture(cv::Size(752, 480), seed);
  cv::Mat map_x(pair.left.size(), CV_32F);
  cv::Mat map_y(pair.left.size(), CV_32F);
  for (int y = 0; y < map_x.rows; ++y) {
    for (int x = 0; x < map_x.cols; ++x) {
      map_x.at<float>(y, x) = static_cast<float>(x + RightDisparity(x, y));
      map_y.at<float>(y, x) = static_cast<float>(y);
    }
  }
  cv::remap(pair.left, pair.right, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REFLECT_101);
  return pair;
}

// True disparity of a left pixel, or nullopt near plane borders (within `margin` pixels in
// the right image) where windows straddle two planes or occlusions.
std::optional<double> TrueDisparity(double u_left, double v, double margin) {
  std::optional<double> found;
  int solutions = 0;
  auto accept = [&](double u_right, double lo, double hi) {
    if (u_right >= lo + margin && u_right < hi - margin) {
      found = u_left - u_right;
      ++solutions;
    }
  };
  accept((u_left - 12.3) / 1.02, 0.0, 250.0);
  accept(u_left - 30.65, 250.0, 500.0);
  accept(u_left - (34.0 + 0.01 * v), 500.0, 752.0);
  return solutions == 1 ? found : std::nullopt;
}

// Median |disparity error| over matched left keypoints with a known disparity, and how many.
std::pair<double, int> MedianDisparityError(const OrbFeatures& left, const StereoMatches& m) {
  std::vector<double> errors;
  for (std::size_t i = 0; i < left.keypoints.size(); ++i) {
    const cv::KeyPoint& kp = left.keypoints[i];
    const auto truth = TrueDisparity(kp.pt.x, kp.pt.y, 12.0 * std::pow(1.2, kp.octave));
    if (truth && m.depth[i] > 0.0f) errors.push_back(std::abs(kp.pt.x - m.u_right[i] - *truth));
  }
  if (errors.empty()) return {1e9, 0};
  return {Quantile(errors, 0.5).value(), static_cast<int>(errors.size())};
}

class StereoMatcherTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const Pair pair = MakePair(17);
    const OrbExtractor extractor;
    extractor.ExtractStereo(pair.left, pair.right, &left_, &right_);
  }
  OrbFeatures left_;
  OrbFeatures right_;
};

TEST_F(StereoMatcherTest, RecoversSubPixelDisparityAndDepth) {
  const StereoMatches m = MatchStereo(left_, right_, kBf, kFx);
  ASSERT_EQ(m.u_right.size(), left_.keypoints.size());
  ASSERT_EQ(m.depth.size(), left_.keypoints.size());
  std::vector<double> errors;
  std::vector<double> integer_rounding;
  int with_truth = 0;
  int gross = 0;
  for (std::size_t i = 0; i < left_.keypoints.size(); ++i) {
    const cv::KeyPoint& kp = left_.keypoints[i];
    const double margin = 12.0 * std::pow(1.2, kp.octave);
    const auto truth = TrueDisparity(kp.pt.x, kp.pt.y, margin);
    if (!truth) continue;
    ++with_truth;
    if (m.depth[i] < 0.0f) {
      EXPECT_EQ(m.u_right[i], -1.0f);
      continue;
    }
    const double disparity = kp.pt.x - m.u_right[i];
    EXPECT_NEAR(m.depth[i], kBf / disparity, 1e-4 * m.depth[i]);
    EXPECT_GE(m.right_index[i], 0);
    const double error = std::abs(disparity - *truth);
    errors.push_back(error);
    integer_rounding.push_back(std::abs(*truth - std::round(*truth)));
    gross += error > 1.0 ? 1 : 0;
  }
  ASSERT_GT(with_truth, 600);
  ASSERT_GT(errors.size(), 0.6 * with_truth);
  const double median_error = Quantile(errors, 0.5).value();
  EXPECT_LT(median_error, 0.1);
  // Well below what integer disparities would give: the parabola fit is doing its job.
  EXPECT_LT(median_error, 0.5 * Quantile(integer_rounding, 0.5).value());
  EXPECT_LT(gross, 0.02 * errors.size());
  // Depth within 1% for the median point (depth error ~ disparity error / disparity).
  std::vector<double> depth_rel;
  for (std::size_t i = 0; i < left_.keypoints.size(); ++i) {
    const cv::KeyPoint& kp = left_.keypoints[i];
    const auto truth = TrueDisparity(kp.pt.x, kp.pt.y, 12.0 * std::pow(1.2, kp.octave));
    if (truth && m.depth[i] > 0.0f) {
      depth_rel.push_back(std::abs(m.depth[i] - kBf / *truth) / (kBf / *truth));
    }
  }
  EXPECT_LT(Quantile(depth_rel, 0.5).value(), 0.01);
  RecordProperty("median_disparity_error_px", std::to_string(median_error));
  RecordProperty("median_depth_rel_error", std::to_string(Quantile(depth_rel, 0.5).value()));
  RecordProperty("matched_of_with_truth",
                 std::to_string(errors.size()) + "/" + std::to_string(with_truth));
  RecordProperty("gross_over_1px", std::to_string(gross));
  EXPECT_EQ(m.num_matches,
            std::count_if(m.depth.begin(), m.depth.end(), [](float d) { return d > 0.0f; }));
}

// The defaults (window-mean SAD, equiangular fit) against ORB-SLAM's choices (centre-pixel
// SAD, parabola) on the same pair: each ORB-SLAM choice costs accuracy.
TEST_F(StereoMatcherTest, DefaultsBeatOrbSlamRefinementChoices) {
  auto error_with = [&](SadNormalization n, SubpixelFit f) {
    StereoMatcherOptions options;
    options.sad_normalization = n;
    options.subpixel_fit = f;
    const auto [median, count] =
        MedianDisparityError(left_, MatchStereo(left_, right_, kBf, kFx, options));
    EXPECT_GT(count, 500);
    return median;
  };
  const double ours = error_with(SadNormalization::kWindowMean, SubpixelFit::kEquiangular);
  const double parabola = error_with(SadNormalization::kWindowMean, SubpixelFit::kParabola);
  const double orb_slam = error_with(SadNormalization::kCentrePixel, SubpixelFit::kParabola);
  const double centre_equiangular =
      error_with(SadNormalization::kCentrePixel, SubpixelFit::kEquiangular);
  RecordProperty("median_px_mean_equiangular", std::to_string(ours));
  RecordProperty("median_px_mean_parabola", std::to_string(parabola));
  RecordProperty("median_px_centre_equiangular", std::to_string(centre_equiangular));
  RecordProperty("median_px_centre_parabola_orbslam", std::to_string(orb_slam));
  EXPECT_LT(ours, 0.05);
  EXPECT_LT(ours, 0.6 * parabola);
  EXPECT_LT(parabola, 0.6 * orb_slam);
  EXPECT_LT(orb_slam, 0.4);  // ORB-SLAM's refinement still works, only less precisely
}

TEST(StereoMatcher, ToleratesABrightnessOffsetBetweenCameras) {
  Pair pair = MakePair(23);
  pair.right.convertTo(pair.right, CV_8U, 1.0, 25.0);  // right camera 25 grey levels brighter
  OrbFeatures left, right;
  OrbExtractor().ExtractStereo(pair.left, pair.right, &left, &right);
  const auto [median, count] = MedianDisparityError(left, MatchStereo(left, right, kBf, kFx));
  EXPECT_GT(count, 500);
  EXPECT_LT(median, 0.05);
  StereoMatcherOptions plain;
  plain.sad_normalization = SadNormalization::kNone;
  const auto [plain_median, plain_count] =
      MedianDisparityError(left, MatchStereo(left, right, kBf, kFx, plain));
  EXPECT_GT(plain_median, 2.0 * median);
  RecordProperty("median_px_offset25_mean", std::to_string(median));
  RecordProperty("median_px_offset25_plain", std::to_string(plain_median));
}

TEST_F(StereoMatcherTest, UnrelatedRightImageGivesAlmostNoMatches) {
  const OrbFeatures unrelated = OrbExtractor().Extract(SyntheticTexture(cv::Size(752, 480), 99));
  const StereoMatches m = MatchStereo(left_, unrelated, kBf, kFx);
  EXPECT_LT(m.num_matches, 0.05 * left_.keypoints.size());
  RecordProperty("unrelated_matches", std::to_string(m.num_matches));
  const StereoMatches good = MatchStereo(left_, right_, kBf, kFx);
  EXPECT_GT(good.num_matches, 10 * std::max(m.num_matches, 1));
}

TEST_F(StereoMatcherTest, DisparityLimitFromMinimumDepth) {
  StereoMatcherOptions options;
  options.min_depth_baselines = kFx / 25.0;  // max disparity 25 px: only the slanted plane
  const StereoMatches m = MatchStereo(left_, right_, kBf, kFx, options);
  ASSERT_GT(m.num_matches, 50);
  for (std::size_t i = 0; i < left_.keypoints.size(); ++i) {
    if (m.depth[i] < 0.0f) continue;
    EXPECT_LT(left_.keypoints[i].pt.x - m.u_right[i], 25.0f);
    EXPECT_GT(m.depth[i], kBf / 25.0 - 1e-4);
  }
}

TEST_F(StereoMatcherTest, SadOutlierRuleKeepsMatchesAtMostFactorTimesMedian) {
  StereoMatcherOptions keep_all;
  keep_all.sad_outlier_factor = 1e9;
  const StereoMatches all = MatchStereo(left_, right_, kBf, kFx, keep_all);
  std::vector<int> sads;
  for (int s : all.sad) {
    if (s >= 0) sads.push_back(s);
  }
  ASSERT_GT(sads.size(), 100u);
  std::sort(sads.begin(), sads.end());
  const double median = sads[sads.size() / 2];
  StereoMatcherOptions strict;
  strict.sad_outlier_factor = 0.8;
  const StereoMatches kept = MatchStereo(left_, right_, kBf, kFx, strict);
  for (std::size_t i = 0; i < all.sad.size(); ++i) {
    const bool expected = all.sad[i] >= 0 && all.sad[i] <= 0.8 * median;
    EXPECT_EQ(kept.depth[i] > 0.0f, expected) << i;
    if (expected) {
      EXPECT_EQ(kept.u_right[i], all.u_right[i]);
    }
  }
}

TEST_F(StereoMatcherTest, RejectsInconsistentInput) {
  EXPECT_THROW(MatchStereo(left_, right_, -1.0, kFx), Error);
  std::vector<Descriptor> short_descriptors(left_.descriptors.begin(), left_.descriptors.end() - 1);
  EXPECT_THROW(MatchStereo(left_.keypoints, short_descriptors, left_.pyramid, right_.keypoints,
                           right_.descriptors, right_.pyramid, kBf, kFx),
               Error);
  StereoMatcherOptions bad;
  bad.sad_half_window = 0;
  EXPECT_THROW(MatchStereo(left_, right_, kBf, kFx, bad), OptionError);
  // Empty input: nothing matched, no crash.
  const StereoMatches none = MatchStereo({}, {}, left_.pyramid, right_.keypoints,
                                         right_.descriptors, right_.pyramid, kBf, kFx);
  EXPECT_TRUE(none.depth.empty());
  EXPECT_EQ(none.num_matches, 0);
}

// Real EuRoC pair (V1_01 static, rectified with the calibration): most keypoints find a
// partner, and their depths are those of a room (no depth truth exists for these images).
TEST(StereoMatcher, RealRectifiedEurocPair) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const std::filesystem::path mav = shared / "euroc" / "V1_01_easy_static" / "mav0";
  const std::string name = "1403715273262142976.png";
  const cv::Mat raw_left =
      cv::imread((mav / "cam0" / "data" / name).string(), cv::IMREAD_GRAYSCALE);
  const cv::Mat raw_right =
      cv::imread((mav / "cam1" / "data" / name).string(), cv::IMREAD_GRAYSCALE);
  if (raw_left.empty() || raw_right.empty()) GTEST_SKIP() << "EuRoC pair " << name << " absent";
  const StereoRectification rectification(testing::EurocCam0(), testing::EurocCam1(),
                                          testing::EurocCam1FromCam0());
  const auto [left_image, right_image] = rectification.Rectify(raw_left, raw_right);
  OrbFeatures left, right;
  OrbExtractor().ExtractStereo(left_image, right_image, &left, &right);
  const double fx = rectification.rectified_camera().fx();
  const StereoMatches m = MatchStereo(left, right, rectification.bf(), fx);
  std::vector<double> depths;
  for (float d : m.depth) {
    if (d > 0.0f) depths.push_back(d);
  }
  RecordProperty("euroc_matches",
                 std::to_string(m.num_matches) + "/" + std::to_string(left.keypoints.size()));
  ASSERT_GT(m.num_matches, 0.4 * left.keypoints.size());
  const double median_depth = Quantile(depths, 0.5).value();
  RecordProperty("euroc_median_depth_m", std::to_string(median_depth));
  EXPECT_GT(median_depth, 1.0);
  EXPECT_LT(median_depth, 8.0);
  // Rows agree: the matched right keypoint's band (+-2 scale, widened to whole rows) holds the
  // left keypoint's row.
  for (std::size_t i = 0; i < m.depth.size(); ++i) {
    if (m.depth[i] < 0.0f) continue;
    const cv::KeyPoint& kr = right.keypoints[m.right_index[i]];
    EXPECT_LT(std::abs(kr.pt.y - left.keypoints[i].pt.y), 2.0 * std::pow(1.2, kr.octave) + 2.0);
  }
}

}  // namespace
}  // namespace pkslam
