#include "dense/dense_cloud.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "core/util/error.h"
#include "core/util/log.h"
#include "core/util/progress.h"
#include "dense/voxel_fusion.h"

namespace pkslam::dense {
namespace {

// Invalidates pixels whose disparity jumps by more than max_step to a valid 4-neighbour.
void FilterDisparityEdges(double max_step, cv::Mat* disparity) {
  const cv::Mat d = disparity->clone();
  for (int r = 0; r < d.rows; ++r) {
    const float* row = d.ptr<float>(r);
    float* out = disparity->ptr<float>(r);
    for (int c = 0; c < d.cols; ++c) {
      if (row[c] <= 0) continue;
      auto jump = [&](float n) { return n > 0 && std::abs(n - row[c]) > max_step; };
      const bool edge = (c > 0 && jump(row[c - 1])) || (c + 1 < d.cols && jump(row[c + 1])) ||
                        (r > 0 && jump(d.ptr<float>(r - 1)[c])) ||
                        (r + 1 < d.rows && jump(d.ptr<float>(r + 1)[c]));
      if (edge) out[c] = 0;
    }
  }
}

struct ViewPoints {
  cv::Mat depth;  // the filtered depth map (kept only for a FilteredDepthSink)
  cv::Mat grey, colour;
  std::vector<Eigen::Vector3f> points;
  std::vector<Rgb> colours;
  std::vector<std::uint8_t> support;
  std::size_t candidates = 0;
  std::size_t unconfirmed = 0;
  std::size_t contradicted = 0;
  std::size_t deferred = 0;
  double valid_share = 0;
};

struct DepthImage {
  cv::Mat depth;  // metres, CV_32FC1
  cv::Mat grey;
  cv::Mat colour;
};

}  // namespace

void DenseOptions::Check() const {
  PKSLAM_CHECK_OPTION(voxel_m > 0 && std::isfinite(voxel_m), "--voxel", "{}", voxel_m);
  PKSLAM_CHECK_OPTION(max_depth_m >= 0, "--max-depth", "{}", max_depth_m);
  PKSLAM_CHECK_OPTION(min_depth_m >= 0 && min_depth_m < MaxDepth(), "--min-depth",
                      "{} (max depth {})", min_depth_m, MaxDepth());
  PKSLAM_CHECK_OPTION(neighbour_max_depth_m >= 0, "--neighbour-max-depth", "{}",
                      neighbour_max_depth_m);
  PKSLAM_CHECK_OPTION(window >= 0, "--window", "{}", window);
  PKSLAM_CHECK_OPTION(min_views <= 2 * window + 1, "--min-views",
                      "{} needs a window of at least {} keyframes each side", min_views,
                      min_views / 2);
  Consistency().Check();
  PKSLAM_CHECK_OPTION(pixel_step >= 1, "--pixel-step", "{}", pixel_step);
  PKSLAM_CHECK_OPTION(border_px >= 0, "border_px", "{}", border_px);
  PKSLAM_CHECK_OPTION(batch >= 1, "batch", "{}", batch);
  stereo.Check();
}

ConsistencyOptions DenseOptions::Consistency() const {
  ConsistencyOptions c;
  c.tolerance_rel = consistency_rel;
  c.min_views = min_views;
  c.keep_unconfirmed = keep_unconfirmed;
  c.majority_veto = majority_veto;
  c.defer_ratio = defer_ratio;
  c.occluder_radius_px = occluder_radius_px;
  c.unconfirmed_max_depth_m = unconfirmed_max_depth_m;
  c.max_depth_m = MaxDepth();
  return c;
}

cv::Mat KeyframeDepth(const KeyframeImages& images, const KeyframeImageSource& source,
                      const DenseOptions& options, double max_depth_m) {
  const double max_depth = max_depth_m > 0 ? max_depth_m : options.MaxDepth();
  cv::Mat depth;
  if (source.source() == DepthSource::kStereo) {
    cv::Mat disparity = ComputeDisparity(images.grey, images.right, options.stereo);
    if (options.edge_disparity_px > 0) FilterDisparityEdges(options.edge_disparity_px, &disparity);
    depth = DisparityToDepth(disparity, source.bf(), max_depth);
  } else {
    depth = images.depth_m.clone();
    PKSLAM_CHECK(depth.type() == CV_32FC1 && depth.size() == images.grey.size(),
                 "depth image does not match the colour image");
  }
  const int b = options.border_px;
  cv::Mat valid;  // the raw footprint shrunk by the border
  if (!source.valid_mask().empty()) {
    PKSLAM_CHECK(source.valid_mask().size() == depth.size(), "valid mask does not match");
    cv::erode(source.valid_mask(), valid,
              cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * b + 1, 2 * b + 1)));
  }
  for (int r = 0; r < depth.rows; ++r) {
    float* z = depth.ptr<float>(r);
    const std::uint8_t* ok = valid.empty() ? nullptr : valid.ptr<std::uint8_t>(r);
    for (int c = 0; c < depth.cols; ++c) {
      const bool inside = r >= b && r < depth.rows - b && c >= b && c < depth.cols - b &&
                          (ok == nullptr || ok[c] != 0);
      if (!inside || !(z[c] >= options.min_depth_m && z[c] <= max_depth)) z[c] = 0;
    }
  }
  return depth;
}

