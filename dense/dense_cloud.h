// `pkslam dense`: a dense point cloud from a run's keyframes. For each keyframe (the run's
// keyframes.txt, world_from_camera of the tracked camera, matched to the dataset's frames by
// exact timestamp): a depth map (rectified SGBM stereo with a left-right check, or the RGB-D
// depth image); the multi-view consistency filter against the `window` keyframes before and
// after it (dense/depth_consistency.h: keep pixels confirmed by >= min_views keyframes, average
// the confirming depths); back-projection to the world frame at the keyframe's final pose; and
// fusion of all keyframes in a voxel grid averaging the points per voxel (dense/voxel_fusion.h).
//
// Depth maps are computed in parallel (TBB) in batches and held only while a keyframe of the
// window needs them; keyframes are fused in order, so the cloud does not depend on the thread
// count.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "dense/depth_consistency.h"
#include "dense/keyframe_images.h"
#include "dense/stereo_depth.h"
#include "io/point_cloud.h"
#include "io/trajectory.h"

namespace pkslam::dense {

struct DenseOptions {
  // Voxel side of the fusion grid (m).
  double voxel_m = 0.01;
  // Depth range used (m). Stereo depth error grows with depth squared (sigma_z = z^2 / bf *
  // sigma_d: ~2 cm at 3 m on EuRoC for a 0.25 px disparity error); 0 = 4 m.
  double max_depth_m = 0;
  double min_depth_m = 0.2;
  // Depths up to this still confirm or contradict other keyframes' depths (m; <= max depth:
  // max depth); only depths up to max depth become points. A surface one keyframe sees at
  // 3.8 m and its neighbour at 4.3 m is then confirmed and averaged instead of left to one
  // noisy view.
  double neighbour_max_depth_m = 8.0;
  // Keep pixels whose depth at least this many keyframes agree on (itself included; 1 = no
  // multi-view filter).
  int min_views = 2;
  // Relative depth agreement of a confirming keyframe (dense/depth_consistency.h).
  double consistency_rel = 0.05;
  // Keep depths fewer than min_views keyframes agree on when no keyframe of the window that
  // should see them contradicts them (dense/depth_consistency.h); false: min_views for all.
  bool keep_unconfirmed = true;
  // Keep unconfirmed depths only up to this depth (m; 0: any). A single view's stereo depth
  // has no second opinion and its error grows with depth^2: on the simulator, unconfirmed
  // points 2-3.5 m from their keyframe had a median error of 2.8-3.5 cm, confirmed ones 1.1-1.8.
  double unconfirmed_max_depth_m = 3.0;
  // A keyframe's surface within this many pixels of a depth's line of sight, in front of
  // it, contradicts it (dense/depth_consistency.h, test (b)).
  double occluder_radius_px = 3.0;
  // Drop depths that more keyframes contradict than confirm.
  bool majority_veto = true;
  // Drop a depth that a confirming keyframe sees from closer than depth / defer_ratio (its
  // estimate is the more accurate one; 0: off).
  double defer_ratio = 0.0;
  // Keyframes (in keyframe order) on each side of a keyframe that may confirm its depths.
  int window = 8;
  // Use every pixel_step-th pixel in both directions (1 = all).
  int pixel_step = 1;
  // Stereo: drop pixels at depth discontinuities, where the disparity differs from a
  // 4-neighbour's by more than this (px; SGBM smears foreground over background there);
  // <= 0 disables.
  double edge_disparity_px = 0.5;
  // Pixels closer than this to the image border (or, with full_view, to the edge of the raw
  // images' footprint) are not used.
  int border_px = 4;
  // Stereo: rectify onto the full view of the raw cameras (KeyframeImageSource::Open's
  // full_view) instead of the run's cropped rectified image. The caller opens the source;
  // this records the choice for the statistics.
  bool full_view = true;
  StereoDepthOptions stereo;
  // Keyframes processed in parallel per batch (memory: ~3 MB per keyframe held, batch + 2 *
  // window held at a time).
  int batch = 8;
  bool quiet = false;  // no progress bar

  double MaxDepth() const { return max_depth_m > 0 ? max_depth_m : 4.0; }
  double NeighbourMaxDepth() const { return std::max(MaxDepth(), neighbour_max_depth_m); }
  ConsistencyOptions Consistency() const;
  void Check() const;
};

struct DenseStats {
  int keyframes = 0;                       // in keyframes.txt
  int keyframes_used = 0;                  // with a matching dataset frame
  std::vector<std::int64_t> missing_t_ns;  // keyframes without a frame of that timestamp
  std::size_t depth_points = 0;         // pixels with a depth (pixel_step grid) before the filter
  std::size_t consistent_points = 0;    // of those, kept by the multi-view filter
  std::size_t unconfirmed_points = 0;   // of the kept, without min_views agreeing keyframes
  std::size_t contradicted_points = 0;  // dropped: a keyframe contradicts them
  std::size_t deferred_points = 0;      // dropped: a confirming keyframe sees them much closer
  std::size_t voxels = 0;               // occupied voxels
  std::size_t points = 0;               // points in the output cloud (one per voxel)
  double mean_valid_depth_share = 0;    // share of pixels with a depth, mean over keyframes
  double seconds = 0;
};

// The depth map (metres, CV_32FC1, 0 = none) of one frame as the dense tool uses it: stereo
// SGBM + left-right check + edge filter, or the RGB-D depth; clipped to [min depth,
// max_depth_m] (<= 0: options.MaxDepth()) and the image border.
cv::Mat KeyframeDepth(const KeyframeImages& images, const KeyframeImageSource& source,
                      const DenseOptions& options, double max_depth_m = 0);

// Per-pixel rays (x/z, y/z) of a camera, for back-projection (undistorts distorted cameras).
cv::Mat RayTable(const CameraModel& camera);  // CV_32FC2

// World points (and colours: grey replicated, or the colour image's RGB) of a depth map.
// `views` (CV_8UC1, optional: empty) gives each point's support (ConsistencyResult::views).
void BackProject(const cv::Mat& depth_m, const cv::Mat& rays, const SE3d& world_from_camera,
                 const cv::Mat& grey, const cv::Mat& colour_bgr, int pixel_step,
                 std::vector<Eigen::Vector3f>* points, std::vector<Rgb>* colours,
                 const cv::Mat& views = cv::Mat(), std::vector<std::uint8_t>* support = nullptr);

// The fused cloud of all keyframes. Keyframes without a dataset frame of the same timestamp
// are skipped and listed in stats (a warning is logged). Throws InputError when no keyframe
// matches a frame (the run belongs to another dataset).
// Called in keyframe order with each keyframe's depth map after the multi-view filter (metres,
// 0 = dropped), its grey and colour (may be empty) images and its pose (dense/mesh.h fuses
// them into a TSDF).
using FilteredDepthSink =
    std::function<void(const cv::Mat& depth_m, const cv::Mat& grey, const cv::Mat& colour_bgr,
                       const SE3d& world_from_camera)>;
PointCloud BuildDenseCloud(const Trajectory& keyframes, const KeyframeImageSource& source,
                           const DenseOptions& options, DenseStats* stats,
                           const FilteredDepthSink& sink = {});

}  // namespace pkslam::dense
