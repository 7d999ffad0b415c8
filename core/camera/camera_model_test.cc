#include "core/camera/camera_model.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <random>

#include "core/camera/test_cameras.h"
#include "core/util/error.h"

namespace pkslam {
namespace {

using testing::EurocCam0;
using testing::EurocCam1;
using testing::TumViKb8;
using Matrix23d = Eigen::Matrix<double, 2, 3>;

// Unproject then Project every pixel centre; returns the largest round-trip error (px).
double MaxPixelRoundTripError(const CameraModel& cam) {
  double max_err = 0.0;
  for (int v = 0; v < cam.height(); ++v) {
    for (int u = 0; u < cam.width(); ++u) {
      const Eigen::Vector2d uv(u, v);
      const Eigen::Vector3d bearing = cam.Unproject(uv);
      EXPECT_NEAR(bearing.norm(), 1.0, 1e-12);
      const auto back = cam.Project(bearing);
      if (!back) {
        ADD_FAILURE() << "pixel " << u << "," << v << " does not project back";
        return INFINITY;
      }
      max_err = std::max(max_err, (*back - uv).norm());
    }
  }
  return max_err;
}

TEST(CameraModelTest, EurocPinholeRoundTripsEveryPixel) {
  for (const CameraModel& cam : {EurocCam0(), EurocCam1()}) {
    const double max_err = MaxPixelRoundTripError(cam);
    RecordProperty("max_round_trip_px_" + std::to_string(cam.cx()), fmt::format("{:.3g}", max_err));
    EXPECT_LT(max_err, 1e-6) << cam.ToString();
  }
}

TEST(CameraModelTest, Kb8RoundTripsEveryPixel) {
  const CameraModel cam = TumViKb8();
  const double max_err = MaxPixelRoundTripError(cam);
  RecordProperty("max_round_trip_px", fmt::format("{:.3g}", max_err));
  EXPECT_LT(max_err, 1e-6);
  // The corners of this fisheye see beyond 90 degrees: the round trip covers z < 0 rays.
  EXPECT_LT(cam.Unproject(Eigen::Vector2d(0, 0)).z(), 0.0);
}

TEST(CameraModelTest, StrongFiveCoefficientDistortionRoundTrips) {
  // Barrel plus k3 and visible tangential terms (the polynomial folds only at r ~ 2.3, far
  // outside the image).
  const CameraModel cam =
      CameraModel::Pinhole(640, 480, 400, 410, 330, 236, {-0.3, 0.1, 0.002, -0.003, -0.01});
  EXPECT_LT(MaxPixelRoundTripError(cam), 1e-6);
}

TEST(CameraModelTest, ProjectThenUnprojectRecoversTheRay) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> lateral(-1.0, 1.0);
  std::uniform_real_distribution<double> depth(0.5, 10.0);
  for (const CameraModel& cam : {EurocCam0(), TumViKb8()}) {
    int projected = 0;
    for (int i = 0; i < 2000; ++i) {
      const double z = depth(rng);
      const Eigen::Vector3d p(lateral(rng) * z, lateral(rng) * z * 0.7, z);
      const auto uv = cam.Project(p);
      ASSERT_TRUE(uv.has_value());
      if (!cam.InImage(*uv)) continue;
      ++projected;
      EXPECT_LT((cam.Unproject(*uv) - p.normalized()).norm(), 1e-10) << p.transpose();
    }
    EXPECT_GT(projected, 500) << cam.ToString();
  }
}

// Central differences of Project.
Matrix23d NumericJacobian(const CameraModel& cam, const Eigen::Vector3d& p) {
  Matrix23d jac;
  for (int k = 0; k < 3; ++k) {
    const double h = 1e-6 * std::max(1.0, std::abs(p[k]));
    Eigen::Vector3d plus = p, minus = p;
    plus[k] += h;
    minus[k] -= h;
    jac.col(k) = (*cam.Project(plus) - *cam.Project(minus)) / (2.0 * h);
  }
  return jac;
}

TEST(CameraModelTest, AnalyticJacobianMatchesCentralDifferences) {
  const CameraModel ideal = CameraModel::Pinhole(752, 480, 458.654, 457.296, 367.215, 248.375);
  const std::vector<Eigen::Vector3d> points = {
      {0.3, -0.2, 2.0}, {-1.1, 0.7, 1.5}, {0.0, 0.0, 3.0}, {2.0, 1.0, 4.0}, {1e-9, -2e-9, 1.0}};
  for (const CameraModel& cam : {EurocCam0(), ideal, TumViKb8()}) {
    for (const Eigen::Vector3d& p : points) {
      Matrix23d analytic;
      ASSERT_TRUE(cam.Project(p, &analytic).has_value());
      const Matrix23d numeric = NumericJacobian(cam, p);
      EXPECT_LT((analytic - numeric).norm(), 1e-5 * std::max(1.0, numeric.norm()))
          << cam.ToString() << "\np " << p.transpose() << "\nanalytic\n"
          << analytic << "\nnumeric\n"
          << numeric;
    }
  }
  // KB8 beyond 90 degrees (z < 0).
  const Eigen::Vector3d behind(1.0, 0.4, -0.3);
  Matrix23d analytic;
  ASSERT_TRUE(TumViKb8().Project(behind, &analytic).has_value());
  EXPECT_LT((analytic - NumericJacobian(TumViKb8(), behind)).norm(), 1e-5 * analytic.norm());
}

std::vector<cv::Point3d> RandomPointsInView(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> lateral(-0.9, 0.9);
  std::uniform_real_distribution<double> depth(0.5, 20.0);
  std::vector<cv::Point3d> points;
  for (int i = 0; i < n; ++i) {
    const double z = depth(rng);
    points.emplace_back(lateral(rng) * z, lateral(rng) * z * 0.6, z);
  }
  return points;
}

TEST(CameraModelTest, PinholeAgreesWithCvProjectPoints) {
  const CameraModel k3_cam =
      CameraModel::Pinhole(640, 480, 400, 410, 330, 236, {-0.3, 0.1, 0.002, -0.003, -0.01});
  const std::vector<cv::Point3d> points = RandomPointsInView(500, 3);
  for (const CameraModel& cam : {EurocCam0(), k3_cam}) {
    std::vector<cv::Point2d> cv_uv;
    cv::projectPoints(points, cv::Vec3d::zeros(), cv::Vec3d::zeros(), cam.CvK(), cam.CvDistortion(),
                      cv_uv);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const auto uv = cam.Project(Eigen::Vector3d(points[i].x, points[i].y, points[i].z));
      ASSERT_TRUE(uv.has_value());
      EXPECT_NEAR(uv->x(), cv_uv[i].x, 1e-9);
      EXPECT_NEAR(uv->y(), cv_uv[i].y, 1e-9);
    }
  }
}

