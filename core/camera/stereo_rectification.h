// Stereo rectification of a calibrated pinhole or fisheye pair (EuRoC, TUM-VI): after it, both
// cameras share one ideal pinhole model, their optical axes are parallel, and the right camera sits
// at x = +baseline in the rectified left frame, so a point appears on the same row in both images
// with disparity u_left - u_right = bf / depth.
//
// Frames: "left"/"right" are the raw (physical) camera frames, "rect_left"/"rect_right" the
// rotated, rectified frames (same centres). A SLAM system tracking rectified images must use
// body_from_rect_left (BodyFromRectLeft) as its camera pose, not body_from_left.
//
// A StereoRectification is immutable after construction; all methods are const and
// thread-safe. Copies share the remap tables (cv::Mat reference counting).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"
#include "core/geometry/so3.h"

namespace pkslam {

class StereoRectification {
 public:
  // Both cameras must be of one model (pinhole radial-tangential, or Kannala-Brandt fisheye:
  // OpenCV's cv::fisheye model) and one size; right_from_left maps left-camera points to
  // right-camera points. Uses cv::stereoRectify with alpha 0 (only valid pixels in the rectified
  // images), or cv::fisheye::stereoRectify with balance 0, and CALIB_ZERO_DISPARITY (shared
  // principal point). Throws OptionError for unsupported inputs (mixed models, size mismatch,
  // zero baseline).
  StereoRectification(const CameraModel& left, const CameraModel& right,
                      const SE3d& right_from_left);
  // The constructor's checks alone, without the pixel maps: throws the same OptionError (an
  // unsupported rig, or a rectified focal length outside 1/4-4x the cameras': implausible).
  static void Check(const CameraModel& left, const CameraModel& right, const SE3d& right_from_left);

  // The shared rectified camera: ideal pinhole, zero distortion, the raw image size.
  const CameraModel& rectified_camera() const { return rectified_; }
  // Distance between the optical centres (m), and fx * baseline (px * m).
  double baseline() const { return baseline_; }
  double bf() const { return rectified_.fx() * baseline_; }

  const CameraModel& left_camera() const { return left_; }
  const CameraModel& right_camera() const { return right_; }
  const SO3d& rect_left_from_left() const { return rect_left_from_left_; }
  const SO3d& rect_right_from_right() const { return rect_right_from_right_; }
  // The rectified pair's extrinsic: identity rotation, translation (-baseline, 0, 0).
  SE3d rect_right_from_rect_left() const;
  // The camera pose of the rectified left camera in the body frame.
  SE3d BodyFromRectLeft(const SE3d& body_from_left) const {
    return body_from_left * SE3d(rect_left_from_left_.Inverse(), Eigen::Vector3d::Zero());
  }

  // Remap tables for cv::remap (CV_32FC1 x and y maps, rectified image size): rectified pixel
  // -> raw pixel.
  const cv::Mat& left_map_x() const { return left_map_x_; }
  const cv::Mat& left_map_y() const { return left_map_y_; }
  const cv::Mat& right_map_x() const { return right_map_x_; }
  const cv::Mat& right_map_y() const { return right_map_y_; }

  // Rectified images (bilinear interpolation, black outside). Any cv::remap-able type; both
  // images must have the calibrated size (throws Error otherwise).
  std::pair<cv::Mat, cv::Mat> Rectify(const cv::Mat& left, const cv::Mat& right) const;

  // The rectified pixel of a raw pixel (for keypoint-level rectification). nullopt only for
  // rays that end up behind the rectified camera (never for a normal stereo rig's image).
  std::optional<Eigen::Vector2d> RectifyLeftPixel(const Eigen::Vector2d& uv_left) const;
  std::optional<Eigen::Vector2d> RectifyRightPixel(const Eigen::Vector2d& uv_right) const;
  // The raw pixel of a rectified pixel (inverse of Rectify*Pixel): where a keypoint found in a
  // rectified image was measured by the physical camera. Online calibration (issue 36) moves
  // keypoints from one rectification to the next through these. nullopt when the raw model
  // cannot image the ray (never inside a normal rig's rectified image).
  std::optional<Eigen::Vector2d> UnrectifyLeftPixel(const Eigen::Vector2d& uv_rect) const;
  std::optional<Eigen::Vector2d> UnrectifyRightPixel(const Eigen::Vector2d& uv_rect) const;

 private:
  CameraModel left_;
  CameraModel right_;
  CameraModel rectified_;
  double baseline_ = 0;
  SO3d rect_left_from_left_;
  SO3d rect_right_from_right_;
  cv::Mat left_map_x_, left_map_y_, right_map_x_, right_map_y_;
};

}  // namespace pkslam
