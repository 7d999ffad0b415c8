// Undistortion of one Kannala-Brandt fisheye camera (TUM-VI's monocular and monocular-inertial
// modes) to an ideal pinhole view, the single-camera counterpart of StereoRectification: the
// tracker, matcher and bundle adjustments work on undistorted keypoints of an ideal pinhole, and a
// fisheye image has no such keypoints beyond 90 degrees from its axis. The view keeps the
// camera's orientation (no rotation) and its fx, fy, cx, cy, so the centre keeps the lens's
// resolution; it covers the central part of the field of view (TUM-VI's 512x512 lens: 53 degrees
// either side of the axis, 62 in the corners, where the lens sees 77 and beyond 90) and the rim
// beyond it is not tracked.
//
// Frames: the pinhole view's camera frame is the fisheye's, so body_from_camera is unchanged.
//
// A FisheyeUndistortion is immutable after construction; all methods are const and thread-safe.
// Copies share the remap tables (cv::Mat reference counting).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>

#include "core/camera/camera_model.h"

namespace pkslam {

class FisheyeUndistortion {
 public:
  // `fisheye` must be Kannala-Brandt (throws OptionError otherwise).
  explicit FisheyeUndistortion(const CameraModel& fisheye);

  // The ideal pinhole view (zero distortion, the raw image size) tracking works with.
  const CameraModel& pinhole_camera() const { return pinhole_; }
  const CameraModel& fisheye_camera() const { return fisheye_; }

  // Remap tables for cv::remap (CV_32FC1): pinhole pixel -> raw fisheye pixel.
  const cv::Mat& map_x() const { return map_x_; }
  const cv::Mat& map_y() const { return map_y_; }

  // The pinhole image of a raw image of the calibrated size (bilinear, black outside; throws
  // Error for another size).
  cv::Mat Undistort(const cv::Mat& raw) const;

  // Raw fisheye pixel -> pinhole pixel; nullopt for rays at or beyond 90 degrees from the axis.
  std::optional<Eigen::Vector2d> UndistortPixel(const Eigen::Vector2d& raw) const;
  // Pinhole pixel -> raw fisheye pixel (the inverse); nullopt when the model cannot image it.
  std::optional<Eigen::Vector2d> DistortPixel(const Eigen::Vector2d& uv) const;

 private:
  CameraModel fisheye_;
  CameraModel pinhole_;
  cv::Mat map_x_, map_y_;
};

}  // namespace pkslam
