#include "core/camera/stereo_rectification.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/util/error.h"

namespace pkslam {
namespace {

Eigen::Matrix3d ToEigen3x3(const cv::Mat& m) {
  Eigen::Matrix3d e;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) e(r, c) = m.at<double>(r, c);
  }
  return e;
}

// The rectifying rotations and projections of a rig, after the checks that it can be rectified
// for row-wise stereo matching; the pixel maps are the constructor's (most of its cost).
struct RectifyingTransforms {
  cv::Mat r1, r2, p1, p2;
  double baseline = 0;
};

RectifyingTransforms ComputeRectifyingTransforms(const CameraModel& left, const CameraModel& right,
                                                 const SE3d& right_from_left) {
  PKSLAM_CHECK_OPTION(left.type() == right.type(), "stereo cameras",
                      "both cameras need the same model (pinhole or Kannala-Brandt)");
  PKSLAM_CHECK_OPTION(left.width() == right.width() && left.height() == right.height(),
                      "stereo cameras", "image sizes differ ({}x{} vs {}x{})", left.width(),
                      left.height(), right.width(), right.height());
  PKSLAM_CHECK_OPTION(right_from_left.translation().norm() > 1e-6, "stereo extrinsic",
                      "baseline is {} m", right_from_left.translation().norm());

  cv::Mat rotation(3, 3, CV_64F);
  cv::Mat translation(3, 1, CV_64F);
  const Eigen::Matrix3d r = right_from_left.RotationMatrix();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) rotation.at<double>(i, j) = r(i, j);
    translation.at<double>(i, 0) = right_from_left.translation()[i];
  }
  const cv::Size size(left.width(), left.height());
  RectifyingTransforms t;
  cv::Mat q;
  if (left.type() == CameraType::kKannalaBrandt8) {
    // Kannala-Brandt with 4 coefficients is OpenCV's fisheye model (Kalibr's "equidistant").
    // Balance 0 alone would fit everything both lenses see into the image: for TUM-VI's 191 px
    // lenses a focal length of 62 px, a third of the resolution where the features are. The
    // second call scales the view (fov_scale divides the focal length) to the lenses' own focal
    // length, keeping the central part of the field; the rim beyond it is not tracked.
    const auto rectify = [&](double fov_scale) {
      cv::fisheye::stereoRectify(left.CvK(), left.CvDistortion(), right.CvK(),
                                 right.CvDistortion(), size, rotation, translation, t.r1, t.r2,
                                 t.p1, t.p2, q, cv::CALIB_ZERO_DISPARITY, size,
                                 /*balance=*/0.0, fov_scale);
    };
    rectify(1.0);
    const double wide_focal = t.p1.at<double>(0, 0);
    const double lens_focal = std::min(left.fx(), right.fx());
    if (wide_focal > 0 && wide_focal < lens_focal) rectify(wide_focal / lens_focal);
  } else {
    cv::stereoRectify(left.CvK(), left.CvDistortion(), right.CvK(), right.CvDistortion(), size,
                      rotation, translation, t.r1, t.r2, t.p1, t.p2, q, cv::CALIB_ZERO_DISPARITY,
                      /*alpha=*/0.0, size);
  }
  // OpenCV rectifies a vertical rig along the columns; the stereo matcher needs rows.
  PKSLAM_CHECK_OPTION(std::abs(t.p2.at<double>(1, 3)) == 0.0, "stereo extrinsic",
                      "the cameras are displaced vertically; only horizontal rigs are supported");
  t.baseline = -t.p2.at<double>(0, 3) / t.p2.at<double>(0, 0);
  PKSLAM_CHECK_OPTION(t.baseline > 0.0, "stereo extrinsic",
                      "the right camera is on the left of the left camera (baseline {} m); "
                      "swap the cameras",
                      t.baseline);
  // With alpha 0 the rectified view keeps only pixels both cameras see; implausible intrinsics
  // or extrinsics shrink that to a sliver and the focal length to tens of thousands of pixels
  // (0 frames tracked). A real rig stays near its cameras' focal length.
  const double focal = t.p1.at<double>(0, 0);
  const double camera_focal = std::min(left.fx(), right.fx());
  if (!(focal >= 0.25 * camera_focal && focal <= 4.0 * camera_focal)) {
    throw OptionError(fmt::format(
        "implausible stereo calibration: rectification gives a focal length of {:.0f} px from "
        "cameras of {:.0f} and {:.0f} px (the intrinsics, distortion or stereo extrinsic cannot "
        "be a real rig)",
        focal, left.fx(), right.fx()));
  }
  return t;
}

}  // namespace

