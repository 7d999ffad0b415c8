// Turns images into Frames: ORB extraction (both stereo images concurrently), stereo matching
// on the rectified pair or depth lookup for RGB-D. Stateless apart from its configuration.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>

#include "core/features/orb_extractor.h"
#include "core/features/stereo_matcher.h"
#include "map_model/frame.h"

namespace pkslam {

class FrameBuilder {
 public:
  FrameBuilder(std::shared_ptr<const CameraRig> rig, const OrbOptions& orb,
               StereoMatcherOptions stereo = {});

  // Frames built from now on use `rig` (a new calibration estimate).
  void SetRig(std::shared_ptr<const CameraRig> rig) { rig_ = std::move(rig); }

  // Rectified grey pair.
  Frame BuildStereo(FrameId id, std::int64_t t_ns, const cv::Mat& left, const cv::Mat& right) const;
  // Grey image + registered depth (CV_16U scaled by rig.depth_factor, or CV_32F metres).
  Frame BuildRgbd(FrameId id, std::int64_t t_ns, const cv::Mat& grey, const cv::Mat& depth) const;
  // Monocular; `initialisation` doubles the feature count (ORB-SLAM's init extractor).
  Frame BuildMonocular(FrameId id, std::int64_t t_ns, const cv::Mat& grey,
                       bool initialisation = false) const;

 private:
  std::shared_ptr<const CameraRig> rig_;
  OrbExtractor extractor_;
  OrbExtractor init_extractor_;
  StereoMatcherOptions stereo_;
};

}  // namespace pkslam
