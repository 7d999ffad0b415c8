// The images of a run's keyframes, as the run's tracker saw them: a dataset on disk (EuRoC
// stereo or TUM RGB-D) opened with the same settings rules as `pkslam run`, stereo pairs
// rectified with the same rectification (built from the same settings, as
// system/rig_factory.cc does), frames found by exact timestamp.
//
// Immutable after Open; Load may be called from several threads.
#pragma once

#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/camera/stereo_rectification.h"
#include "io/euroc_dataset.h"
#include "io/settings.h"
#include "io/tum_rgbd_dataset.h"

namespace pkslam::dense {

enum class DepthSource { kStereo, kRgbd };

struct KeyframeImages {
  std::int64_t t_ns = 0;
  // What tracking worked on: the rectified left image (stereo) or the raw colour image's grey
  // version (RGB-D). CV_8UC1.
  cv::Mat grey;
  // Colour image (CV_8UC3, BGR) for RGB-D, empty for grey stereo.
  cv::Mat colour;
  // Stereo: the rectified right image (CV_8UC1). RGB-D: empty.
  cv::Mat right;
  // RGB-D: depth in metres (CV_32FC1, 0 = none), registered to `grey`. Stereo: empty.
  cv::Mat depth_m;
};

class KeyframeImageSource {
 public:
  // `settings`: the settings file the run used (nullopt: as `pkslam run` defaults: EuRoC
  // sensor.yaml files, TUM RGB-D DATASET/settings.yaml). EuRoC datasets give stereo (cam1
  // required), TUM RGB-D datasets depth images. Throws InputError / OptionError.
  // full_view (stereo with rectification): rectify onto a canvas grown to hold every raw pixel
  // of both cameras, with the run's rectifying rotations and focal length (so the run's
  // keyframe poses and bf stay valid): the run's rectified images (alpha 0, the raw size) crop
  // the distorted periphery the cameras saw.
  static KeyframeImageSource Open(const std::filesystem::path& dataset,
                                  const std::optional<std::filesystem::path>& settings,
                                  bool full_view = false);

  DepthSource source() const { return source_; }
  const Settings& settings() const { return settings_; }
  // The camera of `grey`: the rectified pinhole (stereo) or camera1 as calibrated (RGB-D; may
  // be distorted). Keyframe poses of the run are poses of this camera.
  const CameraModel& camera() const { return camera_; }
  // The ideal pinhole the run's undistorted keypoints live in (same fx, fy, cx, cy, no
  // distortion); equal to camera() for rectified stereo.
  CameraModel PinholeCamera() const;
  // Stereo: rectified fx * baseline (px m); RGB-D: 0.
  double bf() const { return bf_; }
  // full_view: CV_8UC1 over camera()'s image, 255 where the left pixel comes from inside the
  // raw left image and its right counterpart row from inside the raw right image; empty when
  // every pixel is valid.
  const cv::Mat& valid_mask() const { return valid_mask_; }
  const std::optional<StereoRectification>& rectification() const { return rectification_; }

  // Frame timestamps (t_ns) in dataset order.
  const std::vector<std::int64_t>& timestamps() const { return timestamps_; }
  // Index of the frame with this timestamp, or the nearest within a quarter of the frame
  // interval (a pose stamped on the IMU clock: image stamp + the camera-IMU time offset).
  std::optional<std::size_t> FindFrame(std::int64_t t_ns) const;
  // Loads frame `index` (throws InputError for missing/corrupt image files).
  KeyframeImages Load(std::size_t index) const;

 private:
  KeyframeImageSource() = default;

  DepthSource source_ = DepthSource::kStereo;
  Settings settings_;
  CameraModel camera_;
  double bf_ = 0;
  std::optional<StereoRectification> rectification_;
  // full_view remap tables (rectified pixel -> raw pixel, CV_32FC1); empty otherwise.
  cv::Mat left_map_x_, left_map_y_, right_map_x_, right_map_y_;
  cv::Mat valid_mask_;
  std::optional<EurocDataset> euroc_;
  std::optional<TumRgbdDataset> tum_;
  std::vector<std::int64_t> timestamps_;
  std::vector<std::pair<std::size_t, std::size_t>> frames_;  // (left|rgb, right|depth)
};

// cv::undistort of a raw image to `camera`'s ideal pinhole (identity for undistorted cameras).
cv::Mat UndistortImage(const cv::Mat& image, const CameraModel& camera);

}  // namespace pkslam::dense
