// Multi-view consistency of keyframe depth maps: a pixel's depth is kept when other keyframes
// confirm it, and replaced by the mean of the confirming estimates.
//
// Definition. Let p be the camera-frame point of pixel x of view i at depth z_i(x). View j
// confirms it when p, moved into camera j (camera_from_world_j * world_from_camera_i),
// projects inside j's image with depth z_proj > 0, j has a depth z_j at the nearest pixel,
// and |z_j - z_proj| <= tolerance_rel * z_proj. The pixel is kept when itself plus its
// confirming views number at least min_views. Its depth becomes z_i * mean(1, z_j / z_proj
// over the confirming j): each confirmation read back along i's ray (exact for a surface
// patch facing the cameras, and within the tolerance's square otherwise), so independent
// stereo errors average down.
//
// Views that do not see the point (outside the image, no depth there) neither confirm nor
// reject it: occlusions and holes in other views cost confirmations, not points already
// confirmed elsewhere.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"

namespace pkslam::dense {

struct ConsistencyOptions {
  // Relative depth agreement for a confirmation (|z_j - z_proj| / z_proj). Stereo depth
  // error grows with depth (dz = z^2 / bf per pixel of disparity), so the tolerance is relative.
  double tolerance_rel = 0.05;
  // Views (this one included) that must agree; 1 keeps every pixel (no averaging either).
  int min_views = 2;
  // Replace the depth by the mean of the confirming estimates (else keep z_i).
  bool average = true;

  void Check() const;
};

// One neighbouring view: its depth map (CV_32FC1, metres, 0 = none; the camera's image
// geometry) and its pose.
struct DepthView {
  const cv::Mat* depth = nullptr;
  SE3d camera_from_world;
};

struct ConsistencyResult {
  cv::Mat depth;       // filtered (and averaged) depth of view i; 0 = dropped
  int candidates = 0;  // pixels with a depth before the filter (pixel_step grid)
  int kept = 0;        // pixels kept
};

// Filters view i's depth (`rays`: RayTable(camera), `camera`: the model of all depth maps,
// used to project into the neighbours). Only every pixel_step-th pixel (both directions) is
// considered; the others are 0 in the result.
ConsistencyResult FilterByConsistency(const cv::Mat& depth, const SE3d& world_from_camera,
                                      const std::vector<DepthView>& neighbours, const cv::Mat& rays,
                                      const CameraModel& camera, int pixel_step,
                                      const ConsistencyOptions& options);

}  // namespace pkslam::dense
