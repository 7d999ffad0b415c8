// Frame-to-frame RGB-D odometry of seed 000 (the Kinect modelling thesis, chapter 4):
//   preprocessing  colour -> grey; depth range gate + bilateral filter (depth_cloud.h)
//   detection      ORB keypoints and descriptors (core/features/orb_extractor.h)
//   matching       brute-force Hamming against the previous accepted frame, keeping the
//                  `max_matches` best; matched keypoints lifted to 3-D with their depth
//   pose           RANSAC around the closed-form SVD alignment (ransac.h), then the motion
//                  gate (a step rotating or translating more than the limits is rejected and
//                  the next frame is matched against the same reference), then chaining
//                  world_from_current = world_from_reference * reference_from_current.
// Each stage is timed (process CPU time, ms; cpu_time.h) as in the thesis's Table 5-3.
//
// Keypoints without a valid depth are dropped before matching (they cannot be lifted, and
// the thesis lifts only matched keypoints, so the 500 best matches are then all usable).
// Not thread-safe: one object per sequence, called from one thread.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "core/camera/camera_model.h"
#include "core/features/descriptor.h"
#include "core/features/orb_extractor.h"
#include "core/geometry/se3.h"
#include "rgbd/depth_cloud.h"
#include "rgbd/ransac.h"

namespace pkslam::rgbd {

struct FeatureOdometryOptions {
  DepthFilterOptions depth;
  // ORB: ORB-SLAM3's TUM settings (1000 features, 1.2, 8 levels, FAST 20/7).
  OrbOptions orb = [] {
    OrbOptions o;
    o.n_features = 1000;
    o.parallel = false;  // the stages are timed one by one
    return o;
  }();
  // Keep this many matches with the smallest Hamming distance (seed 000: 500).
  int max_matches = 500;
  // Only mutual nearest neighbours (a common brute-force refinement; off = the plain nearest
  // neighbour of every current descriptor, as the thesis describes).
  bool cross_check = true;
  // Matches with a larger Hamming distance (of 256 bits) are never used.
  int max_hamming_distance = 80;
  RansacOptions ransac;
  // Motion gate (seed 000, section 4-6): steps beyond these limits are rejected.
  double max_rotation_deg = 15;
  double max_translation_m = 0.15;
  // After this many consecutive rejected frames the reference is replaced by the current
  // frame at the last pose (a tracking break, counted in the results): offline data cannot
  // "move the camera back" as the thesis asks its user to.
  int max_consecutive_rejections = 15;

  void Check() const;
};

struct StageTimesMs {
  double preprocessing = 0;
  double detection = 0;
  double matching = 0;
  double pose = 0;
  double total() const { return preprocessing + detection + matching + pose; }
};

enum class OdometryStatus {
  kFirst,          // the first frame: pose = initial pose, becomes the reference
  kTracked,        // pose estimated and accepted
  kTooFewMatches,  // rejected: fewer matches than RANSAC's min_inliers
  kRansacFailed,   // rejected: too few inliers
  kMotionGate,     // rejected: step larger than the motion limits
  kReset,          // too many rejections: reference replaced, pose carried over
};
const char* OdometryStatusName(OdometryStatus status);
// Whether the frame has a pose (kFirst, kTracked, kReset).
bool HasPose(OdometryStatus status);

struct OdometryStep {
  OdometryStatus status = OdometryStatus::kFirst;
  SE3d world_from_camera;       // valid when HasPose(status)
  SE3d reference_from_current;  // the RANSAC estimate (identity when none)
  int keypoints = 0;            // ORB keypoints detected
  int keypoints_with_depth = 0;
  int matches = 0;  // after the max_matches cut
  int inliers = 0;
  int ransac_iterations = 0;
  double step_rotation_deg = 0;
  double step_translation_m = 0;
  StageTimesMs times;
  cv::Mat depth_m;  // the preprocessed depth (for map building)
};

class FeatureOdometry {
 public:
  FeatureOdometry(const CameraModel& camera, const FeatureOdometryOptions& options,
                  const SE3d& world_from_first = SE3d());

  // colour_bgr: CV_8UC3 (or CV_8UC1); depth_m: CV_32FC1 metres (0 = none), same size.
  OdometryStep Process(const cv::Mat& colour_bgr, const cv::Mat& depth_m);

 private:
  struct Reference {
    std::vector<Descriptor> descriptors;
    std::vector<Eigen::Vector3d> points;  // camera frame
    SE3d world_from_camera;
  };

  FeatureOdometryOptions options_;
  CameraModel camera_;
  DepthLifter lifter_;
  OrbExtractor extractor_;
  SE3d world_from_first_;
  std::optional<Reference> reference_;
  int consecutive_rejections_ = 0;
  std::uint64_t frame_index_ = 0;
};

struct HammingMatch {
  int query = 0;  // index in the current frame's descriptors
  int train = 0;  // index in the reference's descriptors
  int distance = 0;
};

// Brute-force nearest neighbours of every query descriptor among `train` (mutual ones only
// with cross_check), at most max_distance, sorted by distance (ties by query index), the
// first max_matches kept.
std::vector<HammingMatch> MatchBruteForce(const std::vector<Descriptor>& query,
                                          const std::vector<Descriptor>& train, bool cross_check,
                                          int max_distance, int max_matches);

}  // namespace pkslam::rgbd
