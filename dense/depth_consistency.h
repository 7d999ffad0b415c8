// Multi-view consistency of keyframe depth maps: a pixel's depth is kept when other keyframes
// confirm it, and replaced by the mean of the confirming estimates.
//
// Definition. Let p be the camera-frame point of pixel x of view i at depth z_i(x). View j
// confirms it when p, moved into camera j (camera_from_world_j * world_from_camera_i),
// projects inside j's image with depth z_proj > 0, j has a depth z_j at the nearest pixel,
// and |z_j - z_proj| <= tolerance_rel * z_proj. The pixel is kept when itself plus its
// confirming views number at least min_views. Its depth becomes z_i * the weighted mean of
// (1, z_j / z_proj over the confirming j): each confirmation read back along i's ray (exact
// for a surface patch facing the cameras, and within the tolerance's square otherwise),
// weighted by inverse stereo variance (weight (z_i / z_j)^2 against 1 for z_i, as the depth
// error grows with depth squared), so independent stereo errors average down and a far
// confirming view does not spoil a near one.
//
// Views that do not see the point (outside the image, no depth there) neither confirm nor
// reject it: occlusions and holes in other views cost confirmations, not points already
// confirmed elsewhere.
//
// Visibility-aware veto (keep_unconfirmed). A view j contradicts the pixel when
//   (a) j should see p but sees through it: z_j > (1 + tolerance_rel) * z_proj (p would lie in
//       the free space in front of j's surface), or
//   (b) j sees a surface in front of p (z_j < (1 - tolerance_rel) * z_proj) that lies on i's
//       own line of sight: j's point at that pixel projects back into view i within
//       occluder_radius_px of x, at a depth below (1 - tolerance_rel) * z_i (i's depth would
//       lie behind a surface j measured; a genuine occluder of p in j lies off i's ray, while
//       for a depth delta behind the true surface j's point lands only ~ f * B * delta / z^2
//       pixels from x, B the baseline between the views).
// A pixel with fewer than min_views agreeing views is still kept, unaveraged and flagged
// unconfirmed, when no view contradicts it: a surface only one keyframe saw (the ends of the
// sequence, the side only it looked at, a neighbour's hole) is not evidence of an error, a
// neighbour that should see it and disagrees is. With keep_unconfirmed false, min_views
// applies to every pixel.
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
  // Keep pixels with fewer than min_views agreeing views when no view contradicts them.
  bool keep_unconfirmed = true;
  // Pixels of view i deeper than this are dropped (m; 0: none); the neighbours' depths of any
  // range confirm and contradict.
  double max_depth_m = 0.0;
  // Unconfirmed pixels are kept only up to this depth (m; 0: any): a single view's stereo
  // depth has neither averaging nor a second opinion, and its error grows with depth^2.
  double unconfirmed_max_depth_m = 0.0;
  // Radius (px) of test (b) above.
  double occluder_radius_px = 3.0;
  // Drop pixels (even confirmed ones) that more views contradict than confirm.
  bool majority_veto = true;
  // Drop a pixel when a confirming view sees the same point at a depth below z_i / this
  // (0: off). Stereo depth noise grows with z^2, so that view's own (kept, averaged) estimate
  // of the surface is the better one; far copies of a surface only scatter noisy points
  // around it. Coverage stays: the closer view keeps the surface.
  double defer_ratio = 0.0;

  void Check() const;
};

// One neighbouring view: its depth map (CV_32FC1, metres, 0 = none; the camera's image
// geometry) and its pose.
struct DepthView {
  const cv::Mat* depth = nullptr;
  SE3d camera_from_world;
};

struct ConsistencyResult {
  cv::Mat depth;         // filtered (and averaged) depth of view i; 0 = dropped
  cv::Mat views;         // CV_8UC1: agreeing views of a kept pixel (itself included, capped at
                         // 255); 1 for an unconfirmed pixel; 0 where dropped
  int candidates = 0;    // pixels with a depth before the filter (pixel_step grid)
  int kept = 0;          // pixels kept
  int unconfirmed = 0;   // of those, kept without min_views agreeing views (keep_unconfirmed)
  int contradicted = 0;  // pixels dropped because a view contradicts them
  int deferred = 0;      // pixels dropped because a confirming view sees them much closer
};

// Filters view i's depth (`rays`: RayTable(camera), `camera`: the model of all depth maps,
// used to project into the neighbours). Only every pixel_step-th pixel (both directions) is
// considered; the others are 0 in the result.
ConsistencyResult FilterByConsistency(const cv::Mat& depth, const SE3d& world_from_camera,
                                      const std::vector<DepthView>& neighbours, const cv::Mat& rays,
                                      const CameraModel& camera, int pixel_step,
                                      const ConsistencyOptions& options);

}  // namespace pkslam::dense