TEST(CameraModelTest, Kb8AgreesWithCvFisheyeProjectPoints) {
  const CameraModel cam = TumViKb8();
  const std::vector<cv::Point3d> points = RandomPointsInView(500, 4);
  std::vector<cv::Point2d> cv_uv;
  cv::fisheye::projectPoints(points, cv_uv, cv::Vec3d::zeros(), cv::Vec3d::zeros(), cam.CvK(),
                             cam.CvDistortion());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto uv = cam.Project(Eigen::Vector3d(points[i].x, points[i].y, points[i].z));
    ASSERT_TRUE(uv.has_value());
    EXPECT_NEAR(uv->x(), cv_uv[i].x, 1e-9);
    EXPECT_NEAR(uv->y(), cv_uv[i].y, 1e-9);
  }
}

std::vector<cv::Point2f> PixelGrid(const CameraModel& cam, int step) {
  std::vector<cv::Point2f> pixels;
  for (int v = 0; v < cam.height(); v += step) {
    for (int u = 0; u < cam.width(); u += step) pixels.emplace_back(u, v);
  }
  pixels.emplace_back(cam.width() - 1, cam.height() - 1);
  return pixels;
}

TEST(CameraModelTest, UndistortPixelAgreesWithCvUndistortPoints) {
  const CameraModel cam = EurocCam0();
  const std::vector<cv::Point2f> pixels = PixelGrid(cam, 8);
  std::vector<cv::Point2f> ours;
  cam.UndistortPixels(pixels, &ours);
  ASSERT_EQ(ours.size(), pixels.size());
  // OpenCV's fixed-point iteration, run to convergence.
  std::vector<cv::Point2d> converged;
  std::vector<cv::Point2d> pixels_d(pixels.begin(), pixels.end());
  cv::undistortPoints(pixels_d, converged, cam.CvK(), cam.CvDistortion(), cv::noArray(), cam.CvK(),
                      cv::TermCriteria(cv::TermCriteria::COUNT, 200, 0));
  // OpenCV's default (5 iterations) is what ORB-SLAM uses; it is off at the corners.
  std::vector<cv::Point2f> cv_default;
  cv::undistortPoints(pixels, cv_default, cam.CvK(), cam.CvDistortion(), cv::noArray(), cam.CvK());
  double max_default_err = 0.0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const Eigen::Vector2d single = cam.UndistortPixel(Eigen::Vector2d(pixels[i].x, pixels[i].y));
    EXPECT_NEAR(single.x(), converged[i].x, 1e-6) << pixels[i];
    EXPECT_NEAR(single.y(), converged[i].y, 1e-6) << pixels[i];
    // And it is the pixel an ideal pinhole sees for the same ray.
    const Eigen::Vector3d ray = cam.Unproject(Eigen::Vector2d(pixels[i].x, pixels[i].y));
    EXPECT_NEAR(single.x(), cam.fx() * ray.x() / ray.z() + cam.cx(), 1e-9);
    max_default_err = std::max(
        max_default_err, std::hypot(cv_default[i].x - single.x(), cv_default[i].y - single.y()));
  }
  RecordProperty("cv_default_max_error_px", std::to_string(max_default_err));
  EXPECT_GT(max_default_err, 0.1);  // documents why we do not use the default criteria
}

