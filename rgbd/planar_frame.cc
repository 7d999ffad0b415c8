#include "rgbd/planar_frame.h"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "core/util/cpu_time.h"
#include "core/util/error.h"
#include "rgbd/kmeans_segmentation.h"
#include "rgbd/region_growing.h"

namespace pkslam::rgbd {
namespace {

double MsSince(double start_cpu_ms) { return ProcessCpuMs() - start_cpu_ms; }

// Whether two boxes intersect once one is grown by a pixel: they overlap or touch, also at a
// corner (8-connected neighbours).
bool Touching(const cv::Rect& a, const cv::Rect& b) {
  return a.x <= b.x + b.width && b.x <= a.x + a.width && a.y <= b.y + b.height &&
         b.y <= a.y + a.height;
}

// Neighbour lists by sweeping boxes sorted by their left edge.
std::vector<std::vector<int>> TouchingNeighbours(const std::vector<MergeInput>& segments) {
  const int n = static_cast<int>(segments.size());
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return segments[a].bbox.x != segments[b].bbox.x ? segments[a].bbox.x < segments[b].bbox.x
                                                    : a < b;
  });
  std::vector<std::vector<int>> neighbours(n);
  for (int i = 0; i < n; ++i) {
    const cv::Rect& a = segments[order[i]].bbox;
    for (int j = i + 1; j < n; ++j) {
      const cv::Rect& b = segments[order[j]].bbox;
      if (b.x > a.x + a.width) break;  // all later boxes start further right
      if (Touching(a, b)) {
        neighbours[order[i]].push_back(order[j]);
        neighbours[order[j]].push_back(order[i]);
      }
    }
  }
  for (auto& list : neighbours) std::sort(list.begin(), list.end());
  return neighbours;
}

}  // namespace

SegmentationMethod ParseSegmentationMethod(const std::string& name) {
  if (name == "region") return SegmentationMethod::kRegionGrowing;
  if (name == "kmeans") return SegmentationMethod::kKMeans;
  throw OptionError(fmt::format("unknown segmentation '{}' (region | kmeans)", name));
}

const char* SegmentationMethodName(SegmentationMethod method) {
  return method == SegmentationMethod::kRegionGrowing ? "region" : "kmeans";
}

void PlanarFrameOptions::Check() const {
  PKSLAM_CHECK_OPTION(lab_threshold > 0, "lab_threshold", "{}", lab_threshold);
  PKSLAM_CHECK_OPTION(kmeans_clusters >= 1, "kmeans_clusters", "{}", kmeans_clusters);
  PKSLAM_CHECK_OPTION(kmeans_geometry_weight > 0, "kmeans_geometry_weight", "{}",
                      kmeans_geometry_weight);
  PKSLAM_CHECK_OPTION(kmeans_stride >= 1, "kmeans_stride", "{}", kmeans_stride);
  PKSLAM_CHECK_OPTION(kmeans_iterations >= 1, "kmeans_iterations", "{}", kmeans_iterations);
  PKSLAM_CHECK_OPTION(min_segment_points >= 3, "min_segment_points", "{}", min_segment_points);
  PKSLAM_CHECK_OPTION(merge_angle_deg >= 0 && merge_angle_deg <= 90, "merge_angle_deg", "{}",
                      merge_angle_deg);
  PKSLAM_CHECK_OPTION(merge_max_fit_rms_m > 0, "merge_max_fit_rms_m", "{}", merge_max_fit_rms_m);
  PKSLAM_CHECK_OPTION(merge_max_points >= 0, "merge_max_points", "{}", merge_max_points);
  PKSLAM_CHECK_OPTION(samples_per_plane >= 1, "samples_per_plane", "{}", samples_per_plane);
  PKSLAM_CHECK_OPTION(min_sampled_plane_points >= 0, "min_sampled_plane_points", "{}",
                      min_sampled_plane_points);
}

std::vector<std::vector<int>> MergeSegments(const std::vector<MergeInput>& segments,
                                            const PlanarFrameOptions& options) {
  const int n = static_cast<int>(segments.size());
  const auto neighbours = TouchingNeighbours(segments);
  std::vector<int> group_of(n, -1);
  std::vector<std::vector<int>> groups;
  std::vector<int> stack;
  for (int s = 0; s < n; ++s) {
    if (group_of[s] >= 0) continue;
    const int g = static_cast<int>(groups.size());
    groups.push_back({s});
    group_of[s] = g;
    PointMoments merged = segments[s].moments;
    stack.assign(1, s);
    while (!stack.empty()) {
      const int a = stack.back();
      stack.pop_back();
      if (segments[a].rms_m > options.merge_max_fit_rms_m) continue;
      for (const int b : neighbours[a]) {
        if (group_of[b] >= 0) continue;
        if (segments[b].rms_m > options.merge_max_fit_rms_m) continue;
        if (NormalAngleDeg(segments[a].plane, segments[b].plane) > options.merge_angle_deg)
          continue;
        PointMoments candidate = merged;
        candidate.Add(segments[b].moments);
        if (options.merge_max_points > 0 &&
            candidate.count() > static_cast<std::size_t>(options.merge_max_points)) {
          continue;
        }
        const auto plane = candidate.Fit(options.fit);
        if (!plane || candidate.RmsDistance(*plane) > options.merge_max_fit_rms_m) continue;
        // The union's RMS is dominated by the larger part: a small segment off the plane of a
        // large merged one hardly raises it. The newcomer must fit the merged plane itself.
        if (segments[b].moments.RmsDistance(*plane) > options.merge_max_fit_rms_m) continue;
        merged = candidate;
        group_of[b] = g;
        groups[g].push_back(b);
        stack.push_back(b);
      }
    }
  }
  return groups;
}

