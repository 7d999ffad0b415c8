// A camera frame as tracking sees it: keypoints (raw and undistorted), stereo/RGB-D depth per
// keypoint, descriptors, BoW, a keypoint grid, and tracking's working state (matched map
// points, outlier flags, pose). Owned by the tracker; never shared across threads while it
// is being tracked (keyframes copy what they need).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <opencv2/core/types.hpp>
#include <optional>
#include <vector>

#include "core/bow/bow_vector.h"
#include "core/features/descriptor.h"
#include "core/geometry/se3.h"
#include "core/sensor/camera_rig.h"
#include "core/sensor/rig_calibration.h"
#include "map_model/feature_grid.h"
#include "map_model/keyframe_inertial.h"
#include "map_model/map_ids.h"

namespace pkslam {

class Vocabulary;

// What feature extraction (and stereo / RGB-D depth association) produced for one image.
struct FrameFeatures {
  std::vector<cv::KeyPoint> keypoints;  // raw image coordinates (as extracted)
  std::vector<Descriptor> descriptors;  // one per keypoint
  std::vector<float> right_u;           // stereo/RGB-D: right-image u per keypoint, or -1
  std::vector<float> depth;             // stereo/RGB-D: depth (m) per keypoint, or -1
  // RGB-D: sigma (m) of each depth reading (depth_uncertainty.h); empty for stereo, whose
  // right coordinate is a measurement of its own.
  std::vector<float> depth_sigma;
};

class Frame {
 public:
  Frame() = default;
  // Undistorts keypoints with rig->camera and builds the grid. For RGB-D, pass depth per
  // keypoint and leave right_u empty: it is derived as u_undistorted - bf / depth.
  Frame(FrameId id, std::int64_t t_ns, std::shared_ptr<const CameraRig> rig,
        FrameFeatures features);

  FrameId id() const { return id_; }
  std::int64_t t_ns() const { return t_ns_; }
  double t_s() const { return static_cast<double>(t_ns_) * 1e-9; }
  const CameraRig& rig() const { return *rig_; }
  const std::shared_ptr<const CameraRig>& rig_ptr() const { return rig_; }
  int size() const { return static_cast<int>(keypoints_.size()); }

  const std::vector<cv::KeyPoint>& keypoints() const { return keypoints_; }
  const std::vector<cv::KeyPoint>& keypoints_undistorted() const { return keypoints_un_; }
  const std::vector<float>& right_u() const { return right_u_; }
  const std::vector<float>& depth() const { return depth_; }
  const std::vector<Descriptor>& descriptors() const { return descriptors_; }
  const FeatureGrid& grid() const { return grid_; }

  // Keypoints (undistorted coordinates) within a square of half-size radius around (x, y).
  std::vector<int> FeaturesInArea(double x, double y, double radius, int min_level = -1,
                                  int max_level = -1) const {
    return grid_.FeaturesInArea(keypoints_un_, x, y, radius, min_level, max_level);
  }
  // Into a caller-owned buffer (no allocation per query in matching loops).
  void FeaturesInArea(double x, double y, double radius, int min_level, int max_level,
                      std::vector<int>* out) const {
    grid_.FeaturesInArea(keypoints_un_, x, y, radius, min_level, max_level, out);
  }

  // BoW of the descriptors (computed once; later calls are no-ops).
  void ComputeBoW(const Vocabulary& vocabulary);
  bool HasBoW() const { return bow_computed_; }
  const BowVector& bow() const { return bow_; }
  const FeatureVector& feature_vector() const { return feature_vector_; }

  // Pose. camera_from_world is required by the geometric helpers below.
  void SetPose(const SE3d& camera_from_world);
  bool HasPose() const { return camera_from_world_.has_value(); }
  const SE3d& camera_from_world() const { return *camera_from_world_; }
  const SE3d& world_from_camera() const { return world_from_camera_; }
  Eigen::Vector3d CameraCenter() const { return world_from_camera_.translation(); }

  // World point of keypoint i from its stereo/RGB-D depth, if it has one.
  std::optional<Eigen::Vector3d> UnprojectStereo(int i) const;
  // Camera-frame point of keypoint i from its depth, if it has one.
  std::optional<Eigen::Vector3d> UnprojectToCamera(int i) const;
  bool HasDepth(int i) const { return !depth_.empty() && depth_[i] > 0; }
  // RGB-D: information (1/px^2) of keypoint i's virtual disparity bf / depth from its depth
  // sigma; 0 for stereo keypoints and keypoints without depth (their residual is then on the
  // right coordinate, weighted like u). core/sensor/depth_uncertainty.h.
  double DisparityInformation(int i) const;
  const std::vector<float>& depth_sigma() const { return depth_sigma_; }

  // --- tracking's working state (tracking thread only) ---
  std::vector<MapPointPtr> map_points;  // matched map point per keypoint, or nullptr
  std::vector<std::uint8_t> outliers;   // 1 = rejected by the last pose optimisation
  KeyFramePtr reference_kf;             // keyframe this frame's pose is stored relative to
  FrameImu imu;                         // inertial sensors: preintegration and state

  int NumTrackedMapPoints() const;  // non-null, non-outlier matches

  // Moves the frame to a new calibration of its rig (as KeyFrame::Recalibrate): keypoints
  // through `warp`, the pose (if any) by new_from_old.
  void Recalibrate(std::shared_ptr<const CameraRig> rig, const RigWarp& warp,
                   const SE3d& new_from_old);

 private:
  FrameId id_ = kInvalidId;
  std::int64_t t_ns_ = 0;
  std::shared_ptr<const CameraRig> rig_;
  std::vector<cv::KeyPoint> keypoints_;
  std::vector<cv::KeyPoint> keypoints_un_;
  std::vector<float> right_u_;
  std::vector<float> depth_;
  std::vector<float> depth_sigma_;
  std::vector<Descriptor> descriptors_;
  FeatureGrid grid_;
  bool bow_computed_ = false;
  BowVector bow_;
  FeatureVector feature_vector_;
  std::optional<SE3d> camera_from_world_;
  SE3d world_from_camera_;
};

}  // namespace pkslam