TEST(CameraModelTest, BatchUndistortionEqualsSingleOnEveryPixel) {
  // The batch path (4-lane Newton with a scalar fallback) must equal the robust single path up
  // to float rounding everywhere, including the corners where lanes fall back. 1e-4 px is
  // about two float ulps at u ~ 750.
  const CameraModel k3_cam =
      CameraModel::Pinhole(640, 480, 400, 410, 330, 236, {-0.3, 0.1, 0.002, -0.003, -0.01});
  for (const CameraModel& cam : {EurocCam0(), k3_cam, TumViKb8()}) {
    std::vector<cv::Point2f> pixels = PixelGrid(cam, 1);
    pixels.emplace_back(-0.4f, 3.7f);  // odd count: exercises the tail loop
    std::vector<cv::Point2f> batch;
    cam.UndistortPixels(pixels, &batch);
    ASSERT_EQ(batch.size(), pixels.size());
    int compared = 0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      const Eigen::Vector2d single = cam.UndistortPixel({pixels[i].x, pixels[i].y});
      if (std::isnan(single.x())) {  // KB8 rays beyond 90 degrees
        EXPECT_TRUE(std::isnan(batch[i].x));
        continue;
      }
      ++compared;
      // Float rounding, relative for KB8's huge perspective coordinates near 90 degrees.
      ASSERT_NEAR(batch[i].x, single.x(), 1e-4 + 1e-7 * std::abs(single.x())) << pixels[i];
      ASSERT_NEAR(batch[i].y, single.y(), 1e-4 + 1e-7 * std::abs(single.y())) << pixels[i];
    }
    EXPECT_GT(compared, cam.width() * cam.height() / 2);
  }
}

TEST(CameraModelTest, Kb8UndistortPixelIsThePerspectiveImageOfTheRay) {
  const CameraModel cam = TumViKb8();
  const Eigen::Vector3d p(0.4, -0.3, 1.0);
  const Eigen::Vector2d uv = *cam.Project(p);
  const Eigen::Vector2d und = cam.UndistortPixel(uv);
  EXPECT_NEAR(und.x(), cam.fx() * 0.4 + cam.cx(), 1e-8);
  EXPECT_NEAR(und.y(), cam.fy() * -0.3 + cam.cy(), 1e-8);
  // A corner ray is beyond 90 degrees: no perspective image.
  EXPECT_TRUE(std::isnan(cam.UndistortPixel(Eigen::Vector2d(0, 0)).x()));
}

