#include "rgbd/feature_odometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "core/util/cpu_time.h"
#include "core/util/error.h"

namespace pkslam::rgbd {
namespace {

double MsSince(double start_cpu_ms) { return ProcessCpuMs() - start_cpu_ms; }

constexpr double kRadToDeg = 180.0 / M_PI;

}  // namespace

void FeatureOdometryOptions::Check() const {
  depth.Check();
  orb.Check();
  ransac.Check();
  PKSLAM_CHECK_OPTION(max_matches >= 3, "max_matches", "{}", max_matches);
  PKSLAM_CHECK_OPTION(max_hamming_distance >= 0 && max_hamming_distance <= 256,
                      "max_hamming_distance", "{}", max_hamming_distance);
  PKSLAM_CHECK_OPTION(max_rotation_deg > 0, "max_rotation_deg", "{}", max_rotation_deg);
  PKSLAM_CHECK_OPTION(max_translation_m > 0, "max_translation_m", "{}", max_translation_m);
  PKSLAM_CHECK_OPTION(max_consecutive_rejections >= 0, "max_consecutive_rejections", "{}",
                      max_consecutive_rejections);
}

const char* OdometryStatusName(OdometryStatus status) {
  switch (status) {
    case OdometryStatus::kFirst:
      return "first";
    case OdometryStatus::kTracked:
      return "tracked";
    case OdometryStatus::kTooFewMatches:
      return "too_few_matches";
    case OdometryStatus::kRansacFailed:
      return "ransac_failed";
    case OdometryStatus::kMotionGate:
      return "motion_gate";
    case OdometryStatus::kReset:
      return "reset";
  }
  return "?";
}

bool HasPose(OdometryStatus status) {
  return status == OdometryStatus::kFirst || status == OdometryStatus::kTracked ||
         status == OdometryStatus::kReset;
}

std::vector<HammingMatch> MatchBruteForce(const std::vector<Descriptor>& query,
                                          const std::vector<Descriptor>& train, bool cross_check,
                                          int max_distance, int max_matches) {
  std::vector<HammingMatch> matches;
  if (query.empty() || train.empty()) return matches;
  const int nq = static_cast<int>(query.size());
  const int nt = static_cast<int>(train.size());
  std::vector<int> best_train(nq, -1), best_train_distance(nq, std::numeric_limits<int>::max());
  std::vector<int> best_query(nt, -1), best_query_distance(nt, std::numeric_limits<int>::max());
  for (int q = 0; q < nq; ++q) {
    for (int t = 0; t < nt; ++t) {
      const int d = HammingDistance(query[q], train[t]);
      if (d < best_train_distance[q]) {
        best_train_distance[q] = d;
        best_train[q] = t;
      }
      if (d < best_query_distance[t]) {
        best_query_distance[t] = d;
        best_query[t] = q;
      }
    }
  }
  for (int q = 0; q < nq; ++q) {
    const int t = best_train[q];
    if (best_train_distance[q] > max_distance) continue;
    if (cross_check && best_query[t] != q) continue;
    matches.push_back({q, t, best_train_distance[q]});
  }
  std::stable_sort(
      matches.begin(), matches.end(),
      [](const HammingMatch& a, const HammingMatch& b) { return a.distance < b.distance; });
  if (static_cast<int>(matches.size()) > max_matches) matches.resize(max_matches);
  return matches;
}

FeatureOdometry::FeatureOdometry(const CameraModel& camera, const FeatureOdometryOptions& options,
                                 const SE3d& world_from_first)
    : options_(options),
      camera_(camera),
      lifter_(camera),
      extractor_(options.orb),
      world_from_first_(world_from_first) {
  options_.Check();
}

OdometryStep FeatureOdometry::Process(const cv::Mat& colour_bgr, const cv::Mat& depth_m) {
  PKSLAM_CHECK(!colour_bgr.empty() && colour_bgr.size() == depth_m.size(),
               "colour {}x{} and depth {}x{} differ", colour_bgr.cols, colour_bgr.rows,
               depth_m.cols, depth_m.rows);
  PKSLAM_CHECK(colour_bgr.cols == camera_.width() && colour_bgr.rows == camera_.height(),
               "image {}x{} vs camera {}x{}", colour_bgr.cols, colour_bgr.rows, camera_.width(),
               camera_.height());
  OdometryStep step;
  const std::uint64_t frame = frame_index_++;

  // --- preprocessing ---
  double start = ProcessCpuMs();
  cv::Mat grey;
  if (colour_bgr.channels() == 3) {
    cv::cvtColor(colour_bgr, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = colour_bgr;
  }
  step.depth_m = PreprocessDepth(depth_m, options_.depth);
  step.times.preprocessing = MsSince(start);

  // --- detection ---
  start = ProcessCpuMs();
  OrbFeatures features;
  extractor_.Extract(grey, &features);
  step.times.detection = MsSince(start);
  step.keypoints = static_cast<int>(features.keypoints.size());

  // --- matching (and lifting) ---
  start = ProcessCpuMs();
  Reference current;
  current.descriptors.reserve(features.keypoints.size());
  current.points.reserve(features.keypoints.size());
  for (std::size_t i = 0; i < features.keypoints.size(); ++i) {
    const cv::Point2f& pt = features.keypoints[i].pt;
    const int u = std::clamp(static_cast<int>(std::lround(pt.x)), 0, step.depth_m.cols - 1);
    const int v = std::clamp(static_cast<int>(std::lround(pt.y)), 0, step.depth_m.rows - 1);
    const float d = step.depth_m.at<float>(v, u);
    if (!(d > 0)) continue;
    current.descriptors.push_back(features.descriptors[i]);
    current.points.push_back(lifter_.Lift(pt.x, pt.y, d));
  }
  step.keypoints_with_depth = static_cast<int>(current.points.size());
  std::vector<HammingMatch> matches;
  if (reference_) {
    matches = MatchBruteForce(current.descriptors, reference_->descriptors, options_.cross_check,
                              options_.max_hamming_distance, options_.max_matches);
  }
  step.matches = static_cast<int>(matches.size());
  step.times.matching = MsSince(start);

  // --- pose ---
  start = ProcessCpuMs();
  if (!reference_) {
    step.status = OdometryStatus::kFirst;
    current.world_from_camera = world_from_first_;
  } else {
    std::vector<Eigen::Vector3d> source, target;
    source.reserve(matches.size());
    target.reserve(matches.size());
    for (const HammingMatch& m : matches) {
      source.push_back(current.points[m.query]);
      target.push_back(reference_->points[m.train]);
    }
    RansacOptions ransac = options_.ransac;
    ransac.seed = options_.ransac.seed + frame;
    if (step.matches < options_.ransac.min_inliers) {
      step.status = OdometryStatus::kTooFewMatches;
    } else {
      const RansacResult r = EstimateRigidRansac(source, target, ransac);
      step.ransac_iterations = r.iterations;
      step.inliers = static_cast<int>(r.inliers.size());
      if (!r.success) {
        step.status = OdometryStatus::kRansacFailed;
      } else {
        step.reference_from_current = r.target_from_source;
        step.step_rotation_deg = r.target_from_source.so3().Angle() * kRadToDeg;
        step.step_translation_m = r.target_from_source.translation().norm();
        step.status = (step.step_rotation_deg > options_.max_rotation_deg ||
                       step.step_translation_m > options_.max_translation_m)
                          ? OdometryStatus::kMotionGate
                          : OdometryStatus::kTracked;
      }
    }
    if (step.status == OdometryStatus::kTracked) {
      current.world_from_camera = reference_->world_from_camera * step.reference_from_current;
      current.world_from_camera.Normalize();
      consecutive_rejections_ = 0;
    } else if (++consecutive_rejections_ > options_.max_consecutive_rejections) {
      step.status = OdometryStatus::kReset;
      current.world_from_camera = reference_->world_from_camera;
      consecutive_rejections_ = 0;
    }
  }
  if (HasPose(step.status)) {
    step.world_from_camera = current.world_from_camera;
    reference_ = std::move(current);
  }
  step.times.pose = MsSince(start);
  return step;
}

}  // namespace pkslam::rgbd