void StereoRectification::Check(const CameraModel& left, const CameraModel& right,
                                const SE3d& right_from_left) {
  ComputeRectifyingTransforms(left, right, right_from_left);
}

StereoRectification::StereoRectification(const CameraModel& left, const CameraModel& right,
                                         const SE3d& right_from_left)
    : left_(left), right_(right) {
  const RectifyingTransforms t = ComputeRectifyingTransforms(left, right, right_from_left);
  baseline_ = t.baseline;
  rectified_ =
      CameraModel::Pinhole(left.width(), left.height(), t.p1.at<double>(0, 0),
                           t.p1.at<double>(1, 1), t.p1.at<double>(0, 2), t.p1.at<double>(1, 2));
  rect_left_from_left_ = SO3d(ToEigen3x3(t.r1));
  rect_right_from_right_ = SO3d(ToEigen3x3(t.r2));

  // Float maps: fixed-point (CV_16SC2) maps would quantise sampling positions to 1/32 px,
  // which costs sub-pixel stereo accuracy for a negligible speed gain at VGA size.
  const cv::Size size(left.width(), left.height());
  if (left.type() == CameraType::kKannalaBrandt8) {
    cv::fisheye::initUndistortRectifyMap(left.CvK(), left.CvDistortion(), t.r1, t.p1, size,
                                         CV_32FC1, left_map_x_, left_map_y_);
    cv::fisheye::initUndistortRectifyMap(right.CvK(), right.CvDistortion(), t.r2, t.p2, size,
                                         CV_32FC1, right_map_x_, right_map_y_);
  } else {
    cv::initUndistortRectifyMap(left.CvK(), left.CvDistortion(), t.r1, t.p1, size, CV_32FC1,
                                left_map_x_, left_map_y_);
    cv::initUndistortRectifyMap(right.CvK(), right.CvDistortion(), t.r2, t.p2, size, CV_32FC1,
                                right_map_x_, right_map_y_);
  }
}

SE3d StereoRectification::rect_right_from_rect_left() const {
  return SE3d(SO3d(), Eigen::Vector3d(-baseline_, 0.0, 0.0));
}

std::pair<cv::Mat, cv::Mat> StereoRectification::Rectify(const cv::Mat& left,
                                                         const cv::Mat& right) const {
  const cv::Size size(left_.width(), left_.height());
  PKSLAM_CHECK(left.size() == size && right.size() == size,
               "stereo images must be {}x{}, got {}x{} and {}x{}", size.width, size.height,
               left.cols, left.rows, right.cols, right.rows);
  std::pair<cv::Mat, cv::Mat> rectified;
  cv::remap(left, rectified.first, left_map_x_, left_map_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::remap(right, rectified.second, right_map_x_, right_map_y_, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT);
  return rectified;
}

std::optional<Eigen::Vector2d> StereoRectification::RectifyLeftPixel(
    const Eigen::Vector2d& uv_left) const {
  return rectified_.Project(rect_left_from_left_ * left_.Unproject(uv_left));
}

std::optional<Eigen::Vector2d> StereoRectification::RectifyRightPixel(
    const Eigen::Vector2d& uv_right) const {
  return rectified_.Project(rect_right_from_right_ * right_.Unproject(uv_right));
}

std::optional<Eigen::Vector2d> StereoRectification::UnrectifyLeftPixel(
    const Eigen::Vector2d& uv_rect) const {
  return left_.Project(rect_left_from_left_.Inverse() * rectified_.Unproject(uv_rect));
}

std::optional<Eigen::Vector2d> StereoRectification::UnrectifyRightPixel(
    const Eigen::Vector2d& uv_rect) const {
  return right_.Project(rect_right_from_right_.Inverse() * rectified_.Unproject(uv_rect));
}

}  // namespace pkslam
