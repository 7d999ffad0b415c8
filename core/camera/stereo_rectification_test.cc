#include "core/camera/stereo_rectification.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "core/camera/test_cameras.h"
#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

StereoRectification EurocRectification() {
  return StereoRectification(testing::EurocCam0(), testing::EurocCam1(),
                             testing::EurocCam1FromCam0());
}

TEST(StereoRectificationTest, EurocGeometry) {
  const StereoRectification rect = EurocRectification();
  EXPECT_NEAR(rect.baseline(), 0.110078, 1e-4);
  EXPECT_NEAR(rect.baseline(), testing::EurocCam1FromCam0().translation().norm(), 1e-12);
  const CameraModel& cam = rect.rectified_camera();
  EXPECT_EQ(cam.type(), CameraType::kPinhole);
  EXPECT_FALSE(cam.HasDistortion());
  EXPECT_EQ(cam.width(), 752);
  EXPECT_EQ(cam.height(), 480);
  EXPECT_DOUBLE_EQ(rect.bf(), cam.fx() * rect.baseline());
  // Sanity range; alpha 0 (valid pixels only) gives ~436 here, close to the 435.2 of
  // ORB-SLAM3's precomputed EuRoC rectification.
  EXPECT_GT(cam.fx(), 400.0);
  EXPECT_LT(cam.fx(), 600.0);

  // rect_right_from_right * right_from_left * left_from_rect_left is a pure x translation.
  const SE3d rect_right_from_rect_left =
      SE3d(rect.rect_right_from_right(), Eigen::Vector3d::Zero()) * testing::EurocCam1FromCam0() *
      SE3d(rect.rect_left_from_left().Inverse(), Eigen::Vector3d::Zero());
  EXPECT_LT(rect_right_from_rect_left.so3().Log().norm(), 1e-9);
  EXPECT_LT(
      (rect_right_from_rect_left.translation() - rect.rect_right_from_rect_left().translation())
          .norm(),
      1e-9);
}

TEST(StereoRectificationTest, RandomPointsLandOnTheSameRowWithDisparityBfOverDepth) {
  const StereoRectification rect = EurocRectification();
  const CameraModel left = testing::EurocCam0();
  const CameraModel right = testing::EurocCam1();
  const SE3d right_from_left = testing::EurocCam1FromCam0();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> depth(1.0, 10.0);
  std::uniform_real_distribution<double> lateral(-0.7, 0.7);
  int checked = 0;
  for (int i = 0; i < 5000 && checked < 1000; ++i) {
    const double z = depth(rng);
    const Eigen::Vector3d p_left(lateral(rng) * z, lateral(rng) * z * 0.6, z);
    const Eigen::Vector3d p_right = right_from_left * p_left;
    const auto uv_left = left.Project(p_left);
    const auto uv_right = right.Project(p_right);
    if (!uv_left || !uv_right || !left.InImage(*uv_left) || !right.InImage(*uv_right)) continue;
    const auto rect_left = rect.RectifyLeftPixel(*uv_left);
    const auto rect_right = rect.RectifyRightPixel(*uv_right);
    ASSERT_TRUE(rect_left && rect_right);
    EXPECT_NEAR(rect_left->y(), rect_right->y(), 0.01) << p_left.transpose();
    // Depth along the rectified optical axis.
    const double depth_rect = (rect.rect_left_from_left() * p_left).z();
    const double disparity = rect_left->x() - rect_right->x();
    EXPECT_NEAR(disparity * depth_rect, rect.bf(), 1e-6 * rect.bf()) << p_left.transpose();
    ++checked;
  }
  EXPECT_EQ(checked, 1000);
}

