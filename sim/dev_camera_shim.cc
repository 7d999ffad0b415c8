// TEMPORARY (sim development only): CameraModel's pinhole methods delegating to OpenCV, so
// the simulator can be built and tested before the camera branch lands. CMake compiles this
// file only while core/camera/camera_model.cc does not exist; it is deleted at that merge.
#include <fmt/format.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/util/error.h"

namespace pkslam {

CameraModel CameraModel::Pinhole(int width, int height, double fx, double fy, double cx, double cy,
                                 std::vector<double> distortion) {
  if (width <= 0 || height <= 0 || !(fx > 0) || !(fy > 0)) throw OptionError("bad pinhole");
  if (!(distortion.empty() || distortion.size() == 4 || distortion.size() == 5)) {
    throw OptionError("pinhole distortion needs 0, 4 or 5 coefficients");
  }
  CameraModel c;
  c.type_ = CameraType::kPinhole;
  c.width_ = width;
  c.height_ = height;
  c.fx_ = fx;
  c.fy_ = fy;
  c.cx_ = cx;
  c.cy_ = cy;
  c.distortion_ = std::move(distortion);
  return c;
}

bool CameraModel::HasDistortion() const {
  for (double d : distortion_) {
    if (d != 0.0) return true;
  }
  return false;
}

std::optional<Eigen::Vector2d> CameraModel::Project(const Eigen::Vector3d& p,
                                                    Eigen::Matrix<double, 2, 3>*) const {
  if (p.z() <= 1e-6) return std::nullopt;
  const double x = p.x() / p.z();
  const double y = p.y() / p.z();
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  if (distortion_.size() >= 4) {
    k1 = distortion_[0];
    k2 = distortion_[1];
    p1 = distortion_[2];
    p2 = distortion_[3];
  }
  if (distortion_.size() == 5) k3 = distortion_[4];
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return Eigen::Vector2d(fx_ * xd + cx_, fy_ * yd + cy_);
}

Eigen::Vector3d CameraModel::Unproject(const Eigen::Vector2d& uv) const {
  std::vector<cv::Point2d> in{{uv.x(), uv.y()}};
  std::vector<cv::Point2d> out;
  cv::undistortPoints(
      in, out, CvK(), CvDistortion(), cv::noArray(), cv::noArray(),
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-14));
  return Eigen::Vector3d(out[0].x, out[0].y, 1.0).normalized();
}

bool CameraModel::InImage(const Eigen::Vector2d& uv, double border) const {
  return uv.x() >= border - 0.5 && uv.y() >= border - 0.5 && uv.x() < width_ - 0.5 - border &&
         uv.y() < height_ - 0.5 - border;
}

Eigen::Matrix3d CameraModel::K() const {
  Eigen::Matrix3d k;
  k << fx_, 0, cx_, 0, fy_, cy_, 0, 0, 1;
  return k;
}

cv::Mat CameraModel::CvK() const {
  return (cv::Mat_<double>(3, 3) << fx_, 0, cx_, 0, fy_, cy_, 0, 0, 1);
}

cv::Mat CameraModel::CvDistortion() const {
  cv::Mat d(1, static_cast<int>(distortion_.size()), CV_64F);
  for (std::size_t i = 0; i < distortion_.size(); ++i)
    d.at<double>(static_cast<int>(i)) = distortion_[i];
  return d;
}

std::string CameraModel::ToString() const {
  return fmt::format("pinhole {}x{} f=({}, {}) c=({}, {})", width_, height_, fx_, fy_, cx_, cy_);
}

}  // namespace pkslam