TEST(CameraModelTest, UndistortWithoutDistortionIsIdentity) {
  const CameraModel cam = CameraModel::Pinhole(640, 480, 500, 500, 320, 240);
  EXPECT_FALSE(cam.HasDistortion());
  EXPECT_FALSE(CameraModel::Pinhole(640, 480, 500, 500, 320, 240, {0, 0, 0, 0}).HasDistortion());
  EXPECT_TRUE(EurocCam0().HasDistortion());
  EXPECT_TRUE(
      CameraModel::KannalaBrandt8(640, 480, 500, 500, 320, 240, {0, 0, 0, 0}).HasDistortion());
  const std::vector<cv::Point2f> in = {{1.5f, 2.5f}, {600.f, 400.f}};
  std::vector<cv::Point2f> out;
  cam.UndistortPixels(in, &out);
  EXPECT_EQ(out, in);
  EXPECT_EQ(cam.UndistortPixel(Eigen::Vector2d(10, 20)), Eigen::Vector2d(10, 20));
}

TEST(CameraModelTest, ProjectValidity) {
  const CameraModel cam = EurocCam0();
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(0.1, 0.1, 1e-7)).has_value());
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(0.1, 0.1, -1.0)).has_value());
  EXPECT_TRUE(cam.Project(Eigen::Vector3d(100.0, 0.0, 1.0)).has_value());  // outside, valid
  EXPECT_EQ(cam.max_theta(), M_PI / 2);  // EuRoC's radial polynomial never folds

  // k1 = -0.3 alone folds at r = 1/sqrt(0.9): a point 60 degrees off axis would otherwise land
  // back near the image centre.
  const CameraModel folding = CameraModel::Pinhole(640, 480, 400, 400, 320, 240, {-0.3, 0, 0, 0});
  EXPECT_NEAR(folding.max_theta(), std::atan(1.0 / std::sqrt(0.9)), 1e-9);
  EXPECT_TRUE(folding.Project(Eigen::Vector3d(1.0, 0.0, 1.0)).has_value());
  EXPECT_FALSE(folding.Project(Eigen::Vector3d(std::sqrt(3.0), 0.0, 1.0)).has_value());
  // A pixel beyond the largest distorted radius (0.703) unprojects to about the limit angle.
  const Eigen::Vector3d far = folding.Unproject(Eigen::Vector2d(320 + 400 * 0.9, 240));
  EXPECT_NEAR(std::atan2(far.x(), far.z()), folding.max_theta(), 1e-3);

  const CameraModel kb = TumViKb8();
  EXPECT_TRUE(kb.Project(Eigen::Vector3d(1.0, 0.0, -0.2)).has_value());  // 101 degrees
  EXPECT_FALSE(kb.Project(Eigen::Vector3d(0.0, 0.0, -1.0)).has_value());
  EXPECT_EQ(kb.max_theta(), M_PI);
  const Eigen::Vector2d centre = *kb.Project(Eigen::Vector3d(0, 0, 2));
  EXPECT_EQ(centre, Eigen::Vector2d(kb.cx(), kb.cy()));
  EXPECT_LT((kb.Unproject(centre) - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
}

TEST(CameraModelTest, Kb8RejectsPointsBeyondTheFold) {
  // theta_d' = 1 - 0.3 theta^2 vanishes at theta = 1/sqrt(0.3) ~ 1.826 rad.
  const CameraModel cam =
      CameraModel::KannalaBrandt8(512, 512, 190, 190, 256, 256, {-0.1, 0, 0, 0});
  EXPECT_NEAR(cam.max_theta(), 1.0 / std::sqrt(0.3), 1e-9);
  EXPECT_TRUE(cam.Project(Eigen::Vector3d(std::sin(1.7), 0, std::cos(1.7))).has_value());
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(std::sin(1.9), 0, std::cos(1.9))).has_value());
  // A pixel beyond theta_d(max_theta) unprojects to the limit angle.
  const Eigen::Vector3d far = cam.Unproject(Eigen::Vector2d(256 + 190 * 5.0, 256));
  EXPECT_NEAR(std::acos(far.z()), cam.max_theta(), 1e-9);
}