TEST(StereoRectificationTest, BodyFromRectLeftSeesTheSameWorld) {
  const StereoRectification rect = EurocRectification();
  const SE3d body_from_left = testing::EurocBodyFromCam0();
  const SE3d body_from_rect_left = rect.BodyFromRectLeft(body_from_left);
  EXPECT_LT((body_from_rect_left.translation() - body_from_left.translation()).norm(), 1e-15);
  // A body point seen through the raw left camera and the rectified camera: same rectified
  // pixel whichever way it is computed.
  const Eigen::Vector3d p_body = body_from_left * Eigen::Vector3d(0.3, -0.2, 2.5);
  const Eigen::Vector3d p_left = body_from_left.Inverse() * p_body;
  const Eigen::Vector3d p_rect = body_from_rect_left.Inverse() * p_body;
  ASSERT_GT(p_left.z(), 0.0);
  const auto via_raw = rect.RectifyLeftPixel(*testing::EurocCam0().Project(p_left));
  const auto direct = rect.rectified_camera().Project(p_rect);
  ASSERT_TRUE(via_raw && direct);
  EXPECT_LT((*via_raw - *direct).norm(), 1e-8);
}

TEST(StereoRectificationTest, PixelFunctionAgreesWithTheRemapTables) {
  // The maps send a rectified pixel to its raw source pixel; RectifyLeftPixel must invert that.
  const StereoRectification rect = EurocRectification();
  for (int v = 10; v < 480; v += 47) {
    for (int u = 10; u < 752; u += 53) {
      const Eigen::Vector2d raw(rect.left_map_x().at<float>(v, u),
                                rect.left_map_y().at<float>(v, u));
      const auto back = rect.RectifyLeftPixel(raw);
      ASSERT_TRUE(back.has_value());
      EXPECT_NEAR(back->x(), u, 2e-3);  // float maps
      EXPECT_NEAR(back->y(), v, 2e-3);
    }
  }
  EXPECT_EQ(rect.left_map_x().type(), CV_32FC1);
  EXPECT_EQ(rect.right_map_y().size(), cv::Size(752, 480));
}

TEST(StereoRectificationTest, UnrectifyInvertsRectifyAndMatchesTheRemapTables) {
  const StereoRectification rect = EurocRectification();
  for (int v = 10; v < 480; v += 47) {
    for (int u = 10; u < 752; u += 53) {
      const Eigen::Vector2d uv(u, v);
      const auto raw_left = rect.UnrectifyLeftPixel(uv);
      const auto raw_right = rect.UnrectifyRightPixel(uv);
      ASSERT_TRUE(raw_left && raw_right);
      // The remap tables hold the same raw pixel (as floats).
      EXPECT_NEAR(raw_left->x(), rect.left_map_x().at<float>(v, u), 2e-3);
      EXPECT_NEAR(raw_right->y(), rect.right_map_y().at<float>(v, u), 2e-3);
      const auto back_left = rect.RectifyLeftPixel(*raw_left);
      const auto back_right = rect.RectifyRightPixel(*raw_right);
      ASSERT_TRUE(back_left && back_right);
      EXPECT_LT((*back_left - uv).norm(), 1e-6);
      EXPECT_LT((*back_right - uv).norm(), 1e-6);
    }
  }
}

TEST(StereoRectificationTest, RejectsUnsupportedInput) {
  const CameraModel left = testing::EurocCam0();
  EXPECT_THROW(StereoRectification(left, testing::TumViKb8(), testing::EurocCam1FromCam0()),
               OptionError);
  const CameraModel small = CameraModel::Pinhole(640, 480, 458, 457, 320, 240);
  EXPECT_THROW(StereoRectification(left, small, testing::EurocCam1FromCam0()), OptionError);
  EXPECT_THROW(StereoRectification(left, testing::EurocCam1(), SE3d()), OptionError);
  // Swapped cameras: the "right" one is on the left.
  EXPECT_THROW(
      StereoRectification(left, testing::EurocCam1(), testing::EurocCam1FromCam0().Inverse()),
      OptionError);
  const StereoRectification rect = EurocRectification();
  EXPECT_THROW(rect.Rectify(cv::Mat(480, 752, CV_8U), cv::Mat(100, 100, CV_8U)), Error);
}

