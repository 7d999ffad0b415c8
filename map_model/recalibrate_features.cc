#include "map_model/recalibrate_features.h"

namespace pkslam {

void RecalibrateFeatures(const CameraRig& rig, const RigWarp& warp,
                         std::vector<cv::KeyPoint>* keypoints,
                         std::vector<cv::KeyPoint>* keypoints_undistorted,
                         std::vector<float>* right_u, std::vector<float>* depth) {
  const bool stereo = IsStereo(rig.sensor);
  const bool rgbd = IsRgbd(rig.sensor);
  for (std::size_t i = 0; i < keypoints_undistorted->size(); ++i) {
    cv::KeyPoint& kp = (*keypoints_undistorted)[i];
    const Eigen::Vector2d old_uv(kp.pt.x, kp.pt.y);
    const auto uv = warp.Left(old_uv);
    if (uv) {
      kp.pt = cv::Point2f(static_cast<float>(uv->x()), static_cast<float>(uv->y()));
      if (stereo) (*keypoints)[i].pt = kp.pt;
    }
    const bool has_right = !right_u->empty() && (*right_u)[i] >= 0;
    if (!has_right) continue;
    if (rgbd) {
      (*right_u)[i] = static_cast<float>(kp.pt.x - rig.bf / (*depth)[i]);
      continue;
    }
    const auto right = uv ? warp.Right(Eigen::Vector2d((*right_u)[i], old_uv.y())) : std::nullopt;
    const double disparity = right ? kp.pt.x - right->x() : -1.0;
    if (disparity > 0) {
      (*right_u)[i] = static_cast<float>(right->x());
      (*depth)[i] = static_cast<float>(rig.bf / disparity);
    } else {
      (*right_u)[i] = -1.0f;
      (*depth)[i] = -1.0f;
    }
  }
}

}  // namespace pkslam
