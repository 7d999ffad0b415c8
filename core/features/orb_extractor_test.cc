#include "core/features/orb_extractor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "core/features/keypoint_spread.h"
#include "core/features/synthetic_texture.h"
#include "core/util/error.h"
#include "core/util/quantile.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

const cv::Size kEurocSize(752, 480);

cv::Mat Textured(std::uint64_t seed = 7) { return SyntheticTexture(kEurocSize, seed); }

std::filesystem::path EurocCam0(const std::filesystem::path& shared) {
  return shared / "euroc" / "V1_01_easy_static" / "mav0" / "cam0" / "data";
}

void ExpectSameFeatures(const OrbFeatures& a, const OrbFeatures& b) {
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
  ASSERT_EQ(a.descriptors.size(), b.descriptors.size());
  for (std::size_t i = 0; i < a.keypoints.size(); ++i) {
    EXPECT_EQ(a.keypoints[i].pt, b.keypoints[i].pt);
    EXPECT_EQ(a.keypoints[i].angle, b.keypoints[i].angle);
    EXPECT_EQ(a.keypoints[i].response, b.keypoints[i].response);
    EXPECT_EQ(a.keypoints[i].octave, b.keypoints[i].octave);
    EXPECT_EQ(a.keypoints[i].size, b.keypoints[i].size);
    EXPECT_EQ(a.descriptors[i], b.descriptors[i]);
  }
}

TEST(OrbOptions, CheckRejectsInconsistentValues) {
  EXPECT_NO_THROW(OrbOptions().Check());
  auto bad = [](auto mutate) {
    OrbOptions o;
    mutate(o);
    return o;
  };
  EXPECT_THROW(bad([](OrbOptions& o) { o.n_features = 0; }).Check(), OptionError);
  EXPECT_THROW(bad([](OrbOptions& o) { o.scale_factor = 1.0; }).Check(), OptionError);
  EXPECT_THROW(bad([](OrbOptions& o) { o.n_levels = 0; }).Check(), OptionError);
  EXPECT_THROW(bad([](OrbOptions& o) { o.min_th_fast = 25; }).Check(), OptionError);
  EXPECT_THROW(bad([](OrbOptions& o) { o.patch_size = 30; }).Check(), OptionError);
  // The rotated tests of a 31 patch reach 18.4 px: an 18 px edge leaves no room.
  EXPECT_THROW(bad([](OrbOptions& o) { o.edge_threshold = 18; }).Check(), OptionError);
  EXPECT_THROW(OrbExtractor(bad([](OrbOptions& o) { o.cell_size = 5; })), OptionError);
  EXPECT_THROW(OrbExtractor(bad([](OrbOptions& o) { o.patch_size = -31; })), OptionError);
}

TEST(OrbExtractor, LevelTablesAndQuotas) {
  const OrbExtractor extractor;
  ASSERT_EQ(extractor.NumLevels(), 8);
  for (int level = 0; level < 8; ++level) {
    const double s = std::pow(1.2, level);
    EXPECT_NEAR(extractor.ScaleFactors()[level], s, 1e-5 * s);
    EXPECT_NEAR(extractor.InverseScaleFactors()[level], 1.0 / s, 1e-6);
    EXPECT_NEAR(extractor.LevelSigma2()[level], s * s, 1e-5 * s * s);
    EXPECT_NEAR(extractor.InverseLevelSigma2()[level], 1.0 / (s * s), 1e-6);
  }
  const std::vector<int>& quota = extractor.FeaturesPerLevel();
  EXPECT_EQ(std::accumulate(quota.begin(), quota.end(), 0), 1200);
  EXPECT_EQ(quota[0], 261);  // 1200 * (1 - 1/1.2) / (1 - 1.2^-8)
  for (int level = 1; level + 1 < 8; ++level) {
    EXPECT_NEAR(double(quota[level]) / quota[level - 1], 1.0 / 1.2, 0.02);
  }
}

TEST(OrbExtractor, CountPerLevelMeetsQuotaOnTexturedImage) {
  const OrbExtractor extractor;
  const OrbFeatures f = extractor.Extract(Textured());
  EXPECT_EQ(f.keypoints.size(), 1200u);
  EXPECT_EQ(f.descriptors.size(), f.keypoints.size());
  std::vector<int> per_level(8, 0);
  for (const cv::KeyPoint& kp : f.keypoints) ++per_level[kp.octave];
  EXPECT_EQ(per_level, extractor.FeaturesPerLevel());
  // Grouped by octave, ascending.
  EXPECT_TRUE(std::is_sorted(f.keypoints.begin(), f.keypoints.end(),
                             [](const auto& a, const auto& b) { return a.octave < b.octave; }));
}