// A Kannala-Brandt fisheye pair (TUM-VI's cameras, 10 cm apart with a small rotation) rectifies
// through OpenCV's fisheye model: points land on one row with disparity bf / depth, and the
// pixel functions agree with the remap tables.
TEST(StereoRectificationTest, FisheyePairRectifiesOntoRows) {
  const CameraModel cam = testing::TumViKb8();
  const SE3d right_from_left(SO3d::Exp(Eigen::Vector3d(0.01, -0.02, 0.005)),
                             Eigen::Vector3d(-0.101, 0.002, 0.001));
  const StereoRectification rect(cam, cam, right_from_left);
  EXPECT_EQ(rect.rectified_camera().type(), CameraType::kPinhole);
  EXPECT_NEAR(rect.baseline(), right_from_left.translation().norm(), 1e-9);
  // The lens's own focal length, not the 60-odd px of a view holding the whole field.
  EXPECT_NEAR(rect.rectified_camera().fx(), cam.fx(), 1e-6 * cam.fx());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> xy(-0.8, 0.8), z(1.5, 6.0);
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p_left(xy(rng), xy(rng), z(rng));
    const auto uv_l = cam.Project(p_left);
    const auto uv_r = cam.Project(right_from_left * p_left);
    if (!uv_l || !uv_r) continue;
    const auto rl = rect.RectifyLeftPixel(*uv_l);
    const auto rr = rect.RectifyRightPixel(*uv_r);
    if (!rl || !rr) continue;
    const CameraModel& rc = rect.rectified_camera();
    if (rl->x() < 0 || rl->x() >= rc.width() || rl->y() < 0 || rl->y() >= rc.height()) continue;
    ++checked;
    EXPECT_NEAR(rl->y(), rr->y(), 1e-6);
    const double depth = (rect.rect_left_from_left() * p_left).z();
    EXPECT_NEAR(rl->x() - rr->x(), rect.bf() / depth, 1e-6);
    // The remap table sends the rectified pixel back to where the fisheye camera saw it.
    const int u = static_cast<int>(std::lround(rl->x()));
    const int v = static_cast<int>(std::lround(rl->y()));
    if (u < 0 || v < 0 || u >= rc.width() || v >= rc.height()) continue;
    const auto raw = rect.UnrectifyLeftPixel(Eigen::Vector2d(u, v));
    ASSERT_TRUE(raw.has_value());
    EXPECT_NEAR(rect.left_map_x().at<float>(v, u), raw->x(), 0.05);
    EXPECT_NEAR(rect.left_map_y().at<float>(v, u), raw->y(), 0.05);
  }
  EXPECT_GT(checked, 50);
}

// Check: the constructor's verdict without building the pixel maps, the implausible rig included.
TEST(StereoRectificationTest, CheckAgreesWithTheConstructor) {
  const CameraModel left = testing::EurocCam0();
  EXPECT_NO_THROW(
      StereoRectification::Check(left, testing::EurocCam1(), testing::EurocCam1FromCam0()));
  EXPECT_THROW(StereoRectification::Check(left, testing::EurocCam1(),
                                          testing::EurocCam1FromCam0().Inverse()),
               OptionError);
  // k1 = 50 on the right camera: the views share a sliver, the rectified focal length explodes.
  const CameraModel absurd =
      CameraModel::Pinhole(752, 480, 457.587, 456.134, 379.999, 255.238, {50.0, 0.0, 0.0, 0.0});
  for (const bool check_only : {true, false}) {
    try {
      if (check_only) {
        StereoRectification::Check(left, absurd, testing::EurocCam1FromCam0());
      } else {
        StereoRectification(left, absurd, testing::EurocCam1FromCam0());
      }
      ADD_FAILURE() << "accepted";
    } catch (const OptionError& e) {
      EXPECT_NE(std::string(e.what()).find("implausible stereo calibration"), std::string::npos)
          << e.what();
    }
  }
}

