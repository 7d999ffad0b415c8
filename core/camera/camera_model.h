// Camera models: pinhole with radial-tangential distortion (EuRoC, TUM) and Kannala-Brandt
// equidistant fisheye (KB8, TUM-VI). A CameraModel is a small value type; copy it freely.
//
// Frames: "camera" is the optical frame (x right, y down, z forward). Pixel coordinates have
// (0,0) at the centre of the top-left pixel (OpenCV's convention).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace pkslam {

enum class CameraType {
  kPinhole,        // radial-tangential (k1, k2, p1, p2[, k3]); all-zero = ideal pinhole
  kKannalaBrandt8  // equidistant fisheye (k1, k2, k3, k4)
};

class CameraModel {
 public:
  CameraModel() = default;
  // distortion: {} | {k1,k2,p1,p2} | {k1,k2,p1,p2,k3}. Throws OptionError on bad values.
  static CameraModel Pinhole(int width, int height, double fx, double fy, double cx, double cy,
                             std::vector<double> distortion = {});
  // distortion: {k1,k2,k3,k4}.
  static CameraModel KannalaBrandt8(int width, int height, double fx, double fy, double cx,
                                    double cy, std::array<double, 4> distortion);

  CameraType type() const { return type_; }
  int width() const { return width_; }
  int height() const { return height_; }
  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  const std::vector<double>& distortion() const { return distortion_; }
  bool HasDistortion() const;

  // Projects a point in the camera frame to pixels (with distortion). nullopt when the point
  // cannot be imaged by the model (pinhole: z <= 1e-6; KB8: angle > ~ 180 deg), NOT when it
  // falls outside the image (use InImage). Optional Jacobian d(uv)/d(p_camera).
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& p_camera,
                                         Eigen::Matrix<double, 2, 3>* d_uv_d_p = nullptr) const;

  // Unit bearing vector of a pixel (iterative undistortion). Inverse of Project up to depth.
  Eigen::Vector3d Unproject(const Eigen::Vector2d& uv) const;

  // For pinhole models: the undistorted pixel (the pixel an ideal pinhole with the same
  // fx, fy, cx, cy would see). ORB-SLAM-style trackers work on undistorted keypoints.
  Eigen::Vector2d UndistortPixel(const Eigen::Vector2d& uv) const;
  // Batch form for keypoints (fast path).
  void UndistortPixels(const std::vector<cv::Point2f>& in, std::vector<cv::Point2f>* out) const;

  bool InImage(const Eigen::Vector2d& uv, double border = 0.0) const;

  Eigen::Matrix3d K() const;
  cv::Mat CvK() const;           // 3x3 CV_64F
  cv::Mat CvDistortion() const;  // 1xN CV_64F in OpenCV's order

  std::string ToString() const;  // one line, for logs and `pkslam info`

 private:
  CameraType type_ = CameraType::kPinhole;
  int width_ = 0;
  int height_ = 0;
  double fx_ = 0, fy_ = 0, cx_ = 0, cy_ = 0;
  std::vector<double> distortion_;
};

}  // namespace pkslam