TEST(OrbExtractor, KeypointsRespectBorderAndCarryTheirScale) {
  OrbOptions options;
  options.n_features = 2000;
  const OrbExtractor extractor(options);
  const OrbFeatures f = extractor.Extract(Textured(3));
  ASSERT_GT(f.keypoints.size(), 1900u);
  ASSERT_EQ(f.pyramid.NumLevels(), 8);
  for (const cv::KeyPoint& kp : f.keypoints) {
    ASSERT_GE(kp.octave, 0);
    ASSERT_LT(kp.octave, 8);
    EXPECT_GE(kp.pt.x, 0.0f);
    EXPECT_GE(kp.pt.y, 0.0f);
    EXPECT_LT(kp.pt.x, kEurocSize.width);
    EXPECT_LT(kp.pt.y, kEurocSize.height);
    // Back on its level the keypoint is a whole pixel at least edge_threshold from the border.
    const cv::Mat& level = f.pyramid.levels[kp.octave];
    const double x = f.pyramid.ToLevelX(kp.octave, kp.pt.x);
    const double y = f.pyramid.ToLevelY(kp.octave, kp.pt.y);
    EXPECT_NEAR(x, std::round(x), 1e-3);
    EXPECT_NEAR(y, std::round(y), 1e-3);
    EXPECT_GE(std::lround(x), 19);
    EXPECT_GE(std::lround(y), 19);
    EXPECT_LT(std::lround(x), level.cols - 19);
    EXPECT_LT(std::lround(y), level.rows - 19);
    EXPECT_FLOAT_EQ(kp.size, 31.0f * extractor.ScaleFactors()[kp.octave]);
    EXPECT_GE(kp.angle, 0.0f);
    EXPECT_LT(kp.angle, 360.0f);
    EXPECT_GE(kp.response, 7.0f);  // a FAST score is at least the threshold that found it
  }
  // Level sizes follow round(size / 1.2^k).
  for (int k = 0; k < 8; ++k) {
    EXPECT_EQ(f.pyramid.levels[k].cols, std::lround(752 / std::pow(1.2, k)));
    EXPECT_EQ(f.pyramid.levels[k].rows, std::lround(480 / std::pow(1.2, k)));
  }
}

TEST(OrbExtractor, FillsTexturelessCellsThroughTheLowThreshold) {
  // Left half strong texture, right half faint texture (contrast below the 20 threshold but
  // above 7): ORB-SLAM's fallback still finds keypoints on the right.
  cv::Mat image = Textured(5);
  cv::Mat right = image(cv::Rect(376, 0, 376, 480));
  right.convertTo(right, CV_8U, 0.12, 110);
  const OrbFeatures f = OrbExtractor().Extract(image);
  const auto on_right = std::count_if(f.keypoints.begin(), f.keypoints.end(),
                                      [](const cv::KeyPoint& kp) { return kp.pt.x > 400; });
  EXPECT_GT(on_right, 200);
  OrbOptions no_fallback;
  no_fallback.min_th_fast = 20;
  const OrbFeatures g = OrbExtractor(no_fallback).Extract(image);
  const auto on_right_without = std::count_if(g.keypoints.begin(), g.keypoints.end(),
                                              [](const cv::KeyPoint& kp) { return kp.pt.x > 400; });
  EXPECT_LT(on_right_without, on_right / 4);
}

TEST(OrbExtractor, MaskLimitsKeypoints) {
  const cv::Mat image = Textured();
  cv::Mat mask(image.size(), CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(0, 0, 376, 480)).setTo(255);
  OrbFeatures f;
  OrbExtractor().Extract(image, &f, mask);
  ASSERT_GT(f.keypoints.size(), 500u);
  for (const cv::KeyPoint& kp : f.keypoints) EXPECT_LT(std::lround(kp.pt.x), 376);
}