cv::Mat RayTable(const CameraModel& camera) {
  cv::Mat rays(camera.height(), camera.width(), CV_32FC2);
  for (int r = 0; r < rays.rows; ++r) {
    auto* row = rays.ptr<cv::Vec2f>(r);
    for (int c = 0; c < rays.cols; ++c) {
      const Eigen::Vector3d b = camera.Unproject(Eigen::Vector2d(c, r));
      row[c] = b.z() > 1e-9
                   ? cv::Vec2f(static_cast<float>(b.x() / b.z()), static_cast<float>(b.y() / b.z()))
                   : cv::Vec2f(NAN, NAN);
    }
  }
  return rays;
}

void BackProject(const cv::Mat& depth_m, const cv::Mat& rays, const SE3d& world_from_camera,
                 const cv::Mat& grey, const cv::Mat& colour_bgr, int pixel_step,
                 std::vector<Eigen::Vector3f>* points, std::vector<Rgb>* colours,
                 const cv::Mat& views, std::vector<std::uint8_t>* support) {
  PKSLAM_CHECK(views.empty() || (views.type() == CV_8UC1 && views.size() == depth_m.size()),
               "views map does not match the depth map");
  if (support != nullptr) support->clear();
  PKSLAM_CHECK(depth_m.size() == rays.size() && grey.size() == depth_m.size(),
               "depth, rays and image sizes differ");
  const Eigen::Matrix3f rotation = world_from_camera.RotationMatrix().cast<float>();
  const Eigen::Vector3f translation = world_from_camera.translation().cast<float>();
  points->clear();
  colours->clear();
  for (int r = 0; r < depth_m.rows; r += pixel_step) {
    const float* z = depth_m.ptr<float>(r);
    const auto* ray = rays.ptr<cv::Vec2f>(r);
    const auto* g = grey.ptr<std::uint8_t>(r);
    const auto* bgr = colour_bgr.empty() ? nullptr : colour_bgr.ptr<cv::Vec3b>(r);
    const std::uint8_t* n_views = views.empty() ? nullptr : views.ptr<std::uint8_t>(r);
    for (int c = 0; c < depth_m.cols; c += pixel_step) {
      if (z[c] <= 0 || std::isnan(ray[c][0])) continue;
      const Eigen::Vector3f p_camera(ray[c][0] * z[c], ray[c][1] * z[c], z[c]);
      points->push_back(rotation * p_camera + translation);
      colours->push_back(bgr != nullptr ? Rgb{bgr[c][2], bgr[c][1], bgr[c][0]}
                                        : Rgb{g[c], g[c], g[c]});
      if (support != nullptr) support->push_back(n_views != nullptr ? n_views[c] : 1);
    }
  }
}