// First image-pair file names present in both cam0 and cam1 of the static EuRoC sequence.
std::optional<std::pair<std::filesystem::path, std::filesystem::path>> FirstPair(
    const std::filesystem::path& mav0) {
  std::ifstream csv(mav0 / "cam0" / "data.csv");
  std::string line;
  while (std::getline(csv, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::string name = line.substr(line.find(',') + 1);
    const std::string trimmed = name.substr(0, name.find_last_not_of("\r ") + 1);
    const auto left = mav0 / "cam0" / "data" / trimmed;
    const auto right = mav0 / "cam1" / "data" / trimmed;
    if (std::filesystem::exists(left) && std::filesystem::exists(right)) {
      return std::make_pair(left, right);
    }
  }
  return std::nullopt;
}

// Median |row difference| of cross-checked ORB matches between two images.
double MedianRowDifference(const cv::Mat& a, const cv::Mat& b, int* matches_out) {
  cv::Ptr<cv::ORB> orb = cv::ORB::create(1500);
  std::vector<cv::KeyPoint> kp_a, kp_b;
  cv::Mat desc_a, desc_b;
  orb->detectAndCompute(a, cv::noArray(), kp_a, desc_a);
  orb->detectAndCompute(b, cv::noArray(), kp_b, desc_b);
  std::vector<cv::DMatch> matches;
  cv::BFMatcher(cv::NORM_HAMMING, /*crossCheck=*/true).match(desc_a, desc_b, matches);
  std::vector<double> dy;
  for (const cv::DMatch& m : matches) {
    const cv::Point2f pa = kp_a[m.queryIdx].pt, pb = kp_b[m.trainIdx].pt;
    // Keep plausible stereo matches: small disparity range, good descriptor distance.
    if (m.distance < 40 && pa.x - pb.x > -1 && pa.x - pb.x < 120)
      dy.push_back(std::abs(pa.y - pb.y));
  }
  *matches_out = static_cast<int>(dy.size());
  if (dy.empty()) return INFINITY;
  std::nth_element(dy.begin(), dy.begin() + dy.size() / 2, dy.end());
  return dy[dy.size() / 2];
}

TEST(StereoRectificationTest, RealEurocPairRectifiesOntoRows) {
  PKSLAM_REQUIRE_SHARED_DATA(shared);
  const auto pair = FirstPair(shared / "euroc" / "V1_01_easy_static" / "mav0");
  ASSERT_TRUE(pair.has_value()) << "no stereo pair in the shared EuRoC data";
  const cv::Mat left = cv::imread(pair->first.string(), cv::IMREAD_GRAYSCALE);
  const cv::Mat right = cv::imread(pair->second.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(left.empty());
  ASSERT_FALSE(right.empty());
  const StereoRectification rect = EurocRectification();
  const auto [left_rect, right_rect] = rect.Rectify(left, right);
  ASSERT_EQ(left_rect.size(), left.size());
  ASSERT_EQ(left_rect.type(), CV_8UC1);
  ASSERT_EQ(right_rect.size(), right.size());
  // alpha 0: no black border; the corners of the rectified images hold real pixels.
  EXPECT_GT(cv::countNonZero(left_rect), 0.99 * left_rect.total());
  EXPECT_GT(cv::countNonZero(right_rect), 0.99 * right_rect.total());
  // Rectified matches lie on the same row; the raw images do not.
  int n_rect = 0, n_raw = 0;
  const double dy_rect = MedianRowDifference(left_rect, right_rect, &n_rect);
  const double dy_raw = MedianRowDifference(left, right, &n_raw);
  RecordProperty("median_dy_rectified", std::to_string(dy_rect));
  RecordProperty("median_dy_raw", std::to_string(dy_raw));
  EXPECT_GT(n_rect, 100);
  EXPECT_LT(dy_rect, 0.6);
  EXPECT_LT(dy_rect, dy_raw);
}

}  // namespace
}  // namespace pkslam