TEST(OrbExtractor, RejectsBadImages) {
  const OrbExtractor extractor;
  OrbFeatures f;
  EXPECT_THROW(extractor.Extract(cv::Mat(), &f), Error);
  EXPECT_THROW(extractor.Extract(cv::Mat(480, 752, CV_8UC3, cv::Scalar::all(0)), &f), Error);
  EXPECT_THROW(extractor.Extract(Textured(), &f, cv::Mat(10, 10, CV_8UC1)), Error);
  // Too small for 8 levels of 1.2 (the top level would be empty).
  EXPECT_THROW(extractor.Extract(cv::Mat(1, 1, CV_8UC1, cv::Scalar(0)), &f), Error);
  // Small but valid: no room for keypoints, no crash.
  EXPECT_NO_THROW(extractor.Extract(cv::Mat(40, 40, CV_8UC1, cv::Scalar(9)), &f));
  EXPECT_TRUE(f.keypoints.empty());
}

// Keypoints of `a` mapped by the 2x3 affine `m` onto `b`: pairs (index in a, index in b) of
// the same octave within `tol` level-0 pixels (times the octave scale).
std::vector<std::pair<int, int>> MatchByPosition(const OrbFeatures& a, const OrbFeatures& b,
                                                 const cv::Matx23d& m, double tol) {
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < static_cast<int>(a.keypoints.size()); ++i) {
    const cv::KeyPoint& ka = a.keypoints[i];
    const cv::Point2d p(m(0, 0) * ka.pt.x + m(0, 1) * ka.pt.y + m(0, 2),
                        m(1, 0) * ka.pt.x + m(1, 1) * ka.pt.y + m(1, 2));
    const double r = tol * std::pow(1.2, ka.octave);
    int best = -1;
    double best_d = r;
    for (int j = 0; j < static_cast<int>(b.keypoints.size()); ++j) {
      const cv::KeyPoint& kb = b.keypoints[j];
      if (kb.octave != ka.octave) continue;
      const double d = std::hypot(kb.pt.x - p.x, kb.pt.y - p.y);
      if (d < best_d) {
        best_d = d;
        best = j;
      }
    }
    if (best >= 0) pairs.emplace_back(i, best);
  }
  return pairs;
}

// Angle (degrees) of direction `deg` after the linear part of `m`.
double MapAngle(const cv::Matx23d& m, double deg) {
  const double a = deg * CV_PI / 180.0;
  const double x = m(0, 0) * std::cos(a) + m(0, 1) * std::sin(a);
  const double y = m(1, 0) * std::cos(a) + m(1, 1) * std::sin(a);
  return std::atan2(y, x) * 180.0 / CV_PI;
}

TEST(OrbExtractor, OrientationAndDescriptorFollowAnExact90DegreeRotation) {
  const cv::Mat image = Textured(9);
  cv::Mat rotated;
  cv::rotate(image, rotated, cv::ROTATE_90_CLOCKWISE);  // (x, y) -> (H - 1 - y, x)
  const cv::Matx23d m(0, -1, image.rows - 1, 1, 0, 0);
  const OrbExtractor extractor;
  const OrbFeatures a = extractor.Extract(image);
  const OrbFeatures b = extractor.Extract(rotated);
  const auto pairs = MatchByPosition(a, b, m, 0.01);
  ASSERT_GT(pairs.size(), 100u);
  int level0 = 0;
  int identical = 0;
  std::vector<double> upper_errors;
  for (const auto& [i, j] : pairs) {
    const double error = std::remainder(b.keypoints[j].angle - a.keypoints[i].angle - 90.0, 360.0);
    if (a.keypoints[i].octave == 0) {
      // Level 0 is the image itself: the disc moments rotate exactly.
      EXPECT_NEAR(error, 0.0, 0.01);
      ++level0;
      identical += a.descriptors[i] == b.descriptors[j] ? 1 : 0;
    } else {
      // Bilinear resizing is not exactly rotation-symmetric in its fixed-point rounding.
      upper_errors.push_back(std::abs(error));
    }
  }
  ASSERT_GT(level0, 30);
  ASSERT_GT(upper_errors.size(), 30u);
  EXPECT_LT(Quantile(upper_errors, 0.5).value(), 0.2);
  EXPECT_LT(*std::max_element(upper_errors.begin(), upper_errors.end()), 5.0);
  // Bit-identical except where the two float angles round a test point differently.
  EXPECT_GE(identical, static_cast<int>(0.9 * level0));
}