PointCloud BuildDenseCloud(const Trajectory& keyframes, const KeyframeImageSource& source,
                           const DenseOptions& options, DenseStats* stats,
                           const FilteredDepthSink& sink) {
  options.Check();
  PKSLAM_CHECK(stats != nullptr, "stats is null");
  const auto start = std::chrono::steady_clock::now();
  *stats = DenseStats{};
  stats->keyframes = static_cast<int>(keyframes.size());

  struct Job {
    std::size_t frame;
    SE3d world_from_camera;
  };
  std::vector<Job> jobs;
  for (const StampedPose& kf : keyframes.poses) {
    if (const auto frame = source.FindFrame(kf.t_ns)) {
      jobs.push_back({*frame, kf.pose});
    } else {
      stats->missing_t_ns.push_back(kf.t_ns);
    }
  }
  stats->keyframes_used = static_cast<int>(jobs.size());
  if (jobs.empty()) {
    throw InputError(keyframes.source,
                     "no keyframe timestamp matches a frame of the dataset (another dataset?)");
  }
  if (!stats->missing_t_ns.empty()) {
    PKSLAM_LOG_WARN(
        "{} of {} keyframes have no dataset frame with the same timestamp "
        "(first {:.9f} s); skipped",
        stats->missing_t_ns.size(), keyframes.size(),
        static_cast<double>(stats->missing_t_ns.front()) * 1e-9);
  }

  const cv::Mat rays = RayTable(source.camera());
  const ConsistencyOptions consistency = options.Consistency();
  const std::size_t n = jobs.size();
  const std::size_t window = static_cast<std::size_t>(options.window);
  const std::size_t batch = static_cast<std::size_t>(options.batch);
  // Depth maps (and the images for colours) of the keyframes a block of the window needs;
  // entries are released once no later keyframe's window reaches them.
  std::vector<std::optional<DepthImage>> held(n);
  std::size_t computed = 0;  // depth maps [0, computed) were computed
  VoxelGrid grid(options.voxel_m);
  Progress progress("dense", n, options.quiet);
  double valid_share_sum = 0;
  for (std::size_t begin = 0; begin < n; begin += batch) {
    const std::size_t end = std::min(n, begin + batch);
    const std::size_t need_end = std::min(n, end + window);
    tbb::parallel_for(computed, need_end, [&](std::size_t j) {
      KeyframeImages images = source.Load(jobs[j].frame);
      DepthImage& d = held[j].emplace();
      d.depth = KeyframeDepth(images, source, options, options.NeighbourMaxDepth());
      d.grey = std::move(images.grey);
      d.colour = std::move(images.colour);
    });
    computed = need_end;
    std::vector<ViewPoints> views(end - begin);
    tbb::parallel_for(begin, end, [&](std::size_t i) {
      const DepthImage& d = *held[i];
      std::vector<DepthView> neighbours;
      const std::size_t first = i >= window ? i - window : 0;
      for (std::size_t j = first; j < std::min(n, i + window + 1); ++j) {
        if (j != i) neighbours.push_back({&held[j]->depth, jobs[j].world_from_camera.Inverse()});
      }
      const ConsistencyResult filtered =
          FilterByConsistency(d.depth, jobs[i].world_from_camera, neighbours, rays, source.camera(),
                              options.pixel_step, consistency);
      ViewPoints& v = views[i - begin];
      // Pixels of the pixel_step grid with a depth in [min, max] depth.
      const int step = options.pixel_step;
      const double grid = static_cast<double>((d.depth.rows + step - 1) / step) *
                          static_cast<double>((d.depth.cols + step - 1) / step);
      v.valid_share = static_cast<double>(filtered.candidates) / grid;
      v.candidates = static_cast<std::size_t>(filtered.candidates);
      v.unconfirmed = static_cast<std::size_t>(filtered.unconfirmed);
      v.contradicted = static_cast<std::size_t>(filtered.contradicted);
      v.deferred = static_cast<std::size_t>(filtered.deferred);
      BackProject(filtered.depth, rays, jobs[i].world_from_camera, d.grey, d.colour,
                  options.pixel_step, &v.points, &v.colours, filtered.views, &v.support);
      if (sink) {
        v.depth = filtered.depth;
        v.grey = d.grey;
        v.colour = d.colour;
      }
    });
    for (std::size_t i = begin; i < end; ++i) {
      ViewPoints& v = views[i - begin];
      stats->depth_points += v.candidates;
      stats->consistent_points += v.points.size();
      stats->unconfirmed_points += v.unconfirmed;
      stats->contradicted_points += v.contradicted;
      stats->deferred_points += v.deferred;
      valid_share_sum += v.valid_share;
      grid.AddView(static_cast<int>(i), v.points, v.colours, v.support);
      if (sink) sink(v.depth, v.grey, v.colour, jobs[i].world_from_camera);
      v = ViewPoints{};
      progress.Add();
    }
    // Keyframes before end - window are outside every remaining window.
    for (std::size_t j = 0; j + window < end; ++j) held[j].reset();
    progress.SetSuffix(
        fmt::format("{:.1f} M voxels", static_cast<double>(grid.NumVoxels()) * 1e-6));
  }
  progress.Finish();
  stats->voxels = grid.NumVoxels();
  PointCloud cloud = grid.Extract(1);
  stats->points = cloud.size();
  stats->mean_valid_depth_share = valid_share_sum / static_cast<double>(n);
  stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return cloud;
}

}  // namespace pkslam::dense