PlanarFrame BuildPlanarFrame(const cv::Mat& colour_bgr, const cv::Mat& depth_m,
                             const DepthLifter& lifter, const PlanarFrameOptions& options) {
  options.Check();
  PKSLAM_CHECK(colour_bgr.type() == CV_8UC3 && colour_bgr.size() == depth_m.size(),
               "colour must be CV_8UC3 of the depth's size");
  PlanarFrame frame;
  frame.cloud = LiftDepthImage(depth_m, colour_bgr, lifter, 1);
  const int w = depth_m.cols;
  const int num_pixels = static_cast<int>(depth_m.total());

  // --- 1. segmentation ---
  double start = ProcessCpuMs();
  Segmentation seg;
  if (options.segmentation == SegmentationMethod::kRegionGrowing) {
    seg = SegmentRegionGrowing(BgrToLab(colour_bgr), options.lab_threshold);
  } else {
    KMeansOptions km;
    km.clusters = options.kmeans_clusters;
    km.geometry_weight = options.kmeans_geometry_weight;
    km.stride = options.kmeans_stride;
    km.iterations = options.kmeans_iterations;
    km.seed = options.seed;
    seg = SegmentKMeans(frame.cloud, depth_m.size(), km);
  }
  frame.segments = seg.count;
  frame.segmentation_ms = MsSince(start);

  // --- 2. a plane per segment ---
  start = ProcessCpuMs();
  std::vector<std::vector<int>> members(seg.count);
  std::vector<PointMoments> moments(seg.count);
  std::vector<cv::Rect> boxes(seg.count);
  const int* labels = seg.labels.ptr<int>(0);
  for (std::size_t i = 0; i < frame.cloud.size(); ++i) {
    const int pixel = frame.cloud.pixels[i];
    const int id = labels[pixel];
    if (id < 0) continue;
    members[id].push_back(static_cast<int>(i));
    moments[id].Add(frame.cloud.points[i].cast<double>());
    const cv::Rect px(pixel % w, pixel / w, 1, 1);
    boxes[id] = members[id].size() == 1 ? px : (boxes[id] | px);
  }
  std::vector<MergeInput> fitted;
  std::vector<int> fitted_segment;
  for (int id = 0; id < seg.count; ++id) {
    if (static_cast<int>(members[id].size()) < options.min_segment_points) continue;
    const auto plane = moments[id].Fit(options.fit);
    if (!plane) continue;
    fitted.push_back({*plane, moments[id].RmsDistance(*plane), boxes[id], moments[id]});
    fitted_segment.push_back(id);
  }
  frame.segments_fitted = static_cast<int>(fitted.size());

  // --- 3. merging (region growing only) ---
  std::vector<std::vector<int>> groups;
  if (options.segmentation == SegmentationMethod::kRegionGrowing) {
    groups = MergeSegments(fitted, options);
  } else {
    groups.resize(fitted.size());
    for (std::size_t i = 0; i < fitted.size(); ++i) groups[i] = {static_cast<int>(i)};
  }
  std::size_t planar_points = 0;
  for (const auto& group : groups) {
    PlanarSegment out;
    PointMoments merged;
    for (const int f : group) {
      merged.Add(fitted[f].moments);
      const auto& ids = members[fitted_segment[f]];
      out.point_ids.insert(out.point_ids.end(), ids.begin(), ids.end());
      out.bbox = out.bbox.area() == 0 ? fitted[f].bbox : (out.bbox | fitted[f].bbox);
    }
    const auto plane =
        group.size() == 1 ? std::optional<Plane>(fitted[group[0]].plane) : merged.Fit(options.fit);
    if (!plane) continue;  // cannot happen for accepted merges; kept for safety
    out.plane = *plane;
    out.rms_m = merged.RmsDistance(*plane);
    out.points = static_cast<int>(merged.count());
    planar_points += out.point_ids.size();
    frame.planar.push_back(std::move(out));
  }
  frame.planes = static_cast<int>(frame.planar.size());
  frame.dropped_fraction =
      num_pixels > 0 ? 1.0 - static_cast<double>(planar_points) / num_pixels : 0;
  frame.fitting_ms = MsSince(start);

  // --- 4. projection and sampling ---
  start = ProcessCpuMs();
  std::mt19937_64 rng(options.seed);
  std::vector<int> ids;
  for (const PlanarSegment& s : frame.planar) {
    if (static_cast<int>(s.point_ids.size()) < options.min_sampled_plane_points) continue;
    ++frame.sampled_planes;
    ids = s.point_ids;
    const int n = static_cast<int>(ids.size());
    const int take = std::min(n, options.samples_per_plane);
    for (int k = 0; k < take; ++k) {  // partial Fisher-Yates: a uniform subset
      std::uniform_int_distribution<int> pick(k, n - 1);
      std::swap(ids[k], ids[pick(rng)]);
      const Eigen::Vector3d p = frame.cloud.points[ids[k]].cast<double>();
      frame.samples.push_back(s.plane.Project(p).cast<float>());
    }
  }
  frame.sampling_ms = MsSince(start);
  return frame;
}

}  // namespace pkslam::rgbd