TEST(OrbExtractor, OrientationAndDescriptorFollowAnArbitraryRotation) {
  const cv::Mat image = Textured(4);
  const double rotation_deg = 30.0;
  const cv::Matx23d m = cv::getRotationMatrix2D(cv::Point2f(375.5f, 239.5f), rotation_deg, 1.0);
  cv::Mat rotated;
  cv::warpAffine(image, rotated, m, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  OrbOptions options;
  options.n_features = 2000;
  const OrbExtractor extractor(options);
  const OrbFeatures a = extractor.Extract(image);
  const OrbFeatures b = extractor.Extract(rotated);
  const auto pairs = MatchByPosition(a, b, m, 1.0);
  ASSERT_GT(pairs.size(), 150u);
  std::vector<double> angle_errors;
  std::vector<double> matched_hamming;
  std::vector<double> random_hamming;
  cv::RNG rng(2);
  for (const auto& [i, j] : pairs) {
    const double expected = MapAngle(m, a.keypoints[i].angle);
    angle_errors.push_back(std::abs(std::remainder(b.keypoints[j].angle - expected, 360.0)));
    matched_hamming.push_back(HammingDistance(a.descriptors[i], b.descriptors[j]));
    const int k = rng.uniform(0, static_cast<int>(b.descriptors.size()));
    random_hamming.push_back(HammingDistance(a.descriptors[i], b.descriptors[k]));
  }
  EXPECT_LT(Quantile(angle_errors, 0.5).value(), 3.0);
  EXPECT_LT(Quantile(matched_hamming, 0.5).value(), 64.0);
  EXPECT_GT(Quantile(random_hamming, 0.5).value(), 100.0);
}

TEST(OrbExtractor, DeterministicRepeatedAndSequentialVsParallel) {
  const cv::Mat image = Textured(12);
  const OrbExtractor parallel;
  OrbOptions sequential_options;
  sequential_options.parallel = false;
  const OrbExtractor sequential(sequential_options);
  const OrbFeatures first = parallel.Extract(image);
  OrbFeatures reused = parallel.Extract(Textured(13));  // buffers of another image
  parallel.Extract(image, &reused);
  ExpectSameFeatures(first, reused);
  ExpectSameFeatures(first, sequential.Extract(image));
}

TEST(OrbThreaded, ConcurrentCallsAndStereoGiveTheSameAsAlone) {
  const cv::Mat left = Textured(21);
  const cv::Mat right = Textured(22);
  const OrbExtractor extractor;
  const OrbFeatures left_alone = extractor.Extract(left);
  const OrbFeatures right_alone = extractor.Extract(right);
  OrbFeatures l, r;
  extractor.ExtractStereo(left, right, &l, &r);
  ExpectSameFeatures(left_alone, l);
  ExpectSameFeatures(right_alone, r);

  std::vector<OrbFeatures> results(4);
  std::vector<std::thread> threads;
  threads.reserve(4);
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (int rep = 0; rep < 3; ++rep) extractor.Extract(t % 2 ? right : left, &results[t]);
    });
  }
  for (std::thread& t : threads) t.join();
  for (int t = 0; t < 4; ++t) ExpectSameFeatures(t % 2 ? right_alone : left_alone, results[t]);
}

TEST(OrbThreaded, StereoPropagatesErrors) {
  const OrbExtractor extractor;
  OrbFeatures l, r;
  EXPECT_THROW(extractor.ExtractStereo(Textured(), cv::Mat(), &l, &r), Error);
  EXPECT_THROW(extractor.ExtractStereo(cv::Mat(), Textured(), &l, &r), Error);
}

TEST(OrbExtractor, RealEurocImagesCountSpreadAndOpenCvComparison) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const std::filesystem::path dir = EurocCam0(shared);
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "no " << dir;
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 10u);
  const OrbExtractor extractor;
  const cv::Ptr<cv::ORB> cv_orb =
      cv::ORB::create(1200, 1.2f, 8, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, 20);
  for (std::size_t i = 0; i < files.size(); i += files.size() / 10) {
    const cv::Mat image = cv::imread(files[i].string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(image.empty()) << files[i];
    const OrbFeatures f = extractor.Extract(image);
    EXPECT_GE(f.keypoints.size(), 0.97 * 1200) << files[i];
    EXPECT_LE(f.keypoints.size(), 1200u);
    std::vector<cv::KeyPoint> cv_keypoints;
    cv_orb->detect(image, cv_keypoints);
    EXPECT_GT(OccupiedGridShare(f.keypoints, image.size(), 8, 8),
              OccupiedGridShare(cv_keypoints, image.size(), 8, 8));
    EXPECT_GT(OccupiedPixelCellShare(f.keypoints, image.size(), 8),
              OccupiedPixelCellShare(cv_keypoints, image.size(), 8));
  }
}

}  // namespace
}  // namespace pkslam
