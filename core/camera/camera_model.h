// Camera models: pinhole with radial-tangential distortion (EuRoC, TUM) and Kannala-Brandt
// equidistant fisheye (KB8, TUM-VI). A CameraModel is a small value type; copy it freely.
// All methods are const and thread-safe.
//
// Frames: "camera" is the optical frame (x right, y down, z forward). Pixel coordinates have
// (0,0) at the centre of the top-left pixel (OpenCV's convention), so the image covers
// [-0.5, width - 0.5) x [-0.5, height - 0.5).
//
// Validity limits: a distortion polynomial is only invertible up to the angle where it stops
// increasing; beyond it, points far outside the field of view would fold back into the image.
// Project rejects such points (max_theta(), and for pinhole the equivalent normalised radius).
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/camera/projection.h"

namespace pkslam {

enum class CameraType {
  kPinhole,        // radial-tangential (k1, k2, p1, p2[, k3]); all-zero = ideal pinhole
  kKannalaBrandt8  // equidistant fisheye (k1, k2, k3, k4)
};

class CameraModel {
 public:
  CameraModel() = default;
  // distortion: {} | {k1,k2,p1,p2} | {k1,k2,p1,p2,k3}. Throws OptionError on bad values
  // (width/height <= 0, fx/fy <= 0 or not finite, other lengths, non-finite coefficients).
  static CameraModel Pinhole(int width, int height, double fx, double fy, double cx, double cy,
                             std::vector<double> distortion = {});
  // distortion: {k1,k2,k3,k4}. Throws OptionError like Pinhole.
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
  // Whether pixels differ from an ideal pinhole's: a non-zero radtan coefficient, or KB8
  // (always, even with zero coefficients: it is the equidistant mapping).
  bool HasDistortion() const;
  // Largest angle from the optical axis (rad) that Project accepts: for KB8 where theta_d(theta)
  // stops increasing (at most pi); for pinhole atan of the largest valid normalised radius
  // (< pi/2).
  double max_theta() const { return max_theta_; }

  // Projects a point in the camera frame to pixels (with distortion). nullopt when the point
  // cannot be imaged by the model (pinhole: z <= 1e-6; KB8: angle > ~ 180 deg; both: beyond
  // max_theta()), NOT when it falls outside the image (use InImage). Optional Jacobian
  // d(uv)/d(p_camera).
  std::optional<Eigen::Vector2d> Project(const Eigen::Vector3d& p_camera,
                                         Eigen::Matrix<double, 2, 3>* d_uv_d_p = nullptr) const;

  // Unit bearing vector of a pixel (iterative undistortion). Inverse of Project up to depth.
  // Exact to ~1e-9 px for pixels inside the valid range; a pixel beyond the model's range
  // (outside max_theta()) gets the bearing of the nearest valid angle.
  Eigen::Vector3d Unproject(const Eigen::Vector2d& uv) const;

  // For pinhole models: the undistorted pixel (the pixel an ideal pinhole with the same
  // fx, fy, cx, cy would see). ORB-SLAM-style trackers work on undistorted keypoints.
  // For KB8: the perspective projection of the pixel's ray with the same fx, fy, cx, cy;
  // NaN for rays at >= 90 degrees, which have no perspective image.
  Eigen::Vector2d UndistortPixel(const Eigen::Vector2d& uv) const;
  // Batch form for keypoints (fast path). `out` is resized; it may not alias `in`.
  void UndistortPixels(const std::vector<cv::Point2f>& in, std::vector<cv::Point2f>* out) const;

  // Whether uv lies in the image area shrunk by `border` pixels on every side:
  // border - 0.5 <= u < width - 0.5 - border (same for v).
  bool InImage(const Eigen::Vector2d& uv, double border = 0.0) const;

  Eigen::Matrix3d K() const;
  cv::Mat CvK() const;           // 3x3 CV_64F
  cv::Mat CvDistortion() const;  // 1xN CV_64F in OpenCV's order (1x4 zeros if none)

  // The parameter array for the templated projections (core/camera/projection.h):
  // pinhole: fx fy cx cy k1 k2 p1 p2 k3; KB8: fx fy cx cy k1 k2 k3 k4 0.
  std::array<double, 9> Params() const;

  // Templated projection for Ceres Jets (bundle adjustment), params as from Params().
  // kPinhole: the IDEAL pinhole (distortion ignored), because BA works on undistorted
  // keypoints; use projection::ProjectRadTan for raw pixels. kKannalaBrandt8: the full model.
  // Returns false when the point cannot be projected (see projection.h).
  template <typename T>
  static bool ProjectT(CameraType type, const double* params, const T* p_camera, T* uv) {
    return type == CameraType::kPinhole ? projection::ProjectIdealPinhole(params, p_camera, uv)
                                        : projection::ProjectKannalaBrandt8(params, p_camera, uv);
  }

  std::string ToString() const;  // one line, for logs and `pkslam info`

 private:
  // Normalised distorted coordinates (x_d, y_d) of an undistorted normalised point (pinhole).
  Eigen::Vector2d UndistortNormalized(double xd, double yd) const;
  // Angle theta with theta_d(theta) == rd, clamped to [0, max_theta_] (KB8).
  double SolveKbTheta(double rd) const;

  CameraType type_ = CameraType::kPinhole;
  int width_ = 0;
  int height_ = 0;
  double fx_ = 0, fy_ = 0, cx_ = 0, cy_ = 0;
  std::vector<double> distortion_;
  // Distortion in fixed slots for the hot paths: pinhole k1 k2 p1 p2 k3; KB8 k1 k2 k3 k4 0.
  std::array<double, 5> coeffs_{};
  bool distorted_ = false;
  double max_theta_ = 0;
  // KB8: theta_d(max_theta_), the largest normalised distorted radius Unproject can invert.
  double max_theta_d_ = 0;
  // Pinhole: largest squared normalised radius (x^2 + y^2) / z^2 Project accepts.
  double max_r2_ = 0;
};

}  // namespace pkslam
