#include "core/camera/fisheye_undistortion.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/util/error.h"

namespace pkslam {

FisheyeUndistortion::FisheyeUndistortion(const CameraModel& fisheye) : fisheye_(fisheye) {
  PKSLAM_CHECK_OPTION(fisheye.type() == CameraType::kKannalaBrandt8, "camera",
                      "fisheye undistortion needs a Kannala-Brandt (equidistant) camera");
  const cv::Size size(fisheye.width(), fisheye.height());
  // The view keeps the lens's own scale at the centre (its fx, fy, cx, cy): a view that fills the
  // image with everything the lens saw (OpenCV's estimateNewCameraMatrixForUndistortRectify) has
  // a focal length of 60 px for TUM-VI's 191 px lens, a third of the resolution where the
  // features are, spent on a stretched rim.
  pinhole_ = CameraModel::Pinhole(size.width, size.height, fisheye.fx(), fisheye.fy(),
                                  fisheye.cx(), fisheye.cy());
  const cv::Mat k_new = pinhole_.CvK();
  // Float maps, as the stereo path: fixed-point maps quantise sampling to 1/32 px.
  cv::fisheye::initUndistortRectifyMap(fisheye.CvK(), fisheye.CvDistortion(),
                                       cv::Mat::eye(3, 3, CV_64F), k_new, size, CV_32FC1, map_x_,
                                       map_y_);
}

cv::Mat FisheyeUndistortion::Undistort(const cv::Mat& raw) const {
  PKSLAM_CHECK(raw.cols == fisheye_.width() && raw.rows == fisheye_.height(),
               "fisheye images must be {}x{}, got {}x{}", fisheye_.width(), fisheye_.height(),
               raw.cols, raw.rows);
  cv::Mat out;
  cv::remap(raw, out, map_x_, map_y_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return out;
}

std::optional<Eigen::Vector2d> FisheyeUndistortion::UndistortPixel(
    const Eigen::Vector2d& raw) const {
  return pinhole_.Project(fisheye_.Unproject(raw));
}

std::optional<Eigen::Vector2d> FisheyeUndistortion::DistortPixel(const Eigen::Vector2d& uv) const {
  return fisheye_.Project(pinhole_.Unproject(uv));
}

}  // namespace pkslam