TEST(CameraModelTest, FactoriesValidate) {
  EXPECT_THROW(CameraModel::Pinhole(0, 480, 400, 400, 320, 240), OptionError);
  EXPECT_THROW(CameraModel::Pinhole(640, -1, 400, 400, 320, 240), OptionError);
  EXPECT_THROW(CameraModel::Pinhole(640, 480, 0, 400, 320, 240), OptionError);
  EXPECT_THROW(CameraModel::Pinhole(640, 480, 400, -400, 320, 240), OptionError);
  EXPECT_THROW(CameraModel::Pinhole(640, 480, NAN, 400, 320, 240), OptionError);
  EXPECT_THROW(CameraModel::Pinhole(640, 480, 400, 400, INFINITY, 240), OptionError);
  EXPECT_THROW(CameraModel::Pinhole(640, 480, 400, 400, 320, 240, {0.1, 0.2, 0.0}), OptionError);
  EXPECT_THROW(CameraModel::Pinhole(640, 480, 400, 400, 320, 240, {0, 0, 0, 0, 0, 0}), OptionError);
  EXPECT_THROW(CameraModel::Pinhole(640, 480, 400, 400, 320, 240, {0, NAN, 0, 0}), OptionError);
  EXPECT_THROW(CameraModel::KannalaBrandt8(512, 0, 190, 190, 256, 256, {0, 0, 0, 0}), OptionError);
  EXPECT_THROW(CameraModel::KannalaBrandt8(512, 512, 190, 0, 256, 256, {0, 0, 0, 0}), OptionError);
  EXPECT_THROW(CameraModel::KannalaBrandt8(512, 512, 190, 190, 256, 256, {0, 0, INFINITY, 0}),
               OptionError);
  try {
    CameraModel::Pinhole(640, 480, -1, 400, 320, 240);
    FAIL() << "no throw";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("fx"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(CameraModel::Pinhole(640, 480, 400, 400, 320, 240, {0.1, 0.2, 0.0, 0.0, 0.1}));
}

TEST(CameraModelTest, InImageUsesThePixelArea) {
  const CameraModel cam = CameraModel::Pinhole(640, 480, 500, 500, 320, 240);
  EXPECT_TRUE(cam.InImage({0, 0}));
  EXPECT_TRUE(cam.InImage({-0.5, -0.5}));
  EXPECT_FALSE(cam.InImage({-0.51, 10}));
  EXPECT_TRUE(cam.InImage({639.49, 479.49}));
  EXPECT_FALSE(cam.InImage({639.5, 10}));
  EXPECT_FALSE(cam.InImage({10, 479.5}));
  EXPECT_TRUE(cam.InImage({20, 20}, 20.0));
  EXPECT_FALSE(cam.InImage({19, 20}, 20.0));
  EXPECT_FALSE(cam.InImage({620, 20}, 20.0));
  EXPECT_TRUE(cam.InImage({619, 459}, 20.0));
}

TEST(CameraModelTest, MatricesAndText) {
  const CameraModel cam = EurocCam0();
  const Eigen::Matrix3d k = cam.K();
  EXPECT_EQ(k(0, 0), 458.654);
  EXPECT_EQ(k(1, 1), 457.296);
  EXPECT_EQ(k(0, 2), 367.215);
  EXPECT_EQ(k(1, 2), 248.375);
  EXPECT_EQ(k(2, 2), 1.0);
  EXPECT_EQ(k(1, 0), 0.0);
  const cv::Mat cv_k = cam.CvK();
  ASSERT_EQ(cv_k.type(), CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_EQ(cv_k.at<double>(r, c), k(r, c));
  }
  const cv::Mat d = cam.CvDistortion();
  ASSERT_EQ(d.rows, 1);
  ASSERT_EQ(d.cols, 4);
  EXPECT_EQ(d.at<double>(0, 0), -0.28340811);
  EXPECT_EQ(d.at<double>(0, 3), 1.76187114e-05);
  EXPECT_EQ(CameraModel::Pinhole(640, 480, 500, 500, 320, 240).CvDistortion().cols, 4);
  EXPECT_EQ(TumViKb8().CvDistortion().at<double>(0, 2), -0.00205);

  EXPECT_EQ(cam.ToString(),
            "pinhole-radtan 752x480 fx=458.654 fy=457.296 cx=367.215 cy=248.375 "
            "k1,k2,p1,p2[,k3]=[-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]");
  EXPECT_EQ(TumViKb8().ToString(),
            "kannala-brandt8 512x512 fx=190.98 fy=190.98 cx=254.93 cy=256.89 "
            "k1..k4=[0.00348, 0.000715, -0.00205, 0.000203]");
  const std::array<double, 9> params = TumViKb8().Params();
  EXPECT_EQ(params[4], 0.00348);
  EXPECT_EQ(params[7], 0.000203);
  EXPECT_EQ(params[8], 0.0);
}

}  // namespace
}  // namespace pkslam
