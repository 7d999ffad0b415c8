// One RGB-D frame turned into sampled plane points (seed 001, sections 3-1 to 3-2):
//   1. over-segmentation: Lab region growing (region_growing.h) or the K-Means baseline
//      (kmeans_segmentation.h);
//   2. a plane per segment from its valid-depth points (plane_fit.h); segments with fewer than
//      3 points or a singular fit are dropped (with the zero-depth pixels: the paper's ~4%);
//   3. merging (region growing only, as in the paper): segments are neighbours when their
//      bounding boxes, grown by one pixel, intersect; a stack-driven flood over neighbours
//      merges a neighbour when the normals agree within merge_angle_deg, each segment's own fit
//      is good (RMS below merge_max_fit_rms_m) and the merged segment stays within the limits
//      (its refitted RMS, and the RMS of the newcomer's points to the refitted plane, below
//      merge_max_fit_rms_m -- which also keeps parallel planes at different depths apart --
//      and at most merge_max_points points); merged segments are refitted;
//   4. every point of a plane is projected onto it and N of them are drawn at random (all when
//      fewer; optionally only planes of a minimum size), the points ICP registers.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "rgbd/depth_cloud.h"
#include "rgbd/plane_fit.h"

namespace pkslam::rgbd {

enum class SegmentationMethod { kRegionGrowing, kKMeans };
// "region" | "kmeans"; throws OptionError otherwise.
SegmentationMethod ParseSegmentationMethod(const std::string& name);
const char* SegmentationMethodName(SegmentationMethod method);

struct PlanarFrameOptions {
  SegmentationMethod segmentation = SegmentationMethod::kRegionGrowing;
  // Region growing: Lab distance threshold (the paper tries 10..30 and uses 15).
  double lab_threshold = 15;
  // K-Means: number of clusters (the paper matches the region-growing plane count).
  int kmeans_clusters = 400;
  // K-Means: weight of the (normalised) coordinates against the colour (the paper: "a
  // constant larger than one").
  double kmeans_geometry_weight = 2.0;
  // K-Means: cluster every stride-th pixel (in u and v); its cost is pixels x clusters.
  int kmeans_stride = 2;
  // K-Means: Lloyd iterations.
  int kmeans_iterations = 10;
  PlaneFitMethod fit = PlaneFitMethod::kLeastSquares;
  // Segments with fewer valid points are dropped (3: a plane needs three points).
  int min_segment_points = 3;
  // Merging: largest angle between neighbouring normals [deg] (the paper: 15/30/45/60).
  double merge_angle_deg = 45;
  // Merging: largest plane-fit RMS of a segment and of a merged segment [m].
  double merge_max_fit_rms_m = 0.02;
  // Merging: largest merged segment [points]; 0 = no limit.
  int merge_max_points = 0;
  // Points drawn per plane (the paper: N = 200).
  int samples_per_plane = 200;
  // Planes with fewer points are not sampled (0 = every plane, as the paper). Colour region
  // growing on textured surfaces leaves hundreds of slivers along colour edges: each gives all
  // its few points, so together they can supply most of the samples while holding a few
  // percent of the points, and their normals are unreliable.
  int min_sampled_plane_points = 0;
  // Seed of the sampler and of K-Means (frame results are a function of image and seed).
  std::uint64_t seed = 1;

  void Check() const;
};

struct PlanarSegment {
  Plane plane;
  double rms_m = 0;            // fit RMS of its points
  int points = 0;              // valid-depth points
  cv::Rect bbox;               // pixel bounding box
  std::vector<int> point_ids;  // indices into PlanarFrame::cloud
};

struct PlanarFrame {
  ColouredCloud cloud;                   // every valid-depth pixel, camera frame
  int segments = 0;                      // segmentation output (before dropping)
  int segments_fitted = 0;               // with a plane
  int planes = 0;                        // after merging
  double dropped_fraction = 0;           // pixels without a plane (zero depth or dropped)
  std::vector<PlanarSegment> planar;     // the final planes
  std::vector<Eigen::Vector3f> samples;  // projected, sampled points (camera frame)
  int sampled_planes = 0;                // planes that gave samples
  double segmentation_ms = 0;            // Lab conversion + segmentation
  double fitting_ms = 0;                 // plane fits, merging, refits
  double sampling_ms = 0;                // projection and sampling
  double time_ms() const { return segmentation_ms + fitting_ms + sampling_ms; }
};

// colour_bgr CV_8UC3 and depth_m CV_32FC1 (0 = none) of the lifter's size.
PlanarFrame BuildPlanarFrame(const cv::Mat& colour_bgr, const cv::Mat& depth_m,
                             const DepthLifter& lifter, const PlanarFrameOptions& options);

// The merge step on its own (exposed for tests and the threshold table): groups of segment
// indices, each group one merged plane. Only segments with a plane take part.
struct MergeInput {
  Plane plane;
  double rms_m = 0;
  cv::Rect bbox;
  PointMoments moments;
};
std::vector<std::vector<int>> MergeSegments(const std::vector<MergeInput>& segments,
                                            const PlanarFrameOptions& options);

}  // namespace pkslam::rgbd
