// Which points of a reference surface a set of cameras saw: the denominator of "restricted"
// completeness (how much of what the keyframes could see was reconstructed).
//
// Definition. A reference point p is visible from camera k when
//   (1) it projects inside the image, at least border_px from the border;
//   (2) its depth z_k(p) lies in [min_depth_m, max_depth_m] (the dense tool's depth range);
//   (3) it is not occluded: z_k(p) <= Z_k(u, v) + occlusion_tolerance_m, where Z_k is the
//       z-buffer of the reference cloud itself rendered into camera k, each point splatted as
//       a square of its footprint (spacing_m * f / z pixels, at least one pixel).
// It is visible from the set when it is visible from at least one camera. The reference
// surface is the occluder, so holes in the reconstructed depth maps do not shrink the
// denominator. Surfaces seen at very grazing angles count as self-occluded when their depth
// across one footprint changes by more than the tolerance.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/geometry/se3.h"

namespace pkslam::dense {

struct VisibilityOptions {
  double min_depth_m = 0.2;
  double max_depth_m = 4.0;
  int border_px = 4;
  // Reference point spacing (the simulator's reference_cloud.ply: 0.01 m).
  double spacing_m = 0.01;
  double occlusion_tolerance_m = 0.03;

  void Check() const;
};

// One flag per point (1 = visible from at least one camera). `camera_from_world` poses are in
// the points' frame; `camera` projects camera-frame points to pixels (with its distortion).
std::vector<std::uint8_t> VisibleFromCameras(const std::vector<Eigen::Vector3f>& points,
                                             const std::vector<SE3d>& camera_from_world,
                                             const CameraModel& camera,
                                             const VisibilityOptions& options);

}  // namespace pkslam::dense
