// Keypoint measurements of a frame or keyframe moved to a new calibration of its rig (online
// calibration; KeyFrame::Recalibrate, Frame::Recalibrate): tracking-camera keypoints through
// `warp` (stereo: re-rectified, and the raw keypoints with them since stereo keypoints are
// extracted from the rectified image; monocular: re-undistorted), stereo right coordinates
// re-rectified and depths recomputed with the new bf (RGB-D: the virtual right coordinate from
// the unchanged depth). A keypoint the warp cannot map keeps its coordinates and loses its stereo
// match; a match whose disparity is no longer positive is dropped.
#pragma once

#include <opencv2/core/types.hpp>
#include <vector>

#include "core/sensor/camera_rig.h"
#include "core/sensor/rig_calibration.h"

namespace pkslam {

void RecalibrateFeatures(const CameraRig& rig, const RigWarp& warp,
                         std::vector<cv::KeyPoint>* keypoints,
                         std::vector<cv::KeyPoint>* keypoints_undistorted,
                         std::vector<float>* right_u, std::vector<float>* depth);

}  // namespace pkslam
