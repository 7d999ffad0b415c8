#include "map_model/frame.h"

#include "core/bow/vocabulary.h"
#include "core/sensor/depth_uncertainty.h"
#include "core/util/error.h"
#include "map_model/map_point.h"
#include "map_model/recalibrate_features.h"

namespace pkslam {

Frame::Frame(FrameId id, std::int64_t t_ns, std::shared_ptr<const CameraRig> rig,
             FrameFeatures features)
    : id_(id),
      t_ns_(t_ns),
      rig_(std::move(rig)),
      keypoints_(std::move(features.keypoints)),
      right_u_(std::move(features.right_u)),
      depth_(std::move(features.depth)),
      depth_sigma_(std::move(features.depth_sigma)),
      descriptors_(std::move(features.descriptors)) {
  PKSLAM_CHECK(descriptors_.size() == keypoints_.size(), "{} descriptors for {} keypoints",
               descriptors_.size(), keypoints_.size());
  const std::size_t n = keypoints_.size();
  keypoints_un_ = keypoints_;
  if (rig_->camera.HasDistortion() && n > 0) {
    std::vector<cv::Point2f> raw(n);
    std::vector<cv::Point2f> undistorted;
    for (std::size_t i = 0; i < n; ++i) raw[i] = keypoints_[i].pt;
    rig_->camera.UndistortPixels(raw, &undistorted);
    for (std::size_t i = 0; i < n; ++i) keypoints_un_[i].pt = undistorted[i];
  }
  if (!depth_.empty()) {
    PKSLAM_CHECK(depth_.size() == n, "{} depths for {} keypoints", depth_.size(), n);
    if (right_u_.empty()) {
      // RGB-D: a virtual right coordinate so stereo residuals apply unchanged.
      right_u_.assign(n, -1.0f);
      for (std::size_t i = 0; i < n; ++i) {
        if (depth_[i] > 0) {
          right_u_[i] = keypoints_un_[i].pt.x - static_cast<float>(rig_->bf / depth_[i]);
        }
      }
    }
  }
  if (!depth_sigma_.empty()) {
    PKSLAM_CHECK(depth_sigma_.size() == n, "{} depth sigmas for {} keypoints", depth_sigma_.size(),
                 n);
  }
  if (!right_u_.empty()) {
    PKSLAM_CHECK(right_u_.size() == n, "{} right coordinates for {} keypoints", right_u_.size(), n);
  }
  grid_ = FeatureGrid(keypoints_un_, rig_->bounds);
  map_points.assign(n, nullptr);
  outliers.assign(n, 0);
}

void Frame::Recalibrate(std::shared_ptr<const CameraRig> rig, const RigWarp& warp,
                        const SE3d& new_from_old) {
  if (camera_from_world_) SetPose(new_from_old * *camera_from_world_);
  rig_ = std::move(rig);
  if (keypoints_un_.empty()) return;
  RecalibrateFeatures(*rig_, warp, &keypoints_, &keypoints_un_, &right_u_, &depth_);
  grid_ = FeatureGrid(keypoints_un_, rig_->bounds);
}

void Frame::ComputeBoW(const Vocabulary& vocabulary) {
  if (bow_computed_) return;
  vocabulary.Transform(descriptors_, &bow_, &feature_vector_);
  bow_computed_ = true;
}

void Frame::SetPose(const SE3d& camera_from_world) {
  camera_from_world_ = camera_from_world;
  world_from_camera_ = camera_from_world.Inverse();
}

double Frame::DisparityInformation(int i) const {
  if (depth_sigma_.empty() || !HasDepth(i)) return 0.0;
  return pkslam::DisparityInformation(rig_->bf, depth_[i], depth_sigma_[i]);
}

std::optional<Eigen::Vector3d> Frame::UnprojectToCamera(int i) const {
  if (!HasDepth(i)) return std::nullopt;
  const double z = depth_[i];
  const cv::Point2f& p = keypoints_un_[i].pt;
  return Eigen::Vector3d((p.x - rig_->cx) * z * rig_->inv_fx, (p.y - rig_->cy) * z * rig_->inv_fy,
                         z);
}

std::optional<Eigen::Vector3d> Frame::UnprojectStereo(int i) const {
  const auto p = UnprojectToCamera(i);
  if (!p || !HasPose()) return std::nullopt;
  return world_from_camera_ * *p;
}

int Frame::NumTrackedMapPoints() const {
  int n = 0;
  for (std::size_t i = 0; i < map_points.size(); ++i) {
    if (map_points[i] && !outliers[i]) ++n;
  }
  return n;
}

}  // namespace pkslam
